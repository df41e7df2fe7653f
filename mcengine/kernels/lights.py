"""Lights: Blender lamps and emissive triangles, in Cycles' units.

Lamps are packed into a float64 table (``pack_lights``), a row per lamp with
the columns ``L_*``; emissive triangles are listed separately.  Kernel
functions take the whole table and a row index (``lamps, li``), never a row
slice: in numba, passing an array view to a function that is not inlined
costs tens of nanoseconds, more than the arithmetic here.  One discrete
distribution over "all lamps, then all emissive triangles" picks the light
for next-event estimation, in proportion to an estimate of its power.

Per lamp type (Cycles 5.0, intern/cycles/kernel/light/ and scene/light.cpp):

* point, radius 0: a delta light of intensity P / (4 pi) W/sr;
* point, radius r, soft falloff (the default): a disk of radius r that always
  faces the shading point, radiance P / (4 pi^2 r^2);
* point, radius r, no soft falloff: a sphere of the same radiance;
* spot: a point light (any of the three) times the cone attenuation
  smoothstep((cos a - cos(size/2)) / ((1 - cos(size/2)) * blend)), with a
  measured from the lamp's -Z through its inverse transform (so non-uniform
  object scale makes the cone elliptical); the power is not concentrated
  into the cone;
* sun: irradiance S; with angle > 0 a disk of directions of half-angle
  angle/2 and radiance S / (pi sin^2(angle/2)), otherwise a delta direction;
* area: one-sided (emits into local -Z), rectangle or ellipse whose extents
  are multiplied by the object scale, radiance P / (pi A) (P / pi without
  ``normalize``), with the ``spread`` attenuation; a rectangle (or the part of
  it a spread lets reach the point) is sampled uniformly in solid angle from
  points near it (as Cycles samples it from everywhere), uniformly in area from
  farther ones and for an ellipse;
* emissive triangles: radiance colour x strength on both sides;
* any lamp with an IES profile (a lamp node tree whose IES Texture's Factor scales its
  emission, ``mcengine.ies``): its radiance times the profile along the direction the light
  leaves the sampled point of the lamp, taken into the lamp's frame by the transpose of its
  world matrix (Cycles' lamp shader reads the incoming direction as a normal in object
  space); sampling and light picking do not see the profile, as in Cycles.

Lamps are transparent to rays: a ray that passes through a lamp collects its
light and goes on (Cycles counts it as a transparent bounce).  Shadow rays
ignore lamps.  Lamps with ``use_mis`` off are invisible to BSDF rays.
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import device
from .ies import ies_direction
from .sampling import around, disk_concentric, orthonormal_basis, uniform_cone, uniform_cone_pdf

LT_POINT = 0
LT_SPOT = 1
LT_SUN = 2
LT_AREA = 3

# Lamp table columns.
L_TYPE = 0
L_POS = 1            # 3: position
L_AX = 4             # 3: unit local +X (world)
L_AY = 7             # 3: unit local +Y (world)
L_AZ = 10            # 3: unit local +Z (world); lamps emit along -Z
L_RADIANCE = 13      # 3: surface radiance (intensity for radius-0 points, irradiance for delta suns)
L_RADIUS = 16        # point/spot radius
L_DISK = 17          # 1: point/spot radius is a disk facing the shading point (soft falloff)
L_HALF_X = 18        # area half extents (object scale included)
L_HALF_Y = 19
L_ELLIPSE = 20       # area: 1 for DISK/ELLIPSE
L_AREA = 21          # area of the emitting surface
L_SPOT_COS = 22      # cos(spot_size / 2)
L_SPOT_SMOOTH = 23   # 1 / ((1 - cos) * blend), 0 for a hard edge
L_SPOT_INV = 24      # 9: world-to-local 3x3 of the spot (rows), scale included
L_SUN_OMC = 33       # 1 - cos(angle / 2), computed without cancellation; 0 for a delta sun
L_SPREAD_TAN = 34    # tan(spread / 2); negative: no spread attenuation
L_SPREAD_NORM = 35   # 1 / (tan(spread/2) - spread/2)
L_FLAGS = 36
L_MAX_BOUNCES = 37
L_PMF = 38           # probability of picking this lamp for NEE (by power, scene-wide)
L_IMPORTANCE = 39    # scale of the irradiance estimate that picks lights per shading point
L_LIGHT_SETS = 40    # 2: light linking, the receivers' light sets it lights (light_set_columns)
L_IES = 42           # 1 + the offset of its IES profile in the profiles' array (kernels/ies.py); 0: none
L_IES_TFM = 43       # 9: the columns of its world matrix's 3x3 (scale included): local = M^T d
LIGHT_STRIDE = 52

# Light linking (Blender's light sets, as Cycles reads them): a receiver belongs to one light
# set (0: the default set of unlinked objects) and an emitter lights a mask of light sets.
MAX_LIGHT_SETS = 64
LIGHT_SETS_ALL = (1 << MAX_LIGHT_SETS) - 1

# A light that subtends a cone with 1 - cos(half angle) below this is a delta
# light (a direction, or a point): its cone would be narrower than 1.4e-7 rad,
# which no image can tell from a delta, and below about 1e-16 the cone cannot
# be represented at all.  Both forms give the same irradiance; the choice is
# made here, from this one quantity, for sampling, intersection and radiance.
DELTA_CONE_OMC = 1e-14
# Lamp radii below this are 0: their radiance P / (4 pi^2 r^2) would overflow.
MIN_LAMP_RADIUS = 1e-60

# Per-point light selection never gives a light less than this share of its
# unattenuated weight where it might still contribute (spot edges with a
# radius, area lights seen edge-on): any non-zero probability is unbiased.
IMPORTANCE_FLOOR = 0.02

# L_FLAGS bits.
LF_CAST_SHADOW = 1
LF_USE_MIS = 2
LF_VIS_CAMERA = 4
LF_VIS_DIFFUSE = 8
LF_VIS_GLOSSY = 16
LF_VIS_TRANSMISSION = 32
LF_LIGHT_TRACED = 64      # its caustic paths are light tracing's: path tracing's rays leave them


def light_set_columns(masks) -> np.ndarray:
    """(N, 2) float64 of light-set masks (light linking: bit s for light set s, 0..63), as
    the kernels keep them in a float table: bits 0-31 and bits 32-63, each exact in a float."""
    values = masks.ravel().tolist() if isinstance(masks, np.ndarray) else list(masks)
    return np.array([(int(m) & 0xFFFFFFFF, int(m) >> 32) for m in values],
                    np.float64).reshape(-1, 2)


@device
def in_light_sets(table, row, column, light_set):
    """Whether the light-set mask in ``table[row, column:column + 2]`` (``light_set_columns``)
    holds ``light_set``."""
    if light_set < 32:
        return (np.int64(table[row, column]) >> light_set) & 1 != 0
    return (np.int64(table[row, column + 1]) >> (light_set - 32)) & 1 != 0


def _unit(v):
    n = np.linalg.norm(v)
    return v / n if n > 0 else v


def _spread_normalisation(half):
    """1 / (tan(h) - h), with its Taylor form for small h (as Cycles does)."""
    if half < 0.05:
        x2 = half * half
        return 1.0 / (half * x2 * (1.0 / 3.0 + x2 * (2.0 / 15.0 + x2 * 17.0 / 315.0)))
    return 1.0 / (math.tan(half) - half)


def pack_lights(lights, scene_radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Lamp table (N, LIGHT_STRIDE) and the power estimate of each lamp.

    ``scene_radius`` bounds the geometry; a sun's power is its irradiance times
    the scene's cross-section.
    """
    table = np.zeros((len(lights), LIGHT_STRIDE))
    power = np.zeros(len(lights))
    for i, li in enumerate(lights):
        m = np.asarray(li.matrix_world, np.float64)
        row = table[i]
        strength = np.asarray(li.strength, np.float64)
        scale = np.linalg.norm(m[:3, :3], axis=0)
        row[L_POS:L_POS + 3] = m[:3, 3]
        ax, ay, az = _unit(m[:3, 0]), _unit(m[:3, 1]), _unit(m[:3, 2])
        row[L_AX:L_AX + 3], row[L_AY:L_AY + 3], row[L_AZ:L_AZ + 3] = ax, ay, az
        flags = 0
        flags |= LF_CAST_SHADOW if li.cast_shadow else 0
        flags |= LF_USE_MIS if li.use_mis else 0
        flags |= LF_VIS_CAMERA if li.visible_camera else 0
        flags |= LF_VIS_DIFFUSE if li.visible_diffuse else 0
        flags |= LF_VIS_GLOSSY if li.visible_glossy else 0
        flags |= LF_VIS_TRANSMISSION if li.visible_transmission else 0
        row[L_MAX_BOUNCES] = li.max_bounces
        row[L_LIGHT_SETS:L_LIGHT_SETS + 2] = light_set_columns([li.light_sets])[0]
        row[L_SPREAD_TAN] = -1.0
        row[L_IES_TFM:L_IES_TFM + 9] = m[:3, :3].T.reshape(-1)
        # Negative strengths remove light, as in Cycles; lights are picked by |strength|.
        magnitude = float(np.abs(strength).mean())
        if li.type in ("POINT", "SPOT"):
            row[L_TYPE] = LT_POINT if li.type == "POINT" else LT_SPOT
            r = float(li.radius) if li.radius >= MIN_LAMP_RADIUS else 0.0
            row[L_RADIUS] = r
            row[L_DISK] = 1.0 if li.soft_falloff else 0.0
            if r > 0.0:
                row[L_AREA] = math.pi * r * r if li.soft_falloff else 4.0 * math.pi * r * r
                row[L_RADIANCE:L_RADIANCE + 3] = strength / (4.0 * math.pi * math.pi * r * r)
            else:
                row[L_RADIANCE:L_RADIANCE + 3] = strength / (4.0 * math.pi)
            power[i] = magnitude
            row[L_IMPORTANCE] = magnitude / (4.0 * math.pi)
            if li.type == "SPOT":
                c = math.cos(0.5 * float(li.spot_size))
                row[L_SPOT_COS] = c
                blend = float(li.spot_blend)
                # (1 - c) * blend may underflow to 0 for tiny blends and cones (1 / that: inf).
                smooth_width = (1.0 - c) * blend
                row[L_SPOT_SMOOTH] = 1.0 / smooth_width if smooth_width > 0.0 else 0.0
                inv = np.linalg.inv(m[:3, :3]) if abs(np.linalg.det(m[:3, :3])) > 0 else np.eye(3)
                row[L_SPOT_INV:L_SPOT_INV + 9] = inv.reshape(-1)
                # The cone holds (1 - c)/2 of the sphere's directions at most.
                power[i] *= max(0.5 * (1.0 - c), 1e-3)
        elif li.type == "SUN":
            row[L_TYPE] = LT_SUN
            half = 0.5 * min(max(float(li.angle), 0.0), math.pi)
            omc = 2.0 * math.sin(0.5 * half) ** 2          # 1 - cos(half)
            if omc > DELTA_CONE_OMC:
                row[L_SUN_OMC] = omc
                # pi sin^2(half) from the stored quantity, so that L / pdf is exactly S.
                row[L_RADIANCE:L_RADIANCE + 3] = strength / (math.pi * omc * (2.0 - omc))
            else:
                row[L_RADIANCE:L_RADIANCE + 3] = strength
            power[i] = magnitude * math.pi * scene_radius ** 2
            row[L_IMPORTANCE] = magnitude
        elif li.type == "AREA":
            row[L_TYPE] = LT_AREA
            sx = float(li.size_x)
            sy = float(li.size_x if li.shape in ("SQUARE", "DISK") else li.size_y)
            hx, hy = 0.5 * sx * scale[0], 0.5 * sy * scale[1]
            row[L_HALF_X], row[L_HALF_Y] = hx, hy
            ellipse = li.shape in ("DISK", "ELLIPSE")
            row[L_ELLIPSE] = 1.0 if ellipse else 0.0
            area = 4.0 * hx * hy * (math.pi / 4.0 if ellipse else 1.0)
            row[L_AREA] = area
            if area > 0.0:
                norm_area = area if li.normalize else 1.0
                row[L_RADIANCE:L_RADIANCE + 3] = strength / (math.pi * norm_area)
                power[i] = magnitude * (1.0 if li.normalize else area)
                row[L_IMPORTANCE] = power[i] / math.pi
            spread = float(li.spread)
            if spread < math.pi - 1e-6:
                half = 0.5 * max(spread, 1e-4)
                row[L_SPREAD_TAN] = math.tan(half)
                row[L_SPREAD_NORM] = _spread_normalisation(half)
        row[L_FLAGS] = flags
    return table, power


