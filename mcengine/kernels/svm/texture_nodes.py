"""Texture nodes: procedural patterns and images (kernel/svm/checker.h, noise.h, voronoi.h, ...).

``eval_texture_node`` evaluates one texture node: inputs at regs[b:] in the
order of ``nodes.VALUE_NODES``, outputs to regs[c:].  The Vector input is
always present: when nothing is linked to it, the compiler links the
texture coordinate Cycles uses by default (Generated, UV for images, Incoming for IES).
Each texture's entry point is called, not inlined (compile time); Perlin
noise and its fractals are in ``noise.py``, Voronoi in ``voronoi.py``, Gabor in
``gabor.py``, Cycles' hashes in ``hash.py``.
"""
from __future__ import annotations

import math

from ...jit import deref, device, function
from ..ies import ies_direction
from ..scalar import saturate
from .gabor import gabor_node
from .hash import hash_float, hash_float2, hash_float3, hash_float4, r32
from .input_nodes import normal_to_object
from .math_nodes import fmod
from .nodes import NODES, OFFSETS, OUTPUT_OFFSETS
from .noise import noise_fbm, noise_texture
from .voronoi import voronoi_texture

_CHECKER = NODES["TexChecker"].code
_CK_VECTOR = OFFSETS["TexChecker"]["Vector"]
_CK_COLOR1 = OFFSETS["TexChecker"]["Color1"]
_CK_COLOR2 = OFFSETS["TexChecker"]["Color2"]
_CK_SCALE = OFFSETS["TexChecker"]["Scale"]

_WHITE_NOISE = NODES["TexWhiteNoise"].code
_WN = OFFSETS["TexWhiteNoise"]
_WN_VECTOR, _WN_W, _WN_DIM = _WN["Vector"], _WN["W"], _WN["prop:noise_dimensions"]
_WN_VALUE = OUTPUT_OFFSETS["TexWhiteNoise"]["Value"]
_WN_COLOR = OUTPUT_OFFSETS["TexWhiteNoise"]["Color"]

_NOISE = NODES["TexNoise"].code
_NZ = OFFSETS["TexNoise"]
_NZ_VECTOR, _NZ_W, _NZ_SCALE, _NZ_DETAIL = _NZ["Vector"], _NZ["W"], _NZ["Scale"], _NZ["Detail"]
_NZ_ROUGHNESS, _NZ_LACUNARITY = _NZ["Roughness"], _NZ["Lacunarity"]
_NZ_OFFSET, _NZ_GAIN, _NZ_DISTORTION = _NZ["Offset"], _NZ["Gain"], _NZ["Distortion"]
_NZ_DIM, _NZ_TYPE, _NZ_NORMALIZE = (_NZ["prop:noise_dimensions"], _NZ["prop:noise_type"],
                                    _NZ["prop:normalize"])
_NZ_FAC = OUTPUT_OFFSETS["TexNoise"]["Fac"]
_NZ_COLOR = OUTPUT_OFFSETS["TexNoise"]["Color"]

_VORONOI = NODES["TexVoronoi"].code
_VO = OFFSETS["TexVoronoi"]
_VO_VECTOR, _VO_W, _VO_SCALE, _VO_DETAIL = _VO["Vector"], _VO["W"], _VO["Scale"], _VO["Detail"]
_VO_ROUGHNESS, _VO_LACUNARITY = _VO["Roughness"], _VO["Lacunarity"]
_VO_SMOOTHNESS, _VO_EXPONENT, _VO_RANDOMNESS = (_VO["Smoothness"], _VO["Exponent"],
                                                _VO["Randomness"])
_VO_DIM, _VO_FEATURE = _VO["prop:voronoi_dimensions"], _VO["prop:feature"]
_VO_METRIC, _VO_NORMALIZE = _VO["prop:distance"], _VO["prop:normalize"]
_VOO = OUTPUT_OFFSETS["TexVoronoi"]
_VO_DISTANCE, _VO_COLOR, _VO_POSITION = _VOO["Distance"], _VOO["Color"], _VOO["Position"]
_VO_W_OUT, _VO_RADIUS = _VOO["W"], _VOO["Radius"]

