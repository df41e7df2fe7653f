"""Spot lights beyond the basic cone: scaled, spherical, wide and fully blended.

Tests what the object transform and the radius do to a spot: non-uniform
object scale makes the cone elliptical (Cycles transforms the direction into
the lamp's scaled frame), ``use_soft_falloff`` False makes a radius into a
sphere light, and the extreme blend and cone settings.  World black.

* ``SpotElliptic``: 900 W, spot_size 50 deg, blend 0.15, radius 0, object
  scale (1.8, 0.6, 1.0) and rotated 30 deg about its axis: an elliptical,
  rotated footprint.
* ``SpotSphere``: 600 W, spot_size 60 deg, blend 0.3, radius 0.3,
  ``use_soft_falloff`` False (a sphere light clipped by the cone), greenish.
* ``SpotWide``: 250 W, spot_size 150 deg, blend 1.0, radius 0.1 (soft
  falloff), bluish, low over the sphere.

Run: .venv/bin/python blend_scenes/light_spot_shapes.py
"""
import math

import _common as c


def build(scene):
    c.set_world(scene, (0.0, 0.0, 0.0))
    c.add_stage(scene)
    elliptic = c.add_light(scene, "SpotElliptic", "SPOT", 900.0, (-1.4, -0.2, 3.8),
                           target=(-1.0, 0.2, 0.0), scale=(1.8, 0.6, 1.0),
                           spot_size=math.radians(50.0), spot_blend=0.15, shadow_soft_size=0.0)
    # Turn the squashed cone about its own axis (local Z) after aiming it.
    elliptic.rotation_euler.rotate_axis("Z", math.radians(30.0))
    c.add_light(scene, "SpotSphere", "SPOT", 600.0, (1.8, -1.8, 3.0), target=(0.4, -0.8, 0.0),
                color=(0.75, 1.0, 0.6), spot_size=math.radians(60.0), spot_blend=0.3,
                shadow_soft_size=0.3, use_soft_falloff=False)
    c.add_light(scene, "SpotWide", "SPOT", 250.0, (1.6, 0.9, 1.9), target=(0.9, 0.0, 0.0),
                color=(0.6, 0.75, 1.0), spot_size=math.radians(150.0), spot_blend=1.0,
                shadow_soft_size=0.1, use_soft_falloff=True)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