def pack_profiles(lights, table) -> np.ndarray:
    """The lamps' IES profiles as the kernels read them (``kernels/ies.py``), each once, and
    1 + their offsets in ``table[:, L_IES]`` (0 stays for lamps without one)."""
    blocks, offsets, size = [], {}, 0
    for i, li in enumerate(lights):
        profile = li.ies
        if profile is None:
            continue
        if id(profile) not in offsets:
            offsets[id(profile)] = size
            block = profile.packed()
            blocks.append(block)
            size += len(block)
        table[i, L_IES] = 1 + offsets[id(profile)]
    return np.concatenate(blocks) if blocks else np.zeros(1)


@device
def lamp_profile(lamps, ies, li, dx, dy, dz):
    """The factor of lamp li's IES profile for light leaving it along (dx, dy, dz) (1 without
    a profile): the direction taken into the lamp's frame as Cycles takes it, by the
    transpose of the world matrix (a normal's transform), then looked up."""
    ofs = int(lamps[li, L_IES]) - 1
    if ofs < 0:
        return 1.0
    t = L_IES_TFM
    x = lamps[li, t] * dx + lamps[li, t + 1] * dy + lamps[li, t + 2] * dz
    y = lamps[li, t + 3] * dx + lamps[li, t + 4] * dy + lamps[li, t + 5] * dz
    z = lamps[li, t + 6] * dx + lamps[li, t + 7] * dy + lamps[li, t + 8] * dz
    return ies_direction(ies, ofs, x, y, z)


