"""The Toon BSDF: its diffuse and glossy components, with and without Smooth.

Cycles' toon lobes are flat: intensity 1 within Size (times 90 degrees) of their axis (the
normal, or for glossy the view reflected about it), fading linearly over Smooth, sampled
uniformly in that cone.  Lit by a warm area lamp and a cool point lamp over a grey world, so
the hard terminators of the diffuse lobes and the glossy highlights are in view, on their
own and added to each other; glossy toon after a diffuse bounce is left out when Caustics
Reflective is off (as Cycles' glossy closures are), which this scene leaves on.

* ``Ball``: a smooth sphere r 0.6 at (0.9, 0, 0.6), diffuse toon (0.8, 0.35, 0.25), Size 0.45,
  Smooth 0.05: a hard-edged terminator;
* ``Cube``: the stage's cube, diffuse toon (0.2, 0.4, 0.8) Size 0.7, Smooth 0.3 plus glossy
  toon (0.9, 0.9, 0.9) Size 0.15, Smooth 0.1 (an Add Shader);
* ``Block``: the stage's small box, glossy toon (0.9, 0.75, 0.3) Size 0.35, Smooth 0.25.

``Key``: an area lamp 1.2 m square, 150 W, warm, at (-2.0, -2.2, 3.2) aimed at the objects;
``Fill``: a point lamp 120 W, radius 0.2, bluish, at (2.5, -1.0, 2.0); world (0.08, 0.08,
0.09).  Bounces 6, diffuse 3, glossy 4.

Run: .venv/bin/python blend_scenes/material_toon.py
"""
import _common as c


def _toon(component, color, size, smooth):
    return ("ShaderNodeBsdfToon", {"component": component, "color": color, "size": size,
                                   "smooth": smooth})


def build(scene):
    c.set_world(scene, (0.08, 0.08, 0.09))
    c.set_bounces(scene, 6, 3, glossy=4, transmission=6)
    stage = c.add_stage(scene)
    ball = c.node_material("Ball", "ShaderNodeBsdfToon", component="DIFFUSE", color=(0.8, 0.35, 0.25),
                           size=0.45, smooth=0.05)
    stage["sphere"].data.materials[0] = ball
    stage["cube"].data.materials[0] = c.combine_material(
        "CubeToon", _toon("DIFFUSE", (0.2, 0.4, 0.8), 0.7, 0.3), _toon("GLOSSY", (0.9, 0.9, 0.9), 0.15, 0.1))
    stage["block"].data.materials[0] = c.node_material(
        "BlockToon", "ShaderNodeBsdfToon", component="GLOSSY", color=(0.9, 0.75, 0.3), size=0.35, smooth=0.25)
    c.add_material_lights(scene)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
