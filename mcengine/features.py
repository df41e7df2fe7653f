"""The effects plan: what a render simulates, decided once from the scene.

Before it starts, a render asks this module which effects the scene calls
for, and the kernels skip the work of the others (flags in the ``cfg``
settings vector, ``packing``):

==================== ======================================== ======================================
effect               on when                                  work it costs when on
==================== ======================================== ======================================
light sampling       a lamp or emissive triangle gives light  a light sample and a shadow ray per
                                                              vertex (next-event estimation)
lamp hits            a lamp has a surface rays can meet       every ray tested against the lamps,
                     (radius, size, sun angle; MIS on)        escaped rays against suns
MIS weights          light can be both sampled and hit        light-picking sums at every vertex for
                     (lamp hits, emissive triangles)          the weights of emission found by rays
world lookups        the world is not black                   background radiance for escaped rays
transparent shadows  a material lets shadow rays through      shadow rays traced hit by hit, with the
                                                              shader run at every surface they pass
caustic paths        lights, a glossy/glass/refraction caster Filter Glossy and the caustics switches
                     and a diffuse receiver                   at every vertex; the light paths of
                                                              Path + Light Tracing
subsurface walks     a material has a subsurface closure      a hierarchy over each such object's
                     (Principled Subsurface Weight, the       triangles; random walks inside them
                     Subsurface Scattering node)              (without it: Lambert, the zero-radius
                                                              limit)
light linking        a lamp or emissive object lights only    a light-set test per light sample and
                     some objects (Object > Light Linking)    per lamp or emission a ray finds
==================== ======================================== ======================================

The camera's effects cost nothing when absent without a flag: no lens sample is
drawn for an aperture of 0, no ray time without an open shutter, and only the
objects that move during the shutter are intersected at each ray's time; the
plan names them (``camera``).

Besides the effects, the plan lists what the scene holds: light types, the
kinds of surface (read from the materials' shader graphs) and the materials
whose shaders evaluate nodes at every hit (textures, inputs) rather than only
build closures from constants, and those whose nodes trace rays of their own (Bevel and
Ambient Occlusion: their objects, and for AO the scene, get hierarchies to trace).
``summary()`` is the line shown in the MC Engine panel, on the command line and in the
comparison and study reports.

Every effect can be forced on (``RenderSession(..., force_effects=...)``):
the benchmark (``benchmarks/bench_effects_plan.py``) measures what the plan
saves that way, and the tests check that forcing on an effect the scene does
not call for leaves the image bit for bit the same.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field, replace

import numpy as np

from .kernels.lights import LIGHT_SETS_ALL
from .kernels.motion import moves
from .kernels.state import (
    CFG_CAUSTICS,
    CFG_LAMPS_HIT,
    CFG_LIGHT_LINKING,
    CFG_LIGHTS,
    CFG_MIS,
    CFG_SUBSURFACE,
    CFG_TRANSPARENT_SHADOWS,
    CFG_WORLD,
    MF_TRANSPARENT,
)
from .kernels.svm import OP_NODE
from .kernels.svm.nodes import NODES
from .scene import Link
from .shaders import UNDISPLACED_ATTRIBUTE

# Shader nodes that trace rays of their own (kernels/svm/bevel.py, ao.py).
TRACING_NODES = ("Bevel", "AmbientOcclusion")

# Effect name -> (label for people, cfg flag that switches it in the kernels).
EFFECTS = {
    "nee": ("light sampling", CFG_LIGHTS),
    "lamps_hit": ("lamp hits", CFG_LAMPS_HIT),
    "mis": ("MIS weights", CFG_MIS),
    "world": ("world lookups", CFG_WORLD),
    "transparent_shadows": ("transparent shadows", CFG_TRANSPARENT_SHADOWS),
    "caustics": ("caustic paths", CFG_CAUSTICS),
    "subsurface": ("subsurface walks", CFG_SUBSURFACE),
    "light_linking": ("light linking", CFG_LIGHT_LINKING),
}


@dataclass(frozen=True)
class EffectsPlan:
    lamp_types: dict = field(default_factory=dict)   # e.g. {"AREA": 2, "POINT": 1}
    profiled: int = 0              # lamps with an IES profile (looked up per light sample)
    emissive_triangles: int = 0
    lobes: tuple = ()              # kinds of surface, in LOBE_ORDER
    textures: int = 0              # materials whose shaders evaluate nodes at every hit
    images: int = 0                # images the shaders read
    world_shader: bool = False     # the world varies (its shader runs for escaped rays)
    world_sampled: bool = False    # the world is a light for next-event estimation (its map)
    camera: tuple = ()             # "depth of field", "motion blur (...)": what the camera sees
    displaced: int = 0             # meshes moved by true displacement (``displacement``)
    traced: int = 0                # materials with nodes that trace rays (TRACING_NODES: their
                                   # objects, and for AO the scene, get hierarchies to trace)
    # The effects (see the module docstring); each is a kernel flag.
    nee: bool = False
    lamps_hit: bool = False
    mis: bool = False
    world: bool = False
    transparent_shadows: bool = False
    caustics: bool = False
    subsurface: bool = False
    light_linking: bool = False
    forced: tuple = ()             # effects forced on although the scene does not call for them

    def force(self, names) -> "EffectsPlan":
        """This plan with the effects ``names`` (or every effect for "all") switched on."""
        names = tuple(EFFECTS) if names == "all" else tuple(names)
        unknown = [n for n in names if n not in EFFECTS]
        if unknown:
            raise ValueError(f"unknown effect {unknown[0]!r} (choose from {', '.join(EFFECTS)})")
        added = tuple(n for n in names if not getattr(self, n))
        return replace(self, forced=self.forced + added, **{n: True for n in names})

    def effects_on(self) -> tuple:
        return tuple(n for n in EFFECTS if getattr(self, n))

    def flags(self, cfg) -> None:
        """Write the effects into the kernels' settings vector."""
        for name, (_, index) in EFFECTS.items():
            cfg[index] = 1 if getattr(self, name) else 0

    def summary(self) -> str:
        """One line: the lights and surfaces, then what is simulated and what is skipped."""
        lights = [f"{n} {t.lower()}" for t, n in sorted(self.lamp_types.items())]
        if self.profiled:
            n = self.profiled
            lights = [", ".join(lights) + f" ({n} with {'IES profiles' if n > 1 else 'an IES profile'})"]
        if self.emissive_triangles:
            n = self.emissive_triangles
            lights.append(f"{n} emissive triangle{'s' if n > 1 else ''}")
        if self.world:
            lights.append("world (sampled)" if self.world_sampled
                          else "world shader" if self.world_shader else "world")
        on = [EFFECTS[n][0] + (" (forced)" if n in self.forced else "") for n in self.effects_on()]
        off = [EFFECTS[n][0] for n in EFFECTS if not getattr(self, n)]
        textures = (f"{self.textures} textured material{'s' if self.textures > 1 else ''}"
                    if self.textures else "no textures")
        if self.images:
            textures += f", {self.images} image{'s' if self.images > 1 else ''}"
        if self.displaced:
            textures += f"; {self.displaced} displaced mesh{'es' if self.displaced > 1 else ''}"
        if self.traced:
            textures += (f"; {self.traced} material{'s' if self.traced > 1 else ''} with "
                         f"ray-traced nodes")
        camera = f"; {', '.join(self.camera)}" if self.camera else ""
        return (f"Lights: {', '.join(lights) if lights else 'none'}; "
                f"surfaces: {', '.join(self.lobes) if self.lobes else 'black'}; {textures}{camera} | "
                f"simulated: {', '.join(on) if on else 'nothing'} | "
                f"skipped: {', '.join(off) if off else 'nothing'}")


