"""The samplers MC Engine offers: the one vocabulary every other place reads.

A *sampler* decides which random numbers a path sample draws
(``mcengine.kernels.sampling``):

* ``sobol`` (the default): each pixel's samples are Owen-scrambled, shuffled
  Sobol points with one dimension set per use of randomness and bounce, as
  Cycles samples (its Tabulated Sobol, Sobol-Burley and blue-noise patterns
  all stratify a pixel's samples this way; the blue-noise ones also arrange
  the noise across pixels, which MC Engine does not).  Unbiased; its error
  falls faster than 1/sqrt(N) where the integrand is smooth.
* ``independent``: every number independent of every other, the lecture's
  sampler.  The error of N samples falls exactly as 1/sqrt(N), and a pixel's
  sample variance over N estimates its error exactly; the guarantees that
  rest on that (the 1/N law, the film's variance) hold for it only.

The path tracer uses the scene's sampler; the classic integrators (ray
casting, Whitted, distribution) always draw independent numbers: their ray
trees have no dimension assignment of their own.
"""
from __future__ import annotations

from dataclasses import dataclass

__all__ = ["SamplerInfo", "SAMPLERS", "NAMES", "DEFAULT", "get", "from_enum",
           "from_cycles_pattern"]


@dataclass(frozen=True)
class SamplerInfo:
    name: str          # "sobol", "independent"
    enum_id: str       # Blender enum identifier
    label: str
    description: str
    kernel_code: int   # the integer the kernels know it by (``kernels.sampling.SAMPLER_*``)


SAMPLERS = {info.name: info for info in (
    SamplerInfo("sobol", "SOBOL", "Scrambled Sobol",
                "Owen-scrambled Sobol points per pixel, stratified per bounce as Cycles "
                "samples: less noise per sample", 1),
    SamplerInfo("independent", "INDEPENDENT", "Independent",
                "Independent random numbers (the lecture's sampler): the error falls exactly "
                "as 1/sqrt(samples)", 0),
)}
NAMES = tuple(SAMPLERS)
DEFAULT = "sobol"

# Cycles' sampling patterns (scene.cycles.sampling_pattern) -> the sampler that gives the
# same stratification of a pixel's samples.
CYCLES_PATTERNS = {
    "AUTOMATIC": "sobol", "TABULATED_SOBOL": "sobol", "SOBOL_BURLEY": "sobol",
    "BLUE_NOISE": "sobol", "BLUE_NOISE_FIRST": "sobol", "BLUE_NOISE_ROUND": "sobol",
}


def get(name: str) -> SamplerInfo:
    """The sampler called ``name``; ValueError naming the choices otherwise."""
    try:
        return SAMPLERS[name]
    except KeyError:
        raise ValueError(f"unknown sampler {name!r} (choose from {', '.join(NAMES)})") from None


def from_enum(enum_id: str) -> SamplerInfo:
    """The sampler of a Blender enum identifier ('SOBOL', ...)."""
    for info in SAMPLERS.values():
        if info.enum_id == enum_id:
            return info
    raise ValueError(f"unknown sampler enum {enum_id!r}")


def from_cycles_pattern(pattern: str) -> SamplerInfo | None:
    """The sampler matching Cycles' sampling pattern, or None for a pattern not known here."""
    name = CYCLES_PATTERNS.get(pattern)
    return SAMPLERS[name] if name else None
