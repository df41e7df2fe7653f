"""The Sky Texture's atmosphere: the sky image and the sun disc Cycles precomputes for it.

Blender 5.0's default sky model, Multiple Scattering (Fernando García Liñán's spectral
atmosphere, intern/sky/source/sky_multiple_scattering.cpp), renders in two parts:

* the sky without the sun disc, precomputed on the host into an image of 512 x 256 CIE XYZ
  texels (``sky_image``): for each direction from a viewer at the node's Altitude, the light
  of the sun scattered towards it by air molecules (Rayleigh phase) and aerosols
  (Henyey-Greenstein, g = 0.8) along the view ray, ray-marched in 64 steps with an
  energy-conserving step integral, lit by the sun through a precomputed transmittance table
  and by a fitted multiple-scattering term plus the light of a grey ground (albedo 0.3);
  four wavelengths (630, 560, 490 and 430 nm) are converted to XYZ by a fitted matrix.  The
  image's columns are azimuths from the sun (the sun at the middle column), its rows
  elevations from -90 to +90 degrees, spaced as the square of the distance from the
  horizon so that rows crowd near it;
* the sun disc (``sun_disc_xyz``): the sun's spectral irradiance through the atmosphere
  along the disc's lowest and highest points, spread over its solid angle; the shader
  interpolates the two by elevation and darkens the limb.

The atmosphere's densities scale with the node's Air, Aerosol and Ozone inputs.  The
earlier default, Single Scattering (Nishita's model over 21 wavelengths,
``single_scattering_image``), fills the same kind of image: the upper half with light
scattered once, the lower half with the horizon's colour fading to black.  The shader
(``kernels/svm/image_nodes.py``, ``sky_texture_node``) reads the image by direction, adds
the disc and converts XYZ to the working space.  The legacy Preetham type (an analytic fit,
``preetham_image``) fills the same kind of image and has no disc.  ``sky_images`` makes the
images of a scene's Sky Texture nodes for its image table, named by ``image_name``; ``sun_guide`` the sun cone
that next-event estimation samples beside the world's map (Cycles' sun guiding).
"""
from __future__ import annotations

import functools
import math

import numpy as np

from .scene import Image, SceneDescription

__all__ = ["SKY_TYPES", "disc_solid_angle", "earth_intersection_angle", "image_name", "node_image", "node_parameters",
           "preetham_image", "preetham_xyz", "single_scattering_image", "single_scattering_sun_xyz",
           "sky_image", "sky_images", "sun_disc_xyz", "sun_guide", "sun_position"]

SKY_TYPES = ("MULTIPLE_SCATTERING", "SINGLE_SCATTERING", "PREETHAM")   # the node's types MC Engine renders
IMAGE_SIZE = (512, 256)                     # Cycles' SkyLoader

EARTH_RADIUS = 6371.0                       # km
ATMOSPHERE_THICKNESS = 100.0                # km
ATMOSPHERE_RADIUS = EARTH_RADIUS + ATMOSPHERE_THICKNESS
TRANSMITTANCE_STEPS = 64
INSCATTERING_STEPS = 64
TRANSMITTANCE_SIZE = (256, 64)              # the transmittance table: cos(zenith) x altitude
GROUND_ALBEDO = 0.3
AEROSOL_G = 0.8
# At 630, 560, 490 and 430 nm: the sun's irradiance, the molecules' scattering at sea level,
# ozone's absorption cross-section, aerosols' absorption and scattering cross-sections.
SUN_IRRADIANCE = np.array([1.679, 1.828, 1.986, 1.307])
MOLECULAR_SCATTERING = np.array([6.605e-3, 1.067e-2, 1.842e-2, 3.156e-2])
OZONE_CROSS_SECTION = np.array([3.472e-25, 3.914e-25, 1.349e-25, 11.03e-27])
OZONE_MEAN_DOBSON = 334.5
AEROSOL_ABSORPTION = np.array([2.8722e-24, 4.6168e-24, 7.9706e-24, 1.3578e-23])
AEROSOL_SCATTERING = np.array([1.5908e-22, 1.7711e-22, 2.0942e-22, 2.4033e-22])
AEROSOL_BASE_DENSITY = 1.3681e20
AEROSOL_BACKGROUND_DENSITY = 2e6
AEROSOL_HEIGHT_SCALE = 0.73                 # km
# The four wavelengths' radiance -> CIE XYZ (rows: wavelengths).
SPECTRAL_TO_XYZ = np.array([
    [53.386917738564668023, 22.981337506691024754, 0.0],
    [43.904844466369358263, 71.347795700053393866, 0.102506867965741307],
    [1.6137278251608962005, 18.422960591455485011, 31.742921188390805758],
    [20.762668673810577145, 2.3614213523314368527, 110.48009643252140334]])
# A fit of the light scattered more than once in Earth's atmosphere, per wavelength.
MULTIPLE_SCATTERING_FIT = 0.02 * np.array([0.217, 0.347, 0.594, 1.0])