def lamp_has_surface(light) -> bool:
    """Whether rays can meet the lamp: a radius, a sun angle, an area."""
    if light.type in ("POINT", "SPOT"):
        return light.radius > 0.0
    if light.type == "SUN":
        return light.angle > 0.0
    return light.size_x > 0.0 and light.size_y > 0.0


def lamps_intersectable(lights) -> bool:
    """Cycles' use_light_mis: rays test lamps at all only if a point or spot lamp with a
    radius, or an area lamp, has MIS on (scene/light.cpp); otherwise not even a lamp
    visible to the camera is seen (``packing`` clears that visibility)."""
    return any(li.use_mis and (li.type == "AREA" or (li.type in ("POINT", "SPOT") and li.radius > 0))
               for li in lights)


def lamps_hit_by_rays(lights) -> bool:
    """Whether some lamp can be met by a ray: an intersectable lamp with a surface, or a
    sun with an angle and MIS on (met by escaped rays)."""
    if any(li.type == "SUN" and li.use_mis and lamp_has_surface(li) for li in lights):
        return True
    return lamps_intersectable(lights) and any(
        lamp_has_surface(li) and (li.use_mis or li.visible_camera)
        for li in lights if li.type != "SUN")


CASTERS = {"rough glossy", "sharp glossy", "coat", "rough glass", "sharp glass",
           "rough refraction", "sharp refraction"}
