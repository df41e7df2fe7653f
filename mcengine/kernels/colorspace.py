"""Colour science of the working space: colour models, XYZ, black bodies and spectral colours.

The working space is Blender's default scene-linear space, Linear Rec.709.
Cycles reads its matrices from Blender's OpenColorIO configuration
(scene/shader.cpp :: ShaderManager::init_xyz_transforms: XYZ comes from the
``aces_interchange`` role through OCIO's ACES AP0 -> XYZ D65 matrix), which
gives the values below (computed with Blender 5.0.1's PyOpenColorIO and that
configuration; ``RGB_TO_Y`` also measured by rendering).  The working space is
Rec.709 itself, so colours Cycles defines in Rec.709 (Blackbody) need no
conversion (measured: Cycles renders the fitted curve's values unchanged).

Colour models (util/color.h): ``rgb_to_hsv``/``hsv_to_rgb`` (hexcone) and
``rgb_to_hsl``/``hsl_to_rgb``, with Cycles' treatment of values outside [0, 1].
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import device

# Luminance: the Y row of the working space's RGB -> XYZ matrix.
RGB_TO_Y = (0.212639, 0.715169, 0.072193)
# XYZ (D65) -> working space RGB, rows.
XYZ_TO_RGB = np.array([
    [3.2409701347351074, -1.5373845100402832, -0.4986114203929901],
    [-0.9692435264587402, 1.875967025756836, 0.04155468940734863],
    [0.055629879236221313, -0.20397649705410004, 1.0569710731506348]])
# Black-body colour in Rec.709 (kernel/tables.h): per temperature band, R and G are
# a/T + b T + c, B is ((a T + b) T + c) T + d.  Bands start at these temperatures.
BLACKBODY_BANDS = np.array([965.0, 1167.0, 1449.0, 1902.0, 3315.0, 6365.0])
BLACKBODY_R = np.array([
    [1.61919106e+03, -2.05010916e-03, 5.02995757e+00],
    [2.48845471e+03, -1.11330907e-03, 3.22621544e+00],
    [3.34143193e+03, -4.86551192e-04, 1.76486769e+00],
    [4.09461742e+03, -1.27446582e-04, 7.25731635e-01],
    [4.67028036e+03, 2.91258199e-05, 1.26703442e-01],
    [4.59509185e+03, 2.87495649e-05, 1.50345020e-01],
    [3.78717450e+03, 9.35907826e-06, 3.99075871e-01]], np.float32).astype(np.float64)
BLACKBODY_G = np.array([
    [-4.88999748e+02, 6.04330754e-04, -7.55807526e-02],
    [-7.55994277e+02, 3.16730098e-04, 4.78306139e-01],
    [-1.02363977e+03, 1.20223470e-04, 9.36662319e-01],
    [-1.26571316e+03, 4.87340896e-06, 1.27054498e+00],
    [-1.42529332e+03, -4.01150431e-05, 1.43972784e+00],
    [-1.17554822e+03, -2.16378048e-05, 1.30408023e+00],
    [-5.00799571e+02, -4.59832026e-06, 1.09098763e+00]], np.float32).astype(np.float64)
BLACKBODY_B = np.array([
    [5.96945309e-11, -4.85742887e-08, -9.70622247e-05, -4.07936148e-03],
    [2.40430366e-11, 5.55021075e-08, -1.98503712e-04, 2.89312858e-02],
    [-1.40949732e-11, 1.89878968e-07, -3.56632824e-04, 9.10767778e-02],
    [-3.61460868e-11, 2.84822009e-07, -4.93211319e-04, 1.56723440e-01],
    [-1.97075738e-11, 1.75359352e-07, -2.50542825e-04, -2.22783266e-02],
    [-1.61997957e-13, -1.64216008e-08, 3.86216271e-04, -7.38077418e-01],
    [6.72650283e-13, -2.73078809e-08, 4.24098264e-04, -7.52335691e-01]], np.float32).astype(np.float64)
# Outside the fitted range (below 800 K, from 12000 K on) the colour is constant.
BLACKBODY_COLD = (5.413294490189271, -0.20319390035873933, -0.0822535242887164)
BLACKBODY_HOT = (0.8262954810464208, 0.9945080501520986, 1.566307710274283)

# CIE 1931 colour matching functions (x, y, z) at 380, 385, ..., 780 nm (kernel/tables.h).
CIE_XYZ = np.array([
    0.0014, 0.0000, 0.0065, 0.0022, 0.0001, 0.0105, 0.0042, 0.0001, 0.0201,
    0.0076, 0.0002, 0.0362, 0.0143, 0.0004, 0.0679, 0.0232, 0.0006, 0.1102,
    0.0435, 0.0012, 0.2074, 0.0776, 0.0022, 0.3713, 0.1344, 0.0040, 0.6456,
    0.2148, 0.0073, 1.0391, 0.2839, 0.0116, 1.3856, 0.3285, 0.0168, 1.6230,
    0.3483, 0.0230, 1.7471, 0.3481, 0.0298, 1.7826, 0.3362, 0.0380, 1.7721,
    0.3187, 0.0480, 1.7441, 0.2908, 0.0600, 1.6692, 0.2511, 0.0739, 1.5281,
    0.1954, 0.0910, 1.2876, 0.1421, 0.1126, 1.0419, 0.0956, 0.1390, 0.8130,
    0.0580, 0.1693, 0.6162, 0.0320, 0.2080, 0.4652, 0.0147, 0.2586, 0.3533,
    0.0049, 0.3230, 0.2720, 0.0024, 0.4073, 0.2123, 0.0093, 0.5030, 0.1582,
    0.0291, 0.6082, 0.1117, 0.0633, 0.7100, 0.0782, 0.1096, 0.7932, 0.0573,
    0.1655, 0.8620, 0.0422, 0.2257, 0.9149, 0.0298, 0.2904, 0.9540, 0.0203,
    0.3597, 0.9803, 0.0134, 0.4334, 0.9950, 0.0087, 0.5121, 1.0000, 0.0057,
    0.5945, 0.9950, 0.0039, 0.6784, 0.9786, 0.0027, 0.7621, 0.9520, 0.0021,
    0.8425, 0.9154, 0.0018, 0.9163, 0.8700, 0.0017, 0.9786, 0.8163, 0.0014,
    1.0263, 0.7570, 0.0011, 1.0567, 0.6949, 0.0010, 1.0622, 0.6310, 0.0008,
    1.0456, 0.5668, 0.0006, 1.0026, 0.5030, 0.0003, 0.9384, 0.4412, 0.0002,
    0.8544, 0.3810, 0.0002, 0.7514, 0.3210, 0.0001, 0.6424, 0.2650, 0.0000,
    0.5419, 0.2170, 0.0000, 0.4479, 0.1750, 0.0000, 0.3608, 0.1382, 0.0000,
    0.2835, 0.1070, 0.0000, 0.2187, 0.0816, 0.0000, 0.1649, 0.0610, 0.0000,
    0.1212, 0.0446, 0.0000, 0.0874, 0.0320, 0.0000, 0.0636, 0.0232, 0.0000,
    0.0468, 0.0170, 0.0000, 0.0329, 0.0119, 0.0000, 0.0227, 0.0082, 0.0000,
    0.0158, 0.0057, 0.0000, 0.0114, 0.0041, 0.0000, 0.0081, 0.0029, 0.0000,
    0.0058, 0.0021, 0.0000, 0.0041, 0.0015, 0.0000, 0.0029, 0.0010, 0.0000,
    0.0020, 0.0007, 0.0000, 0.0014, 0.0005, 0.0000, 0.0010, 0.0004, 0.0000,
    0.0007, 0.0002, 0.0000, 0.0005, 0.0002, 0.0000, 0.0003, 0.0001, 0.0000,
    0.0002, 0.0001, 0.0000, 0.0002, 0.0001, 0.0000, 0.0001, 0.0000, 0.0000,
    0.0001, 0.0000, 0.0000, 0.0001, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000,
], np.float32).astype(np.float64).reshape(81, 3)
WAVELENGTH_SCALE = 1.0 / 2.52     # Cycles' empirical scale keeping the spectral colours <= 1


@device
def luminance(r, g, b):
    """Luminance of a working-space colour (RGB to BW, colour -> float links)."""
    return RGB_TO_Y[0] * r + RGB_TO_Y[1] * g + RGB_TO_Y[2] * b


@device
def _mat3(m, x, y, z):
    return (m[0, 0] * x + m[0, 1] * y + m[0, 2] * z,
            m[1, 0] * x + m[1, 1] * y + m[1, 2] * z,
            m[2, 0] * x + m[2, 1] * y + m[2, 2] * z)


@device
def blackbody(t):
    """Colour of a black body at temperature ``t`` (K) in the working space, normalised as
    Cycles' Blackbody node (svm/math_util.h :: svm_math_blackbody_color_rec709), >= 0."""
    if t >= 12000.0:
        r, g, b = BLACKBODY_HOT
    elif t < 800.0:
        r, g, b = BLACKBODY_COLD
    else:
        i = 0
        while i < 6 and t >= BLACKBODY_BANDS[i]:
            i += 1
        inv = 1.0 / t
        r = BLACKBODY_R[i, 0] * inv + BLACKBODY_R[i, 1] * t + BLACKBODY_R[i, 2]
        g = BLACKBODY_G[i, 0] * inv + BLACKBODY_G[i, 1] * t + BLACKBODY_G[i, 2]
        b = ((BLACKBODY_B[i, 0] * t + BLACKBODY_B[i, 1]) * t + BLACKBODY_B[i, 2]) * t + BLACKBODY_B[i, 3]
    return max(r, 0.0), max(g, 0.0), max(b, 0.0)


