"""IES light profiles: lamps whose node trees route an IES Texture into their emission.

Tests the profile's frame (vertical angle 0 along the lamp's -Z, horizontal 0 along -Y,
turning with the lamp), the units (candela x 4 pi / 177.83 x the lamp's power), Cycles'
processing of the file (a round profile from one horizontal angle, a half mirrored to the
full circle), the lookup from the sampled point of a lamp with a size, the file read from a
Text data-block and from a file beside the .blend ('//'), and the tree folded around the
Factor (a Math node scaling it).  The world is black: outside the beams only indirect light.

* ``WallWasher``: a point lamp of radius 0, turned 30 degrees about Z, with an asymmetric
  full-circle profile (Text data-block ``wall_washer.ies``): brighter towards local -X.
* ``Downlight``: a spot of radius 0.1 with a narrow round profile (one horizontal angle) from
  the file ``light_ies_downlight.ies`` next to this script, by a '//' path.
* ``Panel``: a disk area light with a half profile (0-180, mirrored), its Factor times 2.5
  by a Math node before the Emission's Strength.
* ``Sconce``: an emissive quad, tilted, whose material's Emission Strength is an IES Texture
  with its Vector unlinked (Cycles' Incoming in the object's space: towards the receiver of
  a light sample, towards the camera where it is seen), the wall washer's profile x 0.4.

Run: .venv/bin/python blend_scenes/light_ies.py
"""
import math
from pathlib import Path

import _common as c
import bpy

DOWNLIGHT_FILE = "light_ies_downlight.ies"


def ies_text(v_angles, h_angles, candela, keywords=("[TEST] mcengine scene",)):
    """An LM-63-2002 file: candela(h, v) at every horizontal and vertical angle (degrees)."""
    lines = ["IESNA:LM-63-2002", *keywords, "TILT=NONE",
             f"1 -1 1 {len(v_angles)} {len(h_angles)} 1 2 0.2 0.2 0.1",
             "1.0 1.0 40"]
    lines.append(" ".join(f"{v:g}" for v in v_angles))
    lines.append(" ".join(f"{h:g}" for h in h_angles))
    for h in h_angles:
        lines.append(" ".join(f"{candela(h, v):.2f}" for v in v_angles))
    return "\n".join(lines) + "\n"


def wall_washer(h, v):
    """Strongest towards horizontal 90 degrees (the lamp's -X), fading towards the horizon."""
    toward = 0.25 + 0.75 * max(0.0, math.cos(math.radians(h - 90.0))) ** 2
    return 900.0 * toward * max(0.0, math.cos(math.radians(v) * 0.85)) ** 1.5


def downlight(h, v):
    return 2600.0 * math.exp(-(v / 22.0) ** 2)


def panel(h, v):
    return 420.0 * (0.6 + 0.4 * math.cos(math.radians(h))) * max(0.0, math.cos(math.radians(v)))


def profile_tree(owner, mode, source, scale=None):
    """IES Texture -> [Math multiply by scale ->] Emission Strength in the node tree of a lamp
    or an emission material."""
    owner.use_nodes = True
    tree = owner.node_tree
    emission = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeEmission")
    ies = tree.nodes.new("ShaderNodeTexIES")
    ies.location = (-500.0, 0.0)
    ies.mode = mode
    if mode == "INTERNAL":
        ies.ies = source
    else:
        ies.filepath = source
    fac = ies.outputs["Fac"]
    if scale is not None:
        math_node = tree.nodes.new("ShaderNodeMath")
        math_node.operation = "MULTIPLY"
        math_node.location = (-250.0, 0.0)
        math_node.inputs[1].default_value = scale
        tree.links.new(fac, math_node.inputs[0])
        fac = math_node.outputs[0]
    tree.links.new(fac, emission.inputs["Strength"])


def build(scene):
    c.set_world(scene, (0.0, 0.0, 0.0))
    c.add_stage(scene)

    text = bpy.data.texts.new("wall_washer.ies")
    text.write(ies_text(list(range(0, 181, 10)), list(range(0, 361, 15)), wall_washer))
    washer = c.add_light(scene, "WallWasher", "POINT", 6.0, (-0.2, -0.6, 3.2),
                         rotation=(0.0, 0.0, math.radians(30.0)), shadow_soft_size=0.0)
    profile_tree(washer.data, "INTERNAL", text)

    Path(__file__).resolve().with_name(DOWNLIGHT_FILE).write_text(
        ies_text(list(range(0, 91, 5)), [0], downlight))
    spot = c.add_light(scene, "Downlight", "SPOT", 4.0, (1.4, 0.9, 3.0), target=(1.1, 0.3, 0.0),
                       color=(1.0, 0.85, 0.7), spot_size=math.radians(110.0), spot_blend=0.3,
                       shadow_soft_size=0.1)
    profile_tree(spot.data, "EXTERNAL", "//" + DOWNLIGHT_FILE)

    area = c.add_light(scene, "Panel", "AREA", 1.2, (-2.0, 1.6, 2.4), target=(-1.2, 0.6, 0.0),
                       color=(0.7, 0.8, 1.0), shape="DISK", size=0.6)
    profile_tree(area.data, "INTERNAL", _half_profile(), scale=2.5)

    sconce = c.emission_material("Sconce", (1.0, 0.9, 0.75), 1.0)
    profile_tree(sconce, "INTERNAL", text, scale=0.4)
    c.add_quad(scene, "Sconce", [(-0.2, -0.2, 0.0), (0.2, -0.2, 0.0), (0.2, 0.2, 0.0), (-0.2, 0.2, 0.0)],
               sconce, location=(1.5, -1.3, 1.3), rotation=(math.radians(200.0), math.radians(15.0), 0.3))


def _half_profile():
    text = bpy.data.texts.new("panel.ies")
    text.write(ies_text(list(range(0, 91, 10)), list(range(0, 181, 30)), panel))
    return text


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
