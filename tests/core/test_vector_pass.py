"""The Vector pass (motion vectors) against closed forms.

Cycles (geom/primitive.h primitive_motion_vector, film/data_passes.h) writes at
the first surface of each sample, with a weight of 1, the hit point's raster
position at the previous frame minus the frame's, then the frame's minus the next
frame's: (x, y, z, w) in pixels, y up.  Its Blender sync takes the previous and
next frames only when motion blur is off; with it on the pass stays 0.  Here a
plane seen from above (orthographic: 4 pixels per metre; perspective: lens 50 mm,
36 mm sensor, 8 pixels, 4 m away) moves, deforms, or the camera moves.
"""
import numpy as np
import pytest

from mcengine.scene import MotionVectors, ObjectMotion, SceneError

from .expect import render
from .scenes import look_down, translation
from .test_passes import _plane_scene


def _vectors(scene, samples=16):
    scene.integrator.samples = samples
    return render(scene).pass_image("Vector").astype(np.float64)


def _moving(scene, offset):
    """The plane at ``-offset`` at the previous frame and ``+offset`` at the next."""
    g = scene.geometry
    scene.motion_vectors = MotionVectors(objects=[ObjectMotion(
        object=0, vertices=(0, len(g.vertices)),
        matrices=np.stack([translation(*-np.asarray(offset)), np.eye(4), translation(*offset)]))])
    return scene


def test_a_plane_moving_under_an_orthographic_camera():
    scene = _moving(_plane_scene(enabled=("Vector",)), (0.25, 0.125, 0.0))
    # 4 pixels per metre: 1 pixel right and half a pixel up per frame, both halves.
    np.testing.assert_allclose(_vectors(scene), np.broadcast_to([-1.0, -0.5, -1.0, -0.5], (8, 8, 4)),
                               atol=1e-4)


def test_a_camera_moving_over_a_still_plane():
    scene = _plane_scene(enabled=("Vector",), ortho=False)
    scene.motion_vectors = MotionVectors(camera=np.stack([look_down(4.0, x=0.1), look_down(4.0, x=-0.1)]))
    # The plane moves +0.1 m per frame relative to the camera: 8 px over 2 x 0.36 x 4 m.
    px = 0.1 * 8 / (2 * 0.36 * 4.0)
    np.testing.assert_allclose(_vectors(scene), np.broadcast_to([-px, 0.0, -px, 0.0], (8, 8, 4)),
                               atol=1e-4)


def test_a_plane_coming_closer_in_perspective():
    # At the previous frame the plane lies 0.5 m lower, at the next 0.5 m higher: a point at
    # raster offset r from the centre was at r x 4 / 4.5 and will be at r x 4 / 3.5.  The
    # vector is linear in the position, so the mean over a pixel is its centre's value.
    scene = _moving(_plane_scene(enabled=("Vector",), ortho=False), (0.0, 0.0, 0.5))
    r = np.arange(8) + 0.5 - 4.0
    v = _vectors(scene, samples=64)
    np.testing.assert_allclose(v[..., 0], np.broadcast_to(r * (4 / 4.5 - 1), (8, 8)), atol=0.03)
    np.testing.assert_allclose(v[..., 2], np.broadcast_to(r * (1 - 4 / 3.5), (8, 8)), atol=0.03)
    np.testing.assert_allclose(v[..., 1], np.broadcast_to(-r[:, None] * (4 / 4.5 - 1), (8, 8)),
                               atol=0.03)     # rows top to bottom, raster y up


def test_a_deforming_plane():
    # The plane's vertices at half their positions at the previous frame, at 1.5 times at
    # the next: the vector is (-0.5, +0.5) times the position in pixels (4 per metre).
    scene = _plane_scene(enabled=("Vector",))
    g = scene.geometry
    scene.motion_vectors = MotionVectors(objects=[ObjectMotion(
        object=0, vertices=(0, len(g.vertices)),
        positions=np.stack([0.5 * g.vertices, g.vertices, 1.5 * g.vertices]).astype(np.float32),
        normals=np.stack([g.corner_normals()] * 3).astype(np.float32))])
    r = (np.arange(8) + 0.5 - 4.0) * 0.25 * 4
    v = _vectors(scene, samples=64)
    np.testing.assert_allclose(v[..., 0], np.broadcast_to(-0.5 * r, (8, 8)), atol=0.03)
    np.testing.assert_allclose(v[..., 2], np.broadcast_to(-0.5 * r, (8, 8)), atol=0.03)


def test_the_pass_stays_zero_with_motion_blur_on():
    scene = _moving(_plane_scene(enabled=("Vector",), motion_blur=True), (0.25, 0.0, 0.0))
    assert not np.any(_vectors(scene))


def test_bad_motion_is_refused():
    scene = _moving(_plane_scene(enabled=("Vector",)), (0.25, 0.0, 0.0))
    om = scene.motion_vectors.objects[0]
    om.matrices = np.concatenate([om.matrices, om.matrices[:2]])        # 5 steps
    with pytest.raises(SceneError, match="3 steps"):
        scene.validate()
    scene = _plane_scene(enabled=("Vector",))
    scene.motion_vectors = MotionVectors(camera=np.eye(4)[None])
    with pytest.raises(SceneError, match="camera must be 2"):
        scene.validate()


def test_a_saved_scene_keeps_its_motion_vectors(tmp_path):
    from mcengine.scene import SceneDescription
    scene = _moving(_plane_scene(enabled=("Vector",)), (0.25, 0.125, 0.0))
    scene.motion_vectors.camera = np.stack([look_down(4.0, x=0.1), look_down(4.0, x=-0.1)])
    scene.save(tmp_path / "vectors.npz")
    loaded = SceneDescription.load(tmp_path / "vectors.npz")
    assert np.array_equal(_vectors(scene, samples=4), _vectors(loaded, samples=4))
    assert np.abs(_vectors(loaded, samples=4)).max() > 0.5