# -- the atmosphere ----------------------------------------------------------------------------
def _coefficients(altitude, air, aerosol, ozone):
    """(extinction, molecular scattering, aerosol scattering) per km at ``altitude`` (km,
    any shape), each with a last axis of the four wavelengths."""
    h = np.asarray(altitude, np.float64)[..., None]
    molecular = MOLECULAR_SCATTERING * np.exp(-0.07771971 * np.power(h, 1.16364243)) * air
    log_h = np.log(np.maximum(h, 1e-4))
    ozone_density = 3.78547397e20 * np.exp(-(log_h - 3.22261) ** 2 * 5.55555555 - log_h)
    absorption = OZONE_CROSS_SECTION * OZONE_MEAN_DOBSON * ozone_density * ozone
    aerosols = (AEROSOL_BASE_DENSITY * (np.exp(-h / AEROSOL_HEIGHT_SCALE)
                                        + AEROSOL_BACKGROUND_DENSITY / AEROSOL_BASE_DENSITY)
                * aerosol)
    aerosol_scattering = AEROSOL_SCATTERING * aerosols
    extinction = AEROSOL_ABSORPTION * aerosols + aerosol_scattering + absorption + molecular
    return extinction, molecular, aerosol_scattering


def _sphere_distance(origin, direction, radius):
    """Distance along unit ``direction`` (..., 3) from ``origin`` (3,) to the sphere of
    ``radius`` about the planet's centre: the far hit from inside, the near one from
    outside, -1 without a hit.

    In single precision, as Cycles computes it: |origin|^2 - radius^2 loses about 4 km^2
    there, which near the ground moves the distance to it, and so the light scattered along
    short rays towards the ground, by a few tenths of a percent (measured against Cycles'
    renders of the ground from 100 m: 1.1e-3 in the median pixel in double precision,
    9e-5 like this).
    """
    f32 = np.float32
    origin = origin.astype(f32)
    b = direction.astype(f32) @ origin
    c = f32(origin @ origin) - f32(radius) * f32(radius)
    d = b * b - c
    root = np.sqrt(np.maximum(d, f32(0.0)))
    t = np.where(d >= b * b, -b + root, -b - root)
    return np.where((d < 0.0) | ((c > 0.0) & (b > 0.0)), -1.0, t).astype(np.float64)


def _sun_direction(cos_zenith):
    return np.array([-math.sqrt(max(1.0 - cos_zenith * cos_zenith, 0.0)), 0.0, cos_zenith])


def transmittance(cos_zenith, normalized_altitude, densities):
    """Transmittance (..., 4) from a point at ``normalized_altitude`` (0: ground, 1: top of
    the atmosphere) to the sun at zenith cosine ``cos_zenith`` (arrays of one shape),
    ray-marched in TRANSMITTANCE_STEPS midpoint steps to the top of the atmosphere."""
    cos_zenith, normalized_altitude = np.broadcast_arrays(np.asarray(cos_zenith, np.float64),
                                                          np.asarray(normalized_altitude, np.float64))
    r = EARTH_RADIUS + (ATMOSPHERE_RADIUS - EARTH_RADIUS) * normalized_altitude
    sin_zenith = np.sqrt(np.maximum(1.0 - cos_zenith * cos_zenith, 0.0))
    # Origin (0, 0, r), direction (-sin, 0, cos): distance to the atmosphere's sphere.
    b = r * cos_zenith
    c = r * r - ATMOSPHERE_RADIUS * ATMOSPHERE_RADIUS
    d = b * b - c
    root = np.sqrt(np.maximum(d, 0.0))
    t_end = np.where(d >= b * b, -b + root, -b - root)
    t_end = np.where((d < 0.0) | ((c > 0.0) & (b > 0.0)), -1.0, t_end)
    step = t_end / TRANSMITTANCE_STEPS
    depth = np.zeros(cos_zenith.shape + (4,))
    for k in range(TRANSMITTANCE_STEPS):
        t = (k + 0.5) * step
        x, z = -sin_zenith * t, r + cos_zenith * t
        altitude = np.maximum(np.sqrt(x * x + z * z) - EARTH_RADIUS, 0.0)
        depth += _coefficients(altitude, *densities)[0] * step[..., None]
    return np.exp(-depth)


class _TransmittanceTable:
    """Transmittance to the sun over cos(zenith) in [-1, 1] x normalized altitude in [0, 1],
    read bilinearly with clamping."""

    def __init__(self, densities):
        w, h = TRANSMITTANCE_SIZE
        u = np.arange(w) / (w - 1)
        v = np.arange(h) / (h - 1)
        self.table = transmittance(u[None, :] * 2.0 - 1.0, v[:, None], densities)   # (h, w, 4)

    def __call__(self, cos_zenith, normalized_altitude):
        w, h = TRANSMITTANCE_SIZE
        x = (w - 1) * np.clip(cos_zenith * 0.5 + 0.5, 0.0, 1.0)
        y = (h - 1) * np.clip(normalized_altitude, 0.0, 1.0)
        x1, y1 = x.astype(np.int64), y.astype(np.int64)
        x2, y2 = np.minimum(x1 + 1, w - 1), np.minimum(y1 + 1, h - 1)
        fx, fy = (x - x1)[..., None], (y - y1)[..., None]
        flat = self.table.reshape(-1, 4)
        bottom = np.take(flat, y1 * w + x1, axis=0)
        bottom += fx * (np.take(flat, y1 * w + x2, axis=0) - bottom)
        top = np.take(flat, y2 * w + x1, axis=0)
        top += fx * (np.take(flat, y2 * w + x2, axis=0) - top)
        return bottom + fy * (top - bottom)

    def at_ground(self, cos_zenith):
        """The table's row at the ground (normalized altitude 0)."""
        w = TRANSMITTANCE_SIZE[0]
        x = (w - 1) * np.clip(cos_zenith * 0.5 + 0.5, 0.0, 1.0)
        x1 = x.astype(np.int64)
        x2 = np.minimum(x1 + 1, w - 1)
        row = self.table[0]
        left = np.take(row, x1, axis=0)
        return left + (x - x1)[..., None] * (np.take(row, x2, axis=0) - left)

    def at_zenith(self, normalized_altitude):
        """The table's column towards the zenith (cos = 1)."""
        h = TRANSMITTANCE_SIZE[1]
        y = (h - 1) * np.clip(normalized_altitude, 0.0, 1.0)
        y1 = y.astype(np.int64)
        y2 = np.minimum(y1 + 1, h - 1)
        column = self.table[:, -1]
        low = np.take(column, y1, axis=0)
        return low + (y - y1)[..., None] * (np.take(column, y2, axis=0) - low)


