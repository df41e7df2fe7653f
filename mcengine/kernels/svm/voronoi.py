"""Cycles' Voronoi texture (kernel/svm/voronoi.h): F1, F2, smooth F1, distance to edge and
n-sphere radius in 1-4 dimensions, four metrics, fractal octaves.

As in ``noise.py`` a point is (x, y, z, w) of which the first ``dim``
components count (1D: x, filled with the node's W).  Cells are scanned in
Cycles' order (w outermost, x innermost; ties keep the first cell found), and
feature points come from Cycles' hashes: lookup3 of the cell's float
coordinate in 1D, PCG of the integer cell in 2-4D.
"""
from __future__ import annotations

import math

from ...jit import device, function
from ..scalar import saturate
from .hash import hash_float, hash_float2, pcg2, pcg3, pcg4
from .math_nodes import FLT_MAX
from .nodes import CHEBYCHEV, EUCLIDEAN, MANHATTAN, MINKOWSKI
from .nodes import VORONOI_DISTANCE_TO_EDGE as DISTANCE_TO_EDGE
from .nodes import VORONOI_F1 as F1
from .nodes import VORONOI_F2 as F2
from .nodes import VORONOI_N_SPHERE_RADIUS as N_SPHERE_RADIUS
from .nodes import VORONOI_SMOOTH_F1 as SMOOTH_F1


@device
def _point(dim, cx, cy, cz, cw, i, j, k, u, rnd):
    """Feature point of cell (c + offset), relative to cell c."""
    if dim == 1:
        return i + hash_float(cx + i) * rnd, 0.0, 0.0, 0.0
    if dim == 2:
        hx, hy = pcg2(int(cx) + i, int(cy) + j)
        return i + hx * rnd, j + hy * rnd, 0.0, 0.0
    if dim == 3:
        hx, hy, hz = pcg3(int(cx) + i, int(cy) + j, int(cz) + k)
        return i + hx * rnd, j + hy * rnd, k + hz * rnd, 0.0
    hx, hy, hz, hw = pcg4(int(cx) + i, int(cy) + j, int(cz) + k, int(cw) + u)
    return i + hx * rnd, j + hy * rnd, k + hz * rnd, u + hw * rnd


@device
def _color(dim, cx, cy, cz, cw, i, j, k, u):
    """Colour of cell (c + offset)."""
    if dim == 1:
        key = cx + i
        return hash_float(key), hash_float2(key, 1.0), hash_float2(key, 2.0)
    if dim == 2:
        return pcg3(int(cx) + i, int(cy) + j, 0)
    if dim == 3:
        return pcg3(int(cx) + i, int(cy) + j, int(cz) + k)
    r, g, b, _ = pcg4(int(cx) + i, int(cy) + j, int(cz) + k, int(cw) + u)
    return r, g, b


@device
def _sum_pow(dim, dx, dy, dz, dw, e):
    s = abs(dx) ** e
    if dim >= 2:
        s += abs(dy) ** e
    if dim >= 3:
        s += abs(dz) ** e
    if dim >= 4:
        s += abs(dw) ** e
    return s


@device
def distance_bound(dim, metric, e, dx, dy, dz, dw):
    """A monotone stand-in for the distance (Cycles' voronoi_distance_bound)."""
    if dim == 1:
        return abs(dx)
    if metric == EUCLIDEAN:
        return dx * dx + dy * dy + dz * dz + dw * dw
    if metric == MANHATTAN:
        return abs(dx) + abs(dy) + abs(dz) + abs(dw)
    if metric == CHEBYCHEV:
        return max(max(abs(dx), abs(dy)), max(abs(dz), abs(dw)))
    if metric == MINKOWSKI:
        return _sum_pow(dim, dx, dy, dz, dw, e)
    return 0.0


@device
def distance(dim, metric, e, dx, dy, dz, dw):
    if dim == 1:
        return abs(dx)
    if metric == EUCLIDEAN:
        return math.sqrt(dx * dx + dy * dy + dz * dz + dw * dw)
    if metric == MINKOWSKI:
        return _sum_pow(dim, dx, dy, dz, dw, e) ** (1.0 / e)
    return distance_bound(dim, metric, e, dx, dy, dz, dw)