@device
def _smoothstep(t):
    if t <= 0.0:
        return 0.0
    if t >= 1.0:
        return 1.0
    return t * t * (3.0 - 2.0 * t)


@device
def spot_attenuation(lamps, li, ex, ey, ez):
    """Cone attenuation for the emission direction e (light towards the point)."""
    k = L_SPOT_INV
    lx = lamps[li, k] * ex + lamps[li, k + 1] * ey + lamps[li, k + 2] * ez
    ly = lamps[li, k + 3] * ex + lamps[li, k + 4] * ey + lamps[li, k + 5] * ez
    lz = lamps[li, k + 6] * ex + lamps[li, k + 7] * ey + lamps[li, k + 8] * ez
    ln = math.sqrt(lx * lx + ly * ly + lz * lz)
    if ln == 0.0:
        return 0.0
    cos_a = -lz / ln
    c = lamps[li, L_SPOT_COS]
    if lamps[li, L_SPOT_SMOOTH] == 0.0:
        return 1.0 if cos_a > c else 0.0
    return _smoothstep((cos_a - c) * lamps[li, L_SPOT_SMOOTH])


@device
def area_spread(lamps, li, cos_l):
    """Spread attenuation at emission angle theta (cos_l = cos theta)."""
    t = lamps[li, L_SPREAD_TAN]
    if t < 0.0:
        return 1.0
    if cos_l <= 0.0:
        return 0.0
    tan_theta = math.sqrt(max(0.0, 1.0 - cos_l * cos_l)) / cos_l
    return max(t - tan_theta, 0.0) * lamps[li, L_SPREAD_NORM]


@device
def facing(rx, ry, rz, wx, wy, wz, cos_u, sin_u):
    """Cycles' cos(theta_i') of its light tree: the largest cosine between the receiver's
    normal r and a direction within angle u of the unit direction w to the light (u: the
    half-angle the light's bounding sphere, or a sun's disk, subtends); 0 when the whole
    light lies behind the surface.  1 without a normal (r = 0: a surface that transmits)."""
    if rx == 0.0 and ry == 0.0 and rz == 0.0:
        return 1.0
    cos_i = rx * wx + ry * wy + rz * wz
    if cos_i >= cos_u:
        return 1.0
    sin_i = math.sqrt(max(1.0 - cos_i * cos_i, 0.0))
    return max(cos_i * cos_u + sin_i * sin_u, 0.0)