def _inscattering(table, densities, sun_dir, origin, directions, distance):
    """Radiance (..., 4) scattered towards the viewer at ``origin`` along ``directions``
    over ``distance`` km."""
    cos_sun = -(directions @ sun_dir)           # cosine between the light's path and the view
    molecular_phase = 3.0 / (16.0 * math.pi) * (1.0 + cos_sun * cos_sun)
    den = 1.0 + AEROSOL_G * AEROSOL_G + 2.0 * AEROSOL_G * cos_sun
    aerosol_phase = (1.0 - AEROSOL_G * AEROSOL_G) / (4.0 * math.pi * den * np.sqrt(den))
    dt = distance / INSCATTERING_STEPS
    t_ground_zenith = table.at_zenith(np.zeros(1))
    radiance = np.zeros(directions.shape[:-1] + (4,))
    through = np.ones_like(radiance)
    for k in range(INSCATTERING_STEPS):
        t = (k + 0.5) * dt
        x = origin + directions * t[..., None]
        r = np.sqrt(np.einsum("...i,...i->...", x, x))
        altitude = np.maximum(r - EARTH_RADIUS, 0.0)
        normalized = altitude / ATMOSPHERE_THICKNESS
        cos_zenith = (x @ sun_dir) / r
        extinction, molecular, aerosol_scattering = _coefficients(altitude, *densities)
        to_sun = table(cos_zenith, normalized)
        # Second-order light from the ground (Lambertian, lit through the atmosphere) and
        # the fit of higher orders.
        omega = 2.0 * math.pi * (1.0 - np.sqrt(1.0 - (EARTH_RADIUS / r) ** 2))
        # T(ground, point) = T(ground, sun) / T(point, sun), both towards the zenith.
        ground_to_sun = table.at_ground(cos_zenith)
        ground_to_point = t_ground_zenith / table.at_zenith(normalized)
        ground = (omega / (4.0 * math.pi))[..., None] * (GROUND_ALBEDO / math.pi) \
            * ground_to_sun * ground_to_point * cos_zenith[..., None]
        multiple = MULTIPLE_SCATTERING_FIT / (1.0 + 5.0 * np.exp(-17.92 * cos_zenith))[..., None]
        ms = multiple + ground
        source = SUN_IRRADIANCE * (molecular * (molecular_phase[..., None] * to_sun + ms)
                                   + aerosol_scattering * (aerosol_phase[..., None] * to_sun + ms))
        step = np.exp(-dt[..., None] * extinction)
        radiance += through * (source - source * step) / np.maximum(extinction, 1e-7)
        through *= step
    return radiance


def _altitude_km(altitude_m):
    return min(max(float(altitude_m), 1.0), 99999.0) / 1000.0


def sky_image(sun_elevation, altitude, air, aerosol, ozone, size=IMAGE_SIZE):
    """The sky without the sun disc: (height, width, 3) XYZ, row 0 looking straight down.

    Column x looks at azimuth 2 pi (x + 1/2) / width from the sun's opposite (the sun is
    between the two middle columns), row y at elevation sign(s) s^2 pi / 2 with
    s = 2 (y + 1/2) / height - 1.  ``altitude`` is the node's, in metres.
    """
    width, height = size
    densities = (float(air), float(aerosol), float(ozone))
    table = _TransmittanceTable(densities)
    sun_dir = _sun_direction(math.cos(math.pi / 2 - float(sun_elevation)))
    origin = np.array([0.0, 0.0, EARTH_RADIUS + _altitude_km(altitude)])
    half = width // 2
    azimuth = 2.0 * math.pi * (np.arange(half) + 0.5) / width
    row = 2.0 * (np.arange(height) + 0.5) / height - 1.0
    elevation = np.copysign(row * row, row) * (math.pi / 2)
    ce = np.cos(elevation)[:, None]
    directions = np.stack(np.broadcast_arrays(ce * np.cos(azimuth)[None, :],
                                              ce * np.sin(azimuth)[None, :],
                                              np.sin(elevation)[:, None]), axis=-1)
    to_top = _sphere_distance(origin, directions, ATMOSPHERE_RADIUS)
    to_ground = _sphere_distance(origin, directions, EARTH_RADIUS)
    distance = np.where(to_ground < 0.0, to_top, to_ground)
    xyz = _inscattering(table, densities, sun_dir, origin, directions, distance) @ SPECTRAL_TO_XYZ
    image = np.empty((height, width, 3))
    image[:, :half] = xyz
    image[:, width - half:] = xyz[:, ::-1]
    return image


