"""Sun angles: a wide sun (very soft shadows) and a narrow one, no world light.

Tests the distant light's angular diameter where it matters: a 30 deg sun
(half-angle 15 deg) casts shadows with long penumbrae and is sampled over a
wide cone; a 2 deg sun from the other side gives nearly hard shadows.
Radiance is ``energy / (pi sin^2(angle / 2))`` inside the cone, so both give
their ``energy`` in W/m^2 on a surface facing them.  World black, so the
shadows hold only indirect light.

* ``SunWide``: 4 W/m^2, warm, angle 30 deg, 35 deg from the zenith.
* ``SunNarrow``: 1.5 W/m^2, blue, angle 2 deg, 55 deg from the zenith.

Run: .venv/bin/python blend_scenes/light_sun_wide.py
"""
import math

import _common as c


def build(scene):
    c.set_world(scene, (0.0, 0.0, 0.0))
    c.add_stage(scene)
    c.add_light(scene, "SunWide", "SUN", 4.0, (0.0, 0.0, 6.0),
                rotation=(math.radians(35.0), 0.0, math.radians(-50.0)),
                color=(1.0, 0.85, 0.65), angle=math.radians(30.0))
    c.add_light(scene, "SunNarrow", "SUN", 1.5, (0.0, 0.0, 6.0),
                rotation=(math.radians(55.0), 0.0, math.radians(120.0)),
                color=(0.55, 0.7, 1.0), angle=math.radians(2.0))


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
