"""Which effects and light types a scene calls for, decided once per render.

The render asks this module before it starts, so that no work is done for
what the scene does not contain: no shadow rays without lights, no lamp
intersection tests when no lamp can be hit, no background lookups for a black
world.  The lobes (diffuse, sharp reflection, refraction) are found from the
materials the triangles use.  ``summary()`` is the line the MC Engine panel
shows ("Effects: ...").
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Features:
    lamp_types: dict = field(default_factory=dict)   # e.g. {"AREA": 2, "POINT": 1}
    emissive_triangles: int = 0
    world: bool = False            # the background is not black
    lamps_hit: bool = False        # some lamp can be hit by camera or BSDF rays
    nee: bool = False              # something to sample with next-event estimation
    diffuse: bool = False          # some surface has a diffuse lobe
    glossy: bool = False           # ... a mirror or glass lobe
    transmission: bool = False     # ... a glass or refraction lobe

    def summary(self) -> str:
        """One line for the UI and the logs."""
        lights = [f"{n} {t.lower()}" for t, n in sorted(self.lamp_types.items())]
        if self.emissive_triangles:
            n = self.emissive_triangles
            lights.append(f"{n} emissive triangle{'s' if n > 1 else ''}")
        if self.world:
            lights.append("world")
        lobes = [name for name, on in (("diffuse", self.diffuse),
                                       ("sharp reflection", self.glossy),
                                       ("refraction", self.transmission)) if on]
        return (f"Lights: {', '.join(lights) if lights else 'none'}; "
                f"surfaces: {', '.join(lobes) if lobes else 'black'}")


def lamp_can_be_hit(light) -> bool:
    """Cycles: a lamp is intersectable if it has a surface and MIS (or camera visibility)."""
    if light.type in ("POINT", "SPOT"):
        has_surface = light.radius > 0.0
    elif light.type == "SUN":
        has_surface = light.angle > 0.0
    else:
        has_surface = light.size_x > 0.0 and light.size_y > 0.0
    return has_surface and light.use_mis


def detect(scene, emissive_triangles: int, lamp_power) -> Features:
    """Features of ``scene`` given its emissive triangle count and lamp powers."""
    lamps = [li for li, pw in zip(scene.lights, lamp_power) if pw > 0.0]
    used = set(np.unique(scene.geometry.material_index).tolist())
    mats = [m for i, m in enumerate(scene.materials) if i in used]
    has = lambda attr: any(max(getattr(m, attr)) > 0.0 for m in mats)  # noqa: E731
    return Features(
        diffuse=has("base_color"),
        glossy=has("mirror_color") or has("glass_color"),
        transmission=has("glass_color") or has("refraction_color"),
        lamp_types=dict(Counter(li.type for li in lamps)),
        emissive_triangles=int(emissive_triangles),
        world=bool(np.max(np.asarray(scene.world.color, float)) > 0.0),
        lamps_hit=any(lamp_can_be_hit(li) for li in lamps if li.type != "SUN"),
        nee=bool(lamps) or emissive_triangles > 0,
    )
