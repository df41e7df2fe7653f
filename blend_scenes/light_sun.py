"""Sun light: angle 0.1 rad, tilted about 40 deg from vertical, plus a dim world.

Tests the distant light (``energy`` is irradiance in W/m^2 on a surface facing
it, ``angle`` its full angular diameter, so shadows are slightly soft) and a
constant world of 0.02 that fills the shadows.

Run: .venv/bin/python blend_scenes/light_sun.py
"""
import math

import _common as c

SUN_TILT = math.radians(40.0)  # from the zenith
SUN_AZIMUTH = math.radians(-35.0)  # rotation about +Z


def build(scene):
    c.set_world(scene, (0.02, 0.02, 0.02))
    c.add_stage(scene)
    # Only the orientation of a sun matters; its -Z axis is the light direction.
    c.add_light(scene, "Sun", "SUN", 3.0, (0.0, 0.0, 6.0), rotation=(SUN_TILT, 0.0, SUN_AZIMUTH),
                color=(1.0, 0.95, 0.85), angle=0.1)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
