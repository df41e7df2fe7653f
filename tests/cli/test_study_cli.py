"""``mcengine study`` and ``render --integrator``: bad input in one line, the study's files,
the ray accounting line.

Argument errors are checked in-process (they must fail before bpy is
imported); the study and the render run as subprocesses, as a user runs
them, on Blender's default cube at 16 x 12 pixels with 1 and 2 samples: only
the command and its files are under test here (the study's statistics are in
tests/core/test_study.py).
"""
from __future__ import annotations

import csv
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from mcengine_blender import cli
from mcengine_blender.cli.errors import EXIT_BAD_INPUT, EXIT_RENDER_FAILED

MCENGINE = Path(sys.executable).with_name("mcengine")
TIMEOUT = 300  # seconds; the tiny study takes about 15, JIT compilation more

MAKE_SCENES = textwrap.dedent("""
    import sys
    import bpy
    out = sys.argv[1]
    bpy.ops.wm.read_factory_settings(use_empty=False)  # cube, light, camera
    bpy.ops.wm.save_as_mainfile(filepath=out + "/cube.blend")
    bpy.data.objects.remove(bpy.data.objects["Camera"])
    bpy.ops.wm.save_as_mainfile(filepath=out + "/nocamera.blend")
""")


@pytest.fixture(scope="module")
def scenes(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("scenes")
    done = subprocess.run([sys.executable, "-c", MAKE_SCENES, str(folder)],
                          capture_output=True, text=True, timeout=TIMEOUT)
    assert done.returncode == 0, done.stderr
    return folder


def run_cli(*args) -> subprocess.CompletedProcess:
    return subprocess.run([str(MCENGINE), *map(str, args)], capture_output=True, text=True,
                          timeout=TIMEOUT, stdin=subprocess.DEVNULL)


@pytest.mark.parametrize("args, fragment", [
    (["study", "{cube}", "--integrators", "path,bidir"], "unknown integrator 'bidir'"),
    (["study", "{cube}", "--integrators", "path,path"], "listed twice"),
    (["study", "{cube}", "--integrators", ","], "at least one name"),
    (["study", "{cube}", "--max-samples", "0"], "largest sample count must be between 1"),
    (["study", "{cube}", "--seeds", "1"], "at least 2 seeds"),
    (["study", "{cube}", "--resolution", "2x2"], "outside Blender's range"),
    (["study", "{cube}", "--target", "0"], "target relMSE must be positive"),
    (["study", "{cube}", "--max-samples", "64", "--reference-samples", "100"],
     "--reference-samples 100 is too few"),
    (["study", "{cube}", "--integrators", "path,raycast", "--branching", "3"],
     "--branching applies to the distribution integrator only"),
    (["study", "{cube}", "--integrators", "path", "--depth", "3"],
     "--depth applies to the whitted and distribution integrators only"),
    (["study", "{missing}"], "file not found"),
    (["study", "{cube}", "--out", "{cube}"], "output path is not a folder"),
    (["render", "{cube}", "--integrator", "bidir"], "unknown integrator 'bidir'"),
    (["render", "{cube}", "--integrator", "whitted", "--depth", "0"], "depth must be between 1 and 16"),
    (["render", "{cube}", "--branching", "65"], "branching must be between 1 and 64"),
    (["render", "{cube}", "--integrator", "path", "--depth", "4"], "--depth applies to"),
    (["render", "{cube}", "--integrator", "whitted", "--branching", "4"], "--branching applies to"),
    (["render", "{cube}", "--engine", "cycles", "--integrator", "raycast"],
     "do not apply to --engine cycles"),
    (["render", "{cube}", "--sampler", "halton"], "unknown sampler 'halton'"),
    (["render", "{cube}", "--integrator", "whitted", "--sampler", "sobol"],
     "--sampler applies to the path and light integrators only"),
    (["render", "{cube}", "--engine", "cycles", "--sampler", "independent"],
     "do not apply to --engine cycles"),
    (["study", "{cube}", "--integrators", "raycast", "--sampler", "independent"],
     "--sampler applies to the path and light integrators only"),
])
def test_bad_options_are_one_line_before_blender_starts(args, fragment, scenes, capsys):
    args = [a.format(cube=scenes / "cube.blend", missing=scenes / "missing.blend") for a in args]
    assert cli.main(args) == EXIT_BAD_INPUT
    out, err = capsys.readouterr()
    assert out == ""
    assert len(err.splitlines()) == 1 and err.startswith("mcengine: error: "), err
    assert fragment in err


def test_bad_study_options_fail_before_importing_blender(scenes):
    code = ("import sys; from mcengine_blender import cli; "
            f"code = cli.main(['study', {str(scenes / 'cube.blend')!r}, '--seeds', '1']); "
            "print('bpy imported' if 'bpy' in sys.modules else 'bpy not imported'); sys.exit(code)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == EXIT_BAD_INPUT, done.stderr
    assert done.stdout.strip() == "bpy not imported"


def test_study_writes_one_row_per_render_and_the_report(scenes, tmp_path):
    out = tmp_path / "study"
    done = run_cli("study", scenes / "cube.blend", "--max-samples", "2", "--seeds", "2",
                   "--resolution", "16x12", "--integrators", "path,raycast", "--with-cycles",
                   "--sampler", "independent", "--out", out)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [str(out / "study.html")]
    with open(out / "study.csv", newline="") as f:
        reader = csv.DictReader(f)
        rows = list(reader)
    assert reader.fieldnames == ["integrator", "samples", "seed", "replicate", "seconds", "relmse",
                                 "relmse_untrimmed", "smape", "reference"]
    assert [(r["integrator"], r["samples"], r["replicate"]) for r in rows] == [
        (m, n, k) for m in ("path", "raycast", "cycles") for n in ("1", "2") for k in ("0", "1")]
    assert all(float(r["seconds"]) > 0 and float(r["relmse"]) > 0 for r in rows)
    assert {r["reference"] for r in rows if r["integrator"] == "cycles"} == {"cycles"}
    for name in ("error_vs_time.png", "error_vs_samples.png", "equal_time.png", "study.md",
                 "study.json"):
        assert (out / name).is_file(), name
    assert "| Path tracing (Independent sampler) |" in (out / "study.md").read_text()
    # one line per render (4 + 4 references, 1 warm-up, 12 ladder renders), one per integrator
    assert "mcengine: [21/21] cycles 2 samples, seed 1002" in done.stderr
    assert "mcengine: raycast: " in done.stderr and "Traceback" not in done.stderr


def test_study_of_a_scene_without_camera_fails_in_one_line(scenes, tmp_path):
    done = run_cli("study", scenes / "nocamera.blend", "--max-samples", "1", "--seeds", "2",
                   "--resolution", "8x8", "--integrators", "path", "--out", tmp_path)
    assert done.returncode == EXIT_RENDER_FAILED, done.stderr
    lines = done.stderr.splitlines()
    assert lines[-1].startswith("mcengine: error: path render failed") and "camera" in lines[-1]
    assert "Traceback" not in done.stderr and done.stdout == ""


def test_render_with_an_integrator_prints_its_ray_accounting(scenes, tmp_path):
    out = tmp_path / "whitted.exr"
    done = run_cli("render", scenes / "cube.blend", "--integrator", "whitted", "--depth", "3",
                   "--samples", "2", "--resolution", "16x12", "-o", out)
    assert done.returncode == 0, done.stderr
    accounting = [line for line in done.stderr.splitlines() if "rays/pixel" in line]
    assert len(accounting) == 1, done.stderr
    line = accounting[0]
    # two camera rays per pixel; the default cube has no mirror, so Whitted casts no bounce ray
    assert line.startswith("mcengine: rays/pixel: camera 2.0, bounce 0.0, shadow ")
    for phase in ("Mrays/s", "export", "pack", "BVH", "kernels", "tracing", "shading"):
        assert phase in line