@device
def _ranges(dim, reach):
    return reach, reach if dim >= 2 else 0, reach if dim >= 3 else 0, reach if dim >= 4 else 0


@function
def voronoi_octave(feature, dim, metric, e, rnd, smooth, x, y, z, w):
    """One octave of F1, F2 or smooth F1: (distance, r, g, b, px, py, pz, pw)."""
    cx, cy, cz, cw = math.floor(x), math.floor(y), math.floor(z), math.floor(w)
    lx, ly, lz, lw = x - cx, y - cy, z - cz, w - cw
    if feature == SMOOTH_F1:
        rx, ry, rz, rw = _ranges(dim, 2)
        sd = 0.0
        sr = sg = sb = 0.0
        spx = spy = spz = spw = 0.0
        h = -1.0
        for u in range(-rw, rw + 1):
            for k in range(-rz, rz + 1):
                for j in range(-ry, ry + 1):
                    for i in range(-rx, rx + 1):
                        px, py, pz, pw = _point(dim, cx, cy, cz, cw, i, j, k, u, rnd)
                        d = distance(dim, metric, e, px - lx, py - ly, pz - lz, pw - lw)
                        if h == -1.0:
                            h = 1.0
                        else:
                            t = 0.5 + 0.5 * (sd - d) / smooth
                            h = 0.0 if t < 0.0 else (1.0 if t >= 1.0 else t * t * (3.0 - 2.0 * t))
                        corr = smooth * h * (1.0 - h)
                        sd = sd + (d - sd) * h - corr
                        corr /= 1.0 + 3.0 * smooth
                        r, g, b = _color(dim, cx, cy, cz, cw, i, j, k, u)
                        sr = sr + (r - sr) * h - corr
                        sg = sg + (g - sg) * h - corr
                        sb = sb + (b - sb) * h - corr
                        spx = spx + (px - spx) * h - corr
                        spy = spy + (py - spy) * h - corr
                        spz = spz + (pz - spz) * h - corr
                        spw = spw + (pw - spw) * h - corr
        return sd, sr, sg, sb, cx + spx, cy + spy, cz + spz, cw + spw
    rx, ry, rz, rw = _ranges(dim, 1)
    d1 = d2 = FLT_MAX
    o1 = (0, 0, 0, 0)
    o2 = (0, 0, 0, 0)
    p1 = (0.0, 0.0, 0.0, 0.0)
    p2 = (0.0, 0.0, 0.0, 0.0)
    for u in range(-rw, rw + 1):
        for k in range(-rz, rz + 1):
            for j in range(-ry, ry + 1):
                for i in range(-rx, rx + 1):
                    px, py, pz, pw = _point(dim, cx, cy, cz, cw, i, j, k, u, rnd)
                    if feature == F1:
                        d = distance_bound(dim, metric, e, px - lx, py - ly, pz - lz, pw - lw)
                    else:
                        d = distance(dim, metric, e, px - lx, py - ly, pz - lz, pw - lw)
                    if d < d1:
                        d2, o2, p2 = d1, o1, p1
                        d1, o1, p1 = d, (i, j, k, u), (px, py, pz, pw)
                    elif d < d2:
                        d2, o2, p2 = d, (i, j, k, u), (px, py, pz, pw)
    if feature == F1:
        d = distance(dim, metric, e, p1[0] - lx, p1[1] - ly, p1[2] - lz, p1[3] - lw)
        o, p = o1, p1
    else:
        d, o, p = d2, o2, p2
    r, g, b = _color(dim, cx, cy, cz, cw, o[0], o[1], o[2], o[3])
    return d, r, g, b, p[0] + cx, p[1] + cy, p[2] + cz, p[3] + cw