RECEIVERS = {"diffuse", "rough diffuse", "sheen", "translucent", "subsurface"}


def detect(scene, emissive_triangles: int, lamp_power, material_flags, programs=None,
           world=None, images: int = 0) -> EffectsPlan:
    """The plan for ``scene`` given its emissive triangle count, lamp powers, the MF_*
    flags of its materials and their shader programs (``(ops, ranges)``); ``world`` is
    (gives light, varies, sampled by next-event estimation) (None: its constant colour
    decides) and ``images`` the number of images the shaders read."""
    if world is None:
        world = (bool(np.max(np.asarray(scene.world.color, float)) > 0.0), False, False)
    world_lit, world_shader, world_sampled = world
    lamps = [li for li, pw in zip(scene.lights, lamp_power) if pw > 0.0]
    used = scene.geometry.materials_used()
    kinds = set()
    for i in used:
        kinds |= surface_kinds(scene.materials[i])
    lamps_hit = lamps_hit_by_rays(lamps)
    nee = bool(lamps) or emissive_triangles > 0 or world_sampled
    textures = traced = 0
    if programs is not None:
        ops, ranges = programs
        textures = sum(1 for i in used if np.any(ops[ranges[i][0]:ranges[i][1], 0] == OP_NODE))
        traced = len(set(used) & {i for name in TRACING_NODES
                                  for i in materials_with_node(programs, name)})
    return EffectsPlan(
        lobes=tuple(k for k in LOBE_ORDER if k in kinds),
        textures=textures,
        camera=camera_effects(scene),
        displaced=displaced_meshes(scene.geometry),
        traced=traced,
        transparent_shadows=any(material_flags[i] & MF_TRANSPARENT for i in used),
        lamp_types=dict(Counter(li.type for li in lamps)),
        profiled=sum(1 for li in lamps if li.ies is not None),
        emissive_triangles=int(emissive_triangles),
        world=bool(world_lit),
        world_shader=bool(world_lit and world_shader),
        world_sampled=bool(world_sampled),
        images=int(images),
        lamps_hit=lamps_hit,
        nee=nee,
        mis=nee and (lamps_hit or emissive_triangles > 0 or world_sampled),
        caustics=nee and bool(kinds & CASTERS) and bool(kinds & RECEIVERS),
        subsurface="subsurface" in kinds,
        light_linking=nee and light_linked(lamps, scene.geometry),
    )


