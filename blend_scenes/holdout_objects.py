"""Holdout objects: an object's own Holdout and a collection's Holdout in the view layer.

Tests that camera rays reaching a holdout object clear the film by its opacity (black, alpha
0, where it is opaque), keep only its transparent closure (the floor seen through it, its
own diffuse colour gone), and that every other ray sees it as it is: it casts its shadow on
the floor and shows in the mirror behind.

On the stage floor (Diffuse 0.6, ``_common.add_floor``):

* ``Held``: a 64x32 smooth UV sphere of radius 0.6 at (-0.7, 0, 0.6), a Mix Shader (0.4) of
  Diffuse (0.8, 0.3, 0.2) and Transparent (0.9, 0.9, 0.9), with Object > Visibility >
  Holdout on;
* ``Solid``: the same sphere at (0.7, 0, 0.6), Diffuse (0.2, 0.6, 0.3), in the collection
  ``Masked`` whose Holdout is on in the view layer;
* ``Mirror``: a 4 x 2 m sharp Glossy quad (0.9) standing at y = 1.5 behind them.

Lit by ``Key``, a 2 m square area light of 300 W up front left, and the world (0.3, 0.35,
0.4).  The film is not transparent (held-out pixels are black with alpha 0).  Bounces 6,
diffuse 4, glossy 6, transmission 6.

Run: .venv/bin/python blend_scenes/holdout_objects.py
"""
import _common as c
import bpy


def build(scene):
    c.set_world(scene, (0.3, 0.35, 0.4))
    c.set_bounces(scene, 6, 4, glossy=6, transmission=6)
    c.add_floor(scene)
    half = c.combine_material("HalfTransparent", ("ShaderNodeBsdfDiffuse", dict(color=(0.8, 0.3, 0.2))),
                              ("ShaderNodeBsdfTransparent", dict(color=(0.9, 0.9, 0.9))), fac=0.4)
    c.add_uv_sphere(scene, "Held", 0.6, half, location=(-0.7, 0.0, 0.6))
    scene.objects["Held"].is_holdout = True
    masked = bpy.data.collections.new("Masked")
    scene.collection.children.link(masked)
    c.add_uv_sphere(scene, "Solid", 0.6, c.node_material("Solid", "ShaderNodeBsdfDiffuse",
                                                         color=(0.2, 0.6, 0.3)),
                    location=(0.7, 0.0, 0.6))
    solid = scene.objects["Solid"]
    for collection in list(solid.users_collection):
        collection.objects.unlink(solid)
    masked.objects.link(solid)
    scene.view_layers[0].layer_collection.children["Masked"].holdout = True
    mirror = c.node_material("Mirror", "ShaderNodeBsdfGlossy", color=(0.9, 0.9, 0.9), roughness=0.0)
    c.add_quad(scene, "Mirror", [(-2.0, 1.5, 0.0), (2.0, 1.5, 0.0), (2.0, 1.5, 2.0), (-2.0, 1.5, 2.0)],
               mirror)
    c.add_light(scene, "Key", "AREA", 300.0, (-2.0, -2.2, 3.6), target=(0.0, 0.0, 0.3),
                shape="SQUARE", size=2.0)
    c.add_camera(scene, (0.0, -4.5, 2.2), (0.0, 0.3, 0.6), lens_mm=40.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
