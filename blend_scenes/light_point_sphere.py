"""Sphere light: a point light of radius 0.3 with ``use_soft_falloff`` False.

Tests the true spherical point light (uniform radiance P/(4 pi^2 r^2) over a
sphere of radius r, irradiance P/(4 pi d^2) outside it), its soft shadows, and
``visible_camera`` True: the glowing sphere itself is in the frame.  World black.

Run: .venv/bin/python blend_scenes/light_point_sphere.py
"""
import _common as c


def build(scene):
    c.set_world(scene, (0.0, 0.0, 0.0))
    c.add_stage(scene)
    c.add_light(scene, "SphereLight", "POINT", 300.0, (0.0, 1.0, 2.0),
                shadow_soft_size=0.3, use_soft_falloff=False, visible_camera=True)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