_GRADIENT = NODES["TexGradient"].code
_GR_VECTOR = OFFSETS["TexGradient"]["Vector"]
_GR_TYPE = OFFSETS["TexGradient"]["prop:gradient_type"]

_GABOR = NODES["TexGabor"].code

_IES = NODES["TexIES"].code
_IE = OFFSETS["TexIES"]
_IE_VECTOR, _IE_STRENGTH, _IE_IMPLICIT, _IE_TABLE = (_IE["Vector"], _IE["Strength"],
                                                     _IE["prop:implicit_vector"], _IE["prop:table"])

_WAVE = NODES["TexWave"].code
_WV = OFFSETS["TexWave"]
_WV_VECTOR, _WV_SCALE, _WV_DISTORTION = _WV["Vector"], _WV["Scale"], _WV["Distortion"]
_WV_DETAIL, _WV_DSCALE, _WV_DROUGHNESS = _WV["Detail"], _WV["Detail Scale"], _WV["Detail Roughness"]
_WV_PHASE = _WV["Phase Offset"]
_WV_TYPE, _WV_BANDS, _WV_RINGS, _WV_PROFILE = (_WV["prop:wave_type"], _WV["prop:bands_direction"],
                                               _WV["prop:rings_direction"], _WV["prop:wave_profile"])

_BRICK = NODES["TexBrick"].code
_BR = OFFSETS["TexBrick"]
_BR_VECTOR, _BR_COLOR1, _BR_COLOR2, _BR_MORTAR = (_BR["Vector"], _BR["Color1"], _BR["Color2"],
                                                  _BR["Mortar"])
_BR_SCALE, _BR_MORTAR_SIZE, _BR_MORTAR_SMOOTH = _BR["Scale"], _BR["Mortar Size"], _BR["Mortar Smooth"]
_BR_BIAS, _BR_WIDTH, _BR_HEIGHT = _BR["Bias"], _BR["Brick Width"], _BR["Row Height"]
_BR_OFFSET, _BR_OFFSET_FREQ = _BR["prop:offset"], _BR["prop:offset_frequency"]
_BR_SQUASH, _BR_SQUASH_FREQ = _BR["prop:squash"], _BR["prop:squash_frequency"]

_MAGIC = NODES["TexMagic"].code
_MG = OFFSETS["TexMagic"]
_MG_VECTOR, _MG_SCALE, _MG_DISTORTION, _MG_DEPTH = (_MG["Vector"], _MG["Scale"], _MG["Distortion"],
                                                    _MG["prop:turbulence_depth"])

# Cycles' float32 constants (M_2PI_F, M_PI_2_F)
_TWO_PI_F = r32(2.0 * math.pi)
_HALF_PI_F = r32(0.5 * math.pi)


@function
def eval_texture_node(code, regs, b, c, sd_ref, tex_ref):
    """A procedural texture: inputs at regs[b:], outputs to regs[c:]; the point and the texture
    data by reference (``jit.by_ref``)."""
    if code == _CHECKER:
        checker_node(regs, b, c)
    elif code == _NOISE:
        noise_node(regs, b, c)
    elif code == _VORONOI:
        voronoi_node(regs, b, c)
    elif code == _WHITE_NOISE:
        white_noise_node(regs, b, c)
    elif code == _GRADIENT:
        gradient_node(regs, b, c)
    elif code == _WAVE:
        wave_node(regs, b, c)
    elif code == _BRICK:
        brick_node(regs, b, c)
    elif code == _MAGIC:
        magic_node(regs, b, c)
    elif code == _GABOR:
        gabor_node(regs, b, c)
    elif code == _IES:
        ies_node(regs, b, c, deref(sd_ref), deref(tex_ref))


@function
def ies_node(regs, b, c, sd, tex):
    """IES Texture (svm_node_ies): Strength times the profile (the node's table) along the
    Vector, as given where linked; unlinked, the Incoming direction in the object's space, as a
    normal (M^T d; the world and points of no object keep it in world space)."""
    x, y, z = regs[b + _IE_VECTOR], regs[b + _IE_VECTOR + 1], regs[b + _IE_VECTOR + 2]
    if regs[b + _IE_IMPLICIT] != 0.0 and sd.obj >= 0 and sd.prim >= 0:
        x, y, z = normal_to_object(tex.objects[sd.obj], x, y, z)
    regs[c] = regs[b + _IE_STRENGTH] * ies_direction(regs, b + _IE_TABLE + 1, x, y, z)


