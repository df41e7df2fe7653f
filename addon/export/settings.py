"""Render settings shared with Cycles -> :class:`mcengine.scene.Integrator`.

Samples, bounces, clamps, seed and time limit are read from ``scene.cycles``
(the Cycles add-on's settings) so that one .blend renders with the same
settings in both engines.  Without the Cycles add-on, the mcengine defaults
are used and one warning says so.
"""
from __future__ import annotations

import numpy as np

from mcengine import integrators, samplers
from mcengine.scene import Integrator

from ..properties import SAMPLER_AS_CYCLES

__all__ = ["unit_scale", "cycles_settings", "export_integrator", "export_sampler", "sampler_for",
           "hash_uint2"]

_MASK32 = 0xFFFFFFFF
# Cycles hashes (frame_subframe * INT_MAX) as an int when the subframe is non-zero.
_INT_MAX_F = np.float32(2147483647.0)
# lookup3's final(a, b, c): each step is "dst ^= src; dst -= rot(src, k)".
_LOOKUP3_FINAL = (("c", "b", 14), ("a", "c", 11), ("b", "a", 25), ("c", "b", 16),
                  ("a", "c", 4), ("b", "a", 14), ("c", "b", 24))


def unit_scale(scene) -> float:
    """Metres per Blender unit.

    Blender ignores ``scale_length`` when the unit system is 'NONE'
    (``BKE_scene_unit_scale``), and so do we.
    """
    units = scene.unit_settings
    return 1.0 if units.system == "NONE" else float(units.scale_length)


def cycles_settings(ctx, scene):
    """``scene.cycles``, or None (plus one warning) if the Cycles add-on is disabled."""
    cycles = getattr(scene, "cycles", None)
    if cycles is None:
        ctx.warn("the Cycles add-on is disabled: MC Engine reads samples, bounces, clamping, "
                 "seed, time limit and pixel filter from Cycles' settings; using MC Engine "
                 "defaults instead", "Cycles settings")
    return cycles


def hash_uint2(kx: int, ky: int) -> int:
    """Cycles' ``hash_uint2`` (Bob Jenkins' lookup3 ``final`` mix) on 32-bit unsigned ints."""
    def rot(x, k):
        return ((x << k) | (x >> (32 - k))) & _MASK32

    init = (0xDEADBEEF + (2 << 2) + 13) & _MASK32
    s = {"a": (init + kx) & _MASK32, "b": (init + ky) & _MASK32, "c": init}
    for dst, src, k in _LOOKUP3_FINAL:
        s[dst] = ((s[dst] ^ s[src]) - rot(s[src], k)) & _MASK32
    return s["c"]


def render_seed(cycles, scene) -> int:
    """The seed Cycles uses: with ``use_animated_seed``, hashed with the frame (and subframe)."""
    seed = int(cycles.seed)
    if not cycles.use_animated_seed:
        return seed
    hashed = hash_uint2(scene.frame_current & _MASK32, seed & _MASK32)
    if scene.frame_subframe != 0.0:
        sub = int(np.float32(scene.frame_subframe) * _INT_MAX_F)
        hashed = (hashed + hash_uint2(sub & _MASK32, seed & _MASK32)) & _MASK32
    return hashed


def _uses_shadow_caustics(scene) -> bool:
    """Whether Cycles renders shadow caustics (manifold next-event estimation) in the scene:
    it needs a light, a caster and a receiver with their Shadow Caustics switches on."""
    light = caster = receiver = False
    for ob in scene.objects:
        settings = getattr(ob, "cycles", None)
        light = light or (ob.type == "LIGHT" and getattr(ob.data.cycles, "is_caustics_light", False))
        caster = caster or getattr(settings, "is_caustics_caster", False)
        receiver = receiver or getattr(settings, "is_caustics_receiver", False)
    return light and caster and receiver


