"""Motion blur of moving objects: rotation, translation, scale, an emitter, motion steps.

Tests object transform motion as Cycles renders it: the shutter (1 frame,
centred on frame 1) sees objects keyframed with linear interpolation; each
object's transform is sampled at 2^steps + 1 motion steps and interpolated
between them (rotation by slerp, the rest linearly).  `Spinner` turns 90 deg
about Z per frame, `Slider` moves 1.6 m per frame, `Grower` doubles its scale,
`Orbiter` (an emitter, a mesh light that moves) goes 2.4 rad round an arc
with `motion_steps` 3 (9 steps; 3 steps would cut the arc short), `Still` is animated but has its object motion blur
off, and the `Swinging` point lamp moves: Cycles keeps lamps where they are at
the shutter's middle.

Frame 1; shutter 1.0, position CENTER, flat curve; camera at (0, -7, 4.5)
looking at (0, 0, 0.4); `Key` area light 2 m, 300 W; world 0.05.

Run: .venv/bin/python blend_scenes/motion_transform.py
"""
import math

import _common as c


def build(scene):
    scene.frame_set(1)
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 1.0
    scene.render.motion_blur_position = "CENTER"
    c.set_world(scene, (0.05, 0.05, 0.05))
    c.add_floor(scene)
    spinner = c.add_box(scene, "Spinner", (1.6, 0.4, 0.5), c.diffuse_material("Spinner", (0.2, 0.4, 0.8)),
                        location=(-1.6, 0.8, 0.0))
    c.animate(spinner, "rotation_euler", [(0, (0.0, 0.0, 0.0)), (2, (0.0, 0.0, math.radians(180.0)))])
    slider = c.add_uv_sphere(scene, "Slider", 0.45, c.diffuse_material("Slider", (0.8, 0.3, 0.15)),
                             location=(0.0, -0.6, 0.45))
    c.animate(slider, "location", [(0, (-1.6, -0.6, 0.45)), (2, (1.6, -0.6, 0.45))])
    grower = c.add_box(scene, "Grower", (0.6, 0.6, 0.6), c.diffuse_material("Grower", (0.3, 0.7, 0.3)),
                       location=(1.8, 1.0, 0.0))
    c.animate(grower, "scale", [(0, (0.6, 0.6, 0.6)), (2, (1.8, 1.8, 1.8))])
    orbiter = c.add_uv_sphere(scene, "Orbiter", 0.15, c.emission_material("Orbiter", (1.0, 0.7, 0.3), 25.0),
                              location=(0.0, 1.8, 1.5), segments=32, rings=16)
    arc = [0.5 + k / 16 for k in range(17)]              # 2.4 rad per frame, keyed every 1/16 frame
    c.animate(orbiter, "location", [(f, (1.3 * math.sin(2.4 * (f - 1)), 1.8, 1.0 + 1.3 * math.cos(2.4 * (f - 1))))
                                    for f in arc])
    orbiter.cycles.motion_steps = 3
    still = c.add_box(scene, "Still", (0.5, 0.5, 0.8), c.diffuse_material("Still", (0.7, 0.7, 0.2)),
                      location=(-0.4, 2.2, 0.0))
    c.animate(still, "location", [(0, (-1.4, 2.2, 0.0)), (2, (0.6, 2.2, 0.0))])
    still.cycles.use_motion_blur = False
    lamp = c.add_light(scene, "Swinging", "POINT", 150.0, (2.5, -1.5, 2.5), shadow_soft_size=0.1)
    c.animate(lamp, "location", [(0, (0.5, -1.5, 2.5)), (2, (4.5, -1.5, 2.5))])
    c.add_light(scene, "Key", "AREA", 300.0, (-2.0, -2.5, 4.0), target=(0.0, 0.5, 0.0), size=2.0)
    c.add_camera(scene, (0.0, -7.0, 4.5), (0.0, 0.0, 0.4))
    scene.frame_set(1)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