@device
def facing_sphere(rx, ry, rz, dx, dy, dz, d2, radius):
    """:func:`facing` of a sphere of ``radius`` at offset -d (d: from it to the receiver)."""
    if rx == 0.0 and ry == 0.0 and rz == 0.0:
        return 1.0
    if d2 <= radius * radius:
        return 1.0
    d = math.sqrt(d2)
    sin_u = radius / d
    return facing(rx, ry, rz, -dx / d, -dy / d, -dz / d, math.sqrt(1.0 - sin_u * sin_u), sin_u)


@device
def lamp_importance(lamps, li, recv):
    """Rough irradiance lamp li gives at the receiver, ignoring occlusion.

    ``recv`` is (point, normal): the normal facing the viewer, or 0 where the surface
    transmits.  Used to pick the light for next-event estimation there: near lamps, spots
    pointing at it and lamps in front of the surface are picked more often.  Zero only where
    the lamp cannot contribute (behind a one-sided area light, or wholly behind an opaque
    surface).  As in Cycles' light tree the normal is the shading point's, not a bumped
    closure's: a closure whose own normal sees such a lamp gets its light only from rays that
    hit it (MIS weight 1), none from a point lamp of radius 0 or a sun without angle.
    """
    k = lamps[li, L_IMPORTANCE]
    typ = int(lamps[li, L_TYPE])
    if k <= 0.0:
        return k
    px, py, pz, rx, ry, rz = recv
    if typ == LT_SUN:
        omc = lamps[li, L_SUN_OMC]
        return k * facing(rx, ry, rz, lamps[li, L_AZ], lamps[li, L_AZ + 1], lamps[li, L_AZ + 2],
                          1.0 - omc, math.sqrt(max(omc * (2.0 - omc), 0.0)))
    dx, dy, dz = px - lamps[li, L_POS], py - lamps[li, L_POS + 1], pz - lamps[li, L_POS + 2]
    d2 = dx * dx + dy * dy + dz * dz
    if typ == LT_AREA:
        s = -(dx * lamps[li, L_AZ] + dy * lamps[li, L_AZ + 1] + dz * lamps[li, L_AZ + 2])
        if s <= 0.0:
            return 0.0            # behind the emitting side: no light at all
        cos_l = s / math.sqrt(d2)
        radius = math.sqrt(lamps[li, L_HALF_X] ** 2 + lamps[li, L_HALF_Y] ** 2)
        return (k * max(cos_l, IMPORTANCE_FLOOR) / max(d2, lamps[li, L_AREA])
                * facing_sphere(rx, ry, rz, dx, dy, dz, d2, radius))
    att = 1.0
    if typ == LT_SPOT:
        att = max(spot_attenuation(lamps, li, dx, dy, dz), IMPORTANCE_FLOOR)
    r = lamps[li, L_RADIUS]
    return (k * att / max(d2, r * r, 1e-12)
            * facing_sphere(rx, ry, rz, dx, dy, dz, d2, r))


@device
def spread_window(lamps, li, px, py, pz):
    """The part of an area light with spread that can light p, as a rectangle.

    With spread s < 180 deg, a point of the light shines on p only if p lies
    within s/2 of the light's normal as seen from that point, i.e. the point
    lies in a circle of radius t tan(s/2) around p's foot on the light's plane
    (t: p's distance to the plane).  Returns the light-plane rectangle
    ``(x0, x1, y0, y1)`` (local coordinates, metres) bounding that circle and
    the light, and its area; area 0 if p cannot be lit.  Without spread, or
    when the circle covers the whole light, the window is the whole light and
    the area returned is the light's own (an ellipse is then sampled as one).
    Sampling only this window is what Cycles does
    (area.h, area_light_spread_clamp_light); it changes noise, not the mean.
    """
    hx, hy = lamps[li, L_HALF_X], lamps[li, L_HALF_Y]
    tan_half = lamps[li, L_SPREAD_TAN]
    if tan_half < 0.0:
        return -hx, hx, -hy, hy, lamps[li, L_AREA]
    dx, dy, dz = px - lamps[li, L_POS], py - lamps[li, L_POS + 1], pz - lamps[li, L_POS + 2]
    t = -(dx * lamps[li, L_AZ] + dy * lamps[li, L_AZ + 1] + dz * lamps[li, L_AZ + 2])
    if t <= 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    fx = dx * lamps[li, L_AX] + dy * lamps[li, L_AX + 1] + dz * lamps[li, L_AX + 2]
    fy = dx * lamps[li, L_AY] + dy * lamps[li, L_AY + 1] + dz * lamps[li, L_AY + 2]
    r = t * tan_half
    x0, x1 = max(-hx, fx - r), min(hx, fx + r)
    y0, y1 = max(-hy, fy - r), min(hy, fy + r)
    if x1 <= x0 or y1 <= y0:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    if x0 == -hx and x1 == hx and y0 == -hy and y1 == hy:
        return x0, x1, y0, y1, lamps[li, L_AREA]     # not clipped: the whole light
    return x0, x1, y0, y1, (x1 - x0) * (y1 - y0)


