"""Denoising with Intel Open Image Denoise, as Cycles configures it.

Cycles' settings (scene.cycles) carry over: ``use_denoising``, the guide
passes (``denoising_input_passes``: none, albedo, or albedo and normal), the
prefilter and the quality.  The guides are the path tracer's denoising albedo
and normal (``kernels.passes``: the first surface whose closures are not
mostly specular, as Cycles writes them); what OIDN is told follows Cycles'
integrator/denoiser_oidn.cpp:

* the colour is HDR, the film's mean radiance; alpha stays the noisy one;
* prefilter ``ACCURATE``: each guide is first denoised by its own OIDN RT
  filter, then the colour filter is told the guides are clean (``cleanAux``);
* ``NONE``: the guides are used as they are and called clean;
* ``FAST``: the guides are used as they are, OIDN treats them as noisy;
* with normals but no albedo asked for, OIDN needs an albedo anyway: Cycles
  gives it a constant 0.5 (never happens with Blender's three choices).

The denoiser is ``pyoidn`` (the OIDN library bundled in its wheel), imported
when a denoised image is first asked for.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Denoising", "INPUT_PASSES", "PREFILTERS", "QUALITIES", "denoise", "DenoiseError",
           "available"]

INPUT_PASSES = ("RGB", "RGB_ALBEDO", "RGB_ALBEDO_NORMAL")
PREFILTERS = ("NONE", "FAST", "ACCURATE")
QUALITIES = ("HIGH", "BALANCED", "FAST")


class DenoiseError(RuntimeError):
    """OIDN could not be loaded or failed; the message says why."""


@dataclass
class Denoising:
    """Cycles' denoising settings (``scene.cycles`` names, lower case)."""

    enabled: bool = False
    input_passes: str = "RGB_ALBEDO_NORMAL"
    prefilter: str = "ACCURATE"
    quality: str = "HIGH"

    @property
    def uses_albedo(self) -> bool:
        return self.enabled and self.input_passes in ("RGB_ALBEDO", "RGB_ALBEDO_NORMAL")

    @property
    def uses_normal(self) -> bool:
        return self.enabled and self.input_passes == "RGB_ALBEDO_NORMAL"

    def check(self) -> list[str]:
        problems = []
        for name, allowed in (("input_passes", INPUT_PASSES), ("prefilter", PREFILTERS),
                              ("quality", QUALITIES)):
            if getattr(self, name) not in allowed:
                problems.append(f"denoising: unknown {name} {getattr(self, name)!r} "
                                f"(one of {', '.join(allowed)})")
        return problems


def available() -> str | None:
    """None if OIDN loads, else the reason it does not (one line)."""
    try:
        _oidn()
    except DenoiseError as exc:
        return str(exc)
    return None


def _oidn():
    try:
        import pyoidn
        pyoidn.Device.is_cpu_available()
    except Exception as exc:  # a missing wheel, a library that does not load
        raise DenoiseError(f"Open Image Denoise is not available ({type(exc).__name__}: "
                           f"{exc})".splitlines()[0]) from None
    return pyoidn


def _run(pyoidn, inputs: dict, output: np.ndarray, settings: dict) -> None:
    """One OIDN RT filter over ``inputs`` (name -> (h, w, 3) float32) into ``output``."""
    with pyoidn.Device() as device:
        device.commit()
        with pyoidn.Filter(device, pyoidn.OIDN_FILTER_TYPE_RT) as flt:
            for name, image in inputs.items():
                flt.set_image(name, image, pyoidn.OIDN_FORMAT_FLOAT3)
            flt.set_image(pyoidn.OIDN_IMAGE_OUTPUT, output, pyoidn.OIDN_FORMAT_FLOAT3)
            for key, value in settings.items():
                if isinstance(value, bool):
                    flt.set_bool(key, value)
                else:
                    flt.set_int(key, value)
            flt.commit()
            flt.execute()
        error = device.get_error()
    if error is not None:
        raise DenoiseError(f"Open Image Denoise failed: {error}")


_QUALITY_CODES = {"HIGH": 6, "BALANCED": 5, "FAST": 4}   # OIDN_QUALITY_*


def denoise(rgba: np.ndarray, settings: Denoising, albedo: np.ndarray | None = None,
            normal: np.ndarray | None = None) -> np.ndarray:
    """The denoised (h, w, 4) float32 image of a linear RGBA image (alpha kept).

    ``albedo`` and ``normal`` are (h, w, 3) guides, used when ``settings``
    asks for them.  Raises :class:`DenoiseError` if OIDN is missing or fails.
    """
    pyoidn = _oidn()
    img = np.asarray(rgba, np.float32)
    color = np.ascontiguousarray(np.nan_to_num(np.maximum(img[..., :3], 0.0), posinf=0.0))
    quality = _QUALITY_CODES.get(settings.quality, 6)
    inputs = {pyoidn.OIDN_IMAGE_COLOR: color}
    guides = []
    if settings.uses_albedo and albedo is not None:
        guides.append((pyoidn.OIDN_IMAGE_ALBEDO, albedo))
    if settings.uses_normal and normal is not None:
        if not guides:   # OIDN needs an albedo with a normal (Cycles: a constant 0.5)
            guides.append((pyoidn.OIDN_IMAGE_ALBEDO, np.full(color.shape, 0.5, np.float32)))
        guides.append((pyoidn.OIDN_IMAGE_NORMAL, normal))
    for name, guide in guides:
        guide = np.ascontiguousarray(np.nan_to_num(np.asarray(guide, np.float32)))
        if settings.prefilter == "ACCURATE":
            clean = np.empty_like(guide)
            _run(pyoidn, {name: guide}, clean, {"quality": quality})
            guide = clean
        inputs[name] = guide
    out = np.empty_like(color)
    _run(pyoidn, inputs, out, {"hdr": True, "cleanAux": bool(guides) and settings.prefilter != "FAST",
                               "quality": quality})
    result = img.copy()
    result[..., :3] = out
    return result
