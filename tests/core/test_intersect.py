"""Embree closest hits against a brute-force float64 triangle test."""
import numpy as np
import pytest
from numba import njit

from mcengine.kernels import embree
from mcengine.kernels.intersect import Accel, intersect_triangle, triangle_frame
from mcengine.packing import areas_and_normals

# Both ways of calling Embree: packets through the library's C API (the default) and
# embreex's single rays (the fallback where the library is not found).
backends = pytest.mark.parametrize("packets", [True, False], ids=["packets", "embreex"])


def brute_force(o, d, tris):
    """(n,) closest triangle index or -1, and the distance, by Moller-Trumbore in float64."""
    v0, e1, e2 = tris[:, 0], tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    best = np.full(len(o), -1)
    tbest = np.full(len(o), np.inf)
    for k in range(len(tris)):
        p = np.cross(d, e2[k])
        det = p @ e1[k]
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            s = o - v0[k]
            u = np.einsum("ij,ij->i", s, p) * inv
            q = np.cross(s, e1[k])
            v = np.einsum("ij,ij->i", d, q) * inv
            t = (q @ e2[k]) * inv
        ok = (np.abs(det) > 1e-12) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0) & (t < tbest)
        best[ok] = k
        tbest[ok] = t[ok]
    return best, tbest


@backends
def test_closest_hit_matches_brute_force(packets):
    rng = np.random.default_rng(7)
    centers = rng.uniform(-1, 1, (300, 1, 3))
    tris = centers + 0.3 * rng.standard_normal((300, 3, 3))
    accel = Accel(tris.reshape(-1, 3).astype(np.float32), np.arange(900, dtype=np.int32).reshape(-1, 3),
                  packets=packets)
    tris32 = tris.astype(np.float32).astype(np.float64)
    o = rng.uniform(-2, 2, (3999, 3))
    d = rng.standard_normal((3999, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    prim = accel.closest(o.astype(np.float32), d.astype(np.float32), np.full(3999, 1e30, np.float32))
    ref, tref = brute_force(o, d, tris32)
    agree = prim == ref
    # Rays grazing an edge may go either way in float32; they must be rare and
    # then the two hits must be at (nearly) the same distance.
    assert agree.mean() > 0.995
    for i in np.flatnonzero(~agree):
        assert prim[i] >= 0 and ref[i] >= 0
        t, _, _ = intersect_triangle(*o[i], *d[i], *tris32[prim[i]].ravel())
        assert abs(t - tref[i]) < 1e-4 * max(1.0, tref[i])
    assert (ref >= 0).sum() > 300   # the test exercises hits, not just misses


@backends
def test_tfar_limits_hits_and_occlusion(packets):
    tri = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    accel = Accel(tri, np.array([[0, 1, 2]], np.int32), packets=packets)
    o = np.array([[0.2, 0.2, 1.0]] * 2, np.float32)
    d = np.array([[0, 0, -1.0]] * 2, np.float32)
    t = np.array([2.0, 0.5], np.float32)
    assert accel.closest(o, d, t.copy()).tolist() == [0, -1]
    assert accel.occluded(o, d, t.copy()).tolist() == [True, False]


@backends
def test_empty_scene_misses(packets):
    accel = Accel(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int32), packets=packets)
    o = np.zeros((3, 3), np.float32)
    assert accel.closest(o, o + 1, np.ones(3, np.float32)).tolist() == [-1, -1, -1]
    assert accel.occluded(o, o + 1, np.ones(3, np.float32)).tolist() == [False] * 3


def test_float64_refinement_is_exact_on_a_known_hit():
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0]], float)
    t, b1, b2 = intersect_triangle(0.5, 0.25, 3.0, 0.0, 0.0, -1.0, *v.ravel())
    assert (t, b1, b2) == (3.0, 0.25, 0.125)