# Rectangular area lights are sampled by solid angle from points nearer to the sampled
# window's centre than RECT_NEAR half-diagonals, by area from farther ones.  Near a lamp,
# area sampling is noisy (cos / d^2 varies over it: at one half-diagonal the relative
# variance of one sample is 0.5 higher, median over receivers); at RECT_NEAR = 2 it is
# 0.19 higher, at 4 0.05 and at 10 0.009, falling as the square of the lamp's apparent
# size, while the spherical rectangle costs four arcsines, a sine and a cosine more per
# sample, 22 % of the Cornell box's render time when every vertex paid it.  Cycles
# samples every rectangle by solid angle; the choice changes noise only.  Below
# RECT_MIN_SOLID_ANGLE (sr), or with the window seen nearly edge-on (a squared normalised
# edge normal above RECT_MAX_NZ2), the window is sampled by area too: float64 keeps
# Urena's formulas accurate far below Cycles' float32 limits (1e-5 and 0.99999).
RECT_NEAR = 2.0
RECT_MIN_SOLID_ANGLE = 1e-10
RECT_MAX_NZ2 = 1.0 - 1e-12


@device
def _asin(x):
    return math.asin(min(max(x, -1.0), 1.0))


@device
def spherical_rectangle(lamps, li, px, py, pz, x0, x1, y0, y1):
    """The window [x0, x1] x [y0, y1] (lamp coordinates, metres) of rectangular lamp li seen
    from p, as a spherical rectangle (Urena et al. 2013, in the form of Cycles' area.h,
    area_light_rect_sample, which sums arcsines where the paper sums arccosines and loses
    small rectangles to cancellation).

    Returns ``(S, sx0, sx1, sy0, sy1, z0, b0, b1, g, n2max)``: the solid angle S, the
    window relative to p's foot on the lamp's plane, z0 = -(p's distance to the plane),
    the constants ``rect_sample_point`` needs and the largest squared normalised edge
    normal (near 1: the window is seen edge-on)."""
    dx, dy, dz = lamps[li, L_POS] - px, lamps[li, L_POS + 1] - py, lamps[li, L_POS + 2] - pz
    xc = dx * lamps[li, L_AX] + dy * lamps[li, L_AX + 1] + dz * lamps[li, L_AX + 2]
    yc = dx * lamps[li, L_AY] + dy * lamps[li, L_AY + 1] + dz * lamps[li, L_AY + 2]
    z0 = -abs(dx * lamps[li, L_AZ] + dy * lamps[li, L_AZ + 1] + dz * lamps[li, L_AZ + 2])
    sx0, sx1, sy0, sy1 = xc + x0, xc + x1, yc + y0, yc + y1
    z2 = z0 * z0
    n0 = -sy0 / math.sqrt(sy0 * sy0 + z2)
    n1 = sx1 / math.sqrt(sx1 * sx1 + z2)
    n2 = sy1 / math.sqrt(sy1 * sy1 + z2)
    n3 = -sx0 / math.sqrt(sx0 * sx0 + z2)
    g2 = _asin(-n2 * n3)
    g3 = _asin(-n3 * n0)
    s = -(_asin(-n0 * n1) + _asin(-n1 * n2) + g2 + g3)
    return s, sx0, sx1, sy0, sy1, z0, n0, n2, g2 + g3, max(n0 * n0, n1 * n1, n2 * n2, n3 * n3)


@device
def rect_solid_angle(lamps, li, px, py, pz, x0, x1, y0, y1):
    """``spherical_rectangle``'s first nine values where the window is sampled by solid
    angle from p; S = 0 where it is sampled by area (see RECT_NEAR): p is RECT_NEAR
    half-diagonals or more from its centre, or the solid angle is too small, or the window
    too nearly edge-on, for the formulas."""
    dx, dy, dz = lamps[li, L_POS] - px, lamps[li, L_POS + 1] - py, lamps[li, L_POS + 2] - pz
    mx = dx * lamps[li, L_AX] + dy * lamps[li, L_AX + 1] + dz * lamps[li, L_AX + 2] + 0.5 * (x0 + x1)
    my = dx * lamps[li, L_AY] + dy * lamps[li, L_AY + 1] + dz * lamps[li, L_AY + 2] + 0.5 * (y0 + y1)
    mz = dx * lamps[li, L_AZ] + dy * lamps[li, L_AZ + 1] + dz * lamps[li, L_AZ + 2]
    if mx * mx + my * my + mz * mz >= (0.25 * RECT_NEAR * RECT_NEAR) * ((x1 - x0) ** 2 + (y1 - y0) ** 2):
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    s, sx0, sx1, sy0, sy1, z0, b0, b1, g, n2max = spherical_rectangle(lamps, li, px, py, pz,
                                                                      x0, x1, y0, y1)
    if not (s >= RECT_MIN_SOLID_ANGLE) or n2max > RECT_MAX_NZ2:
        s = 0.0
    return s, sx0, sx1, sy0, sy1, z0, b0, b1, g


@device
def rect_sample_point(s, sx0, sx1, sy0, sy1, z0, b0, b1, g, u1, u2):
    """A point (x, y), relative to p's foot on the lamp's plane, of the spherical rectangle
    ``spherical_rectangle`` gave, uniform in solid angle for (u1, u2) uniform."""
    au = u1 * s + g
    sin_au = math.sin(au)
    fu = (math.cos(au) * b0 + b1) / sin_au if sin_au != 0.0 else 0.0
    cu = min(max(math.copysign(1.0 / math.sqrt(fu * fu + b0 * b0), fu), -1.0), 1.0)
    xu = min(max(-(cu * z0) / max(math.sqrt(1.0 - cu * cu), 1e-300), sx0), sx1)
    d2 = xu * xu + z0 * z0
    h0 = sy0 / math.sqrt(d2 + sy0 * sy0)
    h1 = sy1 / math.sqrt(d2 + sy1 * sy1)
    hv = h0 + u2 * (h1 - h0)
    hv2 = hv * hv
    yv = hv * math.sqrt(d2 / (1.0 - hv2)) if hv2 < 1.0 else sy1
    return xu, min(max(yv, sy0), sy1)


