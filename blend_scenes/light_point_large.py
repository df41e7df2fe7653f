"""Large point lights close to the geometry: sphere and soft-falloff disk.

The near field of a point light with a large radius is where the two
point-light models differ most, and where their sampling is hardest: a
sphere light (``use_soft_falloff`` False) sampled by its visible cap, and the
5.0 soft-falloff light, a disk facing the shading point.  Both are seen by
the camera.  World black.

* ``SphereBig``: 150 W, radius 0.5, ``use_soft_falloff`` False, 0.35 m above
  the back edge of the cube, ``visible_camera`` True.
* ``SoftBig``: 120 W, orange, radius 0.7, ``use_soft_falloff`` True, 0.6 m
  above and behind the sphere, ``visible_camera`` True.

Run: .venv/bin/python blend_scenes/light_point_large.py
"""
import _common as c


def build(scene):
    c.set_world(scene, (0.0, 0.0, 0.0))
    c.add_stage(scene)
    c.add_light(scene, "SphereBig", "POINT", 150.0, (-1.1, 0.9, 1.85),
                shadow_soft_size=0.5, use_soft_falloff=False, visible_camera=True)
    c.add_light(scene, "SoftBig", "POINT", 120.0, (1.2, 0.8, 1.8), color=(1.0, 0.6, 0.3),
                shadow_soft_size=0.7, use_soft_falloff=True, visible_camera=True)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
