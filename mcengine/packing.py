"""Packing: a scene description turned into the flat arrays the kernels read.

The scene model (``scene``) is made for people and files; the kernels want
contiguous float64/int32 tables with fixed columns (``kernels.state``,
``kernels.lights``, ``kernels.camera``), the shader programs (``shaders``), the light
picking distributions, and two small settings vectors (``cfg`` integers,
``fcfg`` floats) that also carry the effects plan of ``features``; and, for render
passes, the per-triangle data they read (``pack_passes``).  This module builds
all of them once per render.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from . import cryptomatte, integrators, samplers
from .background import map_size, world_map
from .features import TRACING_NODES, EffectsPlan, lamps_intersectable, materials_with_node, surface_kinds
from .features import detect as detect_plan
from .images import ImageTable
from .kernels.camera import pack_camera
from .kernels.light_sampling import light_distribution
from .kernels.light_tree import S_STRIDE, build_emitter_tree, no_tree, sphere_rows
from .kernels.lights import (
    L_FLAGS,
    L_PMF,
    L_TYPE,
    LF_VIS_CAMERA,
    LF_VIS_DIFFUSE,
    LF_VIS_GLOSSY,
    LF_VIS_TRANSMISSION,
    LIGHT_SETS_ALL,
    LIGHT_STRIDE,
    LT_SUN,
    light_set_columns,
    pack_lights,
    pack_profiles,
)
from .kernels.motion import pack_motion
from .kernels.passes import P_CRYPTO_ASSET, P_CRYPTO_OBJECT, P_OBJECT_ID, P_UV, P_VECTOR, PassData
from .kernels.sampling import SAMPLER_INDEPENDENT, filter_table
from .kernels.shading import emission_estimates
from .kernels.sobol import index_mask
from .kernels.state import (
    CFG_CAUSTICS_REFLECTIVE,
    CFG_CAUSTICS_REFRACTIVE,
    CFG_FILM_TRANSPARENT,
    CFG_FULL_W,
    CFG_LOCAL_LIGHTS,
    CFG_MAX_BOUNCE,
    CFG_MAX_DIFFUSE,
    CFG_MAX_GLOSSY,
    CFG_MAX_TRANSMISSION,
    CFG_MAX_TRANSPARENT,
    CFG_MIN_LIGHT_BOUNCES,
    CFG_REGION_W,
    CFG_REGION_X,
    CFG_REGION_Y,
    CFG_SAMPLER,
    CFG_SEED,
    CFG_SIZE,
    CFG_SOBOL_MASK,
    CFG_WORLD_SHADER,
    CFG_WORLD_VISIBILITY,
    FCFG_CLAMP_DIRECT,
    FCFG_CLAMP_INDIRECT,
    FCFG_EMIT_SCALE,
    FCFG_FILTER_GLOSSY,
    FCFG_SIZE,
    FCFG_WORLD_IMPORTANCE,
    FCFG_WORLD_PMF,
    MF_EMISSION_VARIES,
    MF_EMISSIVE,
    VIS_ALL,
    VIS_DIFFUSE,
    VIS_GLOSSY,
    VIS_SCATTER,
    VIS_SHADOW,
    VIS_TRANSMISSION,
    SceneData,
    alloc_scratch,
)
from .kernels.subsurface import build_local_bvh, no_local_bvh
from .kernels.svm import (
    OBJ_COLOR,
    OBJ_HOLDOUT,
    OBJ_INVERSE,
    OBJ_LIGHT_SETS,
    OBJ_MATRIX,
    OBJ_PASS_INDEX,
    OBJ_RANDOM,
    OBJ_RECEIVER_SET,
    OBJ_STRIDE,
    OBJ_TERMINATOR_GEOMETRY,
    OBJ_TERMINATOR_SHADING,
    OBJ_TEXSPACE_LOC,
    OBJ_TEXSPACE_SIZE,
    OBJ_VISIBILITY,
    OP_NODE,
    TextureData,
)
from .parallel import map_threads
from .passes import kernel_data, motion_corners, world_to_raster
from .scene import DEFAULT_TERMINATOR_OFFSETS, SceneDescription
from .shaders import AttributeLayout, ShaderTable
from .sky import sky_images, sun_guide
from .vectors import bounds, cross, lengths

LOCAL_PICK_MAX_LAMPS = 32     # beyond, lights are picked by power (the scan would cost more)


class PackedScene(NamedTuple):
    sc: SceneData          # the scene's tables
    cfg: np.ndarray        # (CFG_SIZE,) int64 settings
    fcfg: np.ndarray       # (FCFG_SIZE,) float64 settings
    plan: EffectsPlan      # what the scene calls for (``features``)


def sampler_code(it) -> int:
    """The kernels' sampler: the scene's for the path tracer; the classic integrators'
    ray trees always draw independent numbers."""
    if not integrators.get(it.name).uses_sampler:
        return SAMPLER_INDEPENDENT
    return samplers.get(it.sampler).kernel_code


def scene_images(scene: SceneDescription) -> ImageTable:
    """The scene's images and its sky textures' images, loaded as the kernels read them."""
    return ImageTable({**scene.images, **sky_images(scene)})


def pack_scene(scene: SceneDescription, force_effects=(), images: ImageTable | None = None
               ) -> PackedScene:
    """Pack a scene description into the kernels' arrays (see :class:`PackedScene`).

    ``force_effects`` names effects of the plan to switch on although the scene
    does not call for them ("all" for every one): for the benchmark and the tests.
    ``images`` is the scene's ``scene_images`` if the caller has loaded them already.
    """
    g = scene.geometry
    verts = g.vertices.astype(np.float64)
    tris = np.ascontiguousarray(g.triangles, np.int32)
    lo, hi = bounds(verts) if len(tris) else (np.zeros(3), np.zeros(3))
    lamp_pos = [np.asarray(li.matrix_world, float)[:3, 3] for li in scene.lights if li.type != "SUN"]
    if lamp_pos:
        lo = np.minimum(lo, np.min(lamp_pos, axis=0))
        hi = np.maximum(hi, np.max(lamp_pos, axis=0))
    scene_radius = max(0.5 * float(np.linalg.norm(hi - lo)), 1e-6)

    layout, attr = pack_attributes(g)
    if images is None:
        images = scene_images(scene)
    shaders = ShaderTable(scene.materials + [scene.world.material()], layout, images.slots)
    world = len(scene.materials)            # the world's program follows the materials'
    start, end = shaders.ranges[world]
    world_varies = bool(np.any(shaders.ops[start:end, 0] == OP_NODE))
    mat_index = np.ascontiguousarray(g.material_index, np.int32)
    film = scene.film
    camera = pack_camera(scene.camera, film, scene.motion_blur)
    none_f, none_i = np.zeros(0), np.zeros(0, np.int32)
    sc = SceneData(
        verts=verts, tris=tris,
        mat_index=mat_index, svm_ops=shaders.ops, svm_regs=shaders.registers,
        mat_prog=shaders.ranges, mat_emission=shaders.emission, mat_flags=shaders.flags,
        lamps=np.zeros((0, LIGHT_STRIDE)), ies=np.zeros(1), light_cdf=np.zeros(1), emit_tri=none_i, emit_pmf=none_f,
        emit_cdf=np.zeros(1), emit_group=np.zeros((1, S_STRIDE)), emit_tree=no_tree(),
        tri_light=none_i,
        world=shaders.emission[world].copy(), camera=camera,
        filter_table=filter_table(film.filter_type, film.filter_width),
        tex=TextureData(attr=attr, normals=np.ascontiguousarray(g.normals, np.float32),
                        normal_index=np.ascontiguousarray(g.normal_index, np.int32),
                        tri_object=np.ascontiguousarray(g.object_index, np.int32),
                        objects=pack_objects(g), camera=camera, images=images.info,
                        pix8=images.pix8, pixf=images.pixf),
        motion=pack_motion(g, scene.motion_blur.objects if scene.motion_blur else []),
        bg_marginal=np.zeros(2), bg_conditional=np.zeros((1, 2)), bg_sun=np.zeros(5),
        local=no_local_bvh())

    # The world as a light: its importance map, when its radiance varies.
    world_importance = world_power = 0.0
    size = map_size(scene.world, scene.images) if world_varies else None
    if size is not None:
        marginal, conditional, mean = world_map(sc, scene.world, images.slots,
                                                shaders.register_ranges[world], size)
        # A Sky Texture's sun: a cone sampled beside the map, and all of the world's samples
        # when the map saw nothing (a sun too small for its texel centres in a black sky).
        sun, sun_mean = sun_guide(scene.world)
        if mean <= 0.0 and sun[4] > 0.0:
            sun[4], mean = 1.0, sun_mean
        if mean > 0.0:
            sc = sc._replace(bg_marginal=marginal, bg_conditional=conditional, bg_sun=sun)
            world_importance = math.pi * mean                     # irradiance, as a sun's
            world_power = world_importance * math.pi * scene_radius ** 2

    # Lights: lamps, and the triangles of emissive materials.
    if len(tris):
        # The kernels compute the triangles' areas where they need them: here only the
        # emissive materials' triangles need theirs.
        emissive = (shaders.flags[mat_index] & MF_EMISSIVE) != 0
        candidates = np.flatnonzero(emissive)
        candidate_area = areas_and_normals(verts, tris[candidates])[0]
        emissive[candidates] = candidate_area > 0.0
        # An emissive object that no diffuse, glossy, transmission or volume scatter ray sees
        # is no light (Cycles' Object::usable_as_light); the lobes the others do not see are
        # excluded from its light samples (light_sampling.emitter_exclude).
        visibility = g.triangle_visibility()
        if visibility is not None:
            emissive &= (visibility & (VIS_DIFFUSE | VIS_GLOSSY | VIS_TRANSMISSION | VIS_SCATTER)) != 0
    else:
        emissive = np.zeros(0, bool)
        candidates, candidate_area = np.zeros(0, np.int64), np.zeros(0)
    emit_tri = np.flatnonzero(emissive).astype(np.int32)
    radiance = shaders.emission[mat_index[emit_tri]]
    varies = (shaders.flags[mat_index[emit_tri]] & MF_EMISSION_VARIES) != 0
    if np.any(varies):
        estimates = np.zeros((int(varies.sum()), 3))
        emission_estimates(sc, alloc_scratch(sc), emit_tri[varies], estimates)
        radiance[varies] = np.maximum(estimates, 0.0)
    emit_area = candidate_area[np.searchsorted(candidates, emit_tri)]   # emit_tri is among them
    emit_power = radiance.mean(axis=1) * math.pi * emit_area
    tri_light = none_i       # no emissive triangle: no table (4 bytes per triangle)
    if len(emit_tri):
        tri_light = np.full(len(tris), -1, np.int32)
        tri_light[emit_tri] = np.arange(len(emit_tri), dtype=np.int32)

    lamps, lamp_power = pack_lights(scene.lights, scene_radius)
    ies = pack_profiles(scene.lights, lamps)
    cdf, lamp_pmf, emit_pmf, world_pmf = light_distribution(lamp_power, emit_power, world_power)
    emit_cdf = np.concatenate([[0.0], np.cumsum(emit_pmf)])
    if emit_cdf[-1] > 0:
        emit_cdf /= emit_cdf[-1]
    # The emissive triangles as one light for per-point picking (their bounding sphere and
    # an irradiance scale), and the light tree that picks one of them at a point, unless
    # some of them move.
    emit_group = np.zeros((1, S_STRIDE))
    emit_tree = no_tree()
    if len(emit_tri):
        corners = verts[tris[emit_tri]]
        lo_emit, hi_emit = bounds(corners.reshape(-1, 3))
        emit_group = sphere_rows(lo_emit[None], hi_emit[None],
                                 np.array([emit_power.sum() / math.pi]))
        slots = sc.motion.tri_slot
        if not (len(slots) and np.any(slots[emit_tri] >= 0)):
            emit_tree = build_emitter_tree(corners, emit_power)
    if len(lamps):
        lamps[:, L_PMF] = lamp_pmf
        if not lamps_intersectable(scene.lights):
            # Cycles tests no lamp at all then: not even one visible to the camera.
            not_sun = lamps[:, L_TYPE] != LT_SUN
            lamps[not_sun, L_FLAGS] = (lamps[not_sun, L_FLAGS].astype(np.int64) & ~LF_VIS_CAMERA)
    plan = detect_plan(scene, len(emit_tri), lamp_power, shaders.flags,
                       (shaders.ops, shaders.ranges),
                       (world_varies or bool(shaders.emission[world].max() > 0.0), world_varies,
                        world_power > 0.0), len(images.slots))
    if force_effects:
        plan = plan.force(force_effects)

    if (plan.subsurface or plan.traced) and len(tris):
        # The objects a subsurface walk may run in (those with a subsurface material when
        # walks are on) and those a Bevel or Ambient Occlusion node traces get hierarchies of
        # their own; AO nodes' rays also meet the rest of the scene: every triangle shadow
        # rays see, in one more.
        programs = (shaders.ops, shaders.ranges)
        walked = [i for name in TRACING_NODES for i in materials_with_node(programs, name)]
        if plan.subsurface:
            walked += [i for i, mat in enumerate(scene.materials) if "subsurface" in surface_kinds(mat)]
        scene_ids = None
        if set(materials_with_node(programs, "AmbientOcclusion")) & set(g.materials_used()):
            visibility = scene.geometry.triangle_visibility()
            scene_ids = np.arange(len(tris), dtype=np.int32) if visibility is None else \
                np.flatnonzero(visibility & VIS_SHADOW).astype(np.int32)
        tri_object = sc.tex.tri_object
        sc = sc._replace(local=build_local_bvh(
            verts, tris, tri_object, sc.tex.objects.shape[0],
            np.unique(tri_object[np.isin(mat_index, walked)]), scene_ids=scene_ids))

    x0, y0, x1, y1 = film.window
    sc = sc._replace(lamps=lamps, ies=ies, light_cdf=cdf, emit_tri=emit_tri, emit_pmf=emit_pmf,
                     emit_cdf=emit_cdf, emit_group=emit_group, emit_tree=emit_tree,
                     tri_light=tri_light)

    it = scene.integrator
    cfg = np.zeros(CFG_SIZE, np.int64)
    cfg[CFG_MAX_BOUNCE] = it.max_bounces
    cfg[CFG_MAX_DIFFUSE] = it.diffuse_bounces
    cfg[CFG_MAX_GLOSSY] = it.glossy_bounces
    cfg[CFG_MAX_TRANSMISSION] = it.transmission_bounces
    cfg[CFG_MAX_TRANSPARENT] = it.transparent_max_bounces
    cfg[CFG_MIN_LIGHT_BOUNCES] = it.min_light_bounces
    cfg[CFG_SEED] = it.seed & 0x7FFFFFFFFFFFFFFF
    cfg[CFG_FILM_TRANSPARENT] = 1 if film.transparent else 0
    cfg[CFG_WORLD_VISIBILITY] = world_visibility(scene.world)
    cfg[CFG_REGION_X], cfg[CFG_REGION_Y], cfg[CFG_REGION_W] = x0, y0, x1 - x0
    cfg[CFG_FULL_W] = film.width
    cfg[CFG_WORLD_SHADER] = 1 if world_varies else 0
    cfg[CFG_CAUSTICS_REFLECTIVE] = 1 if it.caustics_reflective else 0
    cfg[CFG_CAUSTICS_REFRACTIVE] = 1 if it.caustics_refractive else 0
    plan.flags(cfg)
    cfg[CFG_SAMPLER] = sampler_code(it)
    cfg[CFG_SOBOL_MASK] = index_mask(it.samples)
    fcfg = np.zeros(FCFG_SIZE)
    fcfg[FCFG_FILTER_GLOSSY] = it.filter_glossy
    # Cycles compares |r|+|g|+|b| with 3x the clamp setting; 0 means off.
    fcfg[FCFG_CLAMP_DIRECT] = 3.0 * it.clamp_direct if it.clamp_direct > 0 else math.inf
    fcfg[FCFG_CLAMP_INDIRECT] = 3.0 * it.clamp_indirect if it.clamp_indirect > 0 else math.inf
    emit_share = float(emit_pmf.sum())
    fcfg[FCFG_EMIT_SCALE] = 1.0 / emit_share if emit_share > 0 else 0.0
    fcfg[FCFG_WORLD_PMF] = world_pmf
    fcfg[FCFG_WORLD_IMPORTANCE] = world_importance
    # Per-point light picking pays for itself when there is a choice to make (among the
    # lights, or among the emissive triangles by the tree) and the scan over lamps stays short.
    n_choices = (int(np.count_nonzero(lamp_power)) + (1 if len(emit_tri) else 0)
                 + (1 if world_power > 0.0 else 0))
    choice = 2 <= n_choices or len(emit_tree.rank) > 1
    cfg[CFG_LOCAL_LIGHTS] = 1 if choice and len(lamps) <= LOCAL_PICK_MAX_LAMPS else 0
    return PackedScene(sc, cfg, fcfg, plan)


def pack_attributes(g) -> tuple[AttributeLayout, np.ndarray]:
    """The per-corner attributes as one (T, 3, S) float32 array: the default UV map first
    (``svm.ATTR_DEFAULT_UV``), then every named attribute; and where each one lives.

    A named attribute equal to the default UV map everywhere (the UV map of meshes whose
    only or active render map it is; the export gives it as the same array) is read from
    the default's columns rather than packed again.  Without other named attributes the
    array is the geometry's own UVs, not a copy (24 bytes per triangle: 92 MiB at 4M
    triangles)."""
    layout = AttributeLayout()
    uvs = np.asarray(g.uvs, np.float32).reshape(-1, 3, 2)
    columns = [uvs]
    offset = 2
    for name, a in g.attributes.items():
        if a is g.uvs or (np.shape(a) == uvs.shape and np.array_equal(a, uvs)):
            layout.offsets[name] = (0, 2)
            continue
        a = np.asarray(a, np.float32)
        layout.offsets[name] = (offset, a.shape[2])
        columns.append(a)
        offset += a.shape[2]
    if len(columns) == 1:
        return layout, np.ascontiguousarray(uvs)
    return layout, np.ascontiguousarray(np.concatenate(columns, axis=2))


def world_visibility(world) -> int:
    """The world's Ray Visibility as ``LF_VIS_*`` bits (a lamp's, ``lights.pack_lights``)."""
    return ((LF_VIS_CAMERA if world.visible_camera else 0)
            | (LF_VIS_DIFFUSE if world.visible_diffuse else 0)
            | (LF_VIS_GLOSSY if world.visible_glossy else 0)
            | (LF_VIS_TRANSMISSION if world.visible_transmission else 0))


def pack_objects(g) -> np.ndarray:
    """Per-object data for the shader nodes (``svm.OBJ_*`` columns)."""
    matrix, texspace, info = g.object_arrays()
    o = matrix.shape[0]
    out = np.zeros((max(o, 1), OBJ_STRIDE))
    if o:
        out[:o, OBJ_MATRIX:OBJ_MATRIX + 12] = matrix[:, :3, :].reshape(o, 12)
        out[:o, OBJ_INVERSE:OBJ_INVERSE + 12] = np.linalg.inv(matrix)[:, :3, :].reshape(o, 12)
        out[:o, OBJ_TEXSPACE_LOC:OBJ_TEXSPACE_LOC + 3] = texspace[:, 0]
        out[:o, OBJ_TEXSPACE_SIZE:OBJ_TEXSPACE_SIZE + 3] = texspace[:, 1]
        out[:o, OBJ_RANDOM] = info[:, 0]
        out[:o, OBJ_PASS_INDEX] = info[:, 1]
        out[:o, OBJ_COLOR:OBJ_COLOR + 4] = info[:, 2:6]
    out[:o, OBJ_HOLDOUT] = [1.0 if info.holdout else 0.0 for info in g.object_pass_info()]
    out[:, OBJ_VISIBILITY] = VIS_ALL
    out[:o, OBJ_VISIBILITY] = g.visibility()
    out[:o, OBJ_RECEIVER_SET] = g.receiver_sets()
    out[:, OBJ_LIGHT_SETS:OBJ_LIGHT_SETS + 2] = light_set_columns([LIGHT_SETS_ALL])
    out[:o, OBJ_LIGHT_SETS:OBJ_LIGHT_SETS + 2] = light_set_columns(g.light_sets())
    terminator = g.terminator_offsets() if o else np.array([DEFAULT_TERMINATOR_OFFSETS])
    out[:, OBJ_TERMINATOR_GEOMETRY] = terminator[:, 0]
    # Cycles keeps the Shading Offset s as the frequency of its shift_cos_in (scene/object.cpp).
    out[:, OBJ_TERMINATOR_SHADING] = 1.0 / (1.0 - 0.5 * terminator[:, 1])
    return out


def areas_and_normals(verts, tris, block: int = 1 << 16):
    """Area and unit geometric normal of every triangle, (T,) and (T, 3) float64.

    Computed in blocks of triangles, on threads (``parallel.map_threads``): whole-array
    float64 temporaries (the corners alone are 72 bytes per triangle) would cost more in
    page faults than the arithmetic, and would set the peak memory of large scenes.
    """
    t = len(tris)
    tri_area = np.empty(t)
    tri_normal = np.empty((t, 3))

    def one_block(a):
        p = np.take(verts, tris[a:a + block], axis=0)     # verts[tris], 3x faster
        n = cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        length = lengths(n)
        tri_area[a:a + block] = 0.5 * length
        tri_normal[a:a + block] = n / np.where(length > 0, length, 1.0)[:, None]

    map_threads(one_block, range(0, t, block))
    return tri_area, tri_normal


def pack_passes(scene: SceneDescription, lay) -> PassData:
    """The render passes' kernel data (``kernels.passes.PassData``) for the film layout
    ``lay`` (``passes.layout``): per-triangle UVs, object pass indices and Cryptomatte
    ids, per-material pass indices and ids, only for the passes that read them."""
    g = scene.geometry
    t = g.num_triangles
    tri_uv = np.zeros((1, 3, 3), np.float32)
    objects = g.object_pass_info()
    if P_UV in lay and t:
        has_uv = np.array([o.has_uv for o in objects] or [False], np.float32)[g.object_index]
        tri_uv = np.ascontiguousarray(np.concatenate(
            [g.uvs, np.broadcast_to(has_uv[:, None, None], (t, 3, 1))], axis=2), np.float32)
    tri_object = np.zeros((1, 3), np.float32)
    if t and any(s in lay for s in (P_OBJECT_ID, P_CRYPTO_OBJECT, P_CRYPTO_ASSET)):
        pass_index = g.object_arrays()[2][:, 1]      # Object Info's pass index
        table = np.array([[index, cryptomatte.name_id(o.name), cryptomatte.name_id(o.asset)]
                          for index, o in zip(pass_index, objects)] or [[0.0, 0.0, 0.0]],
                         np.float32)
        tri_object = np.ascontiguousarray(table[g.object_index])
    mat_info = np.array([[m.pass_index, cryptomatte.name_id(m.name)] for m in scene.materials],
                        np.float32).reshape(-1, 2)
    cam = scene.camera
    tri_motion = rasters = None
    if P_VECTOR in lay:
        motion = scene.motion_vectors
        tri_motion = motion_corners(g, motion) if t else None
        film = scene.film
        frame = (film.width, film.height, (film.pixel_aspect_x, film.pixel_aspect_y))
        now = np.asarray(cam.matrix_world, float)
        moved = motion.camera if motion is not None and motion.camera is not None else (now, now)
        scale = motion.view_scale if motion is not None else (1.0, 1.0)
        rasters = [world_to_raster(now, cam, *frame)] + [
            world_to_raster(np.asarray(m, float), cam, *frame, view_scale=k)
            for m, k in zip(moved, scale)]
    return kernel_data(lay, scene.passes, np.asarray(cam.matrix_world, float), cam.type == "ORTHO",
                       tri_uv, tri_object, mat_info, tri_motion, rasters)
