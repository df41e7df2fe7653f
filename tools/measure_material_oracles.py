"""Render the material oracles of ``tests/core/material_oracles.py`` with Cycles.

Each set-up (a material on a plane under a point light, or in a white
furnace) is built with bpy exactly as the test builds it for MC Engine,
rendered by Cycles 5.0 (CPU, Box filter, no denoising or adaptive sampling,
seed 0) into a 32-bit EXR, and the mean RGBA of its pixels is written to
``tests/core/material_oracles.json`` with the samples used.  Point-light
set-ups are noiseless up to the pixel positions; furnaces use enough samples
for 1e-4.

Run: .venv/bin/python -m tools.measure_material_oracles [NAME ...]
"""
from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests.core.material_oracles import (  # noqa: E402
    ALL_ORACLES,
    LIGHT_WATTS,
    SLAB_THICKNESS,
    SUBSURFACE_ORACLES,
    camera_matrix,
    light_position,
)

OUT = REPO / "tests" / "core" / "material_oracles.json"
SAMPLES_LIGHT = 1024   # Cycles' first sample per pixel loses some light through transmission NEE
SAMPLES_FURNACE = 4096
SAMPLES_SUBSURFACE = 16384   # random walks: the standard error over the pixels goes with them
RESOLUTION = 8
ORTHO_SCALE = 0.02
NODE_IDS = {"BsdfGlossy": "ShaderNodeBsdfAnisotropic"}


def build(bpy, name):
    nodes, view, light = ALL_ORACLES[name]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = (SAMPLES_SUBSURFACE if name in SUBSURFACE_ORACLES
                 else SAMPLES_FURNACE if light is None else SAMPLES_LIGHT)
    c.use_denoising = c.use_adaptive_sampling = False
    c.seed = 0
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.max_bounces = 0 if light is not None else 64
    c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = c.max_bounces
    c.pixel_filter_type = "BOX"
    scene.render.resolution_x = scene.render.resolution_y = RESOLUTION
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (
        (1, 1, 1, 1) if light is None else (0, 0, 0, 1))
    scene.world = world
    mesh = bpy.data.meshes.new("plane")
    s = 50.0
    if name in SLAB_THICKNESS:         # and a face below, facing down: a slab
        d = -SLAB_THICKNESS[name]
        mesh.from_pydata([(-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0),
                          (-s, -s, d), (s, -s, d), (s, s, d), (-s, s, d)], [],
                         [(0, 1, 2, 3), (4, 7, 6, 5)])
    else:
        mesh.from_pydata([(-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0)], [], [(0, 1, 2, 3)])
    ob = bpy.data.objects.new("plane", mesh)
    scene.collection.objects.link(ob)
    mat = bpy.data.materials.new(name)
    tree = mat.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    made = []
    for kind, inputs, props in nodes:
        node = tree.nodes.new(NODE_IDS.get(kind, "ShaderNode" + kind))
        for key, value in props.items():
            setattr(node, key, value)
        for key, value in inputs.items():
            sock = node.inputs[key]
            if isinstance(value, tuple) and value and value[0] == "link":
                tree.links.new(made[value[1]].outputs[value[2] if len(value) > 2 else 0], sock)
            elif isinstance(value, tuple):
                sock.default_value = (*value, 1.0)[:len(sock.default_value)]
            else:
                sock.default_value = value
        made.append(node)
    tree.links.new(made[-1].outputs[0], out.inputs["Surface"])
    mesh.materials.append(mat)
    cam = bpy.data.cameras.new("cam")
    cam.type = "ORTHO"
    cam.ortho_scale = ORTHO_SCALE
    cam_ob = bpy.data.objects.new("cam", cam)
    from mathutils import Matrix
    cam_ob.matrix_world = Matrix(camera_matrix(view))
    scene.collection.objects.link(cam_ob)
    scene.camera = cam_ob
    if light is not None:
        lamp = bpy.data.lights.new("lamp", "POINT")
        lamp.energy = LIGHT_WATTS
        lamp.shadow_soft_size = 0.0
        lamp_ob = bpy.data.objects.new("lamp", lamp)
        lamp_ob.location = light_position(*light)
        scene.collection.objects.link(lamp_ob)
    return scene


def render(bpy, scene, path):
    import numpy as np
    import OpenEXR
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    with OpenEXR.File(str(path)) as f:
        px = np.asarray(f.channels()["RGBA"].pixels, np.float64)
    px = px.reshape(-1, 4)
    # The standard error of the mean from the pixels' spread (each pixel an independent mean).
    se = px.std(axis=0, ddof=1) / np.sqrt(len(px))
    return [float(v) for v in px.mean(axis=0)], [float(v) for v in se]


def main(argv=None) -> int:
    import bpy
    names = (argv if argv is not None else sys.argv[1:]) or list(ALL_ORACLES)
    results = json.loads(OUT.read_text()) if OUT.exists() else {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            scene = build(bpy, name)
            rgba, se = render(bpy, scene, Path(tmp) / f"{name}.exr")
            results[name] = {"rgba": rgba, "samples": scene.cycles.samples}
            if name in SUBSURFACE_ORACLES:
                results[name]["se"] = se
            print(f"{name}: {rgba}", flush=True)
    OUT.write_text(json.dumps(results, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
