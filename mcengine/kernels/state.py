"""The wavefront's data: path state, shadow queue, packed scene, settings and counters.

Every stage kernel reads and writes these structure-of-arrays records; each
field is one array indexed by path (or shadow ray, or scene element).  They
are allocated once per worker (``alloc_path_state``, ``alloc_shadow_queue``)
and reused, so memory is bounded by the batch size.  The integer codes below
(path flags, settings, counters) are shared by every integrator.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

from ..jit import device
from .closures.layout import CL_STRIDE, MAX_CLOSURES

# -- path state ----------------------------------------------------------------------
PathState = namedtuple("PathState", [
    "key",           # (B,) uint64   RNG key of the path sample
    "pixel",         # (B,) int32    film pixel (index into the film region)
    "root",          # (B,) int32    camera sample a ray belongs to (classic integrators)
    "ray_o",         # (B, 3) f64    ray origin
    "ray_d",         # (B, 3) f64    unit ray direction
    "ray_tmax",      # (B,) f64      ray length (far clip for camera rays)
    "beta",          # (B, 3) f64    path throughput
    "radiance",      # (B, 3) f64    radiance collected so far
    "transparency",  # (B,) f64      1 if the camera ray escaped to a transparent film
    "bounce",        # (B,) int32    scattering events so far (= index of the next vertex)
    "diffuse",       # (B,) int32    diffuse scattering events so far
    "glossy",        # (B,) int32
    "transmission",  # (B,) int32
    "transparent",   # (B,) int32    transparent passes (lamps count as one)
    "flags",         # (B,) int32    PF_* bits
    "mis_pdf",       # (B,) f64      pdf of the BSDF sample that made the current ray
    "min_pdf",       # (B,) f64      smallest BSDF pdf on the path so far (Filter Glossy)
    "mis_p",         # (B, 6) f64    the receiver that ray left: vertex, normal (0: none; light
                     #               picking there, for MIS: light_sampling.receiver)
    "mis_total",     # (B,) f64      the lights' summed importance at mis_p (PMF_LOCAL picking)
    "self_prim",     # (B,) int32    triangle the ray starts on (-1: none)
    "mis_set",       # (B,) int32    light set the object at mis_p receives (light linking:
                     #               Cycles' mis_ray_object; 0 for camera rays)
    "dp",            # (B,) f64      ray differential: footprint at mis_p (Cycles' compact ray dP)
    "dd",            # (B,) f64      its growth per unit length (the camera's compact dD)
    "time",          # (B,) f64      time of the path's camera sample, in [0, 1] over the shutter
    "alive",         # (B,) uint8    still tracing after this bounce
    "o32",           # (B, 3) f32    Embree input: origins
    "d32",           # (B, 3) f32    Embree input: directions
    "t32",           # (B,) f32      Embree input: tfar
    "live",          # (B,) int32    compaction's scratch: the old slots of the live paths
])

# What a shadow ray's light is for (ShadowQueue.kind): Combined only, Combined and the
# direct or the indirect light passes (with the pass weights in PassBuffers.sw), or the
# Ambient Occlusion pass only.
SK_NONE = 0
SK_DIRECT = 1
SK_INDIRECT = 2
SK_AO = 3

ShadowQueue = namedtuple("ShadowQueue", [
    "o32", "d32", "t32",   # Embree input
    "contrib",             # (B, 3) f64  radiance to add if unoccluded
    "path",                # (B,) int32  path the contribution belongs to
    "time",                # (B,) f64    the path's time over the shutter
    "target",              # (B, 3) f64  end point of the ray (transparent shadows re-aim at it)
    "transparent",         # (B,) int32  transparent bounces the path may still make
    "alive",               # (B,) uint8  still being traced (transparent shadows)
    "depths",              # (B, 5) int32  the path's bounces when the ray left (all, diffuse,
                           #               glossy, transmission, transparent; transparent
                           #               surfaces passed add to the last: Light Path node)
    "travelled",           # (B,) f64    distance from the shading point to the current origin
    "kind",                # (B,) int8   what the ray's light is for (SK_*)
])

Scratch = namedtuple("Scratch", [
    "cl",                  # (MAX_CLOSURES, CL_STRIDE) f64  the closures of the point being shaded
    "cl_light",            # the same, for evaluating the emission of a light sample
    "regs",                # (R,) f64  the shader evaluator's registers (a copy of SceneData.svm_regs)
    "light",               # (4,) f64  the last light sample: direction, excluded labels
    "importance",          # (NL,) f64  each lamp's importance at the point being shaded
])

SceneData = namedtuple("SceneData", [
    "verts",         # (V, 3) f64
    "tris",          # (T, 3) int32   (the shading normals are in ``tex``: TextureData)
    "mat_index",     # (T,) int32
    "svm_ops",       # (P, 4) int32  every material's shader program (kernels.svm)
    "svm_regs",      # (R,) f64      their registers with the constants in place (each worker
                     #               shades with its own copy, Scratch.regs)
    "mat_prog",      # (M + 1, 2) int32  [start, end) of material m's program in svm_ops;
                     #               row M is the world's (its shader, for rays that escape)
    "mat_emission",  # (M, 3) f64    emitted radiance of material m as a light (no layering)
    "mat_flags",     # (M,) int32    MF_* bits
    "lamps",         # (NL, LIGHT_STRIDE) f64
    "ies",           # (K,) f64      the lamps' IES profiles (lights.pack_profiles, kernels/ies.py)
    "light_cdf",     # (NL + NE + 1,) f64  NEE light distribution
    "emit_tri",      # (NE,) int32  emissive triangle ids
    "emit_pmf",      # (NE,) f64    their NEE probabilities
    "emit_cdf",      # (NE + 1,) f64  distribution over emissive triangles alone
    "emit_group",    # (1, 5) f64   emissive triangles as one light: centre, radius^2, scale
                     #              (a row of light_tree.sphere_importance)
    "emit_tree",     # kernels.light_tree.EmitterTree: picks one of them at a point
    "tri_light",     # (T,) int32   index into emit_tri, or -1 (empty without emit_tri)
    "world",         # (3,) f64     background radiance (when constant: CFG_WORLD_SHADER 0)
    "camera",        # (CAMERA_PARAMS,) f64
    "filter_table",  # (FILTER_TABLE_SIZE,) f64
    "tex",           # svm.TextureData: attributes, objects, images for the shader nodes
    "motion",        # kernels.motion.MotionData: the objects that move during the shutter
    "bg_marginal",   # (H + 1,) f64   the world's importance map: CDF over its rows
    "bg_conditional",  # (H, W + 1) f64  CDF over the columns of each row (kernels.background)
    "bg_sun",        # (5,) f64     a sun cone sampled beside the map: direction, cos of its
                     #              half angle, the share of world samples it gets (0: none)
    "local",         # kernels.subsurface.LocalBVH: the own triangles of each object that a
                     #              subsurface walk, a Bevel or an AO node traces, and the
                     #              scene's that AO nodes trace (slot O)
])

# Material flags (mat_flags).
MF_EMISSIVE = 1           # emits light: its triangles are lights for next-event estimation
MF_TRANSPARENT = 2        # has transparent closures and lets shadow rays through them
MF_BUMP_CORRECTION = 4    # Cycles' use_bump_map_correction
MF_EMISSION_VARIES = 8    # its emission depends on the point (textures): light samples run its shader
MF_CLOSURES_ONLY = 16     # its program is closure rows on constant inputs (svm.closures_only)
MF_BSSRDF_BUMP = 32       # a BSSRDF's Normal is linked: walks' exits run its shader (Cycles'
                          # SD_HAS_BSSRDF_BUMP; shaders.Program.bssrdf_bump)

# Path flags.
PF_CAMERA = 1            # no scattering yet: the ray is a camera ray
PF_MIS_SKIP = 2          # emission found by this ray gets MIS weight 1
PF_TERMINATE = 4         # a bounce limit was reached: the next hit only collects emission
PF_TRANSPARENT_BG = 8    # camera ray, also through transparent surfaces (holdout, transparent film)
PF_DIFFUSE = 16          # label of the BSDF sample that made the ray
PF_GLOSSY = 32
PF_TRANSMIT = 64
PF_REFLECT = 128
PF_TRANSPARENT = 256      # the path passed a transparent closure (Cycles' PATH_RAY_TRANSPARENT)
PF_SHADOW = 512           # shading for a shadow ray (transparent shadows; Light Path's Is Shadow Ray)
# Render passes (kernels.passes).
PF_SURFACE_PASS = 1024    # scattered once: light goes to the diffuse/glossy/transmission passes
PF_PASS_DONE = 2048       # normal and UV written for this sample (Cycles' PATH_RAY_SINGLE_PASS_DONE)
PF_DENOISE = 4096         # denoising albedo and normal not written yet
PF_FIRST_SAMPLE = 8192    # the pixel's first sample (depth, position, indices come from it)
PF_SINGULAR = 16384       # the ray was made by a singular (perfectly sharp) lobe
PF_EMISSION = 32768       # shading a light sample's emission (Cycles' PATH_RAY_EMISSION)
PF_CAUSTIC_EYE = 65536    # the camera ray's first surface scattered it through a lobe that is not
                          # singular: its caustic paths may be light tracing's (``light_tracing``)
PF_SUBSURFACE = 131072    # the ray ends where a subsurface walk left the object: ``self_prim`` is
                          # that triangle, shaded there as Lambert (Cycles' PATH_RAY_SUBSURFACE)
PF_DIFFUSE_ANCESTOR = 262144  # a diffuse bounce happened on the path (Cycles'
                              # PATH_RAY_DIFFUSE_ANCESTOR: Christensen-Burley turns Lambert)

# Ray visibility (Object Properties > Visibility > Ray Visibility; Cycles' PATH_RAY_* bits
# of an object's visibility): an object is hit only by rays whose mask shares a bit with
# its own (``intersect.ray_visibility``; Embree's geometry and ray masks).
VIS_CAMERA = 1
VIS_DIFFUSE = 2
VIS_GLOSSY = 4
VIS_TRANSMISSION = 8
VIS_SHADOW = 16
VIS_SCATTER = 32          # volume scatter rays (no volumes yet: kept, never traced)
VIS_ALL = 63

# Integer settings (cfg array).
CFG_MAX_BOUNCE = 0
CFG_MAX_DIFFUSE = 1
CFG_MAX_GLOSSY = 2
CFG_MAX_TRANSMISSION = 3
CFG_MAX_TRANSPARENT = 4
CFG_MIN_LIGHT_BOUNCES = 5
CFG_SEED = 6
CFG_FILM_TRANSPARENT = 7
CFG_WORLD_VISIBILITY = 8  # the world's ray visibility (lights.LF_VIS_* bits)
CFG_LAMPS_HIT = 9         # some lamp can be hit by rays (Cycles' use_light_mis)
CFG_REGION_X = 10         # film region origin and width in the full frame
CFG_REGION_Y = 11
CFG_REGION_W = 12
CFG_FULL_W = 13
CFG_LIGHTS = 14           # next-event estimation has something to sample
CFG_WORLD = 15            # the world is not black
CFG_LOCAL_LIGHTS = 16     # pick lights by their estimated irradiance at each point
CFG_CAUSTICS_REFLECTIVE = 17   # glossy reflection after a diffuse bounce (Cycles' switches)
CFG_CAUSTICS_REFRACTIVE = 18
CFG_TRANSPARENT_SHADOWS = 19   # some material lets shadow rays through: trace them hit by hit
CFG_MIS = 20              # emission found by rays gets MIS weights (some light is sampled and hit)
CFG_CAUSTICS = 21         # caustic paths: Filter Glossy and the caustics switches apply
CFG_SAMPLER = 22          # sampling.SAMPLER_*: which numbers paths draw
CFG_SOBOL_MASK = 23       # mask of the Sobol sampler's shuffled sample index (sobol.index_mask)
CFG_WORLD_SHADER = 24     # the background varies (textures, ray types): run the world's shader
CFG_LIGHT_TRACING = 25    # light tracing renders the caustics of the LF_LIGHT_TRACED lamps
CFG_SUBSURFACE = 26       # BSSRDF closures walk inside their objects (else they are Lambert)
CFG_LIGHT_LINKING = 27    # some light lights only some objects (light linking's light sets)
CFG_SIZE = 28
# Float settings (fcfg array).
FCFG_CLAMP_DIRECT = 0     # limit on |r|+|g|+|b| of a direct contribution (inf: off)
FCFG_CLAMP_INDIRECT = 1
FCFG_EMIT_SCALE = 2       # 1 / (share of the emissive triangles in the scene-wide pmf)
FCFG_FILTER_GLOSSY = 3    # Cycles' blur_glossy; 0: off
FCFG_WORLD_PMF = 4        # probability that NEE picks the world when lights are picked by
                          # power (0: the world is not sampled)
FCFG_WORLD_IMPORTANCE = 5  # the world's importance when lights are picked per point (0: idem)
FCFG_SIZE = 6

# Statistics counters (stats array, per worker).
ST_CAMERA_RAYS = 0
ST_BOUNCE_RAYS = 1
ST_SHADOW_RAYS = 2
ST_SELF_HITS = 3          # rays that re-hit their origin triangle and were re-traced
ST_NONFINITE = 4          # contributions dropped because they were NaN or infinite
ST_SIZE = 5


def alloc_path_state(n: int) -> PathState:
    """Buffers for n paths, allocated once per worker and reused."""
    return PathState(
        key=np.zeros(n, np.uint64), pixel=np.zeros(n, np.int32), root=np.zeros(n, np.int32),
        ray_o=np.zeros((n, 3)), ray_d=np.zeros((n, 3)), ray_tmax=np.zeros(n),
        beta=np.zeros((n, 3)), radiance=np.zeros((n, 3)), transparency=np.zeros(n),
        bounce=np.zeros(n, np.int32), diffuse=np.zeros(n, np.int32),
        glossy=np.zeros(n, np.int32), transmission=np.zeros(n, np.int32),
        transparent=np.zeros(n, np.int32), flags=np.zeros(n, np.int32),
        mis_pdf=np.zeros(n), min_pdf=np.zeros(n), mis_p=np.zeros((n, 6)), mis_total=np.zeros(n),
        self_prim=np.zeros(n, np.int32),
        mis_set=np.zeros(n, np.int32),
        dp=np.zeros(n), dd=np.zeros(n), time=np.zeros(n), alive=np.zeros(n, np.uint8),
        o32=np.zeros((n, 3), np.float32), d32=np.zeros((n, 3), np.float32),
        t32=np.zeros(n, np.float32), live=np.zeros(n, np.int32))


@device
def live_slots(st, n):
    """Write the slots of the live paths among the first n to ``st.live``, in order;
    returns (their count m, the first slot that a compaction changes: n if none)."""
    m = 0
    first = n
    for i in range(n):
        if st.alive[i]:
            st.live[m] = i
            if m != i and first == n:
                first = m
            m += 1
    return m, first


@device
def gather_rows(a, live, first, m):
    """a[j] = a[live[j]] for j in [first, m): one field's compaction (live[j] >= j, so
    the copy runs forward in place)."""
    for j in range(first, m):
        a[j] = a[live[j]]


@device
def gather_rows3(a, live, first, m):
    """``gather_rows`` of an (N, 3) field."""
    for j in range(first, m):
        i = live[j]
        a[j, 0] = a[i, 0]
        a[j, 1] = a[i, 1]
        a[j, 2] = a[i, 2]


@device
def compact_paths(st, n):
    """Move the live paths among the first n to the front, in order; returns (their count,
    the first slot that moved: n if none).  Field by field, each a short loop over
    ``st.live``: every field but ``root``, which only the classic integrators use and keep
    in their own order."""
    m, first = live_slots(st, n)
    if first >= m:
        return m, first
    live = st.live
    gather_rows(st.key, live, first, m)
    gather_rows(st.pixel, live, first, m)
    gather_rows3(st.ray_o, live, first, m)
    gather_rows3(st.ray_d, live, first, m)
    gather_rows(st.ray_tmax, live, first, m)
    gather_rows3(st.beta, live, first, m)
    gather_rows3(st.radiance, live, first, m)
    gather_rows(st.transparency, live, first, m)
    gather_rows(st.bounce, live, first, m)
    gather_rows(st.diffuse, live, first, m)
    gather_rows(st.glossy, live, first, m)
    gather_rows(st.transmission, live, first, m)
    gather_rows(st.transparent, live, first, m)
    gather_rows(st.flags, live, first, m)
    gather_rows(st.mis_pdf, live, first, m)
    gather_rows(st.min_pdf, live, first, m)
    for j in range(first, m):
        i = live[j]
        for c in range(6):
            st.mis_p[j, c] = st.mis_p[i, c]
    gather_rows(st.mis_total, live, first, m)
    gather_rows(st.self_prim, live, first, m)
    gather_rows(st.mis_set, live, first, m)
    gather_rows(st.dp, live, first, m)
    gather_rows(st.dd, live, first, m)
    gather_rows(st.time, live, first, m)
    gather_rows(st.alive, live, first, m)
    gather_rows3(st.o32, live, first, m)
    gather_rows3(st.d32, live, first, m)
    gather_rows(st.t32, live, first, m)
    return m, first


def alloc_shadow_queue(n: int) -> ShadowQueue:
    return ShadowQueue(o32=np.zeros((n, 3), np.float32), d32=np.zeros((n, 3), np.float32),
                       t32=np.zeros(n, np.float32), contrib=np.zeros((n, 3)),
                       path=np.zeros(n, np.int32), time=np.zeros(n), target=np.zeros((n, 3)),
                       transparent=np.zeros(n, np.int32), alive=np.zeros(n, np.uint8),
                       depths=np.zeros((n, 5), np.int32), travelled=np.zeros(n),
                       kind=np.zeros(n, np.int8))


def alloc_scratch(sc: SceneData) -> Scratch:
    """A worker's per-hit scratch space for scene ``sc`` (closures, shader registers, the
    last light sample and the lamps' importances)."""
    return Scratch(cl=np.zeros((MAX_CLOSURES, CL_STRIDE)), cl_light=np.zeros((MAX_CLOSURES, CL_STRIDE)),
                   regs=sc.svm_regs.copy(), light=np.zeros(4), importance=np.zeros(sc.lamps.shape[0]))