def disc_solid_angle(angular_diameter) -> float:
    """Solid angle of the sun disc, 2 pi (1 - cos(diameter / 2)), in single precision as
    Cycles computes it: for a disc this small 1 - cos keeps only a few digits (the default
    0.545 deg disc's is 0.13 % too large, 0.0095 rad's 0.14 % too small), and the disc's
    radiance is its irradiance over it (measured: a plane under a 0.0095 rad sun renders
    0.14 % brighter in Cycles than the exact integral)."""
    f32 = np.float32
    half = f32(angular_diameter) / f32(2.0)
    return float(f32(2.0 * math.pi) * (f32(1.0) - f32(math.cos(float(half)))))


def sun_disc_xyz(sun_elevation, angular_diameter, altitude, air, aerosol, ozone):
    """XYZ radiance of the sun disc at its lowest and highest points: the sun's irradiance
    through the atmosphere there over the disc's solid angle."""
    densities = (float(air), float(aerosol), float(ozone))
    half = float(angular_diameter) / 2.0
    solid_angle = disc_solid_angle(angular_diameter)
    normalized = _altitude_km(altitude) / ATMOSPHERE_THICKNESS
    out = []
    for elevation in (float(sun_elevation) - half, float(sun_elevation) + half):
        t = transmittance(np.array(math.cos(math.pi / 2 - elevation)), np.array(normalized),
                          densities)
        out.append(tuple(float(v) for v in (SUN_IRRADIANCE * t / solid_angle) @ SPECTRAL_TO_XYZ))
    return out[0], out[1]


def earth_intersection_angle(altitude):
    """Elevation (radians, <= 0) of the horizon seen from ``altitude`` metres: the sun disc
    is hidden below it."""
    r = EARTH_RADIUS + float(altitude) / 1000.0
    return -(math.pi / 2 - math.asin(EARTH_RADIUS / r))



# -- Single Scattering (Nishita) ------------------------------------------------------------
# Blender's earlier default (intern/sky/source/sky_single_scattering.cpp): 21 wavelengths from
# 380 to 780 nm, Rayleigh and Mie scattering of the sun's light once along the view ray (32
# steps), its way to the sun attenuated by Rayleigh, Mie and ozone (an 8-node Gauss-Laguerre
# quadrature), in metres.
SS_EARTH_RADIUS = 6360e3
SS_ATMOSPHERE_RADIUS = 6420e3
SS_STEPS = 32
SS_RAYLEIGH_SCALE = 8e3
SS_MIE_SCALE = 1.2e3
SS_MIE_COEFF = 2e-5
SS_MIE_G = 0.76
SS_STEP_NM = 20.0
SS_IRRADIANCE = np.array([
    1.45756829855592995315, 1.56596305559738380175, 1.65148449067670455293,
    1.71496242737209314555, 1.75797983805020541226, 1.78256407885924539336,
    1.79095108475838560302, 1.78541550133410664714, 1.76815554864306845317,
    1.74122069647250410362, 1.70647127164943679389, 1.66556087452739887134,
    1.61993437242451854274, 1.57083597368892080581, 1.51932335059305478886,
    1.46628494965214395407, 1.41245852740172450623, 1.35844961970384092709,
    1.30474913844739281998, 1.25174963272610817455, 1.19975998755420620867])
SS_RAYLEIGH_COEFF = np.array([
    5.424820087636473e-05, 4.418549866505454e-05, 3.635151910165377e-05,
    3.017929012024763e-05, 2.526320226989157e-05, 2.130859310621843e-05,
    1.809838025320633e-05, 1.547057129129042e-05, 1.330284977336850e-05,
    1.150184784075764e-05, 9.99557429990163e-06, 8.72799973630707e-06,
    7.65513700977967e-06, 6.74217203751443e-06, 5.96134125832052e-06,
    5.29034598065810e-06, 4.71115687557433e-06, 4.20910481110487e-06,
    3.77218381260133e-06, 3.39051255477280e-06, 3.05591531679811e-06])
SS_OZONE_COEFF = np.array([
    3.25126849861e-09, 5.85395365047e-09, 1.977191155085e-08, 7.309568762914e-08,
    2.0084561514287e-07, 4.0383958096161e-07, 6.3551335912363e-07, 9.670704118097e-07,
    1.5479740042441e-06, 2.09038647223331e-06, 2.46128056164565e-06, 2.73551299461512e-06,
    2.15125863128643e-06, 1.59051840791988e-06, 1.12356197979857e-06, 7.3527551487574e-07,
    4.6450130357806e-07, 3.3096079921048e-07, 2.2512612292678e-07, 1.487912926649e-07,
    1.6828623364192e-07])
SS_CMF_XYZ = np.array([
    [0.00136800000, 0.00003900000, 0.00645000100], [0.01431000000, 0.00039600000, 0.06785001000],
    [0.13438000000, 0.00400000000, 0.64560000000], [0.34828000000, 0.02300000000, 1.74706000000],
    [0.29080000000, 0.06000000000, 1.66920000000], [0.09564000000, 0.13902000000, 0.81295010000],
    [0.00490000000, 0.32300000000, 0.27200000000], [0.06327000000, 0.71000000000, 0.07824999000],
    [0.29040000000, 0.95400000000, 0.02030000000], [0.59450000000, 0.99500000000, 0.00390000000],
    [0.91630000000, 0.87000000000, 0.00165000100], [1.06220000000, 0.63100000000, 0.00080000000],
    [0.85444990000, 0.38100000000, 0.00019000000], [0.44790000000, 0.17500000000, 0.00002000000],
    [0.16490000000, 0.06100000000, 0.00000000000], [0.04677000000, 0.01700000000, 0.00000000000],
    [0.01135916000, 0.00410200000, 0.00000000000], [0.00289932700, 0.00104700000, 0.00000000000],
    [0.00069007860, 0.00024920000, 0.00000000000], [0.00016615050, 0.00006000000, 0.00000000000],
    [0.00004150994, 0.00001499000, 0.00000000000]])
