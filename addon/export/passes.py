"""Render passes and denoising: the view layer's and Cycles' settings -> the core's.

The passes a view layer enables are read from the same properties Cycles
reads (View Layer > Passes: ``use_pass_z``, ``use_pass_cryptomatte_object``,
``cycles.denoising_store_passes``, ...; the vocabulary is
``mcengine.passes.PASSES``), and the render result gets the same passes,
names and channels as with Cycles (``result_passes``: what
``update_render_passes`` registers and ``render`` adds).  Denoising reads
``scene.cycles`` (``use_denoising``, ``denoiser``, ``denoising_input_passes``,
``denoising_prefilter``, ``denoising_quality``) and the view layer's own
switch; the viewport's denoising reads the ``preview_denoising*`` settings
only (as Cycles, which does not ask the view layer there).  What MC Engine
cannot do is one warning each, naming the fallback.
"""
from __future__ import annotations

from mcengine import integrators
from mcengine.denoise import Denoising
from mcengine.passes import (
    CRYPTO_TYPES,
    DENOISING_PASSES,
    MIST_FALLOFFS,
    NOISY_IMAGE,
    PASSES,
    RenderPasses,
)

__all__ = ["enabled_passes", "export_passes", "export_denoising", "denoising_enabled",
           "preview_denoising", "result_passes"]

# Cycles' view layer passes MC Engine does not produce: (owner, property, what Blender calls it).
_OTHER_PASSES = (
    ("cycles", "use_pass_volume_direct", "Volume Direct"),
    ("cycles", "use_pass_volume_indirect", "Volume Indirect"),
    ("cycles", "use_pass_volume_scatter", "Volume Scatter"),
    ("cycles", "use_pass_volume_transmit", "Volume Transmit"),
    ("cycles", "use_pass_volume_majorant", "Volume Majorant"),
    ("cycles", "use_pass_shadow_catcher", "Shadow Catcher"),
    ("cycles", "pass_debug_sample_count", "Debug Sample Count"),
    ("cycles", "pass_render_time", "Render Time"),
)


def enabled_passes(scene, view_layer) -> RenderPasses:
    """The passes ``view_layer`` enables that MC Engine writes, with their settings."""
    world = getattr(scene, "world", None)
    mist = getattr(world, "mist_settings", None)
    light = getattr(world, "light_settings", None)
    crl = getattr(view_layer, "cycles", None)
    return RenderPasses(
        enabled=tuple(p.name for p in PASSES if getattr(view_layer, p.setting, False)),
        cryptomatte=tuple(prefix for prefix, setting, _slot in CRYPTO_TYPES
                          if getattr(view_layer, setting, False)),
        cryptomatte_depth=int(getattr(view_layer, "pass_cryptomatte_depth", 6)),
        denoising_data=bool(getattr(crl, "denoising_store_passes", False)),
        mist_start=float(mist.start) if mist is not None else 5.0,
        mist_depth=float(mist.depth) if mist is not None else 25.0,
        mist_falloff=mist.falloff if mist is not None and mist.falloff in MIST_FALLOFFS
        else "QUADRATIC",
        alpha_threshold=float(getattr(view_layer, "pass_alpha_threshold", 0.5)),
        ao_distance=float(light.distance) if light is not None else 10.0,
        view_layer=view_layer.name)


def denoising_enabled(scene, view_layer) -> bool:
    """Cycles denoises a view layer when both the scene and the view layer ask for it."""
    cycles = getattr(scene, "cycles", None)
    crl = getattr(view_layer, "cycles", None)
    return bool(getattr(cycles, "use_denoising", False) and getattr(crl, "use_denoising", True))


def result_passes(scene, view_layer) -> list[tuple[str, str, str]]:
    """(name, channel ids, type) of every pass of the render result, Combined first (Cycles'
    list_render_passes order)."""
    out = [("Combined", "RGBA", "COLOR")]
    passes = enabled_passes(scene, view_layer)
    info = {p.name: p for p in PASSES + DENOISING_PASSES}
    for name in passes.names():
        if name.startswith("Crypto"):
            out.append((name, "rgba", "COLOR"))
        else:
            out.append((name, info[name].channels, info[name].kind))
    if denoising_enabled(scene, view_layer):
        # Cycles lists the noisy image before the denoising data passes.
        at = next((k for k, (n, _c, _t) in enumerate(out) if n.startswith("Denoising")), len(out))
        out.insert(at, (NOISY_IMAGE.name, NOISY_IMAGE.channels, NOISY_IMAGE.kind))
    return out


def export_passes(ctx, scene, view_layer, integrator_name: str) -> RenderPasses:
    """The render's passes; warns about enabled passes MC Engine omits."""
    passes = enabled_passes(scene, view_layer)
    crl = getattr(view_layer, "cycles", None)
    others = [label for owner, prop, label in _OTHER_PASSES
              if getattr(crl if owner == "cycles" else view_layer, prop, False)]
    others += [f"AOV '{aov.name}'" for aov in getattr(view_layer, "aovs", ()) if aov.is_valid]
    others += [f"light group '{g.name}'" for g in getattr(view_layer, "lightgroups", ())]
    if others:
        ctx.warn(f"render passes not supported yet ({', '.join(others)}); they are not written",
                 *others)
    if passes.names() and integrator_name != integrators.DEFAULT:
        ctx.warn(f"render passes need the path tracer: the {integrator_name} integrator writes "
                 f"Combined only (the other passes stay 0)", "render passes")
        return RenderPasses(view_layer=view_layer.name)
    return passes


def export_denoising(ctx, scene, view_layer, integrator_name: str) -> Denoising:
    """Cycles' denoising settings, when this view layer is denoised (else disabled)."""
    if not denoising_enabled(scene, view_layer):
        return Denoising(enabled=False)
    from mcengine.denoise import available
    cycles = scene.cycles
    reason = available()
    if reason is not None:
        ctx.warn(f"denoising is enabled but {reason}; rendering without denoising", "denoising")
        return Denoising(enabled=False)
    if getattr(cycles, "denoiser", "OPENIMAGEDENOISE") != "OPENIMAGEDENOISE":
        ctx.warn(f"the {cycles.denoiser} denoiser is not available in MC Engine; using Open "
                 f"Image Denoise", "denoiser")
    input_passes = str(cycles.denoising_input_passes)
    if integrator_name != integrators.DEFAULT and input_passes != "RGB":
        ctx.warn(f"denoising guides (albedo, normal) need the path tracer; the "
                 f"{integrator_name} integrator is denoised from its colour alone",
                 "denoising guides")
        input_passes = "RGB"
    return Denoising(enabled=True, input_passes=input_passes,
                     prefilter=str(cycles.denoising_prefilter),
                     quality=str(getattr(cycles, "denoising_quality", "HIGH")))


def preview_denoising(scene) -> tuple[Denoising, int]:
    """The viewport's denoising (Render > Sampling > Viewport > Denoise) and the sample
    from which it starts: ``scene.cycles.preview_denoising_*``.  Off when Open Image Denoise
    is missing (the viewport then shows the noisy image; F12 warns about it)."""
    cycles = getattr(scene, "cycles", None)
    if cycles is None or not getattr(cycles, "use_preview_denoising", False):
        return Denoising(enabled=False), 1
    from mcengine.denoise import available
    if available() is not None:
        return Denoising(enabled=False), 1
    return (Denoising(enabled=True, input_passes=str(cycles.preview_denoising_input_passes),
                      prefilter=str(cycles.preview_denoising_prefilter),
                      quality=str(cycles.preview_denoising_quality)),
            max(1, int(cycles.preview_denoising_start_sample)))