def materials_with_node(programs, name: str) -> list:
    """The materials whose shader programs (``(ops, ranges)``) evaluate a ``name`` node."""
    ops, ranges = programs
    code = NODES[name].code
    return [i for i, (start, end) in enumerate(ranges)
            if np.any((ops[start:end, 0] == OP_NODE) & (ops[start:end, 1] == code))]


def light_linked(lamps, geometry) -> bool:
    """Whether some lamp or object lights only some of the light sets (light linking)."""
    return (any(int(li.light_sets) != LIGHT_SETS_ALL for li in lamps)
            or bool(np.any(geometry.light_sets() != np.uint64(LIGHT_SETS_ALL))))


def displaced_meshes(geometry) -> int:
    """How many objects true displacement moved (their triangles carry the undisplaced points,
    flagged)."""
    undisplaced = geometry.attributes.get(UNDISPLACED_ATTRIBUTE)
    if undisplaced is None:
        return 0
    flagged = np.asarray(undisplaced)[:, 0, 3] > 0.0
    return len(np.unique(np.asarray(geometry.object_index)[flagged]))


def camera_effects(scene) -> tuple:
    """Depth of field (an aperture), and motion blur with what moves while the shutter is open."""
    out = ["depth of field"] if scene.camera.aperture_size > 0.0 else []
    mb = scene.motion_blur
    if mb is not None:
        what = []
        steps = np.asarray(scene.camera.motion, float)
        if (len(steps) and np.any(steps != steps[len(steps) // 2])) or \
                tuple(scene.camera.view_scale_motion) != (1.0, 1.0):
            what.append("camera")
        n = sum(1 for om in mb.objects if moves(om, scene.geometry.vertices))
        if n:
            what.append(f"{n} moving object{'s' if n > 1 else ''}")
        out.append(f"motion blur ({', '.join(what) if what else 'nothing moves'})")
    return tuple(out)


LOBE_ORDER = ("diffuse", "rough diffuse", "subsurface", "sheen", "translucent", "rough glossy",
              "sharp glossy",
              "coat", "hair", "rough glass", "sharp glass", "rough refraction", "sharp refraction",
              "transparent", "ray portal", "emission", "holdout")
# Roughness below which a microfacet lobe is a perfect mirror (alpha_x alpha_y <= 2e-10).
SHARP_ROUGHNESS = 2e-10 ** 0.25


# Nodes whose kind of surface does not depend on their inputs.
_KINDS = {"BsdfTranslucent": "translucent", "BsdfTransparent": "transparent", "BsdfSheen": "sheen",
          "BsdfHair": "hair", "BsdfRayPortal": "ray portal", "Emission": "emission",
          "Holdout": "holdout"}


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
        elif kind in ("BsdfGlossy", "BsdfMetallic"):
            kinds.add("sharp glossy" if sharp("Roughness", 0.5) else "rough glossy")
        elif kind == "BsdfGlass":
            kinds.add("sharp glass" if sharp("Roughness", 0.0) else "rough glass")
        elif kind == "BsdfRefraction":
            kinds.add("sharp refraction" if sharp("Roughness", 0.0) else "rough refraction")
        elif kind == "SubsurfaceScattering":
            kinds.add("subsurface")
        elif kind == "BsdfToon":
            kinds.add("rough glossy" if node.props.get("component") == "GLOSSY" else "diffuse")
        elif kind in _KINDS:
            kinds.add(_KINDS[kind])
        elif kind == "BsdfPrincipled":
            rough = "sharp" if sharp("Roughness", 0.5) else "rough"
            if below_one("Metallic", 0.0) and below_one("Transmission Weight", 0.0) \
                    and positive("Base Color", (0.8,) * 3):
                if below_one("Subsurface Weight", 0.0):
                    kinds.add("rough diffuse" if positive("Diffuse Roughness", 0.0) else "diffuse")
                if positive("Subsurface Weight", 0.0):
                    kinds.add("subsurface")
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