# Gauss-Laguerre (8 nodes) scaled to the ray: nodes as fractions of it, weights times e^x.
SS_QUADRATURE_NODES = np.array([0.006811185292, 0.03614807107, 0.09004346519, 0.1706680068,
                                0.2818362161, 0.4303406404, 0.6296271457, 0.9145252695])
SS_QUADRATURE_WEIGHTS = np.array([0.01750893642, 0.04135477391, 0.06678839063, 0.09507698807,
                                  0.1283416365, 0.1707430204, 0.2327233347, 0.3562490486])


def _ss_densities(height):
    """(Rayleigh, Mie, ozone) density factors at ``height`` metres, last axis."""
    h = np.asarray(height, np.float64)
    return np.stack([np.exp(-h / SS_RAYLEIGH_SCALE), np.exp(-h / SS_MIE_SCALE),
                     np.maximum(0.0, 1.0 - np.abs(h - 25000.0) / 15000.0)], axis=-1)


def _ss_to_atmosphere(origin, direction):
    """Distance from points ``origin`` (..., 3) along ``direction`` (..., 3) to the top of
    the atmosphere."""
    b = 2.0 * np.einsum("...i,...i->...", direction, origin)
    c = np.einsum("...i,...i->...", origin, origin) - SS_ATMOSPHERE_RADIUS ** 2
    return (-b + np.sqrt(b * b - 4.0 * c)) / 2.0


def _ss_optical_depth(origin, direction):
    """(Rayleigh, Mie, ozone) optical-depth factors from ``origin`` to the top of the
    atmosphere along ``direction`` (Gauss-Laguerre: the densities fall off exponentially)."""
    length = _ss_to_atmosphere(origin, direction)
    depth = 0.0
    for node, weight in zip(SS_QUADRATURE_NODES, SS_QUADRATURE_WEIGHTS):
        p = origin + direction * (node * length)[..., None]
        height = np.sqrt(np.einsum("...i,...i->...", p, p)) - SS_EARTH_RADIUS
        depth = depth + _ss_densities(height) * weight
    return depth * length[..., None]


def _ss_altitude(altitude_m):
    return min(max(float(altitude_m), 1.0), 59999.0)


def single_scattering_image(sun_elevation, altitude, air, aerosol, ozone, size=IMAGE_SIZE):
    """The Single Scattering sky without the sun disc: (height, width, 3) XYZ, row 0 looking
    straight down.  The lower half is black; row y of the upper half looks at elevation
    (y / (height / 2) - 1)^2 pi / 2, column x at azimuth 2 pi x / width - pi from the sun
    (mirrored about the middle column)."""
    width, height = size
    half_w, half_h = width // 2, height // 2
    scale = np.array([float(air), float(aerosol), float(ozone)])
    origin = np.array([0.0, 0.0, SS_EARTH_RADIUS + _ss_altitude(altitude)])
    sun = np.array([math.cos(sun_elevation), 0.0, math.sin(sun_elevation)])
    rows = np.arange(half_h, height)            # the horizon (row half_h) and above
    latitude = math.pi / 2 * (rows / half_h - 1.0) ** 2
    longitude = 2.0 * math.pi / width * np.arange(half_w) - math.pi
    cl = np.cos(latitude)[:, None]
    directions = np.stack(np.broadcast_arrays(cl * np.cos(longitude)[None, :],
                                              cl * np.sin(longitude)[None, :],
                                              np.sin(latitude)[:, None]), axis=-1)
    length = _ss_to_atmosphere(origin, directions)
    segment = length / SS_STEPS
    mu = directions @ sun
    rayleigh_phase = 0.1875 / math.pi * (1.0 + mu * mu)
    g2 = SS_MIE_G * SS_MIE_G
    mie_phase = (3.0 * (1.0 - g2) * (1.0 + mu * mu)) / (
        8.0 * math.pi * (2.0 + g2) * np.power(1.0 + g2 - 2.0 * SS_MIE_G * mu, 1.5))
    # The sun is blocked by the Earth only when below the horizon (Cycles tests the
    # direction's z, not the point's own horizon).
    blocked_test = sun[2] < 0.0
    extinction = np.stack([SS_RAYLEIGH_COEFF, np.full(21, 1.11 * SS_MIE_COEFF), SS_OZONE_COEFF])
    scattering = np.stack([SS_RAYLEIGH_COEFF, np.full(21, SS_MIE_COEFF)])    # (2, 21)
    spectrum = np.zeros(directions.shape[:-1] + (21,))
    depth = np.zeros(directions.shape[:-1] + (3,))
    for k in range(SS_STEPS):
        p = origin + directions * ((k + 0.5) * segment)[..., None]
        h = np.sqrt(np.einsum("...i,...i->...", p, p)) - SS_EARTH_RADIUS
        density = scale * _ss_densities(h)
        depth += segment[..., None] * density
        light = scale * _ss_optical_depth(p, np.broadcast_to(sun, p.shape))
        attenuation = np.exp(-((depth + light) @ extinction))                  # (..., 21)
        inscatter = (rayleigh_phase[..., None] * density[..., :1] * scattering[0]
                     + mie_phase[..., None] * density[..., 1:2] * scattering[1])
        contribution = attenuation * inscatter * SS_IRRADIANCE * segment[..., None]
        if blocked_test:
            b = 2.0 * (p @ sun)
            c = np.einsum("...i,...i->...", p, p) - SS_EARTH_RADIUS ** 2
            contribution[b * b - 4.0 * c >= 0.0] = 0.0
        spectrum += contribution
    xyz = (spectrum @ SS_CMF_XYZ) * SS_STEP_NM
    image = np.zeros((height, width, 3))
    image[half_h + 1:, :half_w] = xyz[1:]
    # Below the horizon: the horizon's colour fading to black at z = -0.4, (1 + 2.5 z)^3.
    below = np.arange(half_h + 1)
    z = np.sin(-math.pi / 2 * (below / half_h - 1.0) ** 2)
    fade = np.where(z >= -0.4, (1.0 + 2.5 * z) ** 3, 0.0)
    image[:half_h + 1, :half_w] = fade[:, None, None] * xyz[:1]
    image[:, width - half_w:] = image[:, :half_w][:, ::-1]
    return image


