"""The Bevel node (kernels/svm/bevel.py) on a flat-shaded box: its radius profile, what it
gives away from edges and where it does not trace, and how the bevelled normal turns across
an edge.  Against Cycles: blend_scenes/material_bevel_ao in the fidelity suite, and the
discrimination case that leaves its Bevel out (tests/fidelity/test_discrimination.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from mcengine.kernels.sampling import make_orthonormals, node_key
from mcengine.kernels.subsurface import build_local_bvh
from mcengine.kernels.svm import ShadingData
from mcengine.kernels.svm.bevel import MIN_RAY_PDF, _cubic_pdf, _cubic_radius, bevel_node, bevel_normal
from mcengine.kernels.svm.nodes import OFFSETS
from mcengine.shaders import NO_TEXTURES

RADIUS = 0.1
# A 2 m cube about the origin, flat faces (every corner normal is its face's normal).
_CORNERS = np.array([(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
                     (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)], float)
_QUADS = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]


def _box():
    tris = np.array([t for a, b, c, d in _QUADS for t in ((a, b, c), (a, c, d))], np.int32)
    e1 = _CORNERS[tris[:, 1]] - _CORNERS[tris[:, 0]]
    e2 = _CORNERS[tris[:, 2]] - _CORNERS[tris[:, 0]]
    n = np.cross(e1, e2)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    normals = np.ascontiguousarray(n, np.float32)                  # a face normal per triangle
    index = np.repeat(np.arange(len(tris), dtype=np.int32)[:, None], 3, axis=1)
    tri_object = np.zeros(len(tris), np.int32)
    return _CORNERS.copy(), tris, NO_TEXTURES._replace(normals=normals, normal_index=index,
                                                       tri_object=tri_object)


@pytest.fixture(scope="module", params=[True, False], ids=["embree", "hierarchy"])
def box(request):
    verts, tris, tex = _box()
    return verts, tris, tex, build_local_bvh(verts, tris, tex.tri_object, 1, [0],
                                             embree_scenes=request.param)


def _top_point(x, y=0.0, key=0, min_pdf=math.inf):
    """A camera ray's shading point on the box's top face (normal +z) at (x, y)."""
    top = 2                   # the top face's first triangle (its barycentrics go unread)
    return ShadingData(float(x), float(y), 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, False,
                       True, True, True, False, top, 0.0, 0.0, 0, 0, 1.0, 0, 0, 0, 0, 0, 0.0,
                       np.uint64(node_key(np.uint64(12345), key)), float(min_pdf))


def test_the_radius_profile_is_a_density_and_its_sampling_inverts_its_cdf():
    """10 (R - r)^3 / (pi R^5) integrates to 1 over the disk; the sampled radius r has
    10 x^2 - 20 x^3 + 15 x^4 - 4 x^5 = xi at x = r / R (the profile's CDF), as Newton's
    method in Cycles finds it."""
    r = np.linspace(0.0, RADIUS, 20001)
    pdf = np.array([_cubic_pdf(RADIUS, x) for x in r])
    assert np.trapz(2.0 * math.pi * r * pdf, r) == pytest.approx(1.0, abs=1e-6)
    assert _cubic_pdf(RADIUS, RADIUS) == 0.0 and _cubic_pdf(RADIUS, 2 * RADIUS) == 0.0
    for xi in np.linspace(0.02, 0.98, 49):
        x = _cubic_radius(RADIUS, xi) / RADIUS
        assert 10 * x**2 - 20 * x**3 + 15 * x**4 - 4 * x**5 == pytest.approx(xi, abs=2e-6)


def test_away_from_edges_the_normal_is_the_faces_exactly(box):
    """Farther than the radius from every edge, every probe finds the face itself."""
    verts, tris, tex, local = box
    for key in range(20):
        for x in (0.0, 0.5, 1.0 - 1.01 * RADIUS):
            n = bevel_normal(RADIUS, 8, _top_point(x, -0.3, key), tex, verts, tris, local)
            assert n == (0.0, 0.0, 1.0)


def _mean_normal(box, x, keys=200, samples=16):
    """The bevelled normal at (x, 0.2) on the top face, averaged over ``keys`` keys."""
    verts, tris, tex, local = box
    return np.array([bevel_normal(RADIUS, samples, _top_point(x, 0.2, k), tex, verts, tris, local)
                     for k in range(keys)]).mean(axis=0)


def test_the_normal_turns_towards_the_side_face_near_an_edge(box):
    """Within the radius of the edge x = 1 the bevelled normal leans towards the side face's
    normal (+x), more the nearer the point; it stays in the plane of the two normals.  On the
    edge itself, where both faces lie within the radius alike, it is near their bisector (not
    exactly: the disk's frame, Cycles', lies diagonally on the top face and not on the side).
    Measured in ten runs of 200 keys: 2.3-2.8, 16.3-17.8 and 44.2-45.1 deg at 0.6, 0.3 and 0
    radii from the edge (with a frame along the edges: 2.5, 17.1 and 45.0)."""
    tilts = []
    for d in (0.6 * RADIUS, 0.3 * RADIUS, 0.0):
        mean = _mean_normal(box, 1.0 - d)
        assert mean[1] == 0.0                             # no lean along the edge
        tilts.append(math.degrees(math.atan2(mean[0], mean[2])))
    assert 1.9 < tilts[0] < 3.2 and 15.5 < tilts[1] < 18.5 and 43.5 < tilts[2] < 46.0


def test_no_tracing_for_shadow_rays_or_after_blurry_bounces(box):
    """Where nodes trace nothing (min_pdf 0: shadow rays, light samples) the node gives the
    shading normal, its Normal input ignored; after a bounce whose pdf was below 8 it gives
    the linked Normal (normalised), as Cycles' svm_node_bevel does; otherwise it bevels."""
    verts, tris, tex, local = box
    spec = OFFSETS["Bevel"]
    regs = np.zeros(16)
    regs[spec["Radius"]] = RADIUS
    regs[spec["prop:samples"]] = 8
    out = 10
    linked = np.array([0.0, 0.6, 0.8])

    def run(min_pdf, normal):
        regs[spec["Normal"]:spec["Normal"] + 3] = normal
        bevel_node(regs, 0, out, _top_point(1.0 - 0.2 * RADIUS, key=3, min_pdf=min_pdf), tex,
                   verts, tris, local)
        return regs[out:out + 3].copy()

    assert run(0.0, linked).tolist() == [0.0, 0.0, 1.0]
    assert run(0.0, 0.0).tolist() == [0.0, 0.0, 1.0]
    assert run(0.99 * MIN_RAY_PDF, 0.0).tolist() == [0.0, 0.0, 1.0]
    assert run(0.99 * MIN_RAY_PDF, linked) == pytest.approx(linked)
    bevelled = run(MIN_RAY_PDF, 0.0)
    assert bevelled[0] > 0.1 and np.linalg.norm(bevelled) == pytest.approx(1.0)
    # A linked Normal is bent by the bevel's own bend: normalize(Normal + bevel - N).
    bent = linked + bevelled - np.array([0.0, 0.0, 1.0])
    assert run(MIN_RAY_PDF, linked) == pytest.approx(bent / np.linalg.norm(bent))


def test_the_disk_frame_is_cycles_make_orthonormals():
    """The probes' MIS weights each axis by its own pick only (Cycles' approximation), so how
    the frame turns about the normal shows in the image: at 4096 samples the edges of
    material_bevel_ao differed from Cycles (|t| up to 15 per pixel) with a frame along the
    box's edges and not with Cycles' frame, a = normalize((1, 1, 1) x n), b = n x a."""
    s = math.sqrt(0.5)
    assert make_orthonormals(0.0, 0.0, 1.0) == pytest.approx((s, -s, 0.0, s, s, 0.0))
    ax, ay, az, bx, by, bz = make_orthonormals(*(np.ones(3) / math.sqrt(3.0)))
    assert (ax * ax + ay * ay + az * az, bx * bx + by * by + bz * bz) == pytest.approx((1.0, 1.0))
