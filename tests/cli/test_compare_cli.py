"""``mcengine compare``: bad input in one line, the files a comparison writes, exit codes.

The command runs as a subprocess, as a user runs it.  Comparisons are tiny
(16 x 16 to 32 x 32 pixels, 8 to 16 samples) since only the command and its
files are under test here; the verdict's statistics are tested in
tests/core/test_compare_stats.py and on real scenes in tests/fidelity.
"""
from __future__ import annotations

import json
import shutil
import struct
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from mcengine_blender.cli.errors import EXIT_BAD_INPUT, EXIT_DIFFER, EXIT_OK, EXIT_RENDER_FAILED

REPO = Path(__file__).resolve().parents[2]
MCENGINE = Path(sys.executable).with_name("mcengine")
CORNELL_BOX = REPO / "blend_scenes" / "cornell_box.blend"
TIMEOUT = 300  # seconds; a tiny comparison takes seconds, JIT compilation more

# A plane under a sun, once plain and once with a Curves Info node's Is Strand as its colour
# (which MC Engine does not support, so that comparison must say "differ"), and a
# scene without a camera (the renders fail).
MAKE_SCENES = textwrap.dedent("""
    import sys
    import bpy
    out = sys.argv[1]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = 32
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, 0.0, 4.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    mesh = bpy.data.meshes.new("Plane")
    mesh.from_pydata([(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], [], [(0, 1, 2, 3)])
    mat = bpy.data.materials.new("Grey")
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    mesh.materials.append(mat)
    scene.collection.objects.link(bpy.data.objects.new("Plane", mesh))
    scene.collection.objects.link(bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN")))
    bpy.ops.wm.save_as_mainfile(filepath=out + "/plain.blend")
    info = mat.node_tree.nodes.new("ShaderNodeHairInfo")
    mat.node_tree.links.new(info.outputs["Is Strand"], bsdf.inputs["Base Color"])
    bpy.ops.wm.save_as_mainfile(filepath=out + "/textured.blend")
    scene.camera = None
    bpy.data.objects.remove(cam)
    bpy.ops.wm.save_as_mainfile(filepath=out + "/nocamera.blend")
""")


