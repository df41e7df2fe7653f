"""Ray visibility: objects hidden from some kinds of rays (Object > Visibility > Ray
Visibility) and a collection that is Indirect Only in the view layer.

Tests that each kind of ray passes through the objects hidden from it, as Cycles' BVH
does: camera rays (a red ball the camera does not see still casts its shadow, bleeds its
colour and shows in the mirror), shadow and diffuse rays (a box that casts no shadow and
bleeds no colour), glossy rays (a
ball missing from the mirror), transmission rays (a box that vanishes behind a glass pane),
glossy rays again (an emissive panel that lights the floor but is missing from the mirror and
gives the mirror no highlight), and that Indirect Only
hides a collection's objects from the camera alone.

On the stage floor (Diffuse 0.6, ``_common.add_floor``):

* ``Ghost``: a 64x32 smooth UV sphere r 0.45 at (-1.2, 0.2, 0.45), Diffuse (0.8, 0.15, 0.1),
  camera visibility off;
* ``NoShadow``: a 0.7 m cube at (0, -0.2, 0), Diffuse (0.2, 0.5, 0.8), shadow and diffuse
  visibility off.  (Shadow alone off renders differently in the two engines, by 1 % on the
  floor at its base: there light samples pass the box that blocks the diffuse rays aimed at
  the same light, so the MIS weights no longer add up to one and the image depends on each
  engine's probability of picking that light, which is not the same: measured with the
  panel, agreeing with it removed or with diffuse rays passing the box too.)
* ``NotInMirror``: a sphere r 0.35 at (1.2, 0.1, 0.35), Diffuse (0.9, 0.8, 0.2), glossy
  visibility off;
* ``Pane``: a 1.2 x 0.9 m sharp Glass BSDF quad (IOR 1.05) standing at y = -1.2 in front
  of ``Shy``, a 0.4 m cube at (0.9, -0.8, 0), Diffuse (0.3, 0.8, 0.3), transmission
  visibility off;
* ``Panel``: a 1.5 x 0.5 m quad at z = 2.2 over the middle facing down, Emission (1, 0.9,
  0.8) x 6, camera and glossy visibility off (it lights diffuse surfaces only);
* ``Bounce``: a sphere r 0.3 at (-0.3, 0.9, 0.3), Diffuse (0.2, 0.8, 0.4), in the collection
  ``Indirect``, Indirect Only in the view layer;
* ``Mirror``: a 4 x 1.6 m sharp Glossy quad (0.9) standing at y = 1.6 behind them.

Lit by ``Key``, a 2 m square area light of 300 W up front left, and the world (0.08, 0.09,
0.1).  Bounces 6, diffuse 4, glossy 6, transmission 6; Caustics Reflective and Refractive
off (the pane and the mirror would throw the key's caustics on the floor: fireflies that
would drown the comparison).

Run: .venv/bin/python blend_scenes/ray_visibility.py
"""
import _common as c
import bpy


def _hide(obj, *rays):
    for ray in rays:
        setattr(obj, f"visible_{ray}", False)


def build(scene):
    c.set_world(scene, (0.08, 0.09, 0.1))
    c.set_bounces(scene, 6, 4, glossy=6, transmission=6, caustics=False)
    c.add_floor(scene)
    diffuse = c.diffuse_material
    ghost = c.add_uv_sphere(scene, "Ghost", 0.45, diffuse("Ghost", (0.8, 0.15, 0.1)),
                            location=(-1.2, 0.2, 0.45))
    _hide(ghost, "camera")
    box = c.add_box(scene, "NoShadow", (0.7, 0.7, 0.7), diffuse("NoShadow", (0.2, 0.5, 0.8)),
                    location=(0.0, -0.2, 0.0))
    _hide(box, "shadow", "diffuse")
    ball = c.add_uv_sphere(scene, "NotInMirror", 0.35, diffuse("NotInMirror", (0.9, 0.8, 0.2)),
                           location=(1.2, 0.1, 0.35))
    _hide(ball, "glossy")
    glass = c.node_material("Pane", "ShaderNodeBsdfGlass", color=(1.0, 1.0, 1.0), roughness=0.0,
                            ior=1.05)
    c.add_quad(scene, "Pane", [(0.3, -1.2, 0.0), (1.5, -1.2, 0.0), (1.5, -1.2, 0.9),
                               (0.3, -1.2, 0.9)], glass)
    shy = c.add_box(scene, "Shy", (0.4, 0.4, 0.4), diffuse("Shy", (0.3, 0.8, 0.3)),
                    location=(0.9, -0.8, 0.0))
    _hide(shy, "transmission")
    panel = c.add_quad(scene, "Panel", [(-0.75, 0.25, 2.2), (-0.75, -0.25, 2.2), (0.75, -0.25, 2.2),
                                        (0.75, 0.25, 2.2)],
                       c.emission_material("Panel", (1.0, 0.9, 0.8), 6.0))
    _hide(panel, "camera", "glossy")
    indirect = bpy.data.collections.new("Indirect")
    scene.collection.children.link(indirect)
    bounce = c.add_uv_sphere(scene, "Bounce", 0.3, diffuse("Bounce", (0.2, 0.8, 0.4)),
                             location=(-0.3, 0.9, 0.3))
    for collection in list(bounce.users_collection):
        collection.objects.unlink(bounce)
    indirect.objects.link(bounce)
    scene.view_layers[0].layer_collection.children["Indirect"].indirect_only = True
    mirror = c.node_material("Mirror", "ShaderNodeBsdfGlossy", color=(0.9, 0.9, 0.9), roughness=0.0)
    c.add_quad(scene, "Mirror", [(-2.0, 1.6, 0.0), (2.0, 1.6, 0.0), (2.0, 1.6, 1.6), (-2.0, 1.6, 1.6)],
               mirror)
    c.add_light(scene, "Key", "AREA", 300.0, (-2.0, -2.2, 3.6), target=(0.0, 0.0, 0.3),
                shape="SQUARE", size=2.0)
    c.add_camera(scene, (0.0, -4.8, 2.0), (0.0, 0.3, 0.5), lens_mm=38.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
