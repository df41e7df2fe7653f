"""Motion blur export: the shutter (length, position, curve, rolling), object transform and
deformation steps, and the camera's motion, read as Cycles' Blender sync reads them."""
import numpy as np
import pytest

from mcengine.kernels.motion import pack_motion

from .helpers import export_scene, new_mesh_object

SQUARE = [(-0.5, -0.5, 0.0), (0.5, -0.5, 0.0), (0.5, 0.5, 0.0), (-0.5, 0.5, 0.0)]


def _at(scene, time, read):
    """``read()`` with the scene evaluated at ``time`` (frame and subframe), then back at 1:
    the expected value of a motion step, from Blender's own animation system (the keys
    are Bezier ones)."""
    frame = int(np.floor(time))
    scene.frame_set(frame, subframe=time - frame)
    try:
        return read()
    finally:
        scene.frame_set(1)


def _sliding_square(scene, name="Slider", x_per_frame=5.0):
    """A square keyed at x = 0 at frame 0 and 2 x_per_frame at frame 2, the scene at frame 1."""
    ob = new_mesh_object(name, SQUARE, [(0, 1, 2, 3)])
    ob.location = (0.0, 0.0, 0.0)
    ob.keyframe_insert("location", frame=0)
    ob.location = (2 * x_per_frame, 0.0, 0.0)
    ob.keyframe_insert("location", frame=2)
    scene.frame_set(1)
    return ob


def _x(ob):
    return lambda: ob.matrix_world.translation.x


def _motion_blur(scene, shutter=0.5, position="CENTER"):
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = shutter
    scene.render.motion_blur_position = position


def test_no_motion_blur_without_the_switch(scene, fake_session):
    _sliding_square(scene)
    assert export_scene(fake_session).motion_blur is None


@pytest.mark.parametrize("position,centre", [("CENTER", 1.0), ("START", 1.25), ("END", 0.75)])
def test_shutter_position_sets_the_steps_and_the_frame(scene, fake_session, position, centre):
    """Shutter 0.5 frames: the steps span it, and the scene (the geometry's own vertices)
    is taken at its middle, as Cycles does for START and END."""
    ob = _sliding_square(scene)
    _motion_blur(scene, 0.5, position)
    desc = export_scene(fake_session)
    (om,) = desc.motion_blur.objects
    assert om.steps == 3 and om.positions is None
    expected = [_at(scene, t, _x(ob)) for t in (centre - 0.25, centre, centre + 0.25)]
    np.testing.assert_allclose(om.matrices[:, 0, 3], expected, atol=1e-5)
    np.testing.assert_allclose(desc.geometry.vertices[:, 0].mean(), expected[1], atol=1e-5)
    assert scene.frame_current == 1 and scene.frame_subframe == 0.0      # put back


def test_motion_steps_unit_scale_and_objects_without_motion_blur(scene, fake_session):
    scene.unit_settings.scale_length = 0.5
    ob = _sliding_square(scene)
    ob.cycles.motion_steps = 2                     # 2^2 + 1 steps
    still = _sliding_square(scene, "NoBlur")
    still.cycles.use_motion_blur = False
    _motion_blur(scene, 1.0)
    desc = export_scene(fake_session)
    (om,) = desc.motion_blur.objects
    assert desc.geometry.object_names[om.object] == "Slider"
    expected = [0.5 * _at(scene, t, _x(ob)) for t in np.linspace(0.5, 1.5, 5)]
    np.testing.assert_allclose(om.matrices[:, 0, 3], expected, atol=1e-5)


def test_static_objects_do_not_move_in_the_kernels(scene, fake_session):
    new_mesh_object("Static", SQUARE, [(0, 1, 2, 3)])
    _motion_blur(scene)
    desc = export_scene(fake_session)
    assert len(pack_motion(desc.geometry, desc.motion_blur.objects).tri_slot) == 0


def _morph_square():
    """A square with a shape key "Up" that lifts it to z = 1: (object, key block)."""
    ob = new_mesh_object("Morph", SQUARE, [(0, 1, 2, 3)])
    ob.shape_key_add(name="Basis")
    key = ob.shape_key_add(name="Up")
    for point in key.data:
        point.co = (point.co.x, point.co.y, 1.0)
    return ob, key


