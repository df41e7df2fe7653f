"""Shader nodes against Cycles, exactly: flat emissive planes under an orthographic camera.

Each case is a material whose Emission colour comes from the node under
test; the harness lays out up to ``GRID x GRID`` cases as unit planes in one
scene (UV 0..1 on each, generated coordinates spanning the plane), seen by an
orthographic camera from above, and renders that scene with Cycles and with
MC Engine.  No light is transported: a camera ray hits a plane and collects
its emission, so the only randomness is where in the pixel the ray goes.  The
pixel filter is made 0.01 px wide (Blender's minimum), so both engines look
at the pixel centres and the images agree to float rounding except in the
pixels a discontinuity of the pattern passes through.

Use::

    cases = {"checker scale 3": lambda nt: checker(nt, scale=3.0), ...}
    images = render_cases(cases)          # name -> (cycles, mcengine) HxWx3 arrays
    for name, (ref, ours) in images.items():
        assert_agree(name, ref, ours)

A case's function gets the material's node tree and returns the output socket
to show (colour, float or vector: Blender converts it for the Emission colour
as Cycles does).  A case may also be a pair ``(build, prepare)``, where
``prepare(ob)`` changes the case's plane object first (extra UV maps, colour
attributes, a rotation, ...).
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

GRID = 6                 # cases per row and column in one scene
CELL = 24                # pixels per case (a plane fills CELL - 2 of them)
GAP = 0.25               # world units between planes (planes are 1 x 1)


def pixel_centre_scene(width: int, height: int):
    """A new empty scene of ``width`` x ``height`` pixels that renders one ray through (about)
    each pixel centre: 1 sample, seed 0, a Blackman-Harris filter 0.01 pixel wide (Box ignores
    the width), no bounces, no denoising or adaptive sampling, the Standard view transform."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.cycles.filter_width = 0.01
    scene.cycles.pixel_filter_type = "BLACKMAN_HARRIS"
    scene.view_settings.view_transform = "Standard"
    scene.cycles.samples = 1
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.seed = 0
    scene.cycles.max_bounces = 0
    return scene


def black_world(scene) -> None:
    """A world whose Background is black."""
    import bpy

    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world


def _scene(cases: dict):
    import bpy

    n = len(cases)
    cols = min(GRID, n)
    rows = -(-n // cols)
    pitch = 1.0 + GAP
    scene = pixel_centre_scene(cols * CELL, rows * CELL)
    cam_data = bpy.data.cameras.new("cam")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = pitch * max(cols, rows)
    cam_data.sensor_fit = "AUTO"
    cam = bpy.data.objects.new("cam", cam_data)
    cam.location = (pitch * (cols - 1) / 2, -pitch * (rows - 1) / 2, 10.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    black_world(scene)
    for k, (name, case) in enumerate(cases.items()):
        build, prepare = case if isinstance(case, tuple) else (case, None)
        r, c = divmod(k, cols)
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=(c * pitch, -r * pitch, 0.0))
        ob = bpy.context.active_object
        ob.name = f"case{k}"
        if prepare is not None:
            prepare(ob)
        mat = bpy.data.materials.new(name)
        mat.use_nodes = True
        nt = mat.node_tree
        nt.nodes.clear()
        out = nt.nodes.new("ShaderNodeOutputMaterial")
        emit = nt.nodes.new("ShaderNodeEmission")
        nt.links.new(emit.outputs["Emission"], out.inputs["Surface"])
        nt.links.new(build(nt), emit.inputs["Color"])
        ob.data.materials.append(mat)
    return scene, rows, cols


_WARM_UP = """
import bpy
from mcengine_blender.batch.render import ensure_registered
from tests.nodes.harness import _scene
ensure_registered()
scene, _rows, _cols = _scene({"warm up": lambda nt: nt.nodes.new("ShaderNodeTexChecker").outputs["Color"]})
scene.render.engine = "MCENGINE"
bpy.ops.render.render()
"""


def compile_kernels_apart() -> None:
    """Compile the kernels (into numba's disk cache) in a separate process, by an MC Engine
    render of a textured plane there.

    With a cold cache, numba compiling in a process where Cycles has rendered crashed
    (a segfault inside bpy.ops.render.render, every time); loading the cached kernels
    does not.  Once per test process; a few seconds when the cache is warm.
    """
    global _compiled
    if not _compiled:
        root = Path(__file__).resolve().parents[2]
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(root), os.environ.get("PYTHONPATH")]))}
        subprocess.run([sys.executable, "-c", _WARM_UP], cwd=root, env=env, check=True)
        _compiled = True


_compiled = False


def render_both(scene) -> dict:
    """Render ``scene`` with Cycles and MC Engine: engine name -> HxWx3 image (top row first)."""
    import bpy

    from mcengine_blender.batch.render import ensure_registered
    compile_kernels_apart()
    ensure_registered()
    images = {}
    for engine in ("CYCLES", "MCENGINE"):
        scene.render.engine = engine
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "out.exr"
            scene.render.image_settings.file_format = "OPEN_EXR"
            scene.render.image_settings.color_depth = "32"
            scene.render.filepath = str(path)
            bpy.ops.render.render(write_still=True)
            img = bpy.data.images.load(str(path))
            w, h = img.size
            px = np.array(img.pixels[:], np.float32).reshape(h, w, 4)[::-1, :, :3]
            bpy.data.images.remove(img)
        images[engine] = px
    return images


def render_cases(cases: dict) -> dict:
    """Render the cases with Cycles and MC Engine: name -> (cycles, mcengine) images."""
    out = {}
    names = list(cases)
    per_scene = GRID * GRID
    for start in range(0, len(names), per_scene):
        chunk = {name: cases[name] for name in names[start:start + per_scene]}
        scene, rows, cols = _scene(chunk)
        images = render_both(scene)
        for k, name in enumerate(chunk):
            r, c = divmod(k, cols)
            sl = (slice(r * CELL + 4, (r + 1) * CELL - 4), slice(c * CELL + 4, (c + 1) * CELL - 4))
            out[name] = (images["CYCLES"][sl], images["MCENGINE"][sl])
    return out


def assert_agree(name: str, ref: np.ndarray, ours: np.ndarray, rel: float = 1e-3,
                 abs_tol: float = 1e-4, edge_fraction: float = 0.0) -> None:
    """Pixel values agree within ``rel`` (relative) or ``abs_tol``; at most ``edge_fraction``
    of the pixels may differ more (where a discontinuity crosses a pixel centre)."""
    bad = np.abs(ours - ref) > np.maximum(abs_tol, rel * np.abs(ref))
    frac = bad.any(axis=2).mean()
    if frac > edge_fraction:
        worst = np.unravel_index(np.argmax(np.abs(ours - ref).max(axis=2)), ref.shape[:2])
        raise AssertionError(
            f"{name}: {frac:.1%} of pixels differ (allowed {edge_fraction:.1%}); worst at {worst}: "
            f"Cycles {ref[worst]}, MC Engine {ours[worst]}")
