"""Animations and frame lists from the command line, as a render farm runs them.

The scene: an orthographic camera looking straight down at an emissive square
(0.5 units wide, 8 x 8 pixels of 64 x 64) whose position and emission strength
are keyframed linearly from x = -1, strength 1 at frame 1 to x = +1, strength 5
at frame 5 (y = 0.25 throughout; black world).  Seen directly, an emitter of
strength s gives pixels of value s, so frame f has, in closed form:

* the centroid of the red channel at 32 + 16 x(f) px from the left, with
  x(f) = -1 + (f - 1) / 2 units (16 px per unit), and 28 px from the top
  (pixel centres at i + 0.5; the Blackman-Harris filter is symmetric, so it
  moves no centroid);
* a total flux of f x 64 (the square's 64 pixels).

At 64 samples the measured seed-to-seed spread (8 seeds x 5 frames) is
0.017 px for a centroid coordinate and 0.48 % for the flux; the bounds below,
0.1 px and 3 %, are six standard deviations.  A frame rendered at the wrong
time is off by 8 px and 20 % or more.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from mcengine.imageio import read_exr
from mcengine_blender.cli.errors import EXIT_INTERRUPTED

MCENGINE = Path(sys.executable).with_name("mcengine")
TIMEOUT = 300
PREVIOUS = b"an image from an earlier run, which must survive\n" * 50

MAKE_SCENE = textwrap.dedent("""
    import sys
    import bpy
    from bpy_extras.anim_utils import action_get_channelbag_for_slot
    folder = sys.argv[1]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = 64
    scene.render.resolution_percentage = 100
    scene.cycles.samples = 64
    scene.cycles.use_denoising = False
    scene.frame_start, scene.frame_end, scene.frame_current = 1, 5, 3
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 4.0
    cam.location = (0, 0, 10)
    scene.collection.objects.link(cam)
    scene.camera = cam
    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    mesh = bpy.data.meshes.new("Square")
    h = 0.25
    mesh.from_pydata([(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], [], [(0, 1, 2, 3)])
    mat = bpy.data.materials.new("Glow")
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    emit = nodes.new("ShaderNodeEmission")
    out = nodes.new("ShaderNodeOutputMaterial")
    mat.node_tree.links.new(emit.outputs[0], out.inputs["Surface"])
    mesh.materials.append(mat)
    square = bpy.data.objects.new("Square", mesh)
    scene.collection.objects.link(square)
    for frame, x, strength in ((1, -1.0, 1.0), (5, 1.0, 5.0)):
        square.location = (x, 0.25, 0)
        square.keyframe_insert("location", frame=frame)
        emit.inputs["Strength"].default_value = strength
        emit.inputs["Strength"].keyframe_insert("default_value", frame=frame)
    for owner in (square, mat.node_tree):
        anim = owner.animation_data
        for fcurve in action_get_channelbag_for_slot(anim.action, anim.action_slot).fcurves:
            for key in fcurve.keyframe_points:
                key.interpolation = "LINEAR"
    bpy.ops.wm.save_as_mainfile(filepath=folder + "/moving.blend")
    scene.render.use_overwrite = False
    bpy.ops.wm.save_as_mainfile(filepath=folder + "/moving_no_overwrite.blend")
""")


@pytest.fixture(scope="module")
def scenes(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("animation")
    done = subprocess.run([sys.executable, "-c", MAKE_SCENE, str(folder)], capture_output=True,
                          text=True, timeout=TIMEOUT)
    assert done.returncode == 0, done.stderr
    return folder


@pytest.fixture
def out(tmp_path) -> Path:
    folder = tmp_path / "out"
    folder.mkdir()
    return folder


def run_cli(*args) -> subprocess.CompletedProcess:
    return subprocess.run([str(MCENGINE), *map(str, args)], capture_output=True, text=True,
                          timeout=TIMEOUT, stdin=subprocess.DEVNULL)


def own_lines(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if line.startswith("mcengine:")]


def expected_square(frame: int) -> tuple[float, float, float]:
    """(centroid x, centroid y, flux) of frame ``frame`` in pixels, in closed form."""
    x = -1.0 + 0.5 * (frame - 1)
    return 32 + 16 * x, 32 - 16 * 0.25, 64.0 * frame


def measured_square(path: Path) -> tuple[float, float, float]:
    red = read_exr(path)[..., 0].astype(np.float64)
    rows, cols = np.mgrid[0:red.shape[0], 0:red.shape[1]] + 0.5
    flux = red.sum()
    return (cols * red).sum() / flux, (rows * red).sum() / flux, flux


def test_animation_renders_each_frame_at_its_time(scenes, out):
    done = run_cli("-b", scenes / "moving.blend", "-E", "MCENGINE", "-o", out / "sq_##", "-a")
    assert done.returncode == 0, done.stderr
    paths = [out / f"sq_{frame:02d}.exr" for frame in range(1, 6)]
    assert done.stdout.splitlines() == [str(p) for p in paths]
    for frame, path in enumerate(paths, start=1):
        cx, cy, flux = measured_square(path)
        ex, ey, eflux = expected_square(frame)
        assert abs(cx - ex) < 0.1 and abs(cy - ey) < 0.1, (frame, cx, cy, ex, ey)
        assert abs(flux / eflux - 1) < 0.03, (frame, flux, eflux)
    # One line per frame, then the summary; no per-10 % progress lines.
    lines = own_lines(done.stderr)
    assert [line.split(":")[1].strip() for line in lines[:5]] == [
        f"frame {f} [{f}/5]" for f in range(1, 6)]
    assert lines[5].startswith("mcengine: rendered 5 of 5 frames of 'Scene' (frames 1..5)")
    assert len(lines) == 6 and "%" not in done.stderr, done.stderr


def test_frame_lists_ranges_and_steps(scenes, out):
    small = ["--samples", "1", "--resolution", "8x8"]
    done = run_cli("-b", scenes / "moving.blend", "-o", out / "a_#", "-f", "1,+2..3,-1", *small)
    assert done.returncode == 0, done.stderr
    done = run_cli("render", scenes / "moving.blend", "-o", out / "b.png", "-s", "2", "-j", "2",
                   "-a", *small)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in out.iterdir()) == [
        "a_1.exr", "a_3.exr", "a_5.exr", "b0002.png", "b0004.png"]


def test_a_single_frame_is_set_before_export(scenes, out):
    done = run_cli("render", scenes / "moving.blend", "-f", "4", "-o", out / "four.exr")
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [str(out / "four.exr")]
    cx, cy, flux = measured_square(out / "four.exr")
    ex, ey, eflux = expected_square(4)
    assert abs(cx - ex) < 0.1 and abs(flux / eflux - 1) < 0.03


@pytest.mark.parametrize("how", ["--no-overwrite", "file setting"])
def test_existing_frames_are_skipped_when_overwrite_is_off(scenes, out, how):
    blend = scenes / ("moving.blend" if how == "--no-overwrite" else "moving_no_overwrite.blend")
    flags = ["--no-overwrite"] if how == "--no-overwrite" else []
    (out / "sq_2.exr").write_bytes(PREVIOUS)
    (out / "sq_3.exr").write_bytes(b"")     # another machine's placeholder
    done = run_cli("-b", blend, "-o", out / "sq_#", "-f", "1..4", *flags,
                   "--samples", "4", "--resolution", "16x16")
    assert done.returncode == 0, done.stderr
    assert (out / "sq_2.exr").read_bytes() == PREVIOUS
    assert (out / "sq_3.exr").read_bytes() == b""
    assert done.stdout.splitlines() == [str(out / "sq_1.exr"), str(out / "sq_4.exr")]
    assert read_exr(out / "sq_4.exr").shape == (16, 16, 4)
    lines = own_lines(done.stderr)
    assert f"mcengine: frame 2 [2/4]: skipped, {out / 'sq_2.exr'} exists (Overwrite is off)" in lines
    assert "2 skipped (their images exist and Overwrite is off)" in lines[-1]


def test_overwrite_on_replaces_and_fills_missing_outputs(scenes, out):
    """Overwrite off writes the missing images of a frame; on, it replaces them all."""
    (out / "sq_1.exr").write_bytes(PREVIOUS)
    small = ["--samples", "2", "--resolution", "8x8", "-f", "1"]
    done = run_cli("-b", scenes / "moving_no_overwrite.blend", "-o", out / "sq_#",
                   "-o", out / "sq_#.png", *small)
    assert done.returncode == 0, done.stderr
    assert (out / "sq_1.exr").read_bytes() == PREVIOUS
    assert done.stdout.splitlines() == [str(out / "sq_1.png")]
    done = run_cli("-b", scenes / "moving_no_overwrite.blend", "-o", out / "sq_#", "--overwrite",
                   *small)
    assert done.returncode == 0, done.stderr
    assert read_exr(out / "sq_1.exr").shape == (8, 8, 4)


def test_interrupted_animation_keeps_finished_frames_and_its_placeholder_goes(scenes, out):
    """Ctrl-C during frame 2: frame 1 stays, frame 2's placeholder is removed, exit 130."""
    proc = subprocess.Popen(
        [str(MCENGINE), "-b", str(scenes / "moving.blend"), "-o", str(out / "sq_#"), "-f", "1,2",
         "--placeholders", "--samples", "20000", "--resolution", "64x64"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, stdin=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + TIMEOUT
        placeholder = out / "sq_2.exr"
        seen_empty = False
        while time.monotonic() < deadline and proc.poll() is None:
            if (out / "sq_1.exr").exists() and placeholder.exists():
                seen_empty = placeholder.stat().st_size == 0
                break
            time.sleep(0.01)
        assert seen_empty, "no empty placeholder for frame 2 while it rendered"
        time.sleep(0.5)
        proc.send_signal(signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=TIMEOUT)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == EXIT_INTERRUPTED, stderr
    assert "Traceback" not in stderr
    assert stdout.splitlines() == [str(out / "sq_1.exr")]
    assert own_lines(stderr)[-1] == "mcengine: interrupted"
    assert sorted(os.listdir(out)) == ["sq_1.exr"]
    assert read_exr(out / "sq_1.exr").shape == (64, 64, 4)
