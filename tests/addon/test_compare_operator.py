"""The "Compare with Cycles" operator, called through bpy as a user's click would.

The scene is built in memory and never saved: the operator must render what
is open, report the verdict, load side_by_side.png as an image datablock and
leave every render setting as it was.  Real renders (MC Engine and Cycles) at
32 x 24 pixels, 16 samples.
"""
import json

import bpy
import pytest

WIDTH, HEIGHT = 32, 24
SAMPLES = 16


def _plane_under_sun(scene, unsupported=False):
    """A grey plane filling the camera's view, lit by a sun, with a dim world."""
    mesh = bpy.data.meshes.new("Plane")
    s = 4.0
    mesh.from_pydata([(-s, -s, -3.0), (s, -s, -3.0), (s, s, -3.0), (-s, s, -3.0)], [],
                     [(0, 1, 2, 3)])
    material = bpy.data.materials.new("Grey")
    tree = material.node_tree
    bsdf = tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.6, 0.6, 0.6, 1.0)
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    if unsupported:  # MC Engine ignores the Curves Info node: its plane stays grey (Cycles':
        info = tree.nodes.new("ShaderNodeHairInfo")       # black, a mesh is not a strand)
        tree.links.new(info.outputs["Is Strand"], bsdf.inputs["Base Color"])
    mesh.materials.append(material)
    scene.collection.objects.link(bpy.data.objects.new("Plane", mesh))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 2.0
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("World")
    world.color = (0.1, 0.1, 0.1)
    scene.world = world
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = WIDTH, HEIGHT, 100
    scene.cycles.samples = SAMPLES


def _settings(scene):
    c = scene.cycles
    return (scene.render.engine, scene.render.resolution_x, scene.render.resolution_y,
            scene.render.resolution_percentage, scene.render.filepath,
            scene.render.image_settings.file_format, c.samples, c.seed, c.use_denoising,
            c.use_adaptive_sampling, c.sample_clamp_indirect, c.time_limit,
            scene.view_settings.view_transform, scene.mcengine.integrator)


def _compare(tmp_path, **kwargs):
    return bpy.ops.mcengine.compare_with_cycles(
        samples=SAMPLES, resolution_percentage=100, seeds=2, directory=str(tmp_path), **kwargs)


def test_compares_the_unsaved_scene_and_shows_the_verdict(scene, tmp_path, capfd):
    _plane_under_sun(scene)
    # Settings a user may have, which the comparison changes and must put back.
    scene.cycles.use_denoising = True
    scene.cycles.use_adaptive_sampling = True
    scene.cycles.sample_clamp_indirect = 10.0
    scene.cycles.time_limit = 30.0
    scene.render.filepath = "//frames/shot_"
    scene.view_settings.view_transform = "AgX"
    scene.mcengine.integrator = "RAYCAST"  # biased: the comparison must use path tracing
    before = _settings(scene)
    assert not bpy.data.is_saved

    assert _compare(tmp_path) == {"FINISHED"}

    assert _settings(scene) == before
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["verdict"] == "agree"
    assert report["settings"]["resolution"] == [WIDTH, HEIGHT]
    assert report["settings"]["samples"] == {"mcengine": SAMPLES, "cycles": SAMPLES}
    # The in-memory plane was rendered: lit grey, not the 0.1 world seen directly.
    assert report["means"]["cycles"]["G"]["mean"] > 0.3
    for name in ("mcengine.exr", "cycles.exr", "side_by_side.png", "report.md"):
        assert (tmp_path / name).is_file(), name
    image = bpy.data.images["MC Engine vs Cycles"]
    assert bpy.path.abspath(image.filepath) == str(tmp_path / "side_by_side.png")
    assert image.size[0] > 4 * WIDTH and image.size[1] > HEIGHT  # four panels, scaled up
    out, err = capfd.readouterr()
    assert "Compare with Cycles: Scene: agree" in out + err
    assert "Traceback" not in out + err


def test_a_difference_is_a_warning_naming_what_mc_engine_ignored(scene, tmp_path, capfd):
    _plane_under_sun(scene, unsupported=True)
    assert _compare(tmp_path) == {"FINISHED"}
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["verdict"] == "differ"
    assert any("HairInfo" in note for note in report["notes"])
    out, err = capfd.readouterr()
    assert "Warning: Compare with Cycles: Scene: differ" in out + err


def test_second_comparison_reuses_the_image(scene, tmp_path):
    _plane_under_sun(scene)
    _compare(tmp_path / "first")
    _compare(tmp_path / "second")
    images = [im for im in bpy.data.images if im.name.startswith("MC Engine vs Cycles")]
    assert len(images) == 1
    assert bpy.path.abspath(images[0].filepath) == str(tmp_path / "second" / "side_by_side.png")


def test_failed_render_is_one_error_and_settings_are_restored(scene, tmp_path, capfd):
    _plane_under_sun(scene)
    scene.camera.data.type = "PANO"
    before = _settings(scene)
    with pytest.raises(RuntimeError, match="Compare with Cycles: mcengine render failed: "
                                           ".*panoramic"):
        _compare(tmp_path)
    assert _settings(scene) == before
    out, err = capfd.readouterr()
    assert "Traceback" not in out + err


def test_needs_a_camera(scene):
    scene.camera = None
    assert not bpy.ops.mcengine.compare_with_cycles.poll()


def test_button_is_in_the_mc_engine_render_panel(addon, scene):
    from .test_render_loop import _panel_text
    operators = []
    _panel_text(addon, scene, operators)
    assert operators == ["mcengine.compare_with_cycles", "mcengine.study_accuracy"]