@device
def _area_sample(lamps, li, px, py, pz, a, b, pdf, area):
    """``sample_lamp``'s result for the point (a hx, b hy) of area lamp li, drawn with the
    solid-angle pdf ``pdf``, or (``pdf`` 0) uniformly from a window of area ``area``."""
    cx, cy, cz = lamps[li, L_POS], lamps[li, L_POS + 1], lamps[li, L_POS + 2]
    hx, hy = lamps[li, L_HALF_X], lamps[li, L_HALF_Y]
    qx = cx + a * hx * lamps[li, L_AX] + b * hy * lamps[li, L_AY]
    qy = cy + a * hx * lamps[li, L_AX + 1] + b * hy * lamps[li, L_AY + 1]
    qz = cz + a * hx * lamps[li, L_AX + 2] + b * hy * lamps[li, L_AY + 2]
    dx, dy, dz = qx - px, qy - py, qz - pz
    d2 = dx * dx + dy * dy + dz * dz
    dist = math.sqrt(d2)
    if dist == 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0
    wx, wy, wz = dx / dist, dy / dist, dz / dist
    # One-sided: the lamp emits along -Z, so wi (towards it) must go along +Z.
    cos_l = wx * lamps[li, L_AZ] + wy * lamps[li, L_AZ + 1] + wz * lamps[li, L_AZ + 2]
    if cos_l <= 0.0:
        return wx, wy, wz, dist, 0.0, 0.0, 0.0, 0.0
    s = area_spread(lamps, li, cos_l)
    if pdf <= 0.0:
        pdf = d2 / (area * cos_l)
    return (wx, wy, wz, dist, s * lamps[li, L_RADIANCE], s * lamps[li, L_RADIANCE + 1],
            s * lamps[li, L_RADIANCE + 2], pdf)


@device
def sample_lamp(lamps, ies, li, px, py, pz, u1, u2):
    """Sample lamp radiance arriving at p.

    Returns ``(wix, wiy, wiz, dist, Lr, Lg, Lb, pdf)``: the unit direction
    to the light, the distance to the sampled point (``inf`` for suns), the
    radiance arriving along wi (attenuations and the IES profile included) and
    the solid-angle pdf of wi.  ``pdf == 0`` with a non-zero L means a delta
    light whose L is already the irradiance-equivalent (L/pdf term); ``L == 0``
    means no light.  A profile is read along -wi, from the sampled point of the
    lamp (Cycles' wi of the lamp's shader); it does not change the sampling.
    """
    wx, wy, wz, dist, lr, lg, lb, pdf = _sample_lamp(lamps, li, px, py, pz, u1, u2)
    if lamps[li, L_IES] > 0.0:
        f = lamp_profile(lamps, ies, li, -wx, -wy, -wz)
        lr, lg, lb = lr * f, lg * f, lb * f
    return wx, wy, wz, dist, lr, lg, lb, pdf


