"""Ambient Occlusion (kernel/svm/ao.h): the fraction of the node's cosine-distributed rays
from the point, about its Normal (the shading normal when unlinked; the opposite one with
Inside), that nothing stops within the Distance; the Color output is that fraction times the
Color input.

The rays meet every triangle that shadow rays see (Cycles' opaque shadow rays: a transparent
surface occludes too), or with Only Local the object's own; they leave the point itself,
ignoring its own triangle, as Cycles' do.  Both kinds go through the hierarchies of
``subsurface.LocalBVH``: the object's own, or the one over the whole scene that it holds for
this node (``LocalBVH`` slot ``objects``, every triangle visible to shadow rays, as they are at
the frame: moving objects occlude as they are at the frame, warned).  A Distance of 0 that
nothing is linked to is the world's AO distance (World > Light Settings, Cycles'
ao_bounces_distance), which the export writes into ``prop:global_distance``.

As Bevel (``svm.bevel``), the node traces only for a path's own shading (``ShadingData.min_pdf``
> 0): for shadow rays, light samples, displacement and the world its AO is 1, as in Cycles.
Unlike Bevel it traces after any bounce.  A shading point's rays are stratified together
(``sampling.branched_2d``).
"""
from __future__ import annotations

import math

import numpy as np

from ...jit import function
from ..sampling import branched_2d, disk_concentric, make_orthonormals
from ..subsurface import local_closest
from .nodes import OFFSETS

_OFF = OFFSETS["AmbientOcclusion"]
_COLOR = _OFF["Color"]
_DISTANCE = _OFF["Distance"]
_NORMAL = _OFF["Normal"]
_SAMPLES = _OFF["prop:samples"]
_INSIDE = _OFF["prop:inside"]
_ONLY_LOCAL = _OFF["prop:only_local"]
_GLOBAL = _OFF["prop:global_distance"]
_K_AO = np.uint64(0x8CB92BA72F3D8DD7)     # the AO rays' numbers apart from Bevel's


@function
def ao_node(regs, b, c, sd, tex, verts, tris, local):
    """Inputs at regs[b:], outputs Color to regs[c:c + 3] and AO to regs[c + 3]."""
    ao = 1.0
    if sd.min_pdf > 0.0:
        distance = regs[b + _DISTANCE]
        if regs[b + _GLOBAL] >= 0.0:
            distance = regs[b + _GLOBAL]
        nx, ny, nz = regs[b + _NORMAL], regs[b + _NORMAL + 1], regs[b + _NORMAL + 2]
        if nx == 0.0 and ny == 0.0 and nz == 0.0:
            nx, ny, nz = sd.nx, sd.ny, sd.nz
        else:
            length = math.sqrt(nx * nx + ny * ny + nz * nz)
            nx, ny, nz = nx / length, ny / length, nz / length
        if regs[b + _INSIDE] != 0.0:
            nx, ny, nz = -nx, -ny, -nz
        slot = sd.obj if regs[b + _ONLY_LOCAL] != 0.0 else tex.objects.shape[0]
        ao = occlusion(distance, int(regs[b + _SAMPLES]), slot, nx, ny, nz, sd, verts, tris, local)
    regs[c] = ao * regs[b + _COLOR]
    regs[c + 1] = ao * regs[b + _COLOR + 1]
    regs[c + 2] = ao * regs[b + _COLOR + 2]
    regs[c + 3] = ao


@function
def occlusion(distance, samples, slot, nx, ny, nz, sd, verts, tris, local):
    """Cycles' svm_ao: the fraction of ``samples`` cosine-distributed rays about n that meet
    nothing of hierarchy ``slot`` of ``local`` within ``distance`` (1 where there is nothing
    to trace)."""
    if not distance > 0.0 or samples < 1 or sd.obj < 0 or sd.prim < 0 or slot >= local.root.shape[0]:
        return 1.0
    tx, ty, tz, bx, by, bz = make_orthonormals(nx, ny, nz)
    key = sd.rng ^ _K_AO
    free = 0
    for s in range(samples):
        u1, u2 = branched_2d(key, s)
        x, y = disk_concentric(u1, u2)
        z = math.sqrt(max(1.0 - x * x - y * y, 0.0))
        dx, dy, dz = x * tx + y * bx + z * nx, x * ty + y * by + z * ny, x * tz + y * bz + z * nz
        _, hit = local_closest(local, verts, tris, slot, sd.px, sd.py, sd.pz, dx, dy, dz,
                               distance, sd.prim)
        if hit < 0:
            free += 1
    return free / samples