@device
def checker(x, y, z):
    """1 on the odd cells of the unit grid, else 0 (Cycles' svm_checker)."""
    # Nudged so that integer coordinates fall consistently into one cell.
    xi = abs(int(math.floor((x + 0.000001) * 0.999999)))
    yi = abs(int(math.floor((y + 0.000001) * 0.999999)))
    zi = abs(int(math.floor((z + 0.000001) * 0.999999)))
    return 1.0 if ((xi % 2 == yi % 2) == (zi % 2 == 1)) else 0.0


@device
def checker_node(regs, b, c):
    scale = regs[b + _CK_SCALE]
    v = b + _CK_VECTOR
    f = checker(regs[v] * scale, regs[v + 1] * scale, regs[v + 2] * scale)
    col = b + (_CK_COLOR1 if f == 1.0 else _CK_COLOR2)
    regs[c], regs[c + 1], regs[c + 2] = regs[col], regs[col + 1], regs[col + 2]
    regs[c + 3] = f


@function
def white_noise_node(regs, b, c):
    """White Noise: hashes of the input's float32 bit patterns (white_noise.h)."""
    v = b + _WN_VECTOR
    x, y, z, w = regs[v], regs[v + 1], regs[v + 2], regs[b + _WN_W]
    dim = int(regs[b + _WN_DIM])
    if dim == 1:
        value, g, bl = hash_float(w), hash_float2(w, 1.0), hash_float2(w, 2.0)
    elif dim == 2:
        value, g, bl = hash_float2(x, y), hash_float3(x, y, 1.0), hash_float3(x, y, 2.0)
    elif dim == 3:
        value, g, bl = hash_float3(x, y, z), hash_float4(x, y, z, 1.0), hash_float4(x, y, z, 2.0)
    else:
        value, g, bl = hash_float4(x, y, z, w), hash_float4(z, x, w, y), hash_float4(w, z, y, x)
    regs[c + _WN_VALUE] = value
    o = c + _WN_COLOR
    regs[o], regs[o + 1], regs[o + 2] = value, g, bl


@device
def scaled_point(regs, v, w_reg, scale, dim):
    """(x, y, z, w): a texture's Vector (at regs[v:]) and W (regs[w_reg]) times Scale, as
    many coordinates as its dimensions; a 1D point is its W, in x."""
    x, y, z = regs[v] * scale, regs[v + 1] * scale, regs[v + 2] * scale
    w = regs[w_reg] * scale
    if dim == 1:
        return w, 0.0, 0.0, 0.0
    if dim == 2:
        return x, y, 0.0, 0.0
    if dim == 3:
        return x, y, z, 0.0
    return x, y, z, w


@function
def noise_node(regs, b, c):
    """Noise texture (noisetex.h): Fac and Color."""
    scale = regs[b + _NZ_SCALE]
    dim = int(regs[b + _NZ_DIM])
    x, y, z, w = scaled_point(regs, b + _NZ_VECTOR, b + _NZ_W, scale, dim)
    detail = min(max(regs[b + _NZ_DETAIL], 0.0), 15.0)
    roughness = max(regs[b + _NZ_ROUGHNESS], 0.0)
    fac, g, bl = noise_texture(dim, x, y, z, w, detail, roughness, regs[b + _NZ_LACUNARITY],
                               regs[b + _NZ_OFFSET], regs[b + _NZ_GAIN],
                               regs[b + _NZ_DISTORTION], int(regs[b + _NZ_TYPE]),
                               regs[b + _NZ_NORMALIZE])
    regs[c + _NZ_FAC] = fac
    o = c + _NZ_COLOR
    regs[o], regs[o + 1], regs[o + 2] = fac, g, bl


