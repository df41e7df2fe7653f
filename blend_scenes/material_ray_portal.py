"""The Ray Portal BSDF: rays that go on from another point, in another direction.

Cycles' Ray Portal (bsdf_ray_portal.h, integrate_surface_ray_portal) moves the ray to its
Position (the shading point when unlinked) and sends it along its Direction (on, straight,
when unlinked), with the node's Color as weight; the pass counts as a transparent bounce,
light the new ray finds is taken without MIS weights, and portals stop shadow rays (a
portal is not a Transparent BSDF: the light behind it does not reach through).

* ``Window``: a 1.2 m x 1.6 m upright quad at x -1.6 .. -0.4, y = -2.6 facing the camera, a Ray Portal
  (0.9, 0.9, 1.0) whose Position is the point 1.5 m higher (Geometry Position + (0, 0, 1.5)):
  through it the camera sees the scene from above the objects' tops;
* ``Sphere``: the stage's sphere, a Mix (0.5) of a Glossy BSDF (0.8, 0.8, 0.8), Roughness 0.2
  and a Ray Portal whose Direction is the surface normal (Geometry Normal);
* ``Block``: the stage's small box, a Ray Portal (0.9, 0.5, 0.3) with nothing linked: seen
  through, tinted, but it casts a full shadow; it stands 1 cm above the floor.

``Key``: an area lamp 1.2 m square, 150 W, warm, at (-2.0, -2.2, 3.2) aimed at the objects;
``Sun``: 2 W/m², 5 degrees, from (0.5, 1, 2); world (0.15, 0.16, 0.2).  Bounces 6, diffuse
3, glossy 4, transparent 8.

Run: .venv/bin/python blend_scenes/material_ray_portal.py
"""
import math

import _common as c


def _window_material():
    material, tree, output = c._new_material("Window")
    geometry = c.shader_node(tree, "ShaderNodeNewGeometry", location=(-600.0, 0.0))
    lift = c.shader_node(tree, "ShaderNodeVectorMath", location=(-300.0, 0.0), operation="ADD")
    lift.inputs[1].default_value = (0.0, 0.0, 1.5)
    portal = c.shader_node(tree, "ShaderNodeBsdfRayPortal", color=(0.9, 0.9, 1.0))
    tree.links.new(geometry.outputs["Position"], lift.inputs[0])
    tree.links.new(lift.outputs["Vector"], portal.inputs["Position"])
    tree.links.new(portal.outputs["BSDF"], output.inputs["Surface"])
    return material


def _sphere_material():
    material = c.combine_material("SpherePortal",
                                  ("ShaderNodeBsdfGlossy", {"color": (0.8, 0.8, 0.8),
                                                            "roughness": 0.2}),
                                  ("ShaderNodeBsdfRayPortal", {}), fac=0.5)
    tree = material.node_tree
    geometry = c.shader_node(tree, "ShaderNodeNewGeometry", location=(-600.0, -300.0))
    portal = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfRayPortal")
    tree.links.new(geometry.outputs["Normal"], portal.inputs["Direction"])
    return material


def build(scene):
    c.set_world(scene, (0.15, 0.16, 0.2))
    c.set_bounces(scene, 6, 3, glossy=4, transmission=6)
    scene.cycles.transparent_max_bounces = 8
    stage = c.add_stage(scene)
    stage["sphere"].data.materials[0] = _sphere_material()
    stage["block"].data.materials[0] = c.node_material("BlockPortal", "ShaderNodeBsdfRayPortal",
                                                       color=(0.9, 0.5, 0.3))
    stage["block"].location.z = 0.01     # off the floor (see material_hair.py's docstring)
    c.add_quad(scene, "Window", [(-0.6, 0.0, 0.0), (0.6, 0.0, 0.0), (0.6, 0.0, 1.6),
                                 (-0.6, 0.0, 1.6)], _window_material(), location=(-1.0, -2.6, 0.0))
    c.add_material_lights(scene, fill=False)
    c.add_light(scene, "Sun", "SUN", 2.0, (0.5, 1.0, 2.0), target=(0.0, 0.0, 0.0), angle=math.radians(5.0))


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