def single_scattering_sun_xyz(sun_elevation, angular_diameter, altitude, air, aerosol):
    """XYZ radiance of the Single Scattering sun disc at its lowest and highest points
    (through Rayleigh and Mie only; black when the whole disc is below the horizon)."""
    half = float(angular_diameter) / 2.0
    solid_angle = disc_solid_angle(angular_diameter)
    bottom, top = max(sun_elevation - half, 0.0), max(sun_elevation + half, 0.0)
    if top <= 0.0:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    origin = np.array([0.0, 0.0, SS_EARTH_RADIUS + _ss_altitude(altitude)])
    out = []
    for elevation in (bottom, top):
        direction = np.array([math.cos(elevation), 0.0, math.sin(elevation)])
        depth = _ss_optical_depth(origin, direction)
        tau = SS_RAYLEIGH_COEFF * depth[0] * float(air) + 1.11 * SS_MIE_COEFF * depth[1] * float(aerosol)
        spectrum = SS_IRRADIANCE * np.exp(-tau) / solid_angle
        out.append(tuple(float(v) for v in (spectrum @ SS_CMF_XYZ) * SS_STEP_NM))
    return out[0], out[1]


# -- Preetham ----------------------------------------------------------------------------------
# "A Practical Analytic Model for Daylight" (Preetham, Shirley, Smits 1999), as Cycles 5.0
# precomputes it (scene/shader_nodes.cpp, sky_texture_precompute_preetham) and evaluates it
# (kernel/svm/sky.h, sky_radiance_preetham).  Each of Y, x and y is a Perez function
# (1 + A e^(B / cos theta)) (1 + C e^(D gamma) + E cos^2 gamma) of the view's zenith angle theta
# and its angle gamma from the sun, with A..E linear in the turbidity T (rows: A..E, columns:
# the factor of T and the constant).
PREETHAM_PEREZ = np.array([
    [[0.1787, -1.4630], [-0.3554, 0.4275], [-0.0227, 5.3251], [0.1206, -2.5771], [-0.0670, 0.3703]],
    [[-0.0193, -0.2592], [-0.0665, 0.0008], [-0.0004, 0.2125], [-0.0641, -0.8989], [-0.0033, 0.0452]],
    [[-0.0167, -0.2608], [-0.0950, 0.0092], [-0.0079, 0.2102], [-0.0441, -1.6537], [-0.0109, 0.0529]],
])
# The zenith's chromaticity x and y: a cubic in the sun's zenith angle for each of T^2, T, 1
# (columns: theta^3, theta^2, theta, 1).
PREETHAM_ZENITH_XY = np.array([
    [[0.00166, -0.00375, 0.00209, 0.0], [-0.02903, 0.06377, -0.03202, 0.00394],
     [0.11693, -0.21196, 0.06052, 0.25886]],
    [[0.00275, -0.00610, 0.00317, 0.0], [-0.04214, 0.08970, -0.04153, 0.00516],
     [0.15346, -0.26756, 0.06670, 0.26688]],
])
PREETHAM_HORIZON = math.pi / 2 - 0.001     # the view's zenith angle is clamped to this
PREETHAM_DEFAULTS = {"sun_direction": (0.0, 0.0, 1.0), "turbidity": 2.2}
# Cycles evaluates the Preetham sky per ray; the image's bilinear lookup differs from that by
# its interpolation error, which falls as the square of the texel size: 3e-5 on average at
# 512 x 256, 7.5e-6 at this size (8 MiB), measured on random directions at turbidity 3.
PREETHAM_IMAGE_SIZE = (1024, 512)


def _perez(config, cos_theta, gamma):
    """The Perez function of ``config`` (A..E) at cos theta and gamma (arrays).  Below a
    turbidity of about 1.2 the luminance's B is positive and the function explodes towards
    the horizon (the clamped theta keeps it finite for the node's turbidities, 1 to 10); in
    Cycles too, where the image's interpolation near the horizon cannot follow it."""
    a, b, c, d, e = config
    cg = np.cos(gamma)
    return ((1.0 + a * np.exp(b / cos_theta))
            * (1.0 + c * np.exp(d * gamma) + e * cg * cg))


def preetham_sun(sun_direction) -> tuple[float, float]:
    """The sun's zenith angle and azimuth (atan2(y, x)) from the node's Sun Direction,
    normalised as Blender's sync does (a zero vector: the zenith)."""
    x, y, z = (float(v) for v in sun_direction)
    length = math.sqrt(x * x + y * y + z * z)
    if length == 0.0:
        return 0.0, 0.0
    return math.acos(min(max(z / length, -1.0), 1.0)), math.atan2(y, x)


