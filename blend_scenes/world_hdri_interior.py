"""An HDRI-lit interior: a closed room lit only through one large window by an HDRI world.

The world is ``textures/sky_small_sun.exr`` (written by ``world_hdri_sun.py``: a blue sky,
a brown ground and a 2 x 2-texel sun of radiance 900 at 35 deg elevation and azimuth
72 deg from +X), strength 1.2, Sampling Manual with a 1024 x 512 map.  No lamps.

The room spans x, y in [-2, 2] m and z in [0, 2.6] m; each of its surfaces is a separate
flat object with its normal facing into the room: ``Floor`` Diffuse (0.55, 0.42, 0.3),
``Ceiling`` Diffuse 0.85, ``Walls`` Diffuse (0.8, 0.78, 0.72), the north wall (y = 2)
with a 3 x 1.5 m window opening (x in [-1.5, 1.5], z in [0.7, 2.2]) and nothing outside.
The sun shines in through the window onto the floor and the west wall, where
``Cabinet``, a 0.6 x 0.6 x 0.9 m box (Diffuse (0.35, 0.45, 0.6)), casts a shadow.  The
camera stands in the south-east corner, looking at the sunlit floor and west wall with
the window at the top right: the image is direct sun, sky light through the window and
its bounces off light-coloured walls (bounces 4/4).

Run: .venv/bin/python blend_scenes/world_hdri_interior.py
"""
import math

import _common as c

HALF = 2.0             # the room's half width and depth
HEIGHT = 2.6
WINDOW_X = 1.5         # the window spans x in [-WINDOW_X, WINDOW_X]
WINDOW_Z = (0.7, 2.2)  # sill and lintel heights


def _walls():
    """Vertices and faces of the four walls, the north one (y = HALF) with the window."""
    h, z0, z1, w = HALF, WINDOW_Z[0], WINDOW_Z[1], WINDOW_X
    vertices = [(-h, -h, 0), (h, -h, 0), (h, -h, HEIGHT), (-h, -h, HEIGHT),   # south
                (h, -h, 0), (h, h, 0), (h, h, HEIGHT), (h, -h, HEIGHT),       # east
                (-h, h, 0), (-h, -h, 0), (-h, -h, HEIGHT), (-h, h, HEIGHT)]   # west
    faces = [(0, 3, 2, 1), (4, 7, 6, 5), (8, 11, 10, 9)]
    # North wall: a 4 x 4 grid of vertices in x (-h, -w, w, h) and z (0, z0, z1, HEIGHT);
    # every cell but the middle one (the window) is a face, facing -Y.
    xs, zs = (-h, -w, w, h), (0.0, z0, z1, HEIGHT)
    base = len(vertices)
    vertices += [(x, h, z) for z in zs for x in xs]
    for row in range(3):
        for col in range(3):
            if (row, col) == (1, 1):
                continue
            a = base + 4 * row + col
            faces.append((a, a + 4, a + 5, a + 1))
    return vertices, faces


def build(scene):
    env = c.environment_world(scene, strength=1.2, map_resolution=1024)
    env.image = c.load_texture("sky_small_sun.exr", "Linear Rec.709")
    h = HALF
    c.add_quad(scene, "Floor", [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)],
               c.diffuse_material("Floor", (0.55, 0.42, 0.3)))
    c.add_quad(scene, "Ceiling", [(-h, -h, HEIGHT), (-h, h, HEIGHT), (h, h, HEIGHT), (h, -h, HEIGHT)],
               c.diffuse_material("Ceiling", (0.85, 0.85, 0.85)))
    vertices, faces = _walls()
    c.add_mesh(scene, "Walls", vertices, faces, c.diffuse_material("Walls", (0.8, 0.78, 0.72)))
    c.add_box(scene, "Cabinet", (0.6, 0.6, 0.9), c.diffuse_material("Cabinet", (0.35, 0.45, 0.6)),
              location=(-0.9, 0.5, 0.0), rotation=(0.0, 0.0, math.radians(15.0)))
    c.add_camera(scene, (1.7, -1.75, 1.6), (-0.9, 0.6, 0.5), lens_mm=20.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