@function
def voronoi_node(regs, b, c):
    """Voronoi texture (voronoi.h): Distance, Color, Position, W, Radius."""
    scale = regs[b + _VO_SCALE]
    dim = int(regs[b + _VO_DIM])
    x, y, z, w = scaled_point(regs, b + _VO_VECTOR, b + _VO_W, scale, dim)
    d, r, g, bl, px, py, pz, pw, radius = voronoi_texture(
        dim, int(regs[b + _VO_FEATURE]), int(regs[b + _VO_METRIC]), x, y, z, w, scale,
        regs[b + _VO_DETAIL], regs[b + _VO_ROUGHNESS], regs[b + _VO_LACUNARITY],
        regs[b + _VO_SMOOTHNESS], regs[b + _VO_EXPONENT], regs[b + _VO_RANDOMNESS],
        regs[b + _VO_NORMALIZE])
    if dim == 1:                       # a 1D position is a W
        px, py, pz, pw = 0.0, 0.0, 0.0, px
    regs[c + _VO_DISTANCE] = d
    o = c + _VO_COLOR
    regs[o], regs[o + 1], regs[o + 2] = r, g, bl
    o = c + _VO_POSITION
    regs[o], regs[o + 1], regs[o + 2] = px, py, pz
    regs[c + _VO_W_OUT] = pw
    regs[c + _VO_RADIUS] = radius


@function
def gradient_node(regs, b, c):
    """Gradient texture (gradient.h), clamped to [0, 1]."""
    v = b + _GR_VECTOR
    x, y, z = regs[v], regs[v + 1], regs[v + 2]
    kind = int(regs[b + _GR_TYPE])
    if kind == 0:                      # linear
        f = x
    elif kind == 1:                    # quadratic
        f = max(x, 0.0) ** 2
    elif kind == 2:                    # easing
        r = saturate(x)
        f = 3.0 * r * r - 2.0 * r * r * r
    elif kind == 3:                    # diagonal
        f = (x + y) * 0.5
    elif kind == 4:                    # radial
        f = math.atan2(y, x) / _TWO_PI_F + 0.5
    else:                              # quadratic sphere, spherical
        r = max(0.999999 - math.sqrt(x * x + y * y + z * z), 0.0)
        f = r * r if kind == 5 else r
    f = saturate(f)
    regs[c], regs[c + 1], regs[c + 2] = f, f, f
    regs[c + 3] = f


@function
def wave_node(regs, b, c):
    """Wave texture (wave.h): bands or rings, sine/saw/triangle, noise distortion."""
    scale = regs[b + _WV_SCALE]
    v = b + _WV_VECTOR
    x = (regs[v] * scale + 0.000001) * 0.999999
    y = (regs[v + 1] * scale + 0.000001) * 0.999999
    z = (regs[v + 2] * scale + 0.000001) * 0.999999
    if int(regs[b + _WV_TYPE]) == 0:           # bands
        d = int(regs[b + _WV_BANDS])
        n = x * 20.0 if d == 0 else (y * 20.0 if d == 1 else (z * 20.0 if d == 2 else
                                                            (x + y + z) * 10.0))
    else:                                       # rings
        d = int(regs[b + _WV_RINGS])
        rx = 0.0 if d == 0 else x
        ry = 0.0 if d == 1 else y
        rz = 0.0 if d == 2 else z
        n = math.sqrt(rx * rx + ry * ry + rz * rz) * 20.0
    n += regs[b + _WV_PHASE]
    distortion = regs[b + _WV_DISTORTION]
    if distortion != 0.0:
        ds = regs[b + _WV_DSCALE]
        n += distortion * (noise_fbm(3, x * ds, y * ds, z * ds, 0.0, regs[b + _WV_DETAIL],
                                     regs[b + _WV_DROUGHNESS], 2.0, 1.0) * 2.0 - 1.0)
    profile = int(regs[b + _WV_PROFILE])
    if profile == 0:
        f = 0.5 + 0.5 * math.sin(n - _HALF_PI_F)
    elif profile == 1:
        n /= _TWO_PI_F
        f = n - math.floor(n)
    else:
        n /= _TWO_PI_F
        f = abs(n - math.floor(n + 0.5)) * 2.0
    regs[c], regs[c + 1], regs[c + 2] = f, f, f
    regs[c + 3] = f


