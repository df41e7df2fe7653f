"""Embree itself: the BVH of the static triangles and its closest-hit and occlusion queries.

The library is the one the embreex wheel ships (``embreex.libs/libembree4-*.so.4``).  The
scene is built through that library's C API and traced from compiled code in packets of
``PACKET`` rays (``rtcIntersect8`` / ``rtcOccluded8``): Embree traverses a packet's rays
together with vector instructions, about a quarter faster per ray than embreex's loop of
single-ray calls on incoherent path-tracing rays (``benchmarks/bench_cornell.py`` prints
the share of worker time spent here).  Where the library cannot be found (a platform whose
embreex wheel puts it elsewhere), :func:`build` falls back to embreex's own Python API,
single rays at a time, with the same answers.

Subsurface walks trace one ray at a time from inside a compiled kernel: each object with a
subsurface material gets a scene of its own (:func:`build_local`), traced with
``rtcIntersect1`` through :func:`intersect_one`; without the library, ``kernels.subsurface``
keeps compiled hierarchies of its own.

Both use Embree's robust mode: its watertight triangle test.  The fast mode lets about one
ray in ten aimed exactly at a shared edge or vertex slip between the triangles
(tests/core/test_intersect.py), a light leak in closed rooms; robust costs ~25 % more per ray.

Rays are float32 with ``tnear`` 0 and no filter callbacks; ``kernels.intersect`` says how
the renderer lives with that.
"""
from __future__ import annotations

import ctypes
import importlib.util
import threading
from pathlib import Path

import llvmlite.ir as ir
import numpy as np
from numba.core import cgutils, types
from numba.extending import intrinsic

from ..jit import kernel

__all__ = ["NO_MASKS", "PACKET", "build", "build_local", "intersect_one", "library_path", "mask_array"]

PACKET = 8                 # rays per Embree call (RTCRayHit8); 16 measured no faster here
_ALIGN = 64                # bytes; Embree's packet structures are aligned to their width
_INVALID_ID = 0xFFFFFFFF   # RTC_INVALID_GEOMETRY_ID
# Embree 4 constants (rtcore_common.h, rtcore_buffer.h, rtcore_geometry.h, rtcore_scene.h).
_GEOMETRY_TYPE_TRIANGLE = 0
_BUFFER_TYPE_INDEX = 0
_BUFFER_TYPE_VERTEX = 1
_FORMAT_UINT3 = 0x5003
_FORMAT_FLOAT3 = 0x9003
_SCENE_FLAG_COMPACT = 1 << 1
_SCENE_FLAG_ROBUST = 1 << 2
_BUILD_QUALITY_MEDIUM = 1     # Embree's default; Cycles' without spatial splits
_BUILD_QUALITY_HIGH = 2       # with spatial splits

# Rows of a packet, each PACKET values wide (the struct-of-arrays RTCRayHit8): the ray, then
# the hit.  Embree writes instPrimID after instID when built with instance arrays, so the
# buffer has a spare row.
_ORG, _TNEAR, _DIR, _TIME, _TFAR, _MASK, _ID, _FLAGS = 0, 3, 4, 7, 8, 9, 10, 11
_PRIM_ID, _GEOM_ID = 17, 18
_ROWS = 24