@function
def voronoi_edge_octave(dim, rnd, x, y, z, w):
    """Distance to the nearest cell edge (Euclidean, whatever the metric)."""
    cx, cy, cz, cw = math.floor(x), math.floor(y), math.floor(z), math.floor(w)
    lx, ly, lz, lw = x - cx, y - cy, z - cz, w - cw
    if dim == 1:
        mid = hash_float(cx) * rnd
        left = -1.0 + hash_float(cx - 1.0) * rnd
        right = 1.0 + hash_float(cx + 1.0) * rnd
        return min(abs((mid + left) / 2.0 - lx), abs((mid + right) / 2.0 - lx))
    rx, ry, rz, rw = _ranges(dim, 1)
    best = FLT_MAX
    vx = vy = vz = vw = 0.0
    for u in range(-rw, rw + 1):
        for k in range(-rz, rz + 1):
            for j in range(-ry, ry + 1):
                for i in range(-rx, rx + 1):
                    px, py, pz, pw = _point(dim, cx, cy, cz, cw, i, j, k, u, rnd)
                    px, py, pz, pw = px - lx, py - ly, pz - lz, pw - lw
                    d = px * px + py * py + pz * pz + pw * pw
                    if d < best:
                        best = d
                        vx, vy, vz, vw = px, py, pz, pw
    best = FLT_MAX
    for u in range(-rw, rw + 1):
        for k in range(-rz, rz + 1):
            for j in range(-ry, ry + 1):
                for i in range(-rx, rx + 1):
                    px, py, pz, pw = _point(dim, cx, cy, cz, cw, i, j, k, u, rnd)
                    px, py, pz, pw = px - lx, py - ly, pz - lz, pw - lw
                    ex, ey, ez, ew = px - vx, py - vy, pz - vz, pw - vw
                    n2 = ex * ex + ey * ey + ez * ez + ew * ew
                    if n2 > 0.0001:
                        n = math.sqrt(n2)
                        d = ((vx + px) * ex + (vy + py) * ey + (vz + pz) * ez
                             + (vw + pw) * ew) / (2.0 * n)
                        best = min(best, d)
    return best


@function
def voronoi_n_sphere_radius(dim, rnd, x, y, z, w):
    """Half the distance from the nearest feature point to its own nearest one."""
    cx, cy, cz, cw = math.floor(x), math.floor(y), math.floor(z), math.floor(w)
    lx, ly, lz, lw = x - cx, y - cy, z - cz, w - cw
    rx, ry, rz, rw = _ranges(dim, 1)
    best = FLT_MAX
    q = (0.0, 0.0, 0.0, 0.0)
    qo = (0, 0, 0, 0)
    for u in range(-rw, rw + 1):
        for k in range(-rz, rz + 1):
            for j in range(-ry, ry + 1):
                for i in range(-rx, rx + 1):
                    px, py, pz, pw = _point(dim, cx, cy, cz, cw, i, j, k, u, rnd)
                    dx, dy, dz, dw = px - lx, py - ly, pz - lz, pw - lw
                    d = dx * dx + dy * dy + dz * dz + dw * dw
                    if d < best:
                        best = d
                        q = (px, py, pz, pw)
                        qo = (i, j, k, u)
    best = FLT_MAX
    n = (0.0, 0.0, 0.0, 0.0)
    for u in range(-rw, rw + 1):
        for k in range(-rz, rz + 1):
            for j in range(-ry, ry + 1):
                for i in range(-rx, rx + 1):
                    if i == 0 and j == 0 and k == 0 and u == 0:
                        continue
                    oi, oj, ok, ol = i + qo[0], j + qo[1], k + qo[2], u + qo[3]
                    px, py, pz, pw = _point(dim, cx, cy, cz, cw, oi, oj, ok, ol, rnd)
                    dx, dy, dz, dw = q[0] - px, q[1] - py, q[2] - pz, q[3] - pw
                    d = dx * dx + dy * dy + dz * dz + dw * dw
                    if d < best:
                        best = d
                        n = (px, py, pz, pw)
    dx, dy, dz, dw = n[0] - q[0], n[1] - q[1], n[2] - q[2], n[3] - q[3]
    return math.sqrt(dx * dx + dy * dy + dz * dz + dw * dw) / 2.0


@device
def _lerp(a, b, t):
    return (1.0 - t) * a + t * b


