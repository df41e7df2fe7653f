"""Spot lights: a hard-edged cone and a soft, blended one with a radius.

Tests the spot cone attenuation (``spot_size`` is the full cone angle,
``spot_blend`` the smoothstep penumbra), that spot power is not renormalised
into the cone, and the soft spot's emitter radius.  Both cones land on the
floor in view; outside them only indirect light remains (world black).

* ``SpotHard``: spot_size 45 deg, blend 0, radius 0 (hard edge, hard shadows).
* ``SpotSoft``: spot_size 70 deg, blend 0.4, radius 0.2, bluish.

Run: .venv/bin/python blend_scenes/light_spot.py
"""
import math

import _common as c


def build(scene):
    c.set_world(scene, (0.0, 0.0, 0.0))
    c.add_stage(scene)
    c.add_light(scene, "SpotHard", "SPOT", 700.0, (-1.9, -1.2, 3.6), target=(-1.1, -0.2, 0.0),
                spot_size=math.radians(45.0), spot_blend=0.0, shadow_soft_size=0.0)
    c.add_light(scene, "SpotSoft", "SPOT", 1000.0, (2.4, 2.4, 4.2), target=(1.0, 0.2, 0.0),
                color=(0.55, 0.75, 1.0), spot_size=math.radians(70.0), spot_blend=0.4,
                shadow_soft_size=0.2)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
