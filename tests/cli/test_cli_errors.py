"""The ``mcengine`` command line: every bad input fails with one line, renders work.

The command runs as a subprocess, as a user runs it (the installed console
script next to this Python).  Small scenes are written by a bpy subprocess once
per module; the argument helpers are also tested in-process, without bpy.
"""
from __future__ import annotations

import hashlib
import io
import re
import struct
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from mcengine_blender.batch.render import error_message
from mcengine_blender.cli.args import ZSTD_MAGIC, _output_for
from mcengine_blender.cli.console import PROGRESS_BAR_WIDTH, Progress, engine_traceback, warning_lines
from mcengine_blender.cli.errors import EXIT_BAD_INPUT, EXIT_RENDER_FAILED
from mcengine_blender.cli.frames import frame_path

REPO = Path(__file__).resolve().parents[2]
MCENGINE = Path(sys.executable).with_name("mcengine")
CORNELL_BOX = REPO / "blend_scenes" / "cornell_box.blend"
RENDER_TIMEOUT = 300  # seconds; a tiny render takes a few, JIT compilation more

MAKE_SCENES = textwrap.dedent("""
    import sys
    import bpy
    out = sys.argv[1]
    bpy.ops.wm.read_factory_settings(use_empty=False)  # cube, light, camera
    scene = bpy.context.scene
    scene.frame_current = 7
    bpy.ops.wm.save_as_mainfile(filepath=out + "/tiny.blend")
    layer = scene.view_layers[0]
    layer.use_pass_z = layer.use_pass_normal = layer.use_pass_cryptomatte_object = True
    bpy.ops.wm.save_as_mainfile(filepath=out + "/passes.blend")
    layer.use_pass_z = layer.use_pass_normal = layer.use_pass_cryptomatte_object = False
    bpy.data.objects.remove(bpy.data.objects["Camera"])
    bpy.ops.wm.save_as_mainfile(filepath=out + "/nocamera.blend")
""")


