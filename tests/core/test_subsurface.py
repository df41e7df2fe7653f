"""Subsurface scattering (random walks, Christensen-Burley disks): against Cycles, and parts
against closed forms.

The Cycles values are ``material_oracles.py``'s SUBSURFACE_ORACLES, rendered by Cycles
5.0.1 with 16384 samples per pixel (``tools/measure_material_oracles.py``), each with the
standard error of its mean from the spread of its 64 pixels.  A walk is random even under a
point light, so every channel of MC Engine's mean must lie within Z_LIMIT combined standard
errors of Cycles' (plus 2e-3 relative for float32 against float64 arithmetic): at this Z a
correct renderer fails one channel of the 27 with probability below 3e-4, and a medium
whose albedo fit is off by a few per cent fails (the furnaces' channels are known to 5e-4;
with the fit's exponent 0.3 instead of 0.25 the random-walk furnaces are 10-20 % off).
A half-space does not depend on the radius; the two slabs 5 mm thick lit from below do: with
every radius 10 % larger or smaller (Random Walk and Christensen-Burley) their red channel
moves by 9.5 to 11.6 combined standard errors.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numba
import numpy as np
import pytest

from mcengine.kernels.closures.bssrdf import (
    BURLEY_TRUNCATE,
    _dipole_rd,
    burley_pdf,
    burley_root,
    dipole_alpha_prime,
    disk_sample,
)
from mcengine.kernels.sampling import (
    SAMPLE_BITS,
    SAMPLER_SOBOL,
    exit_key,
    sample_4d,
    sample_key,
    walk_key,
)
from mcengine.kernels.sobol import index_mask
from mcengine.kernels.state import MF_BSSRDF_BUMP
from mcengine.kernels.subsurface import build_local_bvh, hg_phase, hg_sample, local_closest, remap
from mcengine.passes import RenderPasses
from mcengine.scene import Geometry, Link, Material, ShaderNode
from mcengine.session import RenderSession
from mcengine.shaders import ShaderTable

from .expect import Z_LIMIT, render
from .material_oracles import SUBSURFACE_ORACLES
from .scenes import uv_sphere
from .test_material_oracles import MEASURED, oracle_scene
from .test_sobol import _is_net

RELATIVE = 2e-3


def _channel_stats(session):
    img = session.image().astype(np.float64)
    var = session.variance().astype(np.float64)
    n = img.shape[0] * img.shape[1]
    return img[..., :3].reshape(-1, 3).mean(axis=0), np.sqrt(var[..., :3].reshape(-1, 3).sum(axis=0)) / n


@pytest.mark.parametrize("name", list(SUBSURFACE_ORACLES))
def test_subsurface_matches_cycles(name):
    expected = np.array(MEASURED[name]["rgba"][:3])
    expected_se = np.array(MEASURED[name]["se"][:3])
    scene = oracle_scene(name, samples=2048)
    scene.integrator = replace(scene.integrator, sampler="independent")
    mean, se = _channel_stats(render(scene))
    bound = Z_LIMIT * np.hypot(se, expected_se) + RELATIVE * np.abs(expected)
    assert np.all(np.abs(mean - expected) <= bound), (
        f"{name}: MC Engine {mean.round(5)} (se {se.round(5)}) vs Cycles {expected.round(5)} "
        f"(se {expected_se.round(5)})")


def test_subsurface_off_is_lambert_of_the_same_colour():
    """Without walks (the classic integrators) a BSSRDF is Lambert of its weight, Cycles'
    zero-radius limit: in a furnace the plane then reflects exactly its base colour."""
    scene = oracle_scene("subsurface_furnace", samples=64)
    scene.integrator = replace(scene.integrator, name="distribution", max_bounces=2)
    mean, _se = _channel_stats(render(scene))
    np.testing.assert_allclose(mean, (0.8, 0.4, 0.1), rtol=1e-6)


@pytest.mark.parametrize("embree_scenes", [True, False], ids=["embree", "compiled"])
def test_local_hierarchy_finds_the_closest_hit_on_its_own_object_only(embree_scenes):
    """Against brute force over the object's triangles, for rays that start on one of them
    (the walk's first step, the disk probe's next surface) or inside the object: a second
    object in the way is ignored, and the triangle a ray starts on is never reported.
    Embree's float32 rays may pick the other triangle at a shared edge: rare, and then at
    the same distance; the compiled hierarchy, in float64, agrees exactly."""
    g = Geometry.concatenate([Geometry.from_triangles(uv_sphere(0.5, 16, 8)[0]),
                              Geometry.from_triangles(uv_sphere(1.0, 16, 8)[0]),
                              Geometry.from_triangles(uv_sphere(0.2, 8, 4)[0])])
    verts, tris = g.vertices.astype(np.float64), np.asarray(g.triangles, np.int32)
    obj = np.asarray(g.object_index, np.int32)
    lb = build_local_bvh(verts, tris, obj, 3, [0, 1], embree_scenes=embree_scenes)
    assert (lb.intersect[0] != 0) == embree_scenes
    rng = np.random.default_rng(5)
    own = np.flatnonzero(obj == 1)
    checked = agreed = 0
    for k in range(600):
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        if k % 2:
            skip = int(rng.choice(own))
            u, v = rng.random(2)
            if u + v > 1.0:
                u, v = 1.0 - u, 1.0 - v
            a, b, c = verts[tris[skip]]
            o = a + u * (b - a) + v * (c - a)
        else:
            skip, o = -1, rng.normal(size=3) * 0.3
        t, p = local_closest(lb, verts, tris, 1, *o, *d, math.inf, skip)
        best, found = math.inf, -1
        for q in own:
            if q == skip:
                continue
            a, b, c = verts[tris[q]]
            hit = _moller(o, d, a, b, c)
            if hit < best:
                best, found = hit, q
        assert p != skip or skip < 0
        if p == found:
            agreed += 1
            assert found < 0 or abs(t - best) < 1e-12 * max(best, 1.0)
        else:
            assert embree_scenes and p >= 0 and found >= 0 and abs(t - best) < 1e-5
        checked += found >= 0
    assert checked > 400         # rays leaving the convex sphere outwards meet nothing
    assert agreed >= (600 if not embree_scenes else 594)
    # Object 2 has no hierarchy: nothing is ever hit there.
    assert local_closest(lb, verts, tris, 2, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, math.inf, -1)[1] == -1
    assert obj[local_closest(lb, verts, tris, 0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, math.inf, -1)[1]] == 0
    # A segment that ends before the surface meets nothing.
    assert local_closest(lb, verts, tris, 1, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.9, -1)[1] == -1


def _moller(o, d, a, b, c):
    e1, e2 = b - a, c - a
    pv = np.cross(d, e2)
    det = e1 @ pv
    if det == 0.0:
        return math.inf
    tv = o - a
    u = (tv @ pv) / det
    qv = np.cross(tv, e1)
    v = (d @ qv) / det
    if u < 0 or u > 1 or v < 0 or u + v > 1:
        return math.inf
    t = (e2 @ qv) / det
    return t if t > 0 else math.inf


def test_albedo_remap_is_monotone_and_bounded():
    """The single-scattering albedo the walk uses grows with the surface albedo, stays in
    [0, 1), and the extinction is 1 / (radius (1 - g))."""
    for g in (0.0, 0.3, 0.6, 0.9):
        alphas = [remap(a, 0.5, g)[1] for a in np.linspace(0.0, 1.0, 101)]
        assert alphas[0] == 0.0 and all(0.0 <= x < 1.0 for x in alphas)
        assert all(b >= a for a, b in zip(alphas, alphas[1:]))
        assert remap(0.5, 0.5, g)[0] == pytest.approx(1.0 / (0.5 * (1.0 - g)))


def test_dipole_inverse_recovers_the_albedo():
    for a in (0.05, 0.3, 0.7, 0.95):
        rd = _dipole_rd(a, 2.5)
        assert dipole_alpha_prime(rd, 2.5) == pytest.approx(a, abs=1e-3)   # 12 halvings


@pytest.mark.parametrize("g", [0.0, 0.5, 0.9])
def test_henyey_greenstein_sampling_matches_its_pdf(g):
    """Sampled cosines follow the phase function (chi-square over 20 equal-probability cells
    of the analytic CDF, alpha = 0.01) and the returned pdf is the function's value."""
    rng = np.random.default_rng(11)
    n = 20000
    cos = np.empty(n)
    for k in range(n):
        x, y, z, pdf = hg_sample(0.0, 0.0, 1.0, g, rng.random(), rng.random())
        cos[k] = z
        assert pdf == pytest.approx(hg_phase(z, g), rel=1e-9)
    grid = np.linspace(-1.0, 1.0, 20001)
    density = np.array([hg_phase(c, g) for c in grid]) * 2.0 * math.pi
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(grid))])
    assert cdf[-1] == pytest.approx(1.0, abs=1e-4)
    u = np.interp(cos, grid, cdf)                 # uniform if the cosines follow the pdf
    counts = np.bincount(np.minimum((u * 20).astype(int), 19), minlength=20)
    chi2 = ((counts - n / 20) ** 2 / (n / 20)).sum()
    assert chi2 < 36.19          # chi-square 0.99 quantile, 19 degrees of freedom


