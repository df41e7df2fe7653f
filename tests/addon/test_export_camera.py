"""Camera and film export: lens, sensor fit, shift, clipping, resolution, border region."""
import math

import bpy
import numpy as np
import pytest

from .helpers import export_scene


def test_perspective_camera(scene, fake_session):
    cam = scene.camera
    cam.data.lens, cam.data.sensor_fit = 35.0, "VERTICAL"
    cam.data.sensor_width, cam.data.sensor_height = 30.0, 20.0
    cam.data.shift_x, cam.data.shift_y = 0.1, -0.2
    cam.data.clip_start, cam.data.clip_end = 0.5, 250.0
    cam.location, cam.rotation_euler, cam.scale = (1, -2, 3), (math.pi / 3, 0, 0.4), (2, 2, 2)
    bpy.context.view_layer.update()
    c = export_scene(fake_session).camera
    assert (c.type, c.sensor_fit) == ("PERSP", "VERTICAL")
    assert (c.lens, c.sensor_width, c.sensor_height) == (35.0, 30.0, 20.0)
    assert (c.shift_x, c.shift_y) == (pytest.approx(0.1), pytest.approx(-0.2))
    assert (c.clip_start, c.clip_end) == (0.5, 250.0)
    # object scale dropped (Cycles ignores it), rotation and position kept
    rot = np.array(cam.matrix_world.to_3x3().normalized())
    np.testing.assert_allclose(c.matrix_world[:3, :3], rot, atol=1e-6)
    np.testing.assert_allclose(c.matrix_world[:3, 3], (1, -2, 3), atol=1e-6)


def test_orthographic_camera_in_metres(scene, fake_session):
    scene.unit_settings.scale_length = 0.01
    scene.camera.data.type, scene.camera.data.ortho_scale = "ORTHO", 700.0
    scene.camera.location = (0, 0, 500)
    c = export_scene(fake_session).camera
    assert c.type == "ORTHO" and c.ortho_scale == pytest.approx(7.0)
    assert c.matrix_world[2, 3] == pytest.approx(5.0)


def test_film_settings_come_from_render_and_cycles(scene, fake_session):
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = 101, 57, 50
    r.pixel_aspect_x, r.pixel_aspect_y = 2.0, 1.0
    r.film_transparent = True
    scene.cycles.pixel_filter_type, scene.cycles.filter_width = "GAUSSIAN", 2.5
    scene.cycles.film_exposure = 1.5
    f = export_scene(fake_session).film
    assert (f.width, f.height, f.region) == (50, 28, None)  # 101 * 50 // 100
    assert (f.pixel_aspect_x, f.pixel_aspect_y, f.transparent) == (2.0, 1.0, True)
    assert (f.filter_type, f.filter_width, f.exposure) == ("GAUSSIAN", 2.5, 1.5)


@pytest.mark.parametrize("border,size,region", [
    # Blender truncates float32(fraction) * size; y is flipped to a top-left origin
    ((0.3, 0.1, 0.71, 0.55), (50, 28), (15, 13, 35, 26)),
    ((0.0, 0.0, 1.0, 1.0), (50, 28), (0, 0, 50, 28)),
    ((0.25, 0.5, 0.75, 1.0), (64, 48), (16, 0, 48, 24)),
    # float32(0.7) * 10 rounds to 7.0 in float32 (6.99999988 in float64): x1 is 7, as in Blender
    ((0.1, 0.3, 0.7, 0.7), (10, 10), (1, 3, 7, 7)),
])
def test_border_region(scene, fake_session, addon, border, size, region):
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = size[0] * 2 + 1, size[1] * 2 + 1, 50
    r.use_border = True
    r.border_min_x, r.border_min_y, r.border_max_x, r.border_max_y = border
    assert addon.export.camera.border_region(r) == region
    assert export_scene(fake_session).film.region == region


def test_panoramic_camera_is_an_export_error(scene, addon):
    scene.camera.data.type = "PANO"
    depsgraph = bpy.context.evaluated_depsgraph_get()
    with pytest.raises(addon.export.ExportError, match="camera 'Camera' is panoramic"):
        addon.export.export(depsgraph)


def test_depth_of_field_as_cycles_derives_it(scene, fake_session):
    dof = scene.camera.data.dof
    dof.use_dof, dof.aperture_fstop, dof.focus_distance = True, 2.0, 7.5
    dof.aperture_blades, dof.aperture_rotation, dof.aperture_ratio = 6, 0.3, 1.5
    scene.camera.data.lens = 40.0
    c = export_scene(fake_session).camera
    assert c.aperture_size == pytest.approx(0.040 / (2 * 2.0))     # lens / (2 f-stop), metres
    assert c.focal_distance == pytest.approx(7.5)
    assert (c.aperture_blades, c.aperture_ratio) == (6, pytest.approx(1.5))
    assert c.aperture_rotation == pytest.approx(0.3)
    assert not any("depth of field" in w for w in export_scene(fake_session).warnings)
    dof.aperture_fstop = 0.0                          # Cycles clamps the f-stop to 1e-5
    assert export_scene(fake_session).camera.aperture_size == pytest.approx(0.040 / 2e-5)
    dof.use_dof = False
    c = export_scene(fake_session).camera
    assert (c.aperture_size, c.aperture_ratio) == (0.0, 1.0)


def test_depth_of_field_focus_object_and_units(scene, fake_session):
    scene.unit_settings.scale_length = 0.5
    cam = scene.camera
    cam.location, cam.rotation_euler = (0, -10, 0), (math.pi / 2, 0, 0)    # looking along +Y
    target = bpy.data.objects.new("Target", None)
    scene.collection.objects.link(target)
    target.location = (3.0, -4.0, 2.0)                # 6 units ahead, off the axis
    cam.data.dof.use_dof, cam.data.dof.focus_object = True, target
    cam.data.dof.aperture_fstop = 4.0
    cam.data.type, cam.data.ortho_scale = "ORTHO", 8.0
    bpy.context.view_layer.update()
    c = export_scene(fake_session).camera
    assert c.focal_distance == pytest.approx(6.0 * 0.5)           # depth along the view axis
    assert c.aperture_size == pytest.approx(1.0 / (2 * 4.0) * 0.5)  # orthographic: 1 / (2 f-stop)