class _Library:
    """The Embree library's functions this module calls, and its device."""

    def __init__(self, path: str):
        lib = ctypes.CDLL(path)
        vp = ctypes.c_void_p
        signatures = {
            "rtcNewDevice": (vp, [ctypes.c_char_p]),
            "rtcGetDeviceError": (ctypes.c_int, [vp]),
            "rtcNewScene": (vp, [vp]),
            "rtcSetSceneFlags": (None, [vp, ctypes.c_int]),
            "rtcSetSceneBuildQuality": (None, [vp, ctypes.c_int]),
            "rtcSetGeometryBuildQuality": (None, [vp, ctypes.c_int]),
            "rtcNewGeometry": (vp, [vp, ctypes.c_int]),
            "rtcSetSharedGeometryBuffer": (None, [vp, ctypes.c_int, ctypes.c_uint, ctypes.c_int, vp,
                                                  ctypes.c_size_t, ctypes.c_size_t, ctypes.c_size_t]),
            "rtcSetGeometryMask": (None, [vp, ctypes.c_uint]),
            "rtcCommitGeometry": (None, [vp]),
            "rtcAttachGeometry": (ctypes.c_uint, [vp, vp]),
            "rtcReleaseGeometry": (None, [vp]),
            "rtcCommitScene": (None, [vp]),
            "rtcReleaseScene": (None, [vp]),
        }
        for name, (restype, argtypes) in signatures.items():
            fn = getattr(lib, name)
            fn.restype, fn.argtypes = restype, argtypes
        self.lib = lib
        self.intersect = ctypes.cast(lib.rtcIntersect8, vp).value
        self.intersect_one = ctypes.cast(lib.rtcIntersect1, vp).value
        self.occluded = ctypes.cast(lib.rtcOccluded8, vp).value
        self.device = lib.rtcNewDevice(None)
        if not self.device:
            raise OSError(f"Embree could not create a device from {path}")


_lock = threading.Lock()
_library: _Library | None = None
_library_tried = False


def library_path() -> str | None:
    """Path of the Embree library inside the installed embreex wheel, or None."""
    spec = importlib.util.find_spec("embreex")
    if spec is None or not spec.submodule_search_locations:
        return None
    package = Path(next(iter(spec.submodule_search_locations)))
    for folder, pattern in ((package.parent / "embreex.libs", "libembree4*.so*"),
                            (package.parent / "embreex.libs", "embree4*.dll"),
                            (package / ".dylibs", "libembree4*.dylib")):
        found = sorted(folder.glob(pattern))
        if found:
            return str(found[0])
    return None


def _load() -> _Library | None:
    global _library, _library_tried
    with _lock:
        if not _library_tried:
            _library_tried = True
            path = library_path()
            if path is not None:
                try:
                    _library = _Library(path)
                except (OSError, AttributeError):
                    _library = None
        return _library


def build(vertices, triangles, packets: bool = True, masks=None, spatial_splits: bool = False,
          compact: bool = False, robust: bool = True):
    """A committed Embree scene of these triangles, with ``closest`` and ``occluded``.

    vertices : (V, 3) float32-convertible; triangles : (T, 3) int, T > 0.
    ``masks`` : (T,) uint32, optional: each triangle's visibility mask; a ray (whose own
    mask the queries take) passes through the triangles whose mask shares no bit with its.
    ``packets=False`` (or no library found) uses embreex's single-ray API, which has no
    masks: every triangle is then visible to every ray (``masked`` is False), and its own
    BVH settings.  The library's BVH is built as Cycles builds it (bvh/embree.cpp): robust,
    medium build quality, high with ``spatial_splits`` (Cycles' Use Spatial Splits), and
    Embree's compact layout with ``compact`` (Use Compact BVH: at 4 million triangles 136 MB
    instead of 246 MB, traversed more slowly).  ``robust=False`` builds Embree's fast,
    not watertight mode, which renders never use (``benchmarks/bench_embree_floor.py``
    measures what it would save; embreex's fallback is always robust).
    """
    library = _load() if packets else None
    if library is None:
        return _EmbreexScene(vertices, triangles)
    return _PacketScene(library, vertices, triangles, masks, spatial_splits, compact, robust)


def build_local(vertices, triangles):
    """A committed Embree scene of these triangles for single rays from compiled code
    (:func:`intersect_one`), or None where the library is not found.

    Returns ``(scene, handle, rtcIntersect1's address)``; the scene object owns the handle
    (keep it alive while compiled code uses the handle); primitive ids are rows of
    ``triangles``.  Only the vertices the triangles use are copied.
    """
    library = _load()
    if library is None:
        return None
    used, local = np.unique(np.asarray(triangles), return_inverse=True)
    scene = _PacketScene(library, np.asarray(vertices)[used], local.reshape(-1, 3))
    return scene, scene._scene, library.intersect_one


