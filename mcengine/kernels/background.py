"""The world as a light: its importance map, sampled by next-event estimation (Cycles'
kernel/light/background.h, scene/light.cpp).

When the world's Sampling Method is not None and the world gives light, the
render bakes the world's shader into an equirectangular map of W x H texels
(``bake_background``: one evaluation at each texel's centre, with no ray-type
flags, as Cycles bakes it) and builds a 2D distribution over it
(``mcengine.background``): each texel weighs the mean of its |R|, |G|, |B| times
sin(theta) of its row centre; ``bg_marginal`` is the CDF over rows,
``bg_conditional`` the CDF over the columns of each row.

``sample_background`` picks a texel (binary searches) and a point in it
(linear inversion inside the bin) and returns the direction and its solid-angle
pdf, p_uv / (2 pi^2 sin theta) with theta of the continuous v;
``background_pdf`` gives the same pdf for any direction, for the MIS weight of a
ray that escapes.  The world's radiance itself always comes from its shader
(``shading.world_radiance``), never from the map.

A Sky Texture's sun disc is far smaller than a texel of the map, which sees it only
where a texel's centre falls inside it: the rest of the disc would be found by BSDF
rays alone, as rare, bright fireflies.  As Cycles' sun guiding, a share of the world's
samples then goes to the sun's cone instead (``bg_sun``, set by ``mcengine.packing``
from ``mcengine.sky.sun_guide``), drawn uniformly in it: ``sample_world`` and
``world_pdf`` are the mixture of the cone and the map.  The map keeps the disc's texels
(Cycles leaves the sun out of its bake), which changes only how the samples are shared.
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import by_ref, device, kernel
from .light_sampling import pick_light
from .sampling import orthonormal_basis
from .state import CFG_WORLD_SHADER
from .svm import ShadingData, eval_shader, shader_scene
from .svm.image_nodes import direction_to_equirectangular


@device
def world_radiance(sc, cfg, scratch, dx, dy, dz, flags):
    """Radiance the world sends along -d to a ray of direction d with path ``flags``: its
    constant colour, or its shader run for that direction (Cycles' background shader
    data: the point is the direction, the normal faces back along the ray)."""
    if not cfg[CFG_WORLD_SHADER]:
        return sc.world[0], sc.world[1], sc.world[2]
    # Every field of the type shading.shading_data gives it (float64, bool, int64), so that
    # the shader evaluator is compiled once for surfaces and the world.
    i64 = np.int64
    x, y, z = np.float64(dx), np.float64(dy), np.float64(dz)
    sd = ShadingData(x, y, z, -x, -y, -z, -x, -y, -z, -x, -y, -z, False, False, True, True, False,
                     i64(-1), 0.0, 0.0, i64(-1), i64(flags), math.inf,
                     i64(0), i64(0), i64(0), i64(0), i64(0), 0.0, np.uint64(0), 0.0)
    w = sc.mat_prog.shape[0] - 1
    res = eval_shader(sc.mat_prog[w, 0], sc.mat_prog[w, 1], scratch.regs, scratch.cl_light, sd,
                      by_ref(shader_scene(sc)))
    return res.er, res.eg, res.eb


@device
def equirectangular_direction(u, v):
    """The direction of point (u, v) of Blender's equirectangular image (v = 0: down)."""
    phi = math.pi - 2.0 * math.pi * u
    theta = math.pi - math.pi * v
    s = math.sin(theta)
    return s * math.cos(phi), s * math.sin(phi), math.cos(theta)


@kernel
def bake_background(sc, cfg, scratch, out, y0, y1):
    """The world's radiance at the centre of each texel of rows [y0, y1) of ``out`` (H, W, 3)
    (threads bake bands of rows, each with its own ``scratch``)."""
    h, w = out.shape[0], out.shape[1]
    for y in range(y0, y1):
        for x in range(w):
            dx, dy, dz = equirectangular_direction((x + 0.5) / w, (y + 0.5) / h)
            r, g, b = world_radiance(sc, cfg, scratch, dx, dy, dz, 0)
            out[y, x, 0], out[y, x, 1], out[y, x, 2] = r, g, b