@device
def _sample_lamp(lamps, li, px, py, pz, u1, u2):
    """:func:`sample_lamp` without the IES profile."""
    typ = int(lamps[li, L_TYPE])
    if typ == LT_SUN:
        azx, azy, azz = lamps[li, L_AZ], lamps[li, L_AZ + 1], lamps[li, L_AZ + 2]
        omc = lamps[li, L_SUN_OMC]
        if omc <= 0.0:
            return (azx, azy, azz, math.inf, lamps[li, L_RADIANCE], lamps[li, L_RADIANCE + 1],
                    lamps[li, L_RADIANCE + 2], 0.0)
        x, y, z = uniform_cone(u1, u2, omc)
        wx, wy, wz = around(azx, azy, azz, x, y, z)
        return (wx, wy, wz, math.inf, lamps[li, L_RADIANCE], lamps[li, L_RADIANCE + 1], lamps[li, L_RADIANCE + 2],
                uniform_cone_pdf(omc))

    cx, cy, cz = lamps[li, L_POS], lamps[li, L_POS + 1], lamps[li, L_POS + 2]
    if typ == LT_AREA:
        hx, hy = lamps[li, L_HALF_X], lamps[li, L_HALF_Y]
        if lamps[li, L_AREA] <= 0.0:
            return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0
        sample_area = lamps[li, L_AREA]
        inside = True
        clipped = False
        x0, x1, y0, y1 = -hx, hx, -hy, hy
        if lamps[li, L_SPREAD_TAN] >= 0.0:
            x0, x1, y0, y1, sample_area = spread_window(lamps, li, px, py, pz)
            if sample_area <= 0.0:
                return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0
            clipped = sample_area != lamps[li, L_AREA]
        if lamps[li, L_ELLIPSE] <= 0.0:
            # A rectangle (or the rectangle of it that can light p): by solid angle, as
            # Cycles samples it, from near it; by area (below) from farther (RECT_NEAR).
            s, sx0, sx1, sy0, sy1, z0, b0, b1, g = rect_solid_angle(lamps, li, px, py, pz,
                                                                   x0, x1, y0, y1)
            if s > 0.0:
                xu, yv = rect_sample_point(s, sx0, sx1, sy0, sy1, z0, b0, b1, g, u1, u2)
                # The point, on the lamp's plane: p's foot is at -(sx0 - x0, sy0 - y0).
                a, b = (xu - (sx0 - x0)) / hx, (yv - (sy0 - y0)) / hy
                return _area_sample(lamps, li, px, py, pz, a, b, 1.0 / s, 0.0)
        if clipped:
            # Spread: sample the window of the light that can reach p, uniformly
            # (points of an ellipse's window outside the ellipse give nothing).
            ax, by_ = x0 + u1 * (x1 - x0), y0 + u2 * (y1 - y0)
            if lamps[li, L_ELLIPSE] > 0.0:
                inside = (ax / hx) ** 2 + (by_ / hy) ** 2 <= 1.0
            a, b = ax / hx, by_ / hy
        elif lamps[li, L_ELLIPSE] > 0.0:
            a, b = disk_concentric(u1, u2)
        else:
            a, b = 2.0 * u1 - 1.0, 2.0 * u2 - 1.0
        if not inside:
            return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0
        return _area_sample(lamps, li, px, py, pz, a, b, 0.0, sample_area)

    # Point and spot lamps.
    r = lamps[li, L_RADIUS]
    dx, dy, dz = cx - px, cy - py, cz - pz
    d2 = dx * dx + dy * dy + dz * dz
    d = math.sqrt(d2)
    if d == 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0
    nx, ny, nz = dx / d, dy / d, dz / d
    if r > 0.0 and d <= r:
        return nx, ny, nz, d, 0.0, 0.0, 0.0, 0.0   # inside the lamp: no defined direction
    omc = lamp_cone_omc(r, d2)
    if omc <= DELTA_CONE_OMC:
        # A point: return intensity / d^2 as the L/pdf term (intensity P / (4 pi)
        # is the sphere's or disk's radiance times pi r^2).
        att = 1.0
        if typ == LT_SPOT:
            att = spot_attenuation(lamps, li, -nx, -ny, -nz)
        k = att / d2 if r <= 0.0 else att * math.pi * r * r / d2
        return (nx, ny, nz, d, k * lamps[li, L_RADIANCE], k * lamps[li, L_RADIANCE + 1],
                k * lamps[li, L_RADIANCE + 2], 0.0)
    if lamps[li, L_DISK] > 0.0:
        # Disk of radius r through the centre, facing p.
        a, b = disk_concentric(u1, u2)
        tx, ty, tz, bx, by, bz = orthonormal_basis(nx, ny, nz)
        qx = cx + r * (a * tx + b * bx)
        qy = cy + r * (a * ty + b * by)
        qz = cz + r * (a * tz + b * bz)
        ex, ey, ez = qx - px, qy - py, qz - pz
        q2 = ex * ex + ey * ey + ez * ez
        dist = math.sqrt(q2)
        wx, wy, wz = ex / dist, ey / dist, ez / dist
        cos_l = wx * nx + wy * ny + wz * nz
        if cos_l <= 0.0:
            return wx, wy, wz, dist, 0.0, 0.0, 0.0, 0.0
        pdf = q2 / (math.pi * r * r * cos_l)
    else:
        # Sphere: uniform over the cone of directions it subtends.
        x, y, z = uniform_cone(u1, u2, omc)
        wx, wy, wz = around(nx, ny, nz, x, y, z)
        # Distance to the near side of the sphere along wi.
        b_ = d * z
        disc = r * r - (d2 - b_ * b_)
        dist = b_ - math.sqrt(max(disc, 0.0))
        pdf = uniform_cone_pdf(omc)
    att = 1.0
    if typ == LT_SPOT:
        att = spot_attenuation(lamps, li, -wx, -wy, -wz)
    return (wx, wy, wz, dist, att * lamps[li, L_RADIANCE], att * lamps[li, L_RADIANCE + 1],
            att * lamps[li, L_RADIANCE + 2], pdf)


@device
def lamp_cone_omc(r, d2):
    """1 - cos of the half angle a lamp of radius r subtends at distance^2 d2 (0 for r = 0).

    The sphere's cone has sin^2 = r^2 / d^2, and 1 - cos = sin^2 / (1 + cos),
    free of cancellation.  The facing disk gets the same measure, so both
    forms turn into a point at the same distance (``DELTA_CONE_OMC``).
    """
    sin2 = r * r / d2
    if sin2 >= 1.0:
        return 1.0
    return sin2 / (1.0 + math.sqrt(1.0 - sin2))


@device
def intersect_lamp(lamps, ies, li, ox, oy, oz, dx, dy, dz, tmax, vx, vy, vz):
    """A ray through a lamp: ``(t, Lr, Lg, Lb, pdf)``, t = inf if it misses.

    ``pdf`` is the solid-angle pdf with which :func:`sample_lamp` would pick
    this direction from the ray's vertex v (the surface point the ray left,
    before its origin was offset), for MIS.  The radiance includes the IES
    profile along -d.  Suns are handled by :func:`sun_radiance` on escaped rays.
    """
    t, lr, lg, lb, pdf = _intersect_lamp(lamps, li, ox, oy, oz, dx, dy, dz, tmax, vx, vy, vz)
    if lamps[li, L_IES] > 0.0 and t < math.inf:
        f = lamp_profile(lamps, ies, li, -dx, -dy, -dz)
        lr, lg, lb = lr * f, lg * f, lb * f
    return t, lr, lg, lb, pdf