class _PacketScene:
    """The scene built through the library's C API: ``closest`` and ``occluded`` trace in
    packets from compiled code; compiled code may also trace its handle (``_scene``) one ray
    at a time (:func:`intersect_one`).

    With visibility masks the triangles are grouped by mask, one Embree geometry per group
    (Embree's masks are per geometry); a hit's primitive id is then mapped back from its
    geometry's to the caller's numbering."""

    def __init__(self, library: _Library, vertices, triangles, masks=None,
                 spatial_splits: bool = False, compact: bool = False, robust: bool = True):
        lib = library.lib
        self._library = library
        vertices = np.asarray(vertices, np.float32)
        # Embree reads vertex buffers 16 bytes at a time: one float3 of padding at the end.
        self._vertices = np.zeros((len(vertices) + 1, 3), np.float32)
        self._vertices[:-1] = vertices
        self.masked = masks is not None
        if self.masked:
            masks = np.asarray(masks, np.uint32)
            order = np.argsort(masks, kind="stable").astype(np.int32)
            groups, self._first = np.unique(masks[order], return_index=True)
            self._ids = order
            triangles = np.asarray(triangles)[order]
        else:
            groups = [np.uint32(_INVALID_ID)]
            self._first = np.zeros(1, np.int64)
            self._ids = np.zeros(0, np.int32)
        self._first = self._first.astype(np.int32)
        triangles = np.ascontiguousarray(triangles)
        if triangles.dtype == np.int32:     # the same bits (indices are not negative): no copy
            triangles = triangles.view(np.uint32)
        self._triangles = np.ascontiguousarray(triangles, np.uint32)
        self._scene = lib.rtcNewScene(library.device)
        lib.rtcSetSceneFlags(self._scene, (_SCENE_FLAG_ROBUST if robust else 0)
                             | (_SCENE_FLAG_COMPACT if compact else 0))
        quality = _BUILD_QUALITY_HIGH if spatial_splits else _BUILD_QUALITY_MEDIUM
        lib.rtcSetSceneBuildQuality(self._scene, quality)
        ends = [*self._first[1:], len(self._triangles)]
        for mask, first, end in zip(groups, self._first, ends):
            geometry = lib.rtcNewGeometry(library.device, _GEOMETRY_TYPE_TRIANGLE)
            lib.rtcSetGeometryBuildQuality(geometry, quality)
            lib.rtcSetSharedGeometryBuffer(geometry, _BUFFER_TYPE_VERTEX, 0, _FORMAT_FLOAT3,
                                           self._vertices.ctypes.data, 0, 12, len(vertices))
            lib.rtcSetSharedGeometryBuffer(geometry, _BUFFER_TYPE_INDEX, 0, _FORMAT_UINT3,
                                           self._triangles[first:].ctypes.data, 0, 12,
                                           int(end - first))
            lib.rtcSetGeometryMask(geometry, int(mask))
            lib.rtcCommitGeometry(geometry)
            lib.rtcAttachGeometry(self._scene, geometry)     # ids 0, 1, ... in this order
            lib.rtcReleaseGeometry(geometry)
        lib.rtcCommitScene(self._scene)
        error = lib.rtcGetDeviceError(library.device)
        if error:
            raise RuntimeError(f"Embree failed to build the scene (RTCError {error})")

    def __del__(self):
        scene, self._scene = getattr(self, "_scene", None), None
        if scene:
            self._library.lib.rtcReleaseScene(scene)

    def closest(self, origins, directions, tfar, mask=None):
        prim = np.empty(origins.shape[0], np.int32)
        self._trace(self._library.intersect, origins, directions, tfar, prim, False, mask)
        return prim

    def occluded(self, origins, directions, tfar, mask=None):
        blocked = np.empty(origins.shape[0], np.int32)
        self._trace(self._library.occluded, origins, directions, tfar, blocked, True, mask)
        return blocked != 0

    def _trace(self, fn, origins, directions, tfar, out, occlusion, mask):
        raw = np.empty(_ROWS * PACKET * 4 + PACKET * 4 + 2 * _ALIGN, np.uint8)
        start = -raw.ctypes.data % _ALIGN
        packet = raw[start:start + _ROWS * PACKET * 4].view(np.float32)
        start += _ROWS * PACKET * 4 + _ALIGN
        valid = raw[start:start + PACKET * 4].view(np.int32)
        trace_packets(fn, self._scene, np.ascontiguousarray(origins, np.float32),
                      np.ascontiguousarray(directions, np.float32),
                      np.ascontiguousarray(tfar, np.float32), out, occlusion,
                      packet, packet.view(np.uint32), valid, mask_array(mask), self._first,
                      self._ids)