def run_cli(*args, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([str(MCENGINE), *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=RENDER_TIMEOUT, stdin=subprocess.DEVNULL)


def assert_one_line_error(done: subprocess.CompletedProcess, exit_code: int, *fragments: str) -> None:
    lines = done.stderr.splitlines()
    assert done.returncode == exit_code, done.stderr
    assert "Traceback" not in done.stderr + done.stdout
    assert done.stdout == ""
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("mcengine: error: ")
    for fragment in fragments:
        assert fragment in lines[0]


def read_exr(path: Path) -> np.ndarray:
    import OpenEXR
    with OpenEXR.File(str(path)) as exr:
        channels = exr.parts[0].channels
        assert list(channels) == ["RGBA"], list(channels)
        return channels["RGBA"].pixels


def png_header(path: Path) -> tuple[int, int, int, int]:
    """(width, height, bit depth, colour type) from a PNG's IHDR chunk."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width, height, depth, colour_type = struct.unpack(">IIBB", data[16:26])
    return width, height, depth, colour_type


PNG_RGBA = 6  # PNG colour type of 8-bit RGBA with the depth byte == 8


@pytest.fixture(scope="module")
def scenes(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("scenes")
    done = subprocess.run([sys.executable, "-c", MAKE_SCENES, str(folder)],
                          capture_output=True, text=True, timeout=RENDER_TIMEOUT)
    assert done.returncode == 0, done.stderr
    return folder


@pytest.fixture(scope="module")
def bad_files(tmp_path_factory, scenes) -> Path:
    """Text, a zstd stream that is not a .blend, a truncated .blend, folders and a plain file."""
    import zstandard
    folder = tmp_path_factory.mktemp("bad")
    (folder / "notes.blend").write_text("not a blend file\n")
    (folder / "packed.blend").write_bytes(zstandard.ZstdCompressor().compress(b"PK\x03\x04 zip" * 100))
    (folder / "truncated.blend").write_bytes(_raw_blend(scenes / "tiny.blend")[:4000])
    (folder / "afolder.blend").mkdir()
    (folder / "afolder.exr").mkdir()
    (folder / "afile").write_text("x")
    return folder


def _raw_blend(path: Path) -> bytes:
    """Uncompressed bytes of a .blend (Blender 5 saves zstd-compressed files)."""
    import zstandard
    data = path.read_bytes()
    if data.startswith(ZSTD_MAGIC):
        return zstandard.ZstdDecompressor().stream_reader(io.BytesIO(data)).read()
    return data


# ---------------------------------------------------------------------------
# Bad input: one line on stderr, non-zero exit, nothing rendered
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("args, fragments", [
    ([], ["no command"]),
    (["render"], ["SCENE.blend"]),
    (["render", "{bad}/missing.blend"], ["file not found"]),
    (["render", "{bad}/notes.blend"], ["not a .blend file"]),
    (["render", "{bad}/packed.blend"], ["not a .blend file"]),
    (["render", "{bad}/afolder.blend"], ["not a file"]),
    (["render", "{tiny}", "--engine", "eevee"], ["unknown engine 'eevee'"]),
    (["-b", "{tiny}", "-E", "BLENDER_EEVEE", "-f", "1"], ["unknown engine"]),
    (["render", "{tiny}", "--resolution", "0x5"], ["0x5", "4..65536"]),
    (["render", "{tiny}", "--resolution", "abc"], ["640x480", "'abc'"]),
    (["render", "{tiny}", "--samples", "0"], ["sample count", "got 0"]),
    (["render", "{tiny}", "--samples", "-3"], ["sample count", "got -3"]),
    (["render", "{tiny}", "--samples", "x"], ["sample count", "'x'"]),
    (["render", "{tiny}", "--seed", "-1"], ["seed"]),
    (["render", "{tiny}", "-f", "1,,3"], ["incorrect comma use"]),
    (["-b", "{tiny}", "-a", "-s", "3"], ["put -s before -a/-f"]),
    (["render", "{tiny}", "-o", "{bad}/missing-dir/out.exr"], ["output folder does not exist"]),
    (["render", "{tiny}", "-o", "{bad}/afile/out.exr"], ["not a folder"]),
    (["render", "{tiny}", "-o", "/proc/out.exr"], ["cannot write to output folder /proc"]),
    (["render", "{tiny}", "-o", "{bad}/afolder.exr"], ["output path is a folder"]),
    (["render", "{tiny}", "-o", "{bad}/out.jpg"], ["unsupported output type '.jpg'"]),
    (["render", "{tiny}", "-o", "{bad}/out.png", "-F", "OPEN_EXR"], ["extension .png", "OPEN_EXR"]),
    (["render", "{tiny}", "-F", "TIFF"], ["unsupported format 'TIFF'"]),
    (["-b", "{tiny}", "-P", "script.py", "-a"], ["-P is not supported"]),
    (["render", "{tiny}", "--bogus"], ["unrecognized arguments: --bogus"]),
])
def test_bad_input_is_one_line_and_exit_2(args, fragments, scenes, bad_files):
    args = [arg.format(tiny=scenes / "tiny.blend", bad=bad_files) for arg in args]
    done = run_cli(*args)
    assert_one_line_error(done, EXIT_BAD_INPUT, *fragments)


def test_corrupt_blend_reports_blenders_reason(bad_files, tmp_path):
    done = run_cli("render", bad_files / "truncated.blend", "--engine", "cycles", "-o", tmp_path / "x.exr")
    assert_one_line_error(done, EXIT_RENDER_FAILED, "cannot open", "truncated.blend")
    assert not (tmp_path / "x.exr").exists()


def test_failed_render_reports_engine_error(scenes, tmp_path):
    done = run_cli("render", scenes / "nocamera.blend", "--engine", "cycles", "--resolution", "16x16",
                   "--samples", "1", "-o", tmp_path / "x.exr")
    assert_one_line_error(done, EXIT_RENDER_FAILED, "render failed", "camera")
    assert not (tmp_path / "x.exr").exists()


def test_bad_input_fails_before_importing_blender(scenes):
    """Argument errors must not pay bpy's start-up (about a second), nor its log."""
    code = ("import sys; from mcengine_blender import cli; "
            f"code = cli.main(['render', {str(scenes / 'tiny.blend')!r}, '--samples', '0']); "
            "print('bpy imported' if 'bpy' in sys.modules else 'bpy not imported'); sys.exit(code)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == EXIT_BAD_INPUT, done.stderr
    assert done.stdout.strip() == "bpy not imported", (
        "importing mcengine_blender.cli imported bpy: addon/__init__.py (run for every CLI call) "
        "must import its bpy modules inside register()/unregister()")


def test_runs_as_a_module(bad_files):
    """``python -m mcengine_blender.cli`` is the ``mcengine`` command."""
    done = subprocess.run([sys.executable, "-m", "mcengine_blender.cli", "render",
                           str(bad_files / "missing.blend")], capture_output=True, text=True,
                          timeout=60, stdin=subprocess.DEVNULL)
    assert_one_line_error(done, EXIT_BAD_INPUT, "file not found")


# ---------------------------------------------------------------------------
# Successful renders
# ---------------------------------------------------------------------------

def test_cycles_render_writes_float_exr_with_progress(scenes, tmp_path):
    out = tmp_path / "cycles.exr"
    done = run_cli("render", scenes / "tiny.blend", "--engine", "cycles", "--samples", "4",
                   "--resolution", "16x16", "--seed", "3", "-o", out)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [str(out)]
    assert "Traceback" not in done.stderr
    # Not a terminal: one plain progress line per 10 %, ending at 100 %.
    assert re.search(r"^CYCLES: 100% \(sample 4/4, ", done.stderr, re.MULTILINE), done.stderr
    assert "\r" not in done.stderr
    rgba = read_exr(out)
    assert rgba.shape == (16, 16, 4) and rgba.dtype == np.float32
    assert np.isfinite(rgba).all()
    assert rgba[..., :3].max() > 0.01  # the lit default cube, not a black frame
    assert np.all(rgba[..., 3] == 1.0)  # opaque film: the world covers every pixel


def test_blender_syntax_with_frame_padding_and_relative_path(scenes):
    blend = scenes / "tiny.blend"
    before = hashlib.sha256(blend.read_bytes()).hexdigest()
    args = ["-b", blend, "-E", "cycles", "-o", "//frames/out_####", "-F", "PNG", "-f", "12",
            "--resolution", "20x12", "--samples", "1"]
    # "//" is the .blend's folder, so the missing "frames" folder is found there first.
    assert_one_line_error(run_cli(*args), EXIT_BAD_INPUT, f"does not exist: {scenes / 'frames'}")
    (scenes / "frames").mkdir()
    done = run_cli(*args)
    expected = scenes / "frames" / "out_0012.png"
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [str(expected)]
    assert png_header(expected) == (20, 12, 8, PNG_RGBA)
    assert "frame 12" in done.stderr
    # Overrides apply to the render only; the .blend on disk is untouched.
    assert hashlib.sha256(blend.read_bytes()).hexdigest() == before


def test_one_render_saved_as_exr_and_png(scenes, tmp_path):
    exr, png = tmp_path / "both.exr", tmp_path / "both.png"
    done = run_cli("render", scenes / "tiny.blend", "--engine", "cycles", "--samples", "2",
                   "--resolution", "8x6", "-o", exr, "-o", png)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [str(exr), str(png)]
    assert read_exr(exr).shape == (6, 8, 4)
    assert png_header(png) == (8, 6, 8, PNG_RGBA)


def test_mcengine_render_writes_float_exr(scenes, tmp_path):
    out = tmp_path / "mcengine.exr"
    done = run_cli("render", scenes / "tiny.blend", "--engine", "mcengine", "--samples", "4",
                   "--resolution", "16x16", "-o", out)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [str(out)]
    assert re.search(r"^MCENGINE: 100% \(sample 4/4, ", done.stderr, re.MULTILINE), done.stderr
    rgba = read_exr(out)
    assert rgba.shape == (16, 16, 4)
    assert np.isfinite(rgba).all()
    assert rgba[..., :3].max() > 0.01


def test_multilayer_exr_holds_the_passes_and_metadata(scenes, tmp_path):
    from mcengine.imageio import read_exr_header, read_exr_layers
    out = tmp_path / "layers.exr"
    done = run_cli("render", scenes / "passes.blend", "--samples", "4", "--resolution", "16x12",
                   "-F", "OPEN_EXR_MULTILAYER", "-o", out)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [str(out)]
    layers = read_exr_layers(out)
    assert {"ViewLayer.Combined", "ViewLayer.Depth.Z", "ViewLayer.Normal.X",
            "ViewLayer.CryptoObject02.r"} <= set(layers), sorted(layers)
    assert layers["ViewLayer.Combined"].shape == (12, 16, 4)
    depth = layers["ViewLayer.Depth.Z"]
    assert 0 < depth.min() < 20 and depth.max() == np.float32(1e10)   # the cube and the sky
    header = read_exr_header(out)
    assert header["mcengine.ViewLayer.samples"] == "4"
    manifests = [v for k, v in header.items() if k.startswith("cryptomatte/") and k.endswith("manifest")]
    assert manifests and '"Cube"' in manifests[0]


# ---------------------------------------------------------------------------
# Helpers, in-process (no bpy)
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("raw, fmt, frame, expected", [
    ("//out_####", None, 7, "{blend_dir}/out_0007.exr"),
    ("//a#/b_##_v##.png", None, 3, "{blend_dir}/a#/b_##_v03.png"),
    ("renders/", "PNG", 12, "{cwd}/renders/0012.png"),
    ("x.final", None, 1, "{cwd}/x.final.exr"),
    ("shot.EXR", "OPEN_EXR", 1, "{cwd}/shot.EXR"),
    ("shot", "OPEN_EXR_MULTILAYER", 1, "{cwd}/shot.exr"),
    ("shot.exr", "OPEN_EXR_MULTILAYER", 1, "{cwd}/shot.exr"),
])
def test_output_paths_follow_blender(raw, fmt, frame, expected, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    blend_dir = tmp_path / "scenes"
    output = _output_for(raw, fmt, blend_dir)
    path = frame_path(output.pattern, frame)
    assert str(path) == expected.format(blend_dir=blend_dir, cwd=tmp_path)
    assert output.file_format == (fmt or ("PNG" if raw.endswith(".png") else "OPEN_EXR"))


def test_progress_prints_a_line_per_tenth_when_not_a_terminal():
    stream = io.StringIO()
    progress = Progress(stream, "MCENGINE")
    progress.update("Mem: 2M | Synchronizing object | Cube")
    for sample in range(1, 21):
        progress.on_stats(f"Remaining: 00:01.00 | Mem: 2M | Sample {sample}/20")
    progress.finish()
    lines = stream.getvalue().splitlines()
    percents = [int(re.match(r"MCENGINE: (\d+)%", line)[1]) for line in lines]
    assert percents == [10, 20, 30, 40, 50, 60, 70, 80, 90, 100]


def test_progress_redraws_one_line_on_a_terminal():
    class Terminal(io.StringIO):
        def isatty(self):
            return True

    stream = Terminal()
    progress = Progress(stream, "CYCLES")
    for sample in (1, 2, 4):
        progress.on_stats(f"Sample {sample}/4")
    progress.on_stats(None)  # handlers must never raise
    progress.finish()
    text = stream.getvalue()
    assert "\n" not in text
    assert text.count("\r") == 4
    assert "[" + "#" * PROGRESS_BAR_WIDTH + "] 100%" in text


def test_engine_crash_is_found_in_blenders_log():
    log = ("00:01.0 render | Saved: '/tmp/x.exr'\n"
           "Traceback (most recent call last):\n"
           '  File "engine.py", line 3, in render\n'
           "    raise ValueError('no lights')\n"
           "ValueError: no lights\n"
           "Warning: textures are ignored, using base colour\n")
    assert engine_traceback(log) == "ValueError: no lights"
    assert engine_traceback("Warning: x\n") is None
    assert warning_lines(log) == ["textures are ignored, using base colour"]


def test_operator_errors_become_one_line():
    error = RuntimeError("Error: No camera found in scene\nError: No camera found in scene\n")
    assert error_message(error) == "No camera found in scene"
