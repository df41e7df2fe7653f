"""Camera: depth of field of an orthographic camera (round aperture, focus distance).

Cycles gives an orthographic camera an aperture radius of 1 / (2 f-stop) in
scene units and makes every lens ray converge on the pinhole ray's point at
the focal distance.  The `camera_ortho` scene (its view, fit, shift and
lights) with depth of field, focused on the sphere: the floor in front of and
behind it is blurred.

Camera: as in camera_ortho.py; focus distance 6.25 m (the sphere), f-stop 0.5
(radius 1 m), 0 blades (a disk).

Run: .venv/bin/python blend_scenes/camera_dof_ortho.py
"""
import _common as c
import camera_ortho


def build(scene):
    camera_ortho.build(scene)
    dof = scene.camera.data.dof
    dof.use_dof = True
    dof.focus_distance = 6.25
    dof.aperture_fstop = 0.5


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