@device
def _brick_noise(n):
    """Cycles' fast integer noise of the brick number, in [0, 1)."""
    n = (n + 1013) & 0x7FFFFFFF
    n = (n >> 13) ^ n
    nn = (n * ((n * n * 60493 + 19990303) & 0xFFFFFFFF) + 1376312589) & 0x7FFFFFFF
    return 0.5 * (nn / 1073741824.0)


@function
def brick_node(regs, b, c):
    """Brick texture (brick.h): tinted bricks in rows with offset and squash, mortar."""
    scale = regs[b + _BR_SCALE]
    v = b + _BR_VECTOR
    px, py = regs[v] * scale, regs[v + 1] * scale
    mortar_size = regs[b + _BR_MORTAR_SIZE]
    mortar_smooth = regs[b + _BR_MORTAR_SMOOTH]
    width = regs[b + _BR_WIDTH]
    height = regs[b + _BR_HEIGHT]
    offset_freq = int(regs[b + _BR_OFFSET_FREQ])
    squash_freq = int(regs[b + _BR_SQUASH_FREQ])
    row = int(math.floor(py / height))
    offset = 0.0
    if offset_freq != 0 and squash_freq != 0:
        if row % squash_freq == 0:
            width *= regs[b + _BR_SQUASH]
        if row % offset_freq == 0:
            offset = width * regs[b + _BR_OFFSET]
    brick = int(math.floor((px + offset) / width))
    x = (px + offset) - width * brick
    y = py - height * row
    tint = _brick_noise(((row << 16) + (brick & 0xFFFF)) & 0xFFFFFFFF) + regs[b + _BR_BIAS]
    tint = saturate(tint)
    dist = min(min(x, y), min(width - x, height - y))
    if dist >= mortar_size:
        f = 0.0
    elif mortar_smooth == 0.0:
        f = 1.0
    else:
        t = (1.0 - dist / mortar_size) / mortar_smooth
        f = 0.0 if t <= 0.0 else (1.0 if t >= 1.0 else t * t * (3.0 - 2.0 * t))
    for k in range(3):
        col = regs[b + _BR_COLOR1 + k]
        if f != 1.0:
            col = (1.0 - tint) * col + tint * regs[b + _BR_COLOR2 + k]
        regs[c + k] = col * (1.0 - f) + regs[b + _BR_MORTAR + k] * f
    regs[c + 3] = f


@function
def magic_node(regs, b, c):
    """Magic texture (magic.h): nested sines and cosines, ``turbulence_depth`` deep."""
    scale = regs[b + _MG_SCALE]
    dist = regs[b + _MG_DISTORTION]
    depth = int(regs[b + _MG_DEPTH])
    v = b + _MG_VECTOR
    px = fmod(regs[v], _TWO_PI_F)
    py = fmod(regs[v + 1], _TWO_PI_F)
    pz = fmod(regs[v + 2], _TWO_PI_F)
    x = math.sin((px + py + pz) * 5.0 * scale)
    y = math.cos((-px + py - pz) * 5.0 * scale)
    z = -math.cos((-px - py + pz) * 5.0 * scale)
    if depth > 0:
        x *= dist
        y *= dist
        z *= dist
        y = -math.cos(x - y + z) * dist
        if depth > 1:
            x = math.cos(x - y - z) * dist
        if depth > 2:
            z = math.sin(-x - y - z) * dist
        if depth > 3:
            x = -math.cos(-x + y - z) * dist
        if depth > 4:
            y = -math.sin(-x + y + z) * dist
        if depth > 5:
            y = -math.cos(-x + y + z) * dist
        if depth > 6:
            x = math.cos(x + y + z) * dist
        if depth > 7:
            z = math.sin(x + y - z) * dist
        if depth > 8:
            x = -math.cos(-x - y + z) * dist
        if depth > 9:
            y = -math.sin(x - y + z) * dist
    if dist != 0.0:
        x /= 2.0 * dist
        y /= 2.0 * dist
        z /= 2.0 * dist
    regs[c], regs[c + 1], regs[c + 2] = 0.5 - x, 0.5 - y, 0.5 - z
    regs[c + 3] = (1.5 - x - y - z) / 3.0
