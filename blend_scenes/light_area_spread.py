"""Area-light spread: one light of each shape with a different spread angle.

Tests the area light's ``spread`` (Cycles' cone of emission: radiance times
``max(tan(s/2) - tan(theta), 0) / (tan(s/2) - s/2)``, so the flux stays
constant while the light narrows into a beam), for every shape, with object
scale and a spread light seen directly.  World black.

* ``SpreadSquare``: SQUARE 1.2 m, spread 30 deg, warm, 2.8 m above the cube:
  a bright, soft-edged patch.
* ``SpreadDisk``: DISK 0.8 m with object scale (1.5, 1.0, 1.0), spread 60 deg,
  magenta, tilted towards the sphere.
* ``SpreadRectangle``: RECTANGLE 2.4 x 0.3 m, spread 10 deg, cyan, pointing
  straight down in front of the small block: a narrow projected strip.
* ``SpreadEllipse``: ELLIPSE 1.0 x 0.6 m, spread 120 deg, pale yellow,
  standing behind the objects facing the camera, ``visible_camera`` True (the
  camera sees it only inside its spread cone).

Run: .venv/bin/python blend_scenes/light_area_spread.py
"""
import math

import _common as c


def build(scene):
    c.set_world(scene, (0.0, 0.0, 0.0))
    c.add_stage(scene)
    c.add_light(scene, "SpreadSquare", "AREA", 40.0, (-1.0, 0.4, 2.8),
                color=(1.0, 0.8, 0.6), shape="SQUARE", size=1.2, spread=math.radians(30.0))
    c.add_light(scene, "SpreadDisk", "AREA", 50.0, (2.0, -0.6, 2.2), target=(0.9, 0.0, 0.3),
                scale=(1.5, 1.0, 1.0), color=(1.0, 0.5, 0.85), shape="DISK", size=0.8,
                spread=math.radians(60.0))
    c.add_light(scene, "SpreadRectangle", "AREA", 20.0, (0.1, -1.9, 2.4),
                color=(0.45, 0.9, 1.0), shape="RECTANGLE", size=2.4, size_y=0.3,
                spread=math.radians(10.0))
    c.add_light(scene, "SpreadEllipse", "AREA", 15.0, (0.3, 2.9, 1.2), target=(0.0, -5.2, 4.4),
                color=(1.0, 0.95, 0.6), shape="ELLIPSE", size=1.0, size_y=0.6,
                spread=math.radians(120.0), visible_camera=True)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
