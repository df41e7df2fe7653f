"""Normal maps under grazing light: a normal-mapped Suzanne and floor, a low sun and an area light.

Tests the Normal Map node where it meets light transport, which the node tests (the
normal itself) cannot see: Cycles' bump shadowing term (kernel/closure/bsdf.h) rejects
light on the wrong side of the smooth normal and, with Bump Map Correction on (the
material default), darkens diffuse closures towards grazing light. A low sun and a
mapped normal that tilts far from the smooth one make both large.

The normal map is ``textures/bumps.png`` (64 x 64, 8-bit, read as Non-Color), made here:
the normals of a tangent-space egg crate h ~ sin(2 pi 4 u) sin(2 pi 4 v) of steepest
slope 1.2, tilted up to 50 deg from the surface's.

* ``Floor``: the stage floor, Diffuse BSDF (0.6, 0.6, 0.6) with the map through a Normal
  Map node (tangent space, strength 1) on planar UVs repeated every 1 m.
* ``Suzanne``: Blender's monkey head, Subdivision Surface level 2, smooth, scaled 0.75, at
  (0.1, 0.2, 0.72), turned 25 deg; Principled BSDF at Blender's defaults with base
  (0.8, 0.5, 0.3) and the map (strength 1) on UVs projecting its X and Z, repeated every
  0.5 m of the unscaled mesh.
* ``Sun``: 3 W/m^2, angle 5 deg, 12 deg above the horizon from the right.
* ``Key``: square area light 1 m, 120 W, front left at 3 m.

World (0.02, 0.02, 0.025).  Bounces 4/4.

Run: .venv/bin/python blend_scenes/texture_normal_map.py
"""
import math

import _common as c
import numpy as np

N = 64
CRATES = 4
SLOPE = 1.2          # the steepest slope of the crate: normals tilted up to atan(1.2) = 50 deg


def bump_normals():
    """(N, N, 4) tangent-space normals encoded as 0.5 + 0.5 n, 8-bit values, bottom row first."""
    v, u = (np.mgrid[0:N, 0:N] + 0.5) / N
    w = 2.0 * math.pi * CRATES
    dh_du = SLOPE * np.cos(w * u) * np.sin(w * v)
    dh_dv = SLOPE * np.sin(w * u) * np.cos(w * v)
    n = np.stack([-dh_du, -dh_dv, np.ones_like(u)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    px = np.ones((N, N, 4))
    px[..., :3] = 0.5 + 0.5 * n
    return np.round(px * 255.0) / 255.0


def _normal_mapped(name, image, bl_idname, **values):
    material = c.node_material(name, bl_idname, **values)
    tree = material.node_tree
    shader = next(n for n in tree.nodes if n.bl_idname == bl_idname)
    tex = c.image_texture(tree, image, location=(-600.0, -200.0))
    nmap = c.shader_node(tree, "ShaderNodeNormalMap", location=(-300.0, -200.0), strength=1.0)
    tree.links.new(tex.outputs["Color"], nmap.inputs["Color"])
    tree.links.new(nmap.outputs["Normal"], shader.inputs["Normal"])
    return material


def _xz_uvs(obj, scale):
    """A UV map projecting the object's local X and Z (times ``scale``) onto U and V."""
    mesh = obj.data
    layer = mesh.uv_layers.new(name="UVMap")
    for loop in mesh.loops:
        co = mesh.vertices[loop.vertex_index].co
        layer.data[loop.index].uv = (co.x * scale, co.z * scale)


def build(scene):
    c.set_world(scene, (0.02, 0.02, 0.025))
    image = c.save_texture("bumps.png", bump_normals())
    image.colorspace_settings.name = "Non-Color"
    floor = c.add_floor(scene, _normal_mapped("Floor", image, "ShaderNodeBsdfDiffuse",
                                              color=(0.6, 0.6, 0.6), roughness=0.0))
    c.set_planar_uvs(floor, scale=1.0)
    suzanne = c.add_suzanne(scene, "Suzanne",
                            _normal_mapped("Suzanne", image, "ShaderNodeBsdfPrincipled",
                                           base_color=(0.8, 0.5, 0.3)),
                            subdivision_levels=2, location=(0.1, 0.2, 0.72),
                            rotation=(0.0, 0.0, math.radians(-25.0)), scale=(0.75, 0.75, 0.75))
    _xz_uvs(suzanne, 2.0)
    elevation = math.radians(12.0)
    c.add_light(scene, "Sun", "SUN", 3.0, (4.0 * math.cos(elevation), 0.0, 4.0 * math.sin(elevation)),
                target=(0.0, 0.0, 0.0), angle=math.radians(5.0))
    c.add_light(scene, "Key", "AREA", 120.0, (-2.0, -2.0, 3.0), target=(0.0, 0.0, 0.5), size=1.0)
    c.add_camera(scene, (0.0, -4.2, 2.2), (0.0, 0.0, 0.6), lens_mm=50.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