def preetham_xyz(cos_theta, gamma, sun_theta, turbidity) -> np.ndarray:
    """CIE XYZ (..., 3) of the Preetham sky at views of zenith cosine ``cos_theta`` and angle
    ``gamma`` from a sun at zenith angle ``sun_theta``; the view's theta is clamped to just
    above the horizon (below it the sky repeats the horizon's row, by gamma)."""
    t = float(turbidity)
    ts = float(sun_theta)
    config = PREETHAM_PEREZ @ np.array([t, 1.0])                 # (Y, x, y) x (A..E)
    chi = (4.0 / 9.0 - t / 120.0) * (math.pi - 2.0 * ts)
    zenith_y = ((4.0453 * t - 4.9710) * math.tan(chi) - 0.2155 * t + 2.4192) * 0.06
    zenith_xy = PREETHAM_ZENITH_XY @ np.array([ts ** 3, ts ** 2, ts, 1.0]) @ np.array([t * t, t, 1.0])
    zenith = np.array([zenith_y, *zenith_xy])
    zenith = zenith / np.array([_perez(c, 1.0, ts) for c in config])
    cos_theta = np.maximum(np.asarray(cos_theta, np.float64), math.cos(PREETHAM_HORIZON))
    big_y, x, y = (zenith[k] * _perez(config[k], cos_theta, gamma) for k in range(3))
    safe_y = np.where(y != 0.0, y, 1.0)
    big_x = np.where(y != 0.0, x / safe_y * big_y, 0.0)
    big_z = np.where((y != 0.0) & (big_y != 0.0), (1.0 - x - y) / safe_y * big_y, 0.0)
    return np.stack([big_x, big_y, big_z], axis=-1)


def preetham_image(sun_theta, turbidity, size=PREETHAM_IMAGE_SIZE):
    """The Preetham sky as the shader reads it: (height, width, 3) XYZ laid out as
    ``sky_image`` (columns by azimuth from the sun's opposite, rows square-spaced in
    elevation), for a sun at zenith angle ``sun_theta``; finer than the atmosphere's image,
    as it stands for a function Cycles evaluates exactly."""
    width, height = size
    azimuth = 2.0 * math.pi * (np.arange(width) + 0.5) / width - math.pi     # from the sun
    row = 2.0 * (np.arange(height) + 0.5) / height - 1.0
    elevation = np.copysign(row * row, row) * (math.pi / 2)
    cos_theta = np.sin(elevation)[:, None]
    sin_theta = np.cos(elevation)[:, None]
    cos_gamma = (sin_theta * math.sin(sun_theta) * np.cos(azimuth)[None, :]
                 + cos_theta * math.cos(sun_theta))
    gamma = np.arccos(np.clip(cos_gamma, -1.0, 1.0))
    return preetham_xyz(np.broadcast_to(cos_theta, gamma.shape), gamma, sun_theta, turbidity)


# -- the node --------------------------------------------------------------------------------
MIN_SUN_SIZE = 0.0005        # radians: Cycles clamps the sun's angular diameter to this
# The node's settings as Blender 5.0 creates it (what a property missing from a node reads).
NODE_DEFAULTS = {"sun_disc": 1.0, "sun_size": math.radians(0.545), "sun_intensity": 1.0,
                 "sun_elevation": math.radians(15.0), "sun_rotation": 0.0, "altitude": 100.0,
                 "air_density": 1.0, "aerosol_density": 1.0, "ozone_density": 1.0}


def _setting(props: dict, name: str) -> float:
    return float(props.get(name, NODE_DEFAULTS[name]))


def sun_position(elevation, rotation):
    """(elevation, rotation) as the shader reads them (Cycles' SkyTextureNode::
    simplify_settings): the elevation wrapped into [-pi/2, pi/2] (the rotation turned by pi
    when the sun passes the zenith), the rotation into [0, 2 pi) and then mirrored to
    2 pi - rotation (the shader's azimuth runs the other way)."""
    e, r = math.fmod(float(elevation), 2.0 * math.pi), float(rotation)
    if abs(e) >= math.pi:
        e -= math.copysign(2.0 * math.pi, e)
    if e >= math.pi / 2 or e <= -math.pi / 2:
        e = math.copysign(math.pi, e) - e
        r += math.pi
    r = math.fmod(r, 2.0 * math.pi)
    if r < 0.0:
        r += 2.0 * math.pi
    return e, 2.0 * math.pi - r


def _sky_type(props: dict) -> str:
    return str(props.get("sky_type", SKY_TYPES[0]))


def _atmosphere(props: dict) -> tuple:
    """(wrapped elevation, altitude, air, aerosol, ozone): what the sky image depends on
    (with the sky type)."""
    elevation, _ = sun_position(_setting(props, "sun_elevation"), _setting(props, "sun_rotation"))
    return (elevation, *(_setting(props, name)
                         for name in ("altitude", "air_density", "aerosol_density", "ozone_density")))


def _preetham_settings(props: dict) -> tuple[float, float, float]:
    """(sun zenith angle, sun azimuth, turbidity) of a Preetham sky."""
    theta, azimuth = preetham_sun(props.get("sun_direction", PREETHAM_DEFAULTS["sun_direction"]))
    return theta, azimuth, float(props.get("turbidity", PREETHAM_DEFAULTS["turbidity"]))