@device
def sample_background(marginal, conditional, u1, u2):
    """A direction drawn from the map: (x, y, z, solid-angle pdf); pdf 0 if none."""
    h = conditional.shape[0]
    w = conditional.shape[1] - 1
    y = pick_light(marginal, u1)
    width = marginal[y + 1] - marginal[y]
    if width <= 0.0:
        return 0.0, 0.0, 1.0, 0.0
    dv = min(max((u1 - marginal[y]) / width, 0.0), 1.0)
    row = conditional[y]
    x = pick_light(row, u2)
    cwidth = row[x + 1] - row[x]
    if cwidth <= 0.0:
        return 0.0, 0.0, 1.0, 0.0
    du = min(max((u2 - row[x]) / cwidth, 0.0), 1.0)
    u = (x + du) / w
    v = (y + dv) / h
    s = math.sin(math.pi * v)
    if s <= 0.0:
        return 0.0, 0.0, 1.0, 0.0
    dx, dy, dz = equirectangular_direction(u, v)
    pdf = width * h * cwidth * w / (2.0 * math.pi * math.pi * s)
    return dx, dy, dz, pdf


@device
def sample_world(sc, u1, u2):
    """A direction towards the world: from the sun cone ``sc.bg_sun`` (uniformly, for its
    share of the samples) or from the map; (x, y, z, solid-angle pdf of the mixture)."""
    sun = sc.bg_sun
    share = sun[4]
    if share > 0.0 and u1 < share:
        u1 = u1 / share
        cos_max = sun[3]
        cos_t = 1.0 - u1 * (1.0 - cos_max)
        sin_t = math.sqrt(max(1.0 - cos_t * cos_t, 0.0))
        phi = 2.0 * math.pi * u2
        tx, ty, tz, bx, by, bz = orthonormal_basis(sun[0], sun[1], sun[2])
        lx, ly = sin_t * math.cos(phi), sin_t * math.sin(phi)
        dx = lx * tx + ly * bx + cos_t * sun[0]
        dy = lx * ty + ly * by + cos_t * sun[1]
        dz = lx * tz + ly * bz + cos_t * sun[2]
    else:
        if share > 0.0:
            u1 = min((u1 - share) / (1.0 - share), 1.0)
        dx, dy, dz, pdf = sample_background(sc.bg_marginal, sc.bg_conditional, u1, u2)
        if pdf <= 0.0:
            return dx, dy, dz, 0.0
        if share <= 0.0:
            return dx, dy, dz, pdf          # the map's own: world_pdf would find it again
    return dx, dy, dz, world_pdf(sc, dx, dy, dz)


@device
def world_pdf(sc, dx, dy, dz):
    """Solid-angle pdf with which ``sample_world`` draws direction d (unit)."""
    sun = sc.bg_sun
    share = sun[4]
    pdf = background_pdf(sc.bg_marginal, sc.bg_conditional, dx, dy, dz)
    if share <= 0.0:
        return pdf
    pdf *= 1.0 - share
    cos_max = sun[3]
    if dx * sun[0] + dy * sun[1] + dz * sun[2] >= cos_max:
        pdf += share / (2.0 * math.pi * (1.0 - cos_max))
    return pdf


@device
def background_pdf(marginal, conditional, dx, dy, dz):
    """Solid-angle pdf with which ``sample_background`` draws direction d."""
    h = conditional.shape[0]
    w = conditional.shape[1] - 1
    u, v = direction_to_equirectangular(dx, dy, dz)
    s = math.sin(math.pi * v)
    if s <= 0.0:
        return 0.0
    x = min(max(int(u * w), 0), w - 1)
    y = min(max(int(v * h), 0), h - 1)
    p = (marginal[y + 1] - marginal[y]) * h * (conditional[y, x + 1] - conditional[y, x]) * w
    return p / (2.0 * math.pi * math.pi * s)