def test_shape_key_deformation_is_kept_at_the_steps(scene, fake_session):
    ob, key = _morph_square()
    key.value = 0.0
    key.keyframe_insert("value", frame=0)
    key.value = 1.0
    key.keyframe_insert("value", frame=2)
    scene.frame_set(1)
    _motion_blur(scene, 1.0)
    desc = export_scene(fake_session)
    (om,) = desc.motion_blur.objects
    assert om.positions.shape == (3, 4, 3)
    heights = [_at(scene, t, lambda: key.value) for t in (0.5, 1.0, 1.5)]   # z = the key's value
    np.testing.assert_allclose(om.positions[:, :, 2], np.repeat(heights, 4).reshape(3, 4), atol=1e-5)
    np.testing.assert_allclose(desc.geometry.vertices[:, 2], heights[1], atol=1e-5)
    assert om.normals.shape == (3, 2, 3, 3)

    ob.cycles.use_deform_motion = False            # the switch turns it off
    desc = export_scene(fake_session)
    assert not [o for o in desc.motion_blur.objects if o.positions is not None]


def test_camera_motion_and_lens_change(scene, fake_session):
    cam = scene.camera
    cam.location = (0.0, -5.0, 0.0)
    cam.keyframe_insert("location", frame=0)
    cam.location = (2.0, -5.0, 0.0)
    cam.keyframe_insert("location", frame=2)
    cam.data.lens = 40.0
    cam.data.keyframe_insert("lens", frame=0)
    cam.data.lens = 60.0
    cam.data.keyframe_insert("lens", frame=2)
    scene.frame_set(1)
    _motion_blur(scene, 1.0)
    c = export_scene(fake_session).camera
    np.testing.assert_allclose(c.motion[:, 0, 3], [_at(scene, t, _x(cam)) for t in (0.5, 1.0, 1.5)],
                               atol=1e-5)
    # the view plane scales as 1 / lens (sensor fit AUTO on a wide frame)
    lens = [_at(scene, t, lambda: cam.data.lens) for t in (0.5, 1.0, 1.5)]
    np.testing.assert_allclose(c.view_scale_motion, (lens[1] / lens[0], lens[1] / lens[2]), rtol=1e-5)


def test_shutter_curve_and_rolling_shutter(scene, fake_session):
    _sliding_square(scene)
    _motion_blur(scene)
    curve = scene.render.motion_blur_shutter_curve
    points = curve.curves[0].points              # (0, 1), (0.5, 1), (1, 1) by default
    points[0].location = (0.0, 0.0)
    for point in points:
        point.handle_type = "VECTOR"
    curve.update()
    scene.cycles.rolling_shutter_type = "TOP"
    scene.cycles.rolling_shutter_duration = 0.4
    mb = export_scene(fake_session).motion_blur
    assert mb.shutter_curve.shape == (257,)
    np.testing.assert_allclose(mb.shutter_curve[[0, 32, 64, 128, 200]], [0.0, 0.25, 0.5, 1.0, 1.0],
                               atol=1e-3)
    assert mb.rolling_shutter and mb.rolling_shutter_duration == pytest.approx(0.4)


def _keyed(ob, prop, frames_values):
    for frame, value in frames_values:
        setattr(ob, prop, value)
        ob.keyframe_insert(prop, frame=frame)


