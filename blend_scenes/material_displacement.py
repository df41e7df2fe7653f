"""True displacement: meshes moved by their material's Displacement before rendering
(Material > Settings > Displacement: 'Displacement Only' and 'Displacement and Bump').

* ``Terrain``: a 3 m square (a quad at z = 0) with a Simple Subdivision Surface modifier of
  level 6 (64 x 64 quads), smooth; Principled BSDF, base (0.42, 0.5, 0.3), roughness 0.7;
  'Displacement Only' by a Displacement node (object space, midlevel 0.5, scale 0.6) of a
  Noise texture's Fac on Generated coordinates (scale 2.5, detail 3).  Its normals are
  recomputed from the moved vertices, as Cycles does.
* ``Rock``: a smooth 64x32 UV sphere r 0.4 at (0.55, -0.35, 0.75), Diffuse BSDF (0.6, 0.55,
  0.5); 'Displacement and Bump' by a Displacement node (object space, midlevel 0, scale
  0.12) of a Voronoi texture's Distance (F1, scale 4) on Object coordinates: moved, its
  normals kept, and bumped by the same displacement evaluated at the undisplaced point.
* ``Sun`` 3 W/m^2, angle 3 deg, from the left at 30 deg elevation; world (0.05, 0.06, 0.08).

Run: .venv/bin/python blend_scenes/material_displacement.py
"""
import math

import _common as c


def _displaced(material, method, texture, coordinate, output, texture_values, midlevel, scale):
    """Displace ``material`` (method 'DISPLACEMENT' or 'BOTH') by a Displacement node (object
    space) of ``texture``'s ``output`` on Texture Coordinate ``coordinate``."""
    material.displacement_method = method
    tree = material.node_tree
    out = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial")
    coords = c.shader_node(tree, "ShaderNodeTexCoord", location=(-900.0, -300.0))
    tex = c.shader_node(tree, texture, location=(-600.0, -300.0), **texture_values)
    disp = c.shader_node(tree, "ShaderNodeDisplacement", location=(-300.0, -300.0), midlevel=midlevel,
                         scale=scale, space="OBJECT")
    tree.links.new(coords.outputs[coordinate], tex.inputs["Vector"])
    tree.links.new(tex.outputs[output], disp.inputs["Height"])
    tree.links.new(disp.outputs["Displacement"], out.inputs["Displacement"])
    return material


def _terrain_material():
    material = c.node_material("Terrain", "ShaderNodeBsdfPrincipled", base_color=(0.42, 0.5, 0.3),
                               roughness=0.7)
    return _displaced(material, "DISPLACEMENT", "ShaderNodeTexNoise", "Generated", "Fac",
                      {"scale": 2.5, "detail": 3.0}, midlevel=0.5, scale=0.6)


def _rock_material():
    material = c.node_material("Rock", "ShaderNodeBsdfDiffuse", color=(0.6, 0.55, 0.5))
    return _displaced(material, "BOTH", "ShaderNodeTexVoronoi", "Object", "Distance", {"scale": 4.0},
                      midlevel=0.0, scale=0.12)


def build(scene):
    c.set_world(scene, (0.05, 0.06, 0.08))
    h = 1.5
    terrain = c.add_mesh(scene, "Terrain", [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)],
                         [(0, 1, 2, 3)], _terrain_material(), smooth=True)
    modifier = terrain.modifiers.new("Subdivision", "SUBSURF")
    modifier.subdivision_type = "SIMPLE"
    modifier.levels = modifier.render_levels = 6
    c.add_uv_sphere(scene, "Rock", 0.4, _rock_material(), location=(0.55, -0.35, 0.75))
    c.add_light(scene, "Sun", "SUN", 3.0, (-3.0, -1.5, 2.0), target=(0.0, 0.0, 0.0),
                angle=math.radians(3.0))
    c.add_camera(scene, (0.0, -4.2, 2.6), (0.0, 0.0, 0.2), lens_mm=40.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