def test_exit_key_changes_the_scrambles_and_keeps_the_sample_index():
    key = 0x123456789ABCDEF0
    low = (1 << SAMPLE_BITS) - 1
    for vertex in range(4):
        k2 = int(exit_key(np.uint64(key), vertex))
        assert k2 & low == key & low and k2 != key
        k3 = int(walk_key(np.uint64(key), vertex))
        assert k3 & low == key & low and k3 not in (key, k2)
    assert len({int(exit_key(np.uint64(key), v)) for v in range(16)}) == 16
    assert len({int(walk_key(np.uint64(key), v)) for v in range(16)}) == 16


@numba.njit
def _walk_numbers(seed, pixel, n, vertex, dim_set, mask):
    out = np.zeros((n, 4))
    for s in range(n):
        wkey = walk_key(sample_key(SAMPLER_SOBOL, seed, pixel, s), vertex)
        out[s, 0], out[s, 1], out[s, 2], out[s, 3] = sample_4d(SAMPLER_SOBOL, wkey, dim_set,
                                                                np.uint64(mask))
    return out


@pytest.mark.parametrize("vertex,dim_set", [(0, 0), (2, 1), (1, 2 * 9), (5, 2 * 200 + 1)])
def test_walk_numbers_are_stratified_over_a_pixels_samples(vertex, dim_set):
    """With Sobol, every step's numbers of a walk (its key's dimension sets) over a pixel's
    64 samples put one point in each elementary interval of area 1/64, as the path's own
    numbers do: a walk key that hashed the sample index away would not."""
    points = _walk_numbers(3, 4242, 64, vertex, dim_set, index_mask(64))
    assert _is_net(points[:, :2], 6, 0)
    for d in range(4):
        assert np.array_equal(np.sort(np.floor(points[:, d] * 64)), np.arange(64))