def test_vector_pass_takes_the_previous_and_next_frames(scene, fake_session):
    """The Vector pass without motion blur: every object (its own motion blur off or not)
    and the camera at frames 0 and 2 of frame 1, from Blender's evaluation there (Bezier
    keys at -2 and 4, so the steps are not the keys); still objects are left out."""
    scene.unit_settings.scale_length = 0.5
    ob = new_mesh_object("Mover", SQUARE, [(0, 1, 2, 3)])
    _keyed(ob, "location", [(-2, (0.0, 0.0, 0.0)), (4, (6.0, 3.0, 1.0))])
    _keyed(ob, "rotation_euler", [(-2, (0.0, 0.0, 0.0)), (4, (0.0, 0.0, 1.2))])
    ob.cycles.use_motion_blur = False
    new_mesh_object("Still", SQUARE, [(0, 1, 2, 3)])
    cam = scene.camera
    _keyed(cam, "location", [(-2, (0.0, -5.0, 0.0)), (4, (2.0, -5.0, 1.0))])
    scene.frame_set(1)
    scene.view_layers[0].use_pass_vector = True
    desc = export_scene(fake_session)
    assert desc.motion_blur is None and not desc.passes.motion_blur
    mv = desc.motion_vectors
    (om,) = mv.objects
    assert desc.geometry.object_names[om.object] == "Mover" and om.positions is None
    expected = np.stack([_at(scene, t, lambda: np.array(ob.matrix_world)) for t in (0.0, 1.0, 2.0)])
    expected[:, :3, :] *= 0.5
    np.testing.assert_allclose(om.matrices, expected, atol=1e-5)
    cams = np.stack([_at(scene, t, lambda: np.array(cam.matrix_world)) for t in (0.0, 2.0)])
    np.testing.assert_allclose(mv.camera[:, :3, 3], 0.5 * cams[:, :3, 3], atol=1e-5)
    np.testing.assert_allclose(mv.camera[:, :3, :3], cams[:, :3, :3], atol=1e-5)
    assert scene.frame_current == 1 and scene.frame_subframe == 0.0      # put back

    _motion_blur(scene)                    # Cycles leaves the pass at 0 with motion blur
    desc = export_scene(fake_session)
    assert desc.motion_vectors is None and desc.passes.motion_blur


def test_vector_pass_keeps_deformation(scene, fake_session):
    ob, key = _morph_square()
    _keyed(key, "value", [(-2, 0.0), (4, 1.0)])
    ob.cycles.use_deform_motion = False       # ignored by the pass (measured with Cycles)
    scene.frame_set(1)
    scene.view_layers[0].use_pass_vector = True
    (om,) = export_scene(fake_session).motion_vectors.objects
    heights = [_at(scene, t, lambda: key.value) for t in (0.0, 1.0, 2.0)]
    np.testing.assert_allclose(om.positions[:, :, 2], np.repeat(heights, 4).reshape(3, 4), atol=1e-5)


def _wireframe_material(name, node="ShaderNodeWireframe", output="Fac"):
    import bpy
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    wire = nt.nodes.new(node)
    nt.links.new(wire.outputs[output], nt.nodes["Principled BSDF"].inputs["Roughness"])
    return mat


def test_wireframe_on_a_moving_object_is_warned(scene, fake_session):
    """The Wireframe node reads the frame's triangles: on an object that moves during the
    shutter that differs from Cycles (which reads them at the ray's time), and is warned; on
    one that stays, or without motion blur, it is exact and not warned."""
    ob = _sliding_square(scene)
    still = new_mesh_object("Still", SQUARE, [(0, 1, 2, 3)])
    wire = _wireframe_material("Wire")
    still.data.materials.append(wire)
    _motion_blur(scene)

    def warned():
        return [w for w in export_scene(fake_session).warnings if w.startswith("Wireframe")]
    assert warned() == []
    ob.data.materials.append(wire)
    assert warned() == ["Wireframe on moving objects ('Slider'): the edges of their triangles as "
                        "they are at the frame, not as they move during the shutter"]
    scene.render.use_motion_blur = False
    assert warned() == []


def test_bevel_and_ambient_occlusion_with_moving_objects_are_warned(scene, fake_session):
    """Bevel traces its object's hierarchy, Ambient Occlusion the scene's, both built from the
    frame's triangles: a bevelled object that moves, and any moving object where a material
    uses AO (every object may occlude it), are warned; nothing without motion blur."""
    ob = _sliding_square(scene)
    still = new_mesh_object("Still", SQUARE, [(0, 1, 2, 3)])
    still.data.materials.append(_wireframe_material("Dirt", "ShaderNodeAmbientOcclusion", "AO"))
    _motion_blur(scene)

    def warned():
        return [w for w in export_scene(fake_session).warnings
                if w.startswith(("Bevel", "Ambient Occlusion"))]
    assert warned() == ["Ambient Occlusion with moving objects ('Slider'): they occlude as they "
                        "are at the frame, not as they move during the shutter"]
    ob.data.materials.append(_wireframe_material("Edges", "ShaderNodeBevel", "Normal"))
    assert warned()[0] == ("Bevel on moving objects ('Slider'): their surfaces' normals around "
                           "the point as they are at the frame, not as they move during the shutter")
    scene.render.use_motion_blur = False
    assert warned() == []
