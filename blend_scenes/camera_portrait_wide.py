"""Camera: portrait frame, automatic sensor fit, wide lens, vertical shift.

Tests the AUTO sensor fit on a tall frame (the 36 mm sensor width is applied
to the larger side, here the height), a 20 mm wide-angle lens with strong
perspective, and an architectural vertical shift of -0.3 that keeps the camera
level while the frame slides down onto the floor.  The light-scene stage with
two area lights and a dim world.

Camera: 80 x 128 frame, at (0.0, -3.4, 2.0) looking level along +Y; lens
20 mm, sensor width 36 mm, fit AUTO, shift (0.0, -0.3).

Run: .venv/bin/python blend_scenes/camera_portrait_wide.py
"""
import _common as c

WIDTH, HEIGHT = 80, 128


def build(scene):
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    c.set_world(scene, (0.04, 0.04, 0.05))
    camera = c.add_stage(scene)["camera"]
    camera.location = (0.0, -3.4, 2.0)
    c.look_at(camera, (0.0, 0.0, 2.0))
    camera.data.lens = 20.0
    camera.data.shift_y = -0.3
    c.add_light(scene, "KeyArea", "AREA", 120.0, (-2.0, -2.0, 3.0), target=(0.0, 0.0, 0.3),
                shape="SQUARE", size=1.2, color=(1.0, 0.92, 0.85))
    c.add_light(scene, "RimArea", "AREA", 60.0, (2.2, 1.8, 2.2), target=(0.3, 0.0, 0.5),
                shape="DISK", size=0.8, color=(0.7, 0.85, 1.0))


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
