"""Camera: vertical sensor fit, lens and shift on a wide frame.

Tests the perspective camera's projection when the sensor is fitted to the
frame's height: ``sensor_fit`` VERTICAL with a sensor height of 20 mm and a
35 mm lens on a 128 x 80 frame, with lens shift in both directions (shift is
a fraction of the larger frame side).  The light-scene stage, lit by a sun
(angle 0.05 rad) and a grey world.

Camera: at (0.6, -5.6, 3.4) looking at (0.3, 0.3, 0.4); lens 35 mm, sensor
36 x 20 mm, fit VERTICAL, shift (0.12, -0.08).

Run: .venv/bin/python blend_scenes/camera_sensor_fit.py
"""
import math

import _common as c

WIDTH, HEIGHT = 128, 80


def build(scene):
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    c.set_world(scene, (0.15, 0.17, 0.2))
    camera = c.add_stage(scene)["camera"]
    camera.location = (0.6, -5.6, 3.4)
    c.look_at(camera, (0.3, 0.3, 0.4))
    camera.data.lens = 35.0
    camera.data.sensor_fit = "VERTICAL"
    camera.data.sensor_height = 20.0
    camera.data.shift_x = 0.12
    camera.data.shift_y = -0.08
    c.add_light(scene, "Sun", "SUN", 2.5, (0.0, 0.0, 6.0),
                rotation=(math.radians(40.0), 0.0, math.radians(-30.0)), angle=0.05)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