@pytest.mark.parametrize("inputs", [
    {"Base Color": (1.0, 1.0, 1.0)},                                  # no absorption at all
    {"Base Color": (0.0, 0.0, 0.0)},
    {"Base Color": (1.0, 0.02, 0.0), "Subsurface Scale": 1e-9},       # radius below 1e-8: Lambert
    {"Subsurface Scale": 1e3, "Subsurface Radius": (1.0, 0.0, 1e-12)},  # mixed: a walk and Lambert
    {"IOR": 1.0, "Roughness": 0.0},
    {"IOR": 10.0, "Roughness": 1.0, "Subsurface Anisotropy": 1.0},
    {"Subsurface Anisotropy": -1.0, "Base Color": (0.999, 0.5, 0.001)},
])
def test_hard_subsurface_parameters_stay_finite_and_conserve_energy(inputs):
    """In a white furnace (a half-space of the medium) no parameter makes NaN, Inf, negative
    values or more light than the world gives."""
    scene = oracle_scene("subsurface_furnace", samples=256)
    node = scene.materials[0].nodes[0]
    node.inputs.update({"Specular IOR Level": 0.0, **inputs})
    session = render(scene)
    img = session.image().astype(np.float64)[..., :3]
    assert np.all(np.isfinite(img)) and img.min() >= 0.0
    mean, se = _channel_stats(session)
    assert np.all(mean <= 1.0 + Z_LIMIT * se + 1e-9), mean


@pytest.mark.parametrize("weight,kinds", [(0.0, {"diffuse"}), (0.5, {"diffuse", "subsurface"}),
                                          (1.0, {"subsurface"})])
def test_the_effects_plan_walks_only_for_subsurface_materials(weight, kinds):
    scene = oracle_scene("subsurface_furnace")
    scene.materials[0].nodes[0].inputs.update({"Subsurface Weight": weight})
    plan = RenderSession(scene, threads=1).plan
    assert set(plan.lobes) == kinds
    assert plan.subsurface == ("subsurface" in kinds)