def run_cli(*args, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([str(MCENGINE), *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=TIMEOUT, stdin=subprocess.DEVNULL)


def assert_one_line_error(done, exit_code: int, *fragments: str) -> None:
    lines = done.stderr.splitlines()
    assert done.returncode == exit_code, done.stderr
    assert "Traceback" not in done.stderr + done.stdout
    assert done.stdout == ""
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("mcengine: error: ")
    for fragment in fragments:
        assert fragment in lines[0]


def png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


@pytest.fixture(scope="module")
def scenes(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("compare_scenes")
    done = subprocess.run([sys.executable, "-c", MAKE_SCENES, str(folder)],
                          capture_output=True, text=True, timeout=TIMEOUT)
    assert done.returncode == 0, done.stderr
    return folder


# ---------------------------------------------------------------------------
# Bad input: exit 2 before Blender starts
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("args, fragments", [
    (["compare"], ["either SCENE.blend or --suite"]),
    (["compare", "{plain}", "--suite", "{folder}"], ["either SCENE.blend or --suite"]),
    (["compare", "{folder}/missing.blend"], ["file not found"]),
    (["compare", "--suite", "{folder}/missing"], ["suite folder not found"]),
    (["compare", "--suite", "{plain}"], ["needs a folder"]),
    (["compare", "--suite", "{empty}"], ["no .blend files in"]),
    (["compare", "--suite", "{folder}", "-S", "Scene"], ["cannot be used with --suite"]),
    (["compare", "{plain}", "--seeds", "1"], ["at least 2 seeds"]),
    (["compare", "{plain}", "--seeds", "65"], ["between 1 and 64"]),
    (["compare", "{plain}", "--resolution", "4x4"], ["too small", "8x8 block grid"]),
    (["compare", "{plain}", "--resolution", "0%"], ["percentage", "got 0"]),
    (["compare", "{plain}", "--resolution", "big"], ["640x480"]),
    (["compare", "{plain}", "--alpha", "1"], ["alpha", "between 0 and 1"]),
    (["compare", "{plain}", "--samples", "0"], ["sample count"]),
    (["compare", "{plain}", "--out", "{plain}"], ["not a folder"]),
    (["compare", "{plain}", "--out", "/proc/nope"], ["cannot write to output folder"]),
])
def test_bad_input_is_one_line_and_exit_2(args, fragments, scenes, tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    args = [a.format(plain=scenes / "plain.blend", folder=scenes, empty=empty) for a in args]
    assert_one_line_error(run_cli(*args, cwd=tmp_path), EXIT_BAD_INPUT, *fragments)


def test_bad_input_fails_before_importing_blender(scenes):
    code = ("import sys; from mcengine_blender import cli; "
            f"code = cli.main(['compare', {str(scenes / 'plain.blend')!r}, '--seeds', '1']); "
            "print('bpy imported' if 'bpy' in sys.modules else 'bpy not imported'); sys.exit(code)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == EXIT_BAD_INPUT, done.stderr
    assert done.stdout.strip() == "bpy not imported"


# ---------------------------------------------------------------------------
# Comparisons
# ---------------------------------------------------------------------------

def test_compare_writes_every_file_and_exits_0_on_agree(tmp_path):
    out = tmp_path / "new" / "out"  # created, with its parent
    done = run_cli("compare", CORNELL_BOX, "--samples", "16", "--resolution", "32x32",
                   "--out", out)
    assert done.returncode == EXIT_OK, done.stderr
    assert done.stdout == f"{out / 'report.json'}\n"
    assert "Traceback" not in done.stderr
    report = json.loads((out / "report.json").read_text())
    assert report["verdict"] == "agree"
    assert report["settings"]["resolution"] == [32, 32]
    assert report["settings"]["seeds"] == {"mcengine": [1, 2], "cycles": [1, 2]}
    # Denoising (on in most users' files) is turned off for both engines, and the report says so.
    assert report["settings"]["denoising, adaptive sampling, clamping"] == "off"
    assert set(report["metrics"]) == {"relmse", "smape", "flip"}
    assert 0.0 <= report["metrics"]["flip"] < 1.0
    for engine in ("mcengine", "cycles"):
        assert len(report["times"][engine]["renders"]) == 2
        for ch in "RGB":
            lo, hi = report["means"][engine][ch]["ci"]
            assert lo < report["means"][engine][ch]["mean"] < hi
    width, height = png_size(out / "side_by_side.png")
    assert width > 4 * 32 and height > 32
    markdown = (out / "report.md").read_text()
    assert "**Verdict: AGREE**" in markdown and "mean HDR-FLIP" in markdown
    assert "denoising, adaptive sampling, clamping" in markdown
    from mcengine.imageio import read_exr
    for name in ("mcengine.exr", "cycles.exr"):
        image = read_exr(out / name)
        assert image.shape == (32, 32, 4) and image[..., :3].mean() > 0.1
    assert "cornell_box: agree" in done.stderr


def test_compare_exits_3_on_differ_and_says_why(scenes, tmp_path):
    done = run_cli("compare", scenes / "textured.blend", "--samples", "8", "--resolution", "16x16",
                   "--out", tmp_path)
    assert done.returncode == EXIT_DIFFER, done.stderr
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["verdict"] == "differ"
    assert report["regions"], "the dark plane should show as regions"
    assert "HairInfo" in (tmp_path / "report.md").read_text()
    assert "warning:" in done.stderr and "textured: differ" in done.stderr


def test_failed_render_is_one_line_and_exit_1(scenes, tmp_path):
    done = run_cli("compare", scenes / "nocamera.blend", "--samples", "4", "--resolution", "16x16",
                   "--out", tmp_path)
    assert_one_line_error(done, EXIT_RENDER_FAILED, "render failed", "camera")


def test_suite_writes_one_summary_and_keeps_going_after_a_failure(scenes, tmp_path):
    folder = tmp_path / "suite"
    folder.mkdir()
    for name in ("plain", "textured", "nocamera"):
        shutil.copy(scenes / f"{name}.blend", folder)
    out = tmp_path / "out"
    done = run_cli("compare", "--suite", folder, "--samples", "8", "--resolution", "50%",
                   "--out", out)
    assert done.returncode == EXIT_RENDER_FAILED, done.stderr  # a failure outranks a differ
    assert done.stdout == f"{out / 'summary.json'}\n"
    summary = json.loads((out / "summary.json").read_text())
    verdicts = {row["scene"]: row["verdict"] for row in summary["scenes"]}
    assert verdicts == {"nocamera": "error", "plain": "agree", "textured": "differ"}
    assert (out / "plain" / "report.json").is_file() and (out / "textured" / "thumbnail.png").is_file()
    markdown, page = (out / "summary.md").read_text(), (out / "summary.html").read_text()
    assert "| [plain](plain/report.md) | agree |" in markdown
    assert "**differ**" in markdown and "**error**" in markdown
    assert '<img src="textured/thumbnail.png"' in page
    assert "1/3 scenes agree" in done.stderr


# ---------------------------------------------------------------------------
# Non-finite samples in the report
# ---------------------------------------------------------------------------

# The command, with every MC Engine render made to report 5 dropped samples
# (the count the render session keeps in RenderStats.nonfinite).
WITH_NONFINITE = textwrap.dedent("""
    import sys
    from mcengine import session
    run = session.RenderSession.run
    def run_dropping_five(self, *args, **kwargs):
        result = run(self, *args, **kwargs)
        self.stats.nonfinite += 5
        return result
    session.RenderSession.run = run_dropping_five
    from mcengine_blender import cli
    sys.exit(cli.main(sys.argv[1:]))
""")


def test_nonfinite_samples_are_reported_summed_over_the_renders(scenes, tmp_path):
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-c", WITH_NONFINITE, "compare", str(scenes / "plain.blend"),
                           "--samples", "8", "--resolution", "16x16", "--seeds", "3", "--out", str(out)],
                          capture_output=True, text=True, timeout=TIMEOUT, stdin=subprocess.DEVNULL)
    assert done.returncode == EXIT_OK, done.stderr
    report = json.loads((out / "report.json").read_text())
    assert report["nonfinite_samples"] == 3 * 5
    markdown = (out / "report.md").read_text()
    assert "| non-finite samples dropped (all renders) | 15 | |" in markdown
    assert "dropped 15 non-finite samples" in markdown


def test_no_nonfinite_field_when_none_were_dropped():
    import numpy as np

    from mcengine.evaluation.comparison import EngineRuns, build_comparison, suite_row
    from mcengine.evaluation.pages import report_markdown, suite_summary_markdown
    rng = np.random.default_rng(1)

    def runs(nonfinite):
        return EngineRuns(images=rng.uniform(0.4, 0.6, (2, 16, 16, 4)).astype(np.float32),
                          seconds=[1.0, 1.0], samples=8, seeds=[1, 2], nonfinite=nonfinite)

    clean = build_comparison("clean", runs(0), runs(0))
    assert "nonfinite_samples" not in clean.report
    assert "non-finite" not in report_markdown(clean)
    dropped = build_comparison("dropped", runs(1234), runs(0))
    assert dropped.report["nonfinite_samples"] == 1234
    assert "non-finite samples dropped (all renders) | 1,234 |" in report_markdown(dropped)
    rows = [suite_row(clean, "clean"), suite_row(dropped, "dropped")]
    assert [row.nonfinite for row in rows] == [0, 1234]
    assert "MC Engine dropped non-finite samples in: dropped (1,234)." in suite_summary_markdown(rows)