def _rays_at_shared_edges():
    """A closed sphere's vertices and triangles, and batches of rays (o, d) from inside it
    aimed exactly at its shared edges and vertices."""
    from .scenes import uv_sphere
    tris, _ = uv_sphere(1.0, 24, 12)
    v, inv = np.unique(np.round(tris.reshape(-1, 3), 12), axis=0, return_inverse=True)
    idx = inv.reshape(-1, 3).astype(np.int32)
    verts = v.astype(np.float32)
    targets = np.array([verts[t[a]] * (1 - f) + verts[t[b]] * f
                        for t in idx for a, b in ((0, 1), (1, 2), (2, 0)) for f in (0.0, 0.25, 0.5)],
                       np.float32)
    rng = np.random.default_rng(0)
    batches = []
    for spread in (0.0, 0.1, 0.3):
        o = rng.standard_normal(targets.shape) * spread
        o *= np.minimum(1.0, 0.5 / np.maximum(np.linalg.norm(o, axis=1, keepdims=True), 1e-9))
        o = o.astype(np.float32)        # origins well inside the sphere
        d = targets - o
        batches.append((o, (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)))
    return verts, idx, batches


@backends
def test_rays_aimed_at_shared_edges_and_vertices_never_leak(packets):
    """Watertightness: from inside a closed mesh, rays aimed exactly at its shared
    edges and vertices must hit it (the renderer uses Embree's robust mode)."""
    verts, idx, batches = _rays_at_shared_edges()
    accel = Accel(verts, idx, packets=packets)
    for o, d in batches:
        prim = accel.closest(o, d, np.full(len(o), 1e30, np.float32))
        assert np.all(prim >= 0), f"{int((prim < 0).sum())} of {len(o)} rays leaked"


def test_the_fast_mode_leaks_where_the_robust_one_does_not():
    """What the robust mode buys: Embree's fast mode (``robust=False``, which only the
    benchmarks build) lets several percent of those rays slip between the triangles."""
    verts, idx, batches = _rays_at_shared_edges()
    fast = embree.build(verts, idx, robust=False)
    o = np.concatenate([b[0] for b in batches])
    d = np.concatenate([b[1] for b in batches])
    leaked = int((fast.closest(o, d, np.full(len(o), 1e30, np.float32)) < 0).sum())
    assert leaked > 0.02 * len(o), f"{leaked} of {len(o)} rays leaked"


def test_packets_are_the_default_and_agree_with_embreex_ray_for_ray():
    """The wheel's library is found here, so renders trace in packets; and the packets give
    embreex's answers exactly (the same library, the same robust mode), closest hits and
    occlusion, for batches that do not fill the last packet."""
    assert embree.library_path() is not None
    rng = np.random.default_rng(3)
    tris = (rng.uniform(-1, 1, (200, 1, 3)) + 0.4 * rng.standard_normal((200, 3, 3)))
    verts, idx = tris.reshape(-1, 3).astype(np.float32), np.arange(600, dtype=np.int32).reshape(-1, 3)
    fast, single = Accel(verts, idx), Accel(verts, idx, packets=False)
    assert isinstance(fast._scene, embree._PacketScene)
    n = 20001
    o = rng.uniform(-2, 2, (n, 3)).astype(np.float32)
    d = rng.standard_normal((n, 3))
    d = (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)
    t = rng.uniform(0.0, 3.0, n).astype(np.float32)
    prim = fast.closest(o, d, t)
    assert np.array_equal(prim, single.closest(o, d, t))
    assert 0.2 < (prim >= 0).mean() < 0.9
    blocked = fast.occluded(o, d, t)
    assert np.array_equal(blocked, single.occluded(o, d, t))
    assert np.array_equal(blocked, prim >= 0)


@njit(cache=False)
def _frames(verts, tris):
    out = np.empty((tris.shape[0], 4))
    for p in range(tris.shape[0]):
        out[p, 0], out[p, 1], out[p, 2], out[p, 3] = triangle_frame(verts, tris, p)
    return out


