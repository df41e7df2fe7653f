"""The BVH of the last render is reused for the same triangles, rebuilt for others."""
import numpy as np

from mcengine import accel_cache

VERTICES = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
TRIANGLES = np.array([[0, 1, 2], [0, 1, 3]], np.int32)


def test_same_triangles_reuse_the_bvh_and_others_rebuild_it():
    accel_cache.clear()
    first, reused = accel_cache.accel_for(VERTICES, TRIANGLES)
    assert not reused
    again, reused = accel_cache.accel_for(VERTICES.copy(), TRIANGLES.copy())
    assert reused and again is first
    moved = VERTICES.copy()
    moved[3, 2] = np.nextafter(np.float32(1), np.float32(2))   # one ulp is another scene
    other, reused = accel_cache.accel_for(moved, TRIANGLES)
    assert not reused and other is not first
    fewer, reused = accel_cache.accel_for(VERTICES, TRIANGLES[:1])
    assert not reused
    # The kept BVH answers for its own triangles: a ray down the z axis hits triangle 0.
    hit = fewer.closest(np.array([[0.2, 0.2, 1]], np.float32), np.array([[0, 0, -1]], np.float32),
                        np.array([10], np.float32))
    assert hit.tolist() == [0]
    accel_cache.clear()


def test_the_same_triangles_with_another_ray_visibility_rebuild_it():
    """Objects hidden from some rays are another BVH (Embree's geometry masks)."""
    accel_cache.clear()
    plain, _ = accel_cache.accel_for(VERTICES, TRIANGLES)
    hidden = np.array([1, 63], np.uint8)
    masked, reused = accel_cache.accel_for(VERTICES, TRIANGLES, visibility=hidden)
    assert not reused and masked is not plain and masked.masked
    assert accel_cache.accel_for(VERTICES, TRIANGLES, visibility=hidden.copy())[0] is masked
    assert not accel_cache.accel_for(VERTICES, TRIANGLES)[1]
    accel_cache.clear()


def test_a_scene_without_triangles_has_a_bvh_too():
    """A world preview or an empty scene: no triangles, nothing hit, reused like any other."""
    accel_cache.clear()
    empty, reused = accel_cache.accel_for(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int32))
    assert not reused
    hit = empty.closest(np.zeros((1, 3), np.float32), np.array([[0, 0, 1]], np.float32),
                        np.array([1], np.float32))
    assert hit.tolist() == [-1]
    assert accel_cache.accel_for(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int32))[1]
    accel_cache.clear()


def test_moving_triangles_are_never_reused():
    """The same triangles with an object moving during the shutter: the kept BVH (static)
    would miss the motion, and a BVH with motion is not kept for a static render."""
    from mcengine.kernels.motion import pack_motion
    from mcengine.scene import Geometry, ObjectMotion
    g = Geometry.from_triangles(VERTICES[TRIANGLES], object_names=["Box"])
    shift = np.eye(4)
    shift[0, 3] = 0.5
    motion = pack_motion(g, [ObjectMotion(object=0, vertices=(0, 6),
                                          matrices=np.stack([np.eye(4), np.eye(4), shift]))])
    accel_cache.clear()
    static, _ = accel_cache.accel_for(g.vertices, g.triangles)
    moving, reused = accel_cache.accel_for(g.vertices, g.triangles, motion)
    assert not reused and moving is not static
    assert not accel_cache.accel_for(g.vertices, g.triangles, motion)[1]
    assert not accel_cache.accel_for(g.vertices, g.triangles)[1]
    accel_cache.clear()
