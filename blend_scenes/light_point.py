"""Point lights: a hard one (radius 0) and a coloured soft one (radius 0.3).

Tests the point light as a delta light (radius 0: intensity P/(4 pi) W/sr, hard
shadows) and the 5.0 default soft point light (radius 0.3 with
``use_soft_falloff`` True: a disk facing the shading point, soft shadows),
light colour, and an otherwise black world.

Run: .venv/bin/python blend_scenes/light_point.py  (writes light_point.blend)
"""
import _common as c


def build(scene):
    c.set_world(scene, (0.0, 0.0, 0.0))
    c.add_stage(scene)
    c.add_light(scene, "PointHard", "POINT", 500.0, (-1.6, -1.2, 3.0),
                shadow_soft_size=0.0)
    c.add_light(scene, "PointSoft", "POINT", 300.0, (2.2, 1.6, 2.4),
                color=(1.0, 0.55, 0.25), shadow_soft_size=0.3, use_soft_falloff=True)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
