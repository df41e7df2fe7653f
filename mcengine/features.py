"""Which effects and light types a scene calls for, decided once per render.

The render asks this module before it starts, so that no work is done for
what the scene does not contain: no shadow rays without lights, no lamp
intersection tests when no lamp can be hit, no background lookups for a black
world, no hit-by-hit shadow rays unless a material lets light through.  The
kinds of surface (diffuse, rough or sharp glossy, glass, sheen, ...) are read
from the shader graphs of the materials the triangles use.  ``summary()`` is
the line the MC Engine panel shows.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from .kernels.state import MF_TRANSPARENT
from .scene import Link


@dataclass(frozen=True)
class Features:
    lamp_types: dict = field(default_factory=dict)   # e.g. {"AREA": 2, "POINT": 1}
    emissive_triangles: int = 0
    world: bool = False            # the background is not black
    lamps_hit: bool = False        # some lamp can be hit by camera or BSDF rays
    nee: bool = False              # something to sample with next-event estimation
    lobes: tuple = ()              # kinds of surface, in LOBE_ORDER
    transparent_shadows: bool = False   # shadow rays pass some material's transparency

    def summary(self) -> str:
        """One line for the UI and the logs."""
        lights = [f"{n} {t.lower()}" for t, n in sorted(self.lamp_types.items())]
        if self.emissive_triangles:
            n = self.emissive_triangles
            lights.append(f"{n} emissive triangle{'s' if n > 1 else ''}")
        if self.world:
            lights.append("world")
        return (f"Lights: {', '.join(lights) if lights else 'none'}; "
                f"surfaces: {', '.join(self.lobes) if self.lobes else 'black'}")


def lamp_can_be_hit(light) -> bool:
    """Cycles: a lamp is intersectable if it has a surface and MIS (or camera visibility)."""
    if light.type in ("POINT", "SPOT"):
        has_surface = light.radius > 0.0
    elif light.type == "SUN":
        has_surface = light.angle > 0.0
    else:
        has_surface = light.size_x > 0.0 and light.size_y > 0.0
    return has_surface and light.use_mis


def detect(scene, emissive_triangles: int, lamp_power, material_flags) -> Features:
    """Features of ``scene`` given its emissive triangle count, lamp powers and the MF_*
    flags of its materials."""
    lamps = [li for li, pw in zip(scene.lights, lamp_power) if pw > 0.0]
    used = sorted(set(np.unique(scene.geometry.material_index).tolist()))
    kinds = set()
    for i in used:
        kinds |= surface_kinds(scene.materials[i])
    return Features(
        lobes=tuple(k for k in LOBE_ORDER if k in kinds),
        transparent_shadows=any(material_flags[i] & MF_TRANSPARENT for i in used),
        lamp_types=dict(Counter(li.type for li in lamps)),
        emissive_triangles=int(emissive_triangles),
        world=bool(np.max(np.asarray(scene.world.color, float)) > 0.0),
        lamps_hit=any(lamp_can_be_hit(li) for li in lamps if li.type != "SUN"),
        nee=bool(lamps) or emissive_triangles > 0,
    )


LOBE_ORDER = ("diffuse", "rough diffuse", "sheen", "translucent", "rough glossy", "sharp glossy",
              "coat", "rough glass", "sharp glass", "rough refraction", "sharp refraction",
              "transparent", "emission", "holdout")
# Roughness below which a microfacet lobe is a perfect mirror (alpha_x alpha_y <= 2e-10).
SHARP_ROUGHNESS = 2e-10 ** 0.25


def surface_kinds(material) -> set:
    """The kinds of surface a material's graph can produce (a linked input may take any value)."""
    nodes, surface = material.graph()
    if surface is None:
        return set()
    kinds, seen, todo = set(), set(), [surface.node]
    while todo:
        k = todo.pop()
        if k in seen:
            continue
        seen.add(k)
        node = nodes[k]
        inputs = node.inputs
        for value in inputs.values():
            if isinstance(value, Link):
                todo.append(value.node)

        def get(name, default):
            """The constant value of an input; None when something is linked to it."""
            value = inputs.get(name, default)
            return None if isinstance(value, Link) else value

        def positive(name, default):
            """The input may be above 0 (a linked input may)."""
            value = get(name, default)
            return value is None or max(np.ravel(value)) > 0.0

        def below_one(name, default):
            value = get(name, default)
            return value is None or float(value) < 1.0

        def sharp(name, default):
            value = get(name, default)
            return value is not None and float(value) <= SHARP_ROUGHNESS
        kind = node.type
        if kind == "BsdfDiffuse":
            kinds.add("rough diffuse" if positive("Roughness", 0.0) else "diffuse")
        elif kind == "BsdfGlossy":
            kinds.add("sharp glossy" if sharp("Roughness", 0.5) else "rough glossy")
        elif kind == "BsdfGlass":
            kinds.add("sharp glass" if sharp("Roughness", 0.0) else "rough glass")
        elif kind == "BsdfRefraction":
            kinds.add("sharp refraction" if sharp("Roughness", 0.0) else "rough refraction")
        elif kind in ("BsdfTranslucent", "BsdfTransparent", "BsdfSheen", "Emission", "Holdout"):
            kinds.add({"BsdfTranslucent": "translucent", "BsdfTransparent": "transparent",
                       "BsdfSheen": "sheen", "Emission": "emission", "Holdout": "holdout"}[kind])
        elif kind == "BsdfPrincipled":
            rough = "sharp" if sharp("Roughness", 0.5) else "rough"
            if below_one("Metallic", 0.0) and below_one("Transmission Weight", 0.0) \
                    and positive("Base Color", (0.8,) * 3):
                kinds.add("rough diffuse" if positive("Diffuse Roughness", 0.0) else "diffuse")
            if positive("Metallic", 0.0) or positive("Specular IOR Level", 0.5):
                kinds.add(f"{rough} glossy")
            if positive("Transmission Weight", 0.0):
                kinds.add(f"{rough} glass")
            for name, default, what in (("Coat Weight", 0.0, "coat"), ("Sheen Weight", 0.0, "sheen")):
                if positive(name, default):
                    kinds.add(what)
            if below_one("Alpha", 1.0):
                kinds.add("transparent")
            if positive("Emission Strength", 0.0) and positive("Emission Color", (1, 1, 1)):
                kinds.add("emission")
    return kinds