def _principled(**inputs):
    return ShaderNode("BsdfPrincipled", {"Subsurface Weight": 1.0, **inputs})


_TEXTURE = ShaderNode("TexChecker", {"Scale": 3.0})
_NORMAL_MAP = ShaderNode("NormalMap", {"Color": (0.75, 0.5, 0.933)}, {"space": "OBJECT"})
BSSRDF_BUMP = {     # material: whether Cycles sets SD_HAS_BSSRDF_BUMP (exits run the shader)
    "textured colour": ([_TEXTURE, _principled(**{"Base Color": Link(0, "Color")})], False),
    "normal map": ([_NORMAL_MAP, _principled(Normal=Link(0, "Normal"))], True),
    "normal map, no subsurface": ([_NORMAL_MAP, _principled(**{"Normal": Link(0, "Normal"),
                                                               "Subsurface Weight": 0.0})], False),
    "normal map, linked weight": ([_NORMAL_MAP, _TEXTURE,
                                   _principled(**{"Normal": Link(0, "Normal"),
                                                  "Subsurface Weight": Link(1, "Fac")})], True),
    "geometry normal": ([ShaderNode("NewGeometry"),
                         ShaderNode("SubsurfaceScattering", {"Normal": Link(0, "Normal")})], False),
    "node, normal map": ([_NORMAL_MAP, ShaderNode("SubsurfaceScattering",
                                                  {"Normal": Link(0, "Normal")})], True),
}


def test_exits_run_the_shader_only_where_a_bssrdf_normal_is_linked():
    """Cycles evaluates the shader at a walk's exit only for SD_HAS_BSSRDF_BUMP (a node that
    can make a BSSRDF, its Normal linked to anything but the Geometry node); elsewhere the
    exit is Lambert about the smooth normal, however textured the material."""
    table = ShaderTable([Material(nodes=nodes, surface=Link(len(nodes) - 1, "BSDF"))
                         for nodes, _bump in BSSRDF_BUMP.values()])
    flagged = {name: bool(f & MF_BSSRDF_BUMP) for name, f in zip(BSSRDF_BUMP, table.flags)}
    assert flagged == {name: bump for name, (_nodes, bump) in BSSRDF_BUMP.items()}


def test_diffuse_color_pass_counts_the_subsurface_closure():
    """Cycles' Diffuse Color pass sums diffuse and BSSRDF closures (surface_shader_diffuse):
    Subsurface Weight 0.5 of a (0.8, 0.4, 0.1) base colour without specular gives the colour."""
    scene = oracle_scene("subsurface_furnace", samples=4)
    scene.materials[0].nodes[0].inputs.update({"Subsurface Weight": 0.5})
    scene.passes = RenderPasses(enabled=("Diffuse Color",))
    colour = render(scene).pass_image("Diffuse Color")
    np.testing.assert_allclose(colour, np.broadcast_to([0.8, 0.4, 0.1], colour.shape), rtol=1e-6)


def test_burley_profile_is_a_density_and_its_sampling_inverts_its_cdf():
    """Over r in [0, 16 d] the profile (a density in r: Cycles folds 2 pi r into it) with the
    truncation's normalisation integrates to 1; the root finder inverts its CDF; disk radii
    stay inside the truncation with the probe's half height sqrt(Rm^2 - r^2)."""
    d = 0.3
    r = np.linspace(0.0, BURLEY_TRUNCATE * d, 200001)
    pdf = np.array([burley_pdf(d, x) for x in r])
    assert np.trapz(pdf, r) == pytest.approx(1.0, abs=1e-4)
    for x in (0.05, 0.5, 1.0, 4.0, 12.0):
        cdf = 1.0 - 0.25 * math.exp(-x) - 0.75 * math.exp(-x / 3.0)
        assert burley_root(cdf) == pytest.approx(x, rel=1e-4)
    for xi in np.linspace(0.0, 0.999, 50):
        radius, h = disk_sample(0.0, d, 0.0, xi)          # one channel with a radius
        assert 0.0 <= radius <= BURLEY_TRUNCATE * d
        assert h == pytest.approx(math.sqrt((BURLEY_TRUNCATE * d) ** 2 - radius ** 2))
