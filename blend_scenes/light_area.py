"""Area lights: one of each shape, with rotation, object scale and camera visibility.

Tests the four area-light shapes and their extents (object scale multiplies
them), one-sided Lambertian emission along local -Z with radiance P/(pi A),
and ``visible_camera``.  World black.

* ``AreaSquare``: SQUARE 1.0 m, warm white, pointing straight down.
* ``AreaRectangle``: RECTANGLE 1.6 x 0.3 m, green-cyan, rotated 35 deg about Z
  and tilted towards the cube.
* ``AreaDisk``: DISK 0.6 m with object scale (1.8, 0.8, 1.0) (an ellipse of
  1.08 x 0.48 m in effect), magenta-pink, pointing down.
* ``AreaEllipse``: ELLIPSE 1.2 x 0.5 m, pale blue, standing behind the objects
  facing the camera, ``visible_camera`` True, so it is seen in the frame.

Run: .venv/bin/python blend_scenes/light_area.py
"""
import math

import _common as c


def build(scene):
    c.set_world(scene, (0.0, 0.0, 0.0))
    c.add_stage(scene)
    c.add_light(scene, "AreaSquare", "AREA", 120.0, (-1.8, -1.2, 2.6),
                color=(1.0, 0.85, 0.7), shape="SQUARE", size=1.0)
    c.add_light(scene, "AreaRectangle", "AREA", 100.0, (-0.2, 1.9, 2.2),
                rotation=(math.radians(-30.0), 0.0, math.radians(35.0)),
                color=(0.4, 1.0, 0.8), shape="RECTANGLE", size=1.6, size_y=0.3)
    c.add_light(scene, "AreaDisk", "AREA", 80.0, (1.8, -1.4, 2.0), scale=(1.8, 0.8, 1.0),
                color=(1.0, 0.45, 0.7), shape="DISK", size=0.6)
    c.add_light(scene, "AreaEllipse", "AREA", 60.0, (0.9, 2.8, 1.0), target=(0.6, -1.0, 0.3),
                color=(0.7, 0.8, 1.0), shape="ELLIPSE", size=1.2, size_y=0.5,
                visible_camera=True)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
