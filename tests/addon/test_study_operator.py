"""The "Study Accuracy vs Time" operator and the MC Engine panel's integrator and ray lines.

The operator runs on a scene built in memory and never saved, as a user's
click would: real renders with all four integrators at 16 x 12 pixels, 1 to 4
samples, two seeds.  In background mode there is no Image Editor, so the test
checks that the plot was loaded as the image datablock.
"""
import csv

import bpy
import pytest

from .test_render_loop import _panel_text

WIDTH, HEIGHT = 32, 24


def _plane_under_sun_and_sky(scene):
    """A grey plane lit by a sun and a bright world: ray casting leaves the sky light out."""
    mesh = bpy.data.meshes.new("Plane")
    s = 4.0
    mesh.from_pydata([(-s, -s, -3.0), (s, -s, -3.0), (s, s, -3.0), (-s, s, -3.0)], [],
                     [(0, 1, 2, 3)])
    material = bpy.data.materials.new("Grey")
    material.node_tree.nodes["Principled BSDF"].inputs["Specular IOR Level"].default_value = 0.0
    mesh.materials.append(material)
    scene.collection.objects.link(bpy.data.objects.new("Plane", mesh))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 2.0
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("World")
    world.color = (0.5, 0.5, 0.5)
    scene.world = world
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = WIDTH, HEIGHT, 100


def _own_settings(scene):
    own = scene.mcengine
    return (own.integrator, own.depth, own.branching, scene.render.resolution_x,
            scene.render.resolution_y, scene.cycles.samples, scene.cycles.use_adaptive_sampling)


@pytest.mark.timeout(300)
def test_study_of_the_unsaved_scene_loads_its_plot(scene, tmp_path, capfd):
    _plane_under_sun_and_sky(scene)
    scene.mcengine.integrator = "WHITTED"
    scene.mcengine.depth, scene.mcengine.branching = 7, 5
    scene.cycles.use_adaptive_sampling = True
    before = _own_settings(scene)
    assert not bpy.data.is_saved

    result = bpy.ops.mcengine.study_accuracy(max_samples=4, size=16, seeds=2,
                                             directory=str(tmp_path))

    assert result == {"FINISHED"}
    assert _own_settings(scene) == before
    with open(tmp_path / "study.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 5 * 3 * 2          # integrators x (1, 2, 4) x seeds
    assert {r["integrator"] for r in rows} == {"path", "raycast", "whitted", "distribution", "light"}
    image = bpy.data.images["MC Engine Study"]
    assert bpy.path.abspath(image.filepath) == str(tmp_path / "error_vs_time.png")
    assert image.size[0] > 300 and image.size[1] > 200
    out, err = capfd.readouterr()
    assert "Info: Study: time to relMSE 0.02: path" in out + err
    assert "raycast levels off at relMSE" in out + err     # the missing sky light
    assert "Traceback" not in out + err


def test_study_needs_a_camera(scene):
    scene.camera = None
    assert not bpy.ops.mcengine.study_accuracy.poll()


@pytest.mark.parametrize("integrator, drawn", [
    ("PATH", ["integrator", "sampler"]), ("RAYCAST", ["integrator", "sampler"]),
    ("WHITTED", ["integrator", "sampler", "depth"]),
    ("DISTRIBUTION", ["integrator", "sampler", "depth", "branching"]),
])
def test_panel_draws_the_integrator_settings_that_apply(addon, scene, integrator, drawn):
    scene.mcengine.integrator = integrator
    scene.mcengine.depth, scene.mcengine.branching = 3, 4
    props = []
    lines = _panel_text(addon, scene, props=props)
    assert props == drawn
    if integrator == "DISTRIBUTION":
        assert lines[0] == "Up to 21 rays per sample (1 + b + ... + b^(depth-1))"


def test_panel_shows_the_last_renders_ray_accounting(addon, scene):
    _plane_under_sun_and_sky(scene)
    scene.render.resolution_x, scene.render.resolution_y = 8, 6
    scene.cycles.samples = 4
    bpy.ops.render.render()
    lines = _panel_text(addon, scene)
    rays = next(line for line in lines if line.startswith("rays/pixel: camera 4.0"))
    assert "bounce" in rays and "shadow" in rays
    assert any(line.endswith("Mrays/s") for line in lines)
    assert any(line.startswith("export ") and "BVH" in line for line in lines)
