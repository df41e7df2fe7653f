"""Object transforms: rotation, non-uniform and negative scale, parenting.

Tests that meshes, their smooth normals, emissive meshes and area lights are
placed by the full world matrix, including shear (non-uniform scale of a
parent combined with a child's rotation) and mirroring (negative scale, which
flips the triangle winding).  A floor, the light-scene camera, a grey world
of 0.05 and these objects:

* ``TiltedBox``: 0.8 m box rotated (25, 40, 15) deg with scale (1.5, 0.6, 0.9).
* ``Ellipsoid``: smooth UV sphere r 0.5, scale (1.5, 0.7, 1.0), turned 30 deg.
* ``MirroredWedge``: an asymmetric wedge with scale (-1.2, 1.0, 1.0).
* ``MirroredEllipsoid``: smooth UV sphere r 0.35, scale (-1.0, 0.6, 0.6).
* ``Pivot`` (empty, rotated 40 deg, scale (1.4, 1.0, 0.7)) -> ``ChildBox``
  (rotated 20 deg) -> ``GrandchildSphere`` (smooth, sheared by its ancestors).
* ``LightRig`` (empty, rotated, scale (1.6, 0.8, 1.0)) -> ``RigArea``: a
  RECTANGLE area light 1.0 x 0.5 m whose extents the parent's scale stretches.
* ``MirroredArea``: SQUARE area light 0.7 m with scale (-1.2, 1.0, 1.0).
* ``MirroredGlow``: an emissive quad (two-sided) with scale (-1.5, 0.5, 1.0),
  tilted 30 deg.

Run: .venv/bin/python blend_scenes/transforms.py
"""
import math

import _common as c

WEDGE_VERTICES = [(-0.4, -0.3, 0.0), (0.4, -0.3, 0.0), (0.4, 0.3, 0.0), (-0.4, 0.3, 0.0),
                  (-0.4, -0.3, 0.7), (-0.4, 0.3, 0.7), (0.1, 0.3, 0.3)]
WEDGE_FACES = [(0, 3, 2, 1), (0, 1, 4), (1, 2, 6, 4), (2, 3, 5, 6), (3, 0, 4, 5), (4, 6, 5)]


def build(scene):
    c.set_world(scene, (0.05, 0.05, 0.05))
    h = c.STAGE_FLOOR_HALF_SIZE
    c.add_quad(scene, "Floor", [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)],
               c.diffuse_material("Floor", (0.6, 0.6, 0.6)))
    c.add_camera(scene, c.STAGE_CAMERA_LOCATION, c.STAGE_CAMERA_TARGET)

    deg = math.radians
    c.add_box(scene, "TiltedBox", (0.8, 0.8, 0.8),
              c.lambert_principled_material("TiltedBox", (0.2, 0.35, 0.7)),
              location=(-1.7, 0.8, 0.55), rotation=(deg(25.0), deg(40.0), deg(15.0)),
              scale=(1.5, 0.6, 0.9))
    c.add_uv_sphere(scene, "Ellipsoid", 0.5, c.diffuse_material("Ellipsoid", (0.8, 0.8, 0.8)),
                    location=(0.5, 1.0, 0.5), rotation=(0.0, 0.0, deg(30.0)),
                    scale=(1.5, 0.7, 1.0))
    c.add_mesh(scene, "MirroredWedge", WEDGE_VERTICES, WEDGE_FACES,
               c.diffuse_material("Wedge", (0.75, 0.35, 0.15)),
               location=(-0.6, -0.7, 0.0), rotation=(0.0, 0.0, deg(-15.0)),
               scale=(-1.2, 1.0, 1.0))
    c.add_uv_sphere(scene, "MirroredEllipsoid", 0.35,
                    c.diffuse_material("MirroredEllipsoid", (0.3, 0.7, 0.35)),
                    location=(0.5, -1.3, 0.21), scale=(-1.0, 0.6, 0.6))

    pivot = c.add_empty(scene, "Pivot", location=(1.3, 0.1, 0.0),
                        rotation=(0.0, 0.0, deg(40.0)), scale=(1.4, 1.0, 0.7))
    child = c.add_box(scene, "ChildBox", (0.5, 0.5, 0.5),
                      c.diffuse_material("ChildBox", (0.7, 0.7, 0.3)),
                      location=(0.3, 0.0, 0.0), rotation=(0.0, 0.0, deg(20.0)))
    child.parent = pivot
    grandchild = c.add_uv_sphere(scene, "GrandchildSphere", 0.3,
                                 c.diffuse_material("GrandchildSphere", (0.8, 0.5, 0.7)),
                                 location=(0.0, 0.0, 0.9), rotation=(deg(30.0), 0.0, 0.0))
    grandchild.parent = child

    rig = c.add_empty(scene, "LightRig", location=(-0.6, 0.2, 3.0),
                      rotation=(deg(-20.0), 0.0, deg(30.0)), scale=(1.6, 0.8, 1.0))
    area = c.add_light(scene, "RigArea", "AREA", 150.0, (0.0, 0.0, 0.0), color=(1.0, 0.9, 0.8),
                       shape="RECTANGLE", size=1.0, size_y=0.5)
    area.parent = rig
    c.add_light(scene, "MirroredArea", "AREA", 60.0, (2.2, -1.6, 2.0),
                rotation=(deg(30.0), deg(20.0), 0.0), scale=(-1.2, 1.0, 1.0),
                color=(0.6, 0.8, 1.0), shape="SQUARE", size=0.7)
    c.add_quad(scene, "MirroredGlow", [(-0.3, -0.2, 0.0), (0.3, -0.2, 0.0),
                                       (0.3, 0.2, 0.0), (-0.3, 0.2, 0.0)],
               c.emission_material("MirroredGlow", (1.0, 0.5, 0.2), 2.0),
               location=(-1.1, -1.4, 1.0), rotation=(deg(30.0), 0.0, deg(10.0)),
               scale=(-1.5, 0.5, 1.0))


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