@device
def _intersect_lamp(lamps, li, ox, oy, oz, dx, dy, dz, tmax, vx, vy, vz):
    """:func:`intersect_lamp` without the IES profile."""
    typ = int(lamps[li, L_TYPE])
    if typ == LT_SUN:
        return math.inf, 0.0, 0.0, 0.0, 0.0
    cx, cy, cz = lamps[li, L_POS], lamps[li, L_POS + 1], lamps[li, L_POS + 2]
    if typ == LT_AREA:
        azx, azy, azz = lamps[li, L_AZ], lamps[li, L_AZ + 1], lamps[li, L_AZ + 2]
        cos_l = dx * azx + dy * azy + dz * azz       # > 0: the ray meets the emitting side
        if cos_l <= 0.0 or lamps[li, L_AREA] <= 0.0:
            return math.inf, 0.0, 0.0, 0.0, 0.0
        t = ((cx - ox) * azx + (cy - oy) * azy + (cz - oz) * azz) / cos_l
        if t <= 0.0 or t >= tmax:
            return math.inf, 0.0, 0.0, 0.0, 0.0
        hx, hy, hz = ox + t * dx - cx, oy + t * dy - cy, oz + t * dz - cz
        a = (hx * lamps[li, L_AX] + hy * lamps[li, L_AX + 1] + hz * lamps[li, L_AX + 2]) / lamps[li, L_HALF_X]
        b = (hx * lamps[li, L_AY] + hy * lamps[li, L_AY + 1] + hz * lamps[li, L_AY + 2]) / lamps[li, L_HALF_Y]
        if lamps[li, L_ELLIPSE] > 0.0:
            if a * a + b * b > 1.0:
                return math.inf, 0.0, 0.0, 0.0, 0.0
        elif abs(a) > 1.0 or abs(b) > 1.0:
            return math.inf, 0.0, 0.0, 0.0, 0.0
        s = area_spread(lamps, li, cos_l)
        sample_area = lamps[li, L_AREA]
        hx, hy = lamps[li, L_HALF_X], lamps[li, L_HALF_Y]
        x0, x1, y0, y1 = -hx, hx, -hy, hy
        if lamps[li, L_SPREAD_TAN] >= 0.0:
            # The light sampler only draws from the spread window seen from v.
            x0, x1, y0, y1, sample_area = spread_window(lamps, li, vx, vy, vz)
            ax, by_ = a * hx, b * hy
            if sample_area <= 0.0 or ax < x0 or ax > x1 or by_ < y0 or by_ > y1:
                return t, s * lamps[li, L_RADIANCE], s * lamps[li, L_RADIANCE + 1], s * lamps[li, L_RADIANCE + 2], 0.0
        sa = 0.0
        if lamps[li, L_ELLIPSE] <= 0.0:       # a rectangle: sampled by solid angle from v
            sa = rect_solid_angle(lamps, li, vx, vy, vz, x0, x1, y0, y1)[0]
        pdf = 1.0 / sa if sa > 0.0 else t * t / (sample_area * cos_l)
        return t, s * lamps[li, L_RADIANCE], s * lamps[li, L_RADIANCE + 1], s * lamps[li, L_RADIANCE + 2], pdf

    r = lamps[li, L_RADIUS]
    if r <= 0.0:
        return math.inf, 0.0, 0.0, 0.0, 0.0
    px, py, pz = cx - ox, cy - oy, cz - oz
    d2 = px * px + py * py + pz * pz
    disk = lamps[li, L_DISK] > 0.0
    b_ = px * dx + py * dy + pz * dz
    disc = r * r - (d2 - b_ * b_)
    # First the cheap tests (most rays miss most lamps): the ray points away from the lamp or
    # passes its sphere; a disk lies inside the sphere, and is left to its own test unless
    # the ray passes by a margin far beyond rounding (so the result is the same).
    if b_ <= 0.0 or disc < (-1e-12 * d2 if disk else 0.0):
        return math.inf, 0.0, 0.0, 0.0, 0.0
    if d2 <= r * r or lamp_cone_omc(r, d2) <= DELTA_CONE_OMC:
        return math.inf, 0.0, 0.0, 0.0, 0.0   # inside, or a point from here: rays miss it
    if disk:
        d = math.sqrt(d2)
        # Disk through the centre facing the ray origin.
        nx, ny, nz = px / d, py / d, pz / d
        cos_l = dx * nx + dy * ny + dz * nz
        if cos_l <= 0.0:
            return math.inf, 0.0, 0.0, 0.0, 0.0
        t = d / cos_l
        if t >= tmax:
            return math.inf, 0.0, 0.0, 0.0, 0.0
        hx, hy, hz = ox + t * dx - cx, oy + t * dy - cy, oz + t * dz - cz
        if hx * hx + hy * hy + hz * hz > r * r:
            return math.inf, 0.0, 0.0, 0.0, 0.0
        pdf = t * t / (math.pi * r * r * cos_l)
    else:
        t = b_ - math.sqrt(disc)
        if t <= 0.0 or t >= tmax:
            return math.inf, 0.0, 0.0, 0.0, 0.0
        pdf = uniform_cone_pdf(lamp_cone_omc(r, d2))
    att = 1.0
    if typ == LT_SPOT:
        att = spot_attenuation(lamps, li, -dx, -dy, -dz)
    return t, att * lamps[li, L_RADIANCE], att * lamps[li, L_RADIANCE + 1], att * lamps[li, L_RADIANCE + 2], pdf


@device
def sun_radiance(lamps, ies, li, dx, dy, dz):
    """(Lr, Lg, Lb, pdf) of a sun with angle > 0 seen along the escaped direction d (its
    IES profile read along -d)."""
    omc = lamps[li, L_SUN_OMC]
    if omc <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    if 1.0 - (dx * lamps[li, L_AZ] + dy * lamps[li, L_AZ + 1] + dz * lamps[li, L_AZ + 2]) > omc:
        return 0.0, 0.0, 0.0, 0.0
    f = lamp_profile(lamps, ies, li, -dx, -dy, -dz)
    return (f * lamps[li, L_RADIANCE], f * lamps[li, L_RADIANCE + 1], f * lamps[li, L_RADIANCE + 2],
            uniform_cone_pdf(omc))