def _image_key(props: dict) -> tuple:
    """What the node's sky image depends on besides its type: the atmosphere, or the
    Preetham sun's zenith angle and the turbidity (the image is laid out about the sun)."""
    if _sky_type(props) == "PREETHAM":
        theta, _, turbidity = _preetham_settings(props)
        return theta, turbidity
    return _atmosphere(props)


def image_name(props: dict) -> str:
    """The name of the sky image a Sky Texture node with these properties reads (one image
    per atmosphere, shared by the nodes that have the same)."""
    return f".sky {_sky_type(props).lower()} " + " ".join(f"{v:.9g}" for v in _image_key(props))


def node_image(node) -> str:
    """The name of the image a shader node reads ("" for none): its ``image`` property, or
    a Sky Texture's precomputed sky."""
    if node.type == "TexSky":
        return image_name(node.props)
    return str(node.props.get("image", ""))


def node_parameters(props: dict) -> dict:
    """The Sky Texture's kernel properties (``kernels.svm.nodes``, "TexSky"): the sun's
    wrapped elevation and rotation, its angular diameter (-1: no disc), intensity, the
    horizon's elevation and the disc's XYZ at its bottom and top.  A Preetham sky has no disc;
    its rotation puts its sun where the image has it (see ``preetham_image``)."""
    if _sky_type(props) == "PREETHAM":
        theta, azimuth, _ = _preetham_settings(props)
        out = {"sky_elevation": math.pi / 2 - theta, "sky_rotation": azimuth - math.pi / 2,
               "sky_diameter": -1.0, "sun_intensity": 1.0, "sky_horizon": 0.0}
        out.update({f"sky_{end}_{axis}": 0.0 for end in ("bottom", "top") for axis in "xyz"})
        return out
    elevation, rotation = sun_position(_setting(props, "sun_elevation"),
                                       _setting(props, "sun_rotation"))
    _, altitude, air, aerosol, ozone = _atmosphere(props)
    diameter = max(_setting(props, "sun_size"), MIN_SUN_SIZE)
    if _sky_type(props) == "SINGLE_SCATTERING":
        bottom, top = single_scattering_sun_xyz(elevation, diameter, altitude, air, aerosol)
    else:
        bottom, top = sun_disc_xyz(elevation, diameter, altitude, air, aerosol, ozone)
    out = {"sky_elevation": elevation, "sky_rotation": rotation,
           "sky_diameter": diameter if _setting(props, "sun_disc") else -1.0,
           "sun_intensity": _setting(props, "sun_intensity"),
           "sky_horizon": earth_intersection_angle(altitude)}
    for axis, v0, v1 in zip("xyz", bottom, top):
        out[f"sky_bottom_{axis}"] = v0
        out[f"sky_top_{axis}"] = v1
    return out


@functools.lru_cache(maxsize=4)
def _cached_image(sky_type: str, key: tuple) -> np.ndarray:
    compute = {"SINGLE_SCATTERING": single_scattering_image,
               "PREETHAM": preetham_image}.get(sky_type, sky_image)
    xyz = compute(*key)
    rgba = np.ones(xyz.shape[:2] + (4,), np.float32)
    rgba[..., :3] = xyz
    rgba.setflags(write=False)
    return rgba


def sky_images(scene: SceneDescription) -> dict:
    """{name: Image} of the sky images the scene's Sky Texture nodes read (XYZ in the colour
    channels, stored as data).  The last few are kept in memory: a re-render, a frame of an
    animation or the viewport does not compute them again (about 5 s each)."""
    nodes = [n for m in [*scene.materials, scene.world.material()] for n in m.nodes
             if n.type == "TexSky"]
    out = {}
    for node in nodes:
        name = image_name(node.props)
        if name not in out:
            out[name] = Image(pixels=_cached_image(_sky_type(node.props), _image_key(node.props)),
                              colorspace="data", alpha="NONE")
    return out


SUN_GUIDE_SHARE = 0.5        # of the world's light samples, when its sun is sampled apart


def sun_guide(world) -> tuple[np.ndarray, float]:
    """The sun cone next-event estimation samples beside the world's map (``kernels.
    background.sample_world``): (direction, cos of its half angle, share of the samples)
    and an estimate of the sun's radiance averaged over the sphere (what it adds to the
    world's importance; whatever scales the node's colour after it is not counted), for
    the sun of the world's first Sky Texture that has a disc above the horizon and reads the
    ray direction unchanged (its Vector unlinked); zeros without one."""
    from .kernels.colorspace import XYZ_TO_RGB
    out = np.zeros(5)
    for node in world.material().nodes:
        if node.type != "TexSky" or "Vector" in node.inputs:
            continue
        params = node_parameters(node.props)
        half = 0.5 * params["sky_diameter"]
        e, r = params["sky_elevation"], params["sky_rotation"]
        if half <= 0.0 or e + half <= params["sky_horizon"]:
            continue
        out[:3] = (-math.cos(e) * math.sin(r), math.cos(e) * math.cos(r), math.sin(e))
        out[3] = math.cos(half)
        out[4] = SUN_GUIDE_SHARE
        middle = [0.5 * (params[f"sky_bottom_{a}"] + params[f"sky_top_{a}"]) for a in "xyz"]
        rgb = np.abs(XYZ_TO_RGB @ np.array(middle)) * params["sun_intensity"]
        # The limb darkening averages 0.8 over the disc.
        return out, float(rgb.mean()) * 0.8 * 2.0 * math.pi * (1.0 - out[3]) / (4.0 * math.pi)
    return out, 0.0