def mask_array(mask):
    """A query's ray masks as the compiled tracers take them: none (every ray sees
    everything), one for all rays, or one per ray."""
    if mask is None:
        return NO_MASKS
    return np.atleast_1d(np.asarray(mask, np.uint32))


NO_MASKS = np.zeros(0, np.uint32)


class _EmbreexScene:
    """The scene through embreex's Python API: single rays in its C loop (no masks)."""

    masked = False

    def __init__(self, vertices, triangles):
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh
        self._scene = rtcore_scene.EmbreeScene(robust=True)
        TriangleMesh(self._scene, np.ascontiguousarray(vertices, np.float32),
                     np.ascontiguousarray(triangles, np.int32))
        # Commit now: embreex commits on the first query, which is not safe to do from two
        # threads at once.
        self._scene.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32))

    def closest(self, origins, directions, tfar, mask=None):
        return self._scene.run(origins, directions, dists=tfar, query="INTERSECT")

    def occluded(self, origins, directions, tfar, mask=None):
        return self._scene.run(origins, directions, dists=tfar, query="OCCLUDED") != -1


@intrinsic
def _call_packet(typingctx, fn, valid, scene, rays):
    """Call ``fn(valid, scene, rays, NULL)``: rtcIntersect8 / rtcOccluded8 at address fn.

    The address is an argument, not a constant, so the compiled code caches across processes.
    """
    sig = types.void(fn, valid, scene, rays)

    def codegen(context, builder, signature, args):
        pointer = ir.IntType(8).as_pointer()
        fnty = ir.FunctionType(ir.VoidType(), [pointer] * 4)
        callee = builder.inttoptr(args[0], fnty.as_pointer())
        builder.call(callee, [builder.inttoptr(a, pointer) for a in args[1:]]
                     + [ir.Constant(pointer, None)])
    return sig, codegen


