"""Motion blur of a moving camera: it pans, travels and zooms while the shutter opens
along a curve, read out row by row (rolling shutter).

Tests camera motion as Cycles renders it: the camera's transform at its 3
motion steps, interpolated (slerp, lerp) at each sample's time; the focal
length changing from 40 to 55 mm over the frame, which Cycles applies by
scaling the view plane between its values at shutter open, frame and close;
the shutter curve (a ramp from 0.2 up to 1 at the end of the shutter), whose
inverted CDF gives the times; and the rolling shutter (rows from the top,
duration 0.3).  The scene itself is still: the light-scene stage, a sun, a
grey world.

Frame 1; shutter 0.8 frames, CENTER; camera keyed at frames 0 and 2: from
(-1.2, -6.5, 3.6) to (1.2, -5.5, 4.2), aimed at (0.3, 0.2, 0.4) and then
turned 12 deg; lens 40 -> 55 mm.

Run: .venv/bin/python blend_scenes/motion_camera.py
"""
import math

import _common as c


def build(scene):
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 0.8
    scene.render.motion_blur_position = "CENTER"
    curve = scene.render.motion_blur_shutter_curve
    points = curve.curves[0].points             # (0, 1), (0.5, 1), (1, 1) by default
    points.remove(points[1])
    points[0].location = (0.0, 0.2)
    points[-1].location = (1.0, 1.0)
    for point in points:
        point.handle_type = "VECTOR"
    curve.update()
    scene.cycles.rolling_shutter_type = "TOP"
    scene.cycles.rolling_shutter_duration = 0.3
    c.set_world(scene, (0.12, 0.13, 0.15))
    camera = c.add_stage(scene)["camera"]
    c.add_light(scene, "Sun", "SUN", 2.5, (0.0, 0.0, 6.0),
                rotation=(math.radians(40.0), 0.0, math.radians(-30.0)), angle=0.05)
    c.look_at(camera, (0.3, 0.2, 0.4))
    aim = tuple(camera.rotation_euler)
    c.animate(camera, "location", [(0, (-1.2, -6.5, 3.6)), (2, (1.2, -5.5, 4.2))])
    c.animate(camera, "rotation_euler", [(0, aim), (2, (aim[0], aim[1], aim[2] + math.radians(12.0)))])
    c.animate(camera, "data.lens", [(0, 40.0), (2, 55.0)])
    scene.frame_set(1)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