@device
def wavelength(nm):
    """Colour of monochromatic light of wavelength ``nm`` in the working space, as Cycles'
    Wavelength node: CIE table lerped at 5 nm steps, XYZ -> RGB, / 2.52, >= 0."""
    s = (nm - 380.0) * (1.0 / 5.0)
    if not (s > -1.0 and s < 80.0):         # truncation toward zero: (-1, 0) reads entry 0
        return 0.0, 0.0, 0.0
    i = int(s)
    f = s - i                               # negative just below 380 nm: extrapolates, as Cycles
    x = CIE_XYZ[i, 0] + f * (CIE_XYZ[i + 1, 0] - CIE_XYZ[i, 0])
    y = CIE_XYZ[i, 1] + f * (CIE_XYZ[i + 1, 1] - CIE_XYZ[i, 1])
    z = CIE_XYZ[i, 2] + f * (CIE_XYZ[i + 1, 2] - CIE_XYZ[i, 2])
    r, g, b = _mat3(XYZ_TO_RGB, x, y, z)
    return (max(r * WAVELENGTH_SCALE, 0.0), max(g * WAVELENGTH_SCALE, 0.0),
            max(b * WAVELENGTH_SCALE, 0.0))


@device
def rgb_to_hsv(r, g, b):
    """Hexcone HSV; hue in [0, 1), 0 for greys and black."""
    cmax = max(r, max(g, b))
    cmin = min(r, min(g, b))
    delta = cmax - cmin
    s = delta / cmax if cmax != 0.0 else 0.0
    h = 0.0
    if s != 0.0:
        cr, cg, cb = (cmax - r) / delta, (cmax - g) / delta, (cmax - b) / delta
        if r == cmax:
            h = cb - cg
        elif g == cmax:
            h = 2.0 + cr - cb
        else:
            h = 4.0 + cg - cr
        h /= 6.0
        if h < 0.0:
            h += 1.0
    return h, s, cmax