@function
def voronoi_texture(dim, feature, metric, x, y, z, w, scale, detail, roughness, lacunarity,
                    smoothness, exponent, randomness, normalize):
    """The Voronoi node at the scaled point: (distance, r, g, b, px, py, pz, pw, radius)."""
    detail = min(max(detail, 0.0), 15.0)
    roughness = saturate(roughness)
    rnd = saturate(randomness)
    smooth = min(max(smoothness / 2.0, 0.0), 0.5)
    if feature == N_SPHERE_RADIUS:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, voronoi_n_sphere_radius(dim, rnd, x, y, z, w)
    zero_input = detail == 0.0 or roughness == 0.0
    octaves = int(math.ceil(detail)) + 1
    rmd = detail - math.floor(detail)
    amp = 1.0
    fscale = 1.0
    if feature == DISTANCE_TO_EDGE:
        max_dist = 0.5 + 0.5 * rnd
        max_amp = max_dist
        dist = 8.0
        for i in range(octaves):
            d = voronoi_edge_octave(dim, rnd, x * fscale, y * fscale, z * fscale, w * fscale)
            if zero_input:
                dist = d
                break
            if i <= detail:
                max_amp = _lerp(max_amp, max_dist / fscale, amp)
                dist = _lerp(dist, min(dist, d / fscale), amp)
                fscale *= lacunarity
                amp *= roughness
            elif rmd != 0.0:
                lerp_amp = _lerp(max_amp, max_dist / fscale, amp)
                max_amp = _lerp(max_amp, lerp_amp, rmd)
                lerp_dist = _lerp(dist, min(dist, d / fscale), amp)
                dist = _lerp(dist, min(dist, lerp_dist), rmd)
        if normalize != 0.0:
            dist /= max_amp
        return dist, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    m = 0.5 + 0.5 * rnd
    max_dist = m if dim == 1 else distance(dim, metric, exponent, m, m, m if dim >= 3 else 0.0,
                                           m if dim >= 4 else 0.0)
    if feature == F2:
        max_dist *= 2.0
    if feature == SMOOTH_F1 and smooth == 0.0:
        feature = F1
    max_amp = 0.0
    dist = r = g = b = px = py = pz = pw = 0.0
    for i in range(octaves):
        od, orr, og, ob, opx, opy, opz, opw = voronoi_octave(
            feature, dim, metric, exponent, rnd, smooth, x * fscale, y * fscale, z * fscale,
            w * fscale)
        if zero_input:
            max_amp = 1.0
            dist, r, g, b, px, py, pz, pw = od, orr, og, ob, opx, opy, opz, opw
            break
        if i <= detail:
            max_amp += amp
            dist += od * amp
            r += orr * amp
            g += og * amp
            b += ob * amp
            px = _lerp(px, opx / fscale, amp)
            py = _lerp(py, opy / fscale, amp)
            pz = _lerp(pz, opz / fscale, amp)
            pw = _lerp(pw, opw / fscale, amp)
            fscale *= lacunarity
            amp *= roughness
        elif rmd != 0.0:
            max_amp = _lerp(max_amp, max_amp + amp, rmd)
            dist = _lerp(dist, dist + od * amp, rmd)
            r = _lerp(r, r + orr * amp, rmd)
            g = _lerp(g, g + og * amp, rmd)
            b = _lerp(b, b + ob * amp, rmd)
            px = _lerp(px, _lerp(px, opx / fscale, amp), rmd)
            py = _lerp(py, _lerp(py, opy / fscale, amp), rmd)
            pz = _lerp(pz, _lerp(pz, opz / fscale, amp), rmd)
            pw = _lerp(pw, _lerp(pw, opw / fscale, amp), rmd)
    if normalize != 0.0:
        dist /= max_amp * max_dist
        r /= max_amp
        g /= max_amp
        b /= max_amp
    if scale != 0.0:
        px, py, pz, pw = px / scale, py / scale, pz / scale, pw / scale
    else:
        px = py = pz = pw = 0.0
    return dist, r, g, b, px, py, pz, pw, 0.0