@kernel
def trace_packets(fn, scene, o, d, tfar, out, occlusion, packet, packet_u, valid, mask, first,
                  ids):
    """Trace rays (o, d, (0, tfar)) PACKET at a time through ``fn``.

    Closest hits: out = primitive id or -1.  Occlusion: out = 1 where blocked, else 0.
    ``packet`` / ``packet_u`` are one _ROWS x PACKET buffer aligned to _ALIGN bytes, seen
    as float32 and uint32; ``valid`` PACKET int32 aligned likewise.  ``mask``: the rays'
    visibility masks (none: all bits; one: every ray's; else one per ray); ``first``: each
    geometry's first triangle in the order ``ids`` maps to the caller's ids (none: the
    caller's order).
    """
    w = PACKET
    n = o.shape[0]
    masks = mask.shape[0]
    for s in range(0, n, w):
        m = min(w, n - s)
        for k in range(w):
            i = s + k if k < m else s
            valid[k] = -1 if k < m else 0
            for c in range(3):
                packet[(_ORG + c) * w + k] = o[i, c]
                packet[(_DIR + c) * w + k] = d[i, c]
            packet[_TNEAR * w + k] = 0.0
            packet[_TIME * w + k] = 0.0
            packet[_TFAR * w + k] = tfar[i]
            if masks == 0:
                packet_u[_MASK * w + k] = _INVALID_ID
            else:
                packet_u[_MASK * w + k] = mask[i] if masks > 1 else mask[0]
            packet_u[_ID * w + k] = 0
            packet_u[_FLAGS * w + k] = 0
            packet_u[_PRIM_ID * w + k] = _INVALID_ID
            packet_u[_GEOM_ID * w + k] = _INVALID_ID
        _call_packet(fn, valid.ctypes.data, scene, packet.ctypes.data)
        if occlusion:
            # rtcOccluded sets tfar to -inf on the rays it finds blocked.
            for k in range(m):
                out[s + k] = 1 if packet[_TFAR * w + k] < 0.0 else 0
        else:
            for k in range(m):
                geom = packet_u[_GEOM_ID * w + k]
                if geom == _INVALID_ID:
                    out[s + k] = -1
                else:
                    q = first[geom] + np.int32(packet_u[_PRIM_ID * w + k])
                    out[s + k] = ids[q] if ids.shape[0] else q


_RAY_HIT_WORDS = 24     # RTCRayHit: 12 words of ray, 8 of hit, spare for instPrimID, padding


@intrinsic
def intersect_one(typingctx, fn, scene, ox, oy, oz, dx, dy, dz, tnear, tfar):
    """Closest hit of one ray (o, d) within [tnear, tfar] in a :func:`build_local` scene:
    ``fn(scene, &rayhit, NULL)`` (fn: rtcIntersect1) with the RTCRayHit on the stack.
    Returns (the hit's float32 distance as float64, its primitive id or -1)."""
    sig = types.Tuple((types.float64, types.int64))(fn, scene, ox, oy, oz, dx, dy, dz, tnear, tfar)

    def codegen(context, builder, signature, args):
        i32, f32, i8p = ir.IntType(32), ir.FloatType(), ir.IntType(8).as_pointer()
        slot = cgutils.alloca_once(builder, ir.ArrayType(i32, _RAY_HIT_WORDS))
        slot.align = 16
        words = builder.bitcast(slot, i32.as_pointer())
        floats = builder.bitcast(slot, f32.as_pointer())

        def at(pointer, k):
            return builder.gep(pointer, [ir.Constant(i32, k)])
        for k, value in ((_ORG, args[2]), (_ORG + 1, args[3]), (_ORG + 2, args[4]),
                         (_DIR, args[5]), (_DIR + 1, args[6]), (_DIR + 2, args[7]),
                         (_TNEAR, args[8]), (_TFAR, args[9])):
            builder.store(builder.fptrunc(value, f32), at(floats, k))
        builder.store(ir.Constant(f32, 0.0), at(floats, _TIME))
        for k, value in ((_MASK, _INVALID_ID), (_ID, 0), (_FLAGS, 0),
                         (_PRIM_ID, _INVALID_ID), (_GEOM_ID, _INVALID_ID)):
            builder.store(ir.Constant(i32, value), at(words, k))
        fnty = ir.FunctionType(ir.VoidType(), [i8p] * 3)
        callee = builder.inttoptr(args[0], fnty.as_pointer())
        builder.call(callee, [builder.inttoptr(args[1], i8p), builder.bitcast(slot, i8p),
                              ir.Constant(i8p, None)])
        geom = builder.load(at(words, _GEOM_ID))
        hit = builder.icmp_unsigned("!=", geom, ir.Constant(i32, _INVALID_ID))
        prim = builder.select(hit, builder.zext(builder.load(at(words, _PRIM_ID)), ir.IntType(64)),
                              ir.Constant(ir.IntType(64), -1))
        t = builder.fpext(builder.load(at(floats, _TFAR)), ir.DoubleType())
        return context.make_tuple(builder, signature.return_type, [t, prim])
    return sig, codegen