@device
def hsv_to_rgb(h, s, v):
    """Inverse of :func:`rgb_to_hsv`; a hue outside [0, 1] is not wrapped (as Cycles)."""
    if s == 0.0:
        return v, v, v
    if h == 1.0:
        h = 0.0
    h *= 6.0
    i = math.floor(h)
    f = h - i
    p = v * (1.0 - s)
    q = v * (1.0 - s * f)
    t = v * (1.0 - s * (1.0 - f))
    if i == 0.0:
        return v, t, p
    if i == 1.0:
        return q, v, p
    if i == 2.0:
        return p, v, t
    if i == 3.0:
        return p, q, v
    if i == 4.0:
        return t, p, v
    return v, p, q


@device
def rgb_to_hsl(r, g, b):
    """HSL; lightness capped at 1."""
    cmax = max(r, max(g, b))
    cmin = min(r, min(g, b))
    lum = min(1.0, (cmax + cmin) / 2.0)
    h = s = 0.0
    if cmax != cmin:
        delta = cmax - cmin
        s = delta / (2.0 - cmax - cmin) if lum > 0.5 else delta / (cmax + cmin)
        if cmax == r:
            h = (g - b) / delta + (6.0 if g < b else 0.0)
        elif cmax == g:
            h = (b - r) / delta + 2.0
        else:
            h = (r - g) / delta + 4.0
    return h / 6.0, s, lum


@device
def hsl_to_rgb(h, s, lum):
    nr = min(max(abs(h * 6.0 - 3.0) - 1.0, 0.0), 1.0)
    ng = min(max(2.0 - abs(h * 6.0 - 2.0), 0.0), 1.0)
    nb = min(max(2.0 - abs(h * 6.0 - 4.0), 0.0), 1.0)
    chroma = (1.0 - abs(2.0 * lum - 1.0)) * s
    return (nr - 0.5) * chroma + lum, (ng - 0.5) * chroma + lum, (nb - 0.5) * chroma + lum
