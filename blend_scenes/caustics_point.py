"""Caustics of lamps of radius 0: a glass ball and a mirror under a point lamp and a spot.

The scene path tracing (and Cycles) cannot light fully: the ball's focused
spot on the floor and the patch of light the mirror throws come from a point
lamp and a spot of radius 0, which no ray can hit, so both engines render them
black and agree (the fidelity suite).  MC Engine's Path + Light Tracing
integrator (``--integrator light``) renders them; its study is in README
(*Caustics of point lamps*).  The stage is ``caustics.py``'s.

* ``Floor``, ``GlassBall``, ``Mirror``: as in ``caustics.py``.
* ``Key``: point lamp, radius 0, 150 W, 1.6 m above the ball.
* ``Spot``: spot lamp, radius 0, 300 W, 40 deg cone, blend 0.1, aimed at the
  mirror's centre from (-0.6, -1.8, 1.6).

World black.  Bounces 8, diffuse 4, glossy 8, transmission 8.

Run: .venv/bin/python blend_scenes/caustics_point.py
"""
import math

import _common as c
import caustics


def build(scene):
    caustics.stage(scene)
    c.add_light(scene, "Key", "POINT", 150.0, (-0.6, 0.3, 2.1), shadow_soft_size=0.0)
    c.add_light(scene, "Spot", "SPOT", 300.0, (-0.6, -1.8, 1.6), target=(1.3, 0.9, 0.45),
                shadow_soft_size=0.0, spot_size=math.radians(40.0), spot_blend=0.1)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