def test_triangle_frames_are_the_packed_ones_to_the_bit():
    """The kernels compute a triangle's normal and area where they need them
    (``triangle_frame``); the packing computes the emissive triangles' (and displacement
    all of them) with ``areas_and_normals``: both give the same bits, on ordinary, sliver,
    tiny, huge, collinear and repeated-vertex triangles."""
    rng = np.random.default_rng(11)
    groups = [rng.uniform(-10, 10, (3000, 3)), rng.uniform(-1e-20, 1e-20, (300, 3)),
              rng.uniform(-1e6, 1e6, (300, 3))]
    # Each group's own triangles, corners distinct: none of them is degenerate.
    tris, first = [], 0
    for g in groups:
        tris.append(first + np.argsort(rng.random((len(g), len(g))), axis=1)[:, :3])
        first += len(g)
    verts = np.concatenate(groups + [[[0, 0, 0], [1, 1, 1], [2, 2, 2]]])
    verts = verts.astype(np.float32).astype(np.float64)     # as the packed scene's
    # A cross product whose square underflows: a zero length, a non-zero normal.
    verts = np.concatenate([verts, [[1e-160, 0, 0], [0, 1e-160, 0]]])
    n = len(verts)
    degenerate = np.array([[0, 0, 5]] * 5 + [[n - 5, n - 4, n - 3]] * 5 + [[n - 5, n - 2, n - 1]] * 5)
    tris = np.concatenate([degenerate] + tris).astype(np.int32)
    area, normal = areas_and_normals(verts, tris)
    frames = _frames(verts, tris)
    assert np.array_equal(frames[:, :3].view(np.uint64), normal.view(np.uint64))
    assert np.array_equal(frames[:, 3].view(np.uint64), area.view(np.uint64))
    assert (area[:15] == 0.0).all() and (area[15:] > 0.0).all()
    assert (normal[10:15, 2] > 0.0).all()


@pytest.mark.parametrize("spatial_splits, compact", [(True, False), (False, True), (True, True)],
                         ids=["spatial-splits", "compact", "both"])
def test_cycles_bvh_settings_reach_embree_and_find_the_same_hits(spatial_splits, compact,
                                                                 monkeypatch):
    """Use Spatial Splits and Use Compact BVH: Embree is asked for its high build quality and
    its compact layout (which holds the same triangles in less memory, counted by Embree's
    memory monitor), and every ray finds what the default BVH finds."""
    import ctypes
    library = embree._load()
    qualities = []
    set_quality = library.lib.rtcSetSceneBuildQuality
    monkeypatch.setattr(library.lib, "rtcSetSceneBuildQuality",
                        lambda scene, quality: (qualities.append(quality), set_quality(scene, quality)))
    monitor = ctypes.CFUNCTYPE(ctypes.c_bool, ctypes.c_void_p, ctypes.c_ssize_t, ctypes.c_bool)
    allocated = [0]

    def count(_user, nbytes, _post):
        allocated[0] += max(nbytes, 0)
        return True

    callback = monitor(count)
    library.lib.rtcSetDeviceMemoryMonitorFunction.argtypes = [ctypes.c_void_p, monitor, ctypes.c_void_p]
    rng = np.random.default_rng(5)
    centers = rng.uniform(-1, 1, (20000, 1, 3))
    tris = (centers + 0.05 * rng.standard_normal((20000, 3, 3))).reshape(-1, 3).astype(np.float32)
    index = np.arange(len(tris), dtype=np.int32).reshape(-1, 3)
    library.lib.rtcSetDeviceMemoryMonitorFunction(library.device, callback, None)
    try:
        default = Accel(tris, index)
        default_bytes, allocated[0] = allocated[0], 0
        chosen = Accel(tris, index, spatial_splits=spatial_splits, compact=compact)
        chosen_bytes = allocated[0]
    finally:
        library.lib.rtcSetDeviceMemoryMonitorFunction(library.device, monitor(), None)
    assert qualities == [1, 2 if spatial_splits else 1]      # medium, then high with splits
    if compact:
        assert chosen_bytes < 0.8 * default_bytes
    o = rng.uniform(-2, 2, (4000, 3)).astype(np.float32)
    d = rng.normal(size=(4000, 3))
    d = (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)
    tfar = np.full(4000, 1e30, np.float32)
    prim, prim2 = default.closest(o, d, tfar), chosen.closest(o, d, tfar)
    assert (prim >= 0).sum() > 500
    # Embree's test of a ray against a triangle does not depend on the BVH: the same hits
    # but where two triangles meet the ray at the same distance.
    for i in np.flatnonzero(prim2 != prim):
        assert prim[i] >= 0 and prim2[i] >= 0
        t1 = intersect_triangle(*o[i], *d[i], *tris[3 * prim[i]:3 * prim[i] + 3].ravel())[0]
        t2 = intersect_triangle(*o[i], *d[i], *tris[3 * prim2[i]:3 * prim2[i] + 3].ravel())[0]
        assert abs(t1 - t2) < 1e-5
    assert (prim2 == prim).mean() > 0.999
    np.testing.assert_array_equal(chosen.occluded(o, d, tfar), default.occluded(o, d, tfar))
