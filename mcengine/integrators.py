"""The integrators MC Engine offers: the one vocabulary every other place reads.

An *integrator* is the light-transport algorithm of a render.  Each has a name
(what the command line, the scene description and the reports say), the
identifier of Blender's enum property (``scene.mcengine.integrator``), a label
and a description for the UI, and which of the two tree-shape parameters it
reads: ``depth`` (ray levels, the camera ray being level 1) and ``branching``
(secondary rays per hit).  ``rays_per_sample`` is the lecture's count of
closest-hit rays one camera sample can cast at most.

The path tracer is the default and matches Cycles; Path + Light Tracing adds
light tracing for the caustics path tracing cannot find (``mcengine.kernels.
light_tracing``: point and spot lamps of radius 0 through sharp glass and in
sharp mirrors) and is otherwise path tracing; the others are the lecture's
classic algorithms (``mcengine.kernels.classic``).
"""
from __future__ import annotations

from dataclasses import dataclass

__all__ = ["IntegratorInfo", "INTEGRATORS", "NAMES", "DEFAULT", "DEPTH_RANGE", "BRANCHING_RANGE",
           "DEFAULT_DEPTH", "DEFAULT_BRANCHING", "get", "from_enum", "check_parameters"]

DEPTH_RANGE = (1, 16)          # ray levels of Whitted and distribution ray tracing
BRANCHING_RANGE = (1, 64)      # secondary rays per hit of distribution ray tracing
DEFAULT_DEPTH = 5
DEFAULT_BRANCHING = 4


@dataclass(frozen=True)
class IntegratorInfo:
    name: str              # "path", "light", "raycast", "whitted", "distribution"
    enum_id: str           # Blender enum identifier
    label: str
    description: str
    uses_depth: bool       # reads ``depth`` (ray levels)
    uses_branching: bool   # reads ``branching`` (rays per hit)
    matches_cycles: bool
    kernel_code: int       # the integer the kernels know it by (``kernels.classic.CODE_*``)
    # What its images leave out, in words: why its error stops falling (study report).
    leaves_out: str = ""
    # The integrator whose images it renders exactly on a scene without mirrors or
    # glass (nothing for its extra rays to follow), or "".
    reduces_to: str = ""
    # Runs light tracing beside path tracing (``kernels.light_tracing``).
    light_tracing: bool = False

    @property
    def uses_sampler(self) -> bool:
        """Draws its numbers from the scene's sampler (``Integrator.sampler``); the classic
        integrators' ray trees always draw independent numbers."""
        return self.kernel_code == 0

    def rays_per_sample(self, depth: int, branching: int) -> int:
        """Most closest-hit rays one camera sample casts: 1, 2^r - 1 or 1 + b + ... + b^(r-1)."""
        if not self.uses_depth:
            return 1
        b = branching if self.uses_branching else 2
        return sum(b ** k for k in range(depth))

    def rays_formula(self) -> str:
        """The formula of :meth:`rays_per_sample` in the lecture's notation."""
        if not self.uses_depth:
            return "1"
        return "1 + b + ... + b^(depth-1)" if self.uses_branching else "2^depth - 1"

    def settings_text(self, depth: int, branching: int) -> str:
        """One line describing the parameters this integrator uses ('' if none)."""
        if not self.uses_depth:
            return ""
        if not self.uses_branching:
            return f"depth {depth}"
        return (f"depth {depth}, branching {branching}: up to "
                f"{self.rays_per_sample(depth, branching):,} rays per sample")


INTEGRATORS = {info.name: info for info in (
    IntegratorInfo("path", "PATH", "Path Tracing",
                   "One secondary ray per bounce, light sampling with multiple importance "
                   "sampling, Russian roulette; matches Cycles", False, False, True, 0,
                   leaves_out="path tracing is unbiased: a plateau means the reference is not "
                              "converged enough or the two differ"),
    IntegratorInfo("raycast", "RAYCAST", "Ray Casting",
                   "Camera rays and direct light from every light; no reflected light: fast "
                   "and biased", False, False, False, 1,
                   leaves_out="it stops at the first hit, so all light reflected between "
                              "surfaces (indirect light) and everything seen in mirrors or "
                              "through glass is missing"),
    IntegratorInfo("whitted", "WHITTED", "Whitted",
                   "Direct light plus perfect mirror and refraction rays down to Depth ray "
                   "levels: 2^depth - 1 rays per sample at most", True, False, False, 2,
                   leaves_out="it follows only perfect mirror and refraction rays, so light "
                              "reflected between diffuse or glossy surfaces is missing",
                   reduces_to="raycast"),
    IntegratorInfo("distribution", "DISTRIBUTION", "Distribution",
                   "Direct light plus Branching rays at every hit down to Depth ray levels: "
                   "1 + b + ... + b^(depth-1) rays per sample", True, True, False, 3,
                   leaves_out="its ray tree stops at the depth, so light that needs more "
                              "bounces is missing"),
    IntegratorInfo("light", "PATH_LIGHT", "Path + Light Tracing",
                   "Path tracing, and light tracing joined to the camera for the caustics that "
                   "rays from the camera cannot find: point and spot lamps of radius 0 through "
                   "sharp glass and in sharp mirrors", False, False, False, 0,
                   leaves_out="path + light tracing is unbiased: a plateau means the reference is "
                              "not converged enough or the two differ",
                   light_tracing=True),
)}
NAMES = tuple(INTEGRATORS)
DEFAULT = "path"


def get(name: str) -> IntegratorInfo:
    """The integrator called ``name``; ValueError naming the choices otherwise."""
    try:
        return INTEGRATORS[name]
    except KeyError:
        raise ValueError(f"unknown integrator {name!r} (choose from {', '.join(NAMES)})") from None


def from_enum(enum_id: str) -> IntegratorInfo:
    """The integrator of a Blender enum identifier ('PATH', ...)."""
    for info in INTEGRATORS.values():
        if info.enum_id == enum_id:
            return info
    raise ValueError(f"unknown integrator enum {enum_id!r}")


def check_parameters(depth: int, branching: int) -> None:
    """ValueError unless depth and branching lie in their ranges."""
    for what, value, (lo, hi) in (("depth", depth, DEPTH_RANGE),
                                  ("branching", branching, BRANCHING_RANGE)):
        if not lo <= value <= hi:
            raise ValueError(f"integrator {what} must be {lo}..{hi}, got {value}")
