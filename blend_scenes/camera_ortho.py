"""Camera: orthographic projection with horizontal sensor fit and shift.

Tests the orthographic camera: ``ortho_scale`` is the width of the view (fit
HORIZONTAL on a 128 x 96 frame), rays are parallel, and shift moves the view
by a fraction of that width.  The light-scene stage seen from above at an
angle, lit by a spot light, a sun and a grey world, so depth gives no cue
and only the projection decides where things land.

Camera: orthographic, ortho_scale 6.5, fit HORIZONTAL, at (3.0, -4.0, 5.0)
looking at (0.0, 0.2, 0.3), shift (-0.06, 0.04).

Run: .venv/bin/python blend_scenes/camera_ortho.py
"""
import math

import _common as c

WIDTH, HEIGHT = 128, 96


def build(scene):
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    c.set_world(scene, (0.1, 0.1, 0.1))
    camera = c.add_stage(scene)["camera"]
    camera.location = (3.0, -4.0, 5.0)
    c.look_at(camera, (0.0, 0.2, 0.3))
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 6.5
    camera.data.sensor_fit = "HORIZONTAL"
    camera.data.shift_x = -0.06
    camera.data.shift_y = 0.04
    c.add_light(scene, "Spot", "SPOT", 800.0, (-2.0, -1.5, 4.0), target=(-0.5, 0.2, 0.0),
                spot_size=math.radians(55.0), spot_blend=0.2, shadow_soft_size=0.15)
    c.add_light(scene, "Sun", "SUN", 1.0, (0.0, 0.0, 6.0),
                rotation=(math.radians(50.0), 0.0, math.radians(140.0)),
                color=(0.8, 0.9, 1.0), angle=0.1)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
