"""World light only: a constant sky (0.2, 0.4, 0.6) x 1.5 and no lamps.

Tests background lighting and its importance sampling, ambient-occlusion-like
shading of the floor and objects, and the world seen directly (the camera is
lower than in the other stages so the sky shows above the horizon).

Run: .venv/bin/python blend_scenes/world_color.py
"""
import _common as c

WORLD_COLOR = (0.2, 0.4, 0.6)
WORLD_STRENGTH = 1.5


def build(scene):
    c.set_world(scene, WORLD_COLOR, WORLD_STRENGTH)
    stage = c.add_stage(scene)
    camera = stage["camera"]
    camera.location = (0.0, -6.0, 1.6)
    c.look_at(camera, (0.0, 0.0, 0.6))


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
