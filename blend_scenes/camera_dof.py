"""Camera: depth of field with a hexagonal, anamorphic aperture and a focus object.

Tests the thin lens: a 50 mm lens at f/0.07 (aperture radius 0.36 m) focused
on a sphere 3 m away (``dof.focus_object``, its depth along the view axis), a
box 1.6 m from the camera blurred in front of it, and a row of small bright
emitters 10 m away whose out-of-focus images are the aperture itself: a
hexagon (6 blades turned 30 deg) squeezed horizontally by the anamorphic
ratio 1.6.  A square area light and a grey world light the floor.

Camera: at (0, -6, 1.1) looking at (0, 0, 0.7); lens 50 mm; focus object
`FocusSphere` at (0.2, -3, 0.7); f-stop 0.07, 6 blades, rotation 30 deg,
ratio 1.6.

Run: .venv/bin/python blend_scenes/camera_dof.py
"""
import math

import _common as c


def build(scene):
    c.set_world(scene, (0.08, 0.08, 0.1))
    c.add_floor(scene)
    focus = c.add_uv_sphere(scene, "FocusSphere", 0.45, c.diffuse_material("Focus", (0.8, 0.75, 0.6)),
                            location=(0.2, -3.0, 0.7))
    c.add_box(scene, "NearBox", (0.5, 0.5, 0.6), c.diffuse_material("Near", (0.7, 0.25, 0.1)),
              location=(-0.55, -4.4, 0.25), rotation=(0.0, 0.0, math.radians(25.0)))
    glow = c.emission_material("Glow", (1.0, 0.8, 0.5), 30.0)
    for k, x in enumerate((-3.0, -1.5, 0.0, 1.5, 3.0)):
        c.add_uv_sphere(scene, f"Bokeh{k}", 0.08, glow, segments=16, rings=8,
                        location=(x, 4.0, 0.9 + 0.35 * (k % 2)))
    c.add_box(scene, "Backdrop", (8.0, 0.2, 3.0), c.diffuse_material("Backdrop", (0.3, 0.4, 0.5)),
              location=(0.0, 4.6, 0.0))
    c.add_light(scene, "Key", "AREA", 250.0, (2.0, -3.5, 3.5), target=(0.0, -2.5, 0.3), size=1.5)
    camera = c.add_camera(scene, (0.0, -6.0, 1.1), (0.0, 0.0, 0.7))
    dof = camera.data.dof
    dof.use_dof = True
    dof.focus_object = focus
    dof.aperture_fstop = 0.07
    dof.aperture_blades = 6
    dof.aperture_rotation = math.radians(30.0)
    dof.aperture_ratio = 1.6


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