def export_integrator(ctx, scene, view_layer) -> Integrator:
    """Sampling and path settings from ``scene.cycles``; warns about what is not supported."""
    cycles = cycles_settings(ctx, scene)
    if cycles is None:
        return Integrator()
    if getattr(cycles, "use_fast_gi", False):
        ctx.warn("Fast GI Approximation is not supported; rendering full global illumination",
                 "Fast GI")
    if getattr(cycles, "texture_limit_render", "OFF") != "OFF":
        ctx.warn(f"Texture Limit ({cycles.texture_limit_render} px) is not supported; images are "
                 "read at full size", "texture limit")
    culled = [kind for kind in ("camera", "distance") if getattr(cycles, f"use_{kind}_cull", False)
              and any(getattr(ob.cycles, f"use_{kind}_cull", False) for ob in scene.objects)]
    if culled:
        ctx.warn(f"{' and '.join(culled).capitalize()} Culling is not supported; the culled objects "
                 "are rendered", "culling")
    if _uses_shadow_caustics(scene):
        ctx.warn("Shadow Caustics are not supported yet; those caustics are left to path tracing "
                 "(a few bright samples, not Cycles' focused light)", "shadow caustics")
    samples = int(cycles.samples)
    if cycles.use_layer_samples == "USE" and view_layer.samples > 0:
        samples = int(view_layer.samples)  # Cycles' per-view-layer sample override
    return Integrator(
        samples=samples,
        seed=render_seed(cycles, scene),
        max_bounces=int(cycles.max_bounces),
        diffuse_bounces=int(cycles.diffuse_bounces),
        glossy_bounces=int(cycles.glossy_bounces),
        transmission_bounces=int(cycles.transmission_bounces),
        transparent_max_bounces=int(cycles.transparent_max_bounces),
        min_light_bounces=int(cycles.min_light_bounces),
        clamp_direct=float(cycles.sample_clamp_direct),
        clamp_indirect=float(cycles.sample_clamp_indirect),
        filter_glossy=float(cycles.blur_glossy),
        caustics_reflective=bool(cycles.caustics_reflective),
        caustics_refractive=bool(cycles.caustics_refractive),
        time_limit=float(cycles.time_limit),
        use_adaptive_sampling=bool(cycles.use_adaptive_sampling),
        adaptive_threshold=float(cycles.adaptive_threshold),
        adaptive_min_samples=int(cycles.adaptive_min_samples),
        use_spatial_splits=bool(cycles.debug_use_spatial_splits),
        use_compact_bvh=bool(cycles.debug_use_compact_bvh),
        sampler=export_sampler(ctx, scene, cycles),
        **mcengine_settings(scene),
    )


def export_sampler(ctx, scene, cycles) -> str:
    """The sampler's name (:func:`sampler_for`); a Cycles pattern not known here is warned
    and rendered with the default sampler."""
    info = sampler_for(scene, cycles)
    if info is None:
        info = samplers.get(samplers.DEFAULT)
        ctx.warn(f"Cycles' sampling pattern {cycles.sampling_pattern!r} is not known to MC "
                 f"Engine; rendering with the {info.label} sampler", "sampling pattern")
    return info.name


def sampler_for(scene, cycles):
    """MC Engine's own sampler choice, or with "As Cycles" (the default) the one matching
    Cycles' sampling pattern: scrambled Sobol for each of Cycles' patterns (the blue-noise
    ones also spread the noise across pixels as blue noise, which MC Engine does not: its
    pixels are scrambled independently).  None for a pattern not known here."""
    own = getattr(scene, "mcengine", None)
    if own is not None and own.sampler != SAMPLER_AS_CYCLES:
        return samplers.from_enum(own.sampler)
    return samplers.from_cycles_pattern(str(cycles.sampling_pattern))


def mcengine_settings(scene) -> dict:
    """MC Engine's own integrator choice (``scene.mcengine``), for the Integrator."""
    own = getattr(scene, "mcengine", None)
    if own is None:
        return {}
    return {"name": integrators.from_enum(own.integrator).name, "depth": int(own.depth),
            "branching": int(own.branching)}
