"""F12 with the real core: a tiny scene whose pixels are known exactly."""
import bpy
import numpy as np

from .helpers import new_mesh_object


def test_f12_renders_with_the_real_core(scene, render_exr):
    """An emitter over the upper half of an orthographic view: every camera sample there sees
    exactly its radiance (black base colour, no world), the lower half sees nothing."""
    scene.render.resolution_x, scene.render.resolution_y = 16, 12
    scene.camera.data.type, scene.camera.data.ortho_scale = "ORTHO", 4.0
    scene.world = None
    scene.cycles.samples = 4
    scene.cycles.use_denoising = scene.cycles.use_adaptive_sampling = False
    mat = bpy.data.materials.new("Glow")
    node = mat.node_tree.nodes["Principled BSDF"]
    node.inputs["Base Color"].default_value = (0, 0, 0, 1)
    node.inputs["Specular IOR Level"].default_value = 0.0
    node.inputs["Emission Color"].default_value = (1, 0.5, 0.25, 1)
    node.inputs["Emission Strength"].default_value = 2.0
    new_mesh_object("Upper", [(-5, 0, -1), (5, 0, -1), (5, 5, -1), (-5, 5, -1)], [(0, 1, 2, 3)],
                    materials=[mat])
    image = render_exr()
    assert image.shape == (12, 16, 4)
    # The edge is between rows 5 and 6; the Blackman-Harris filter reaches 1.5 px, so rows
    # 0-3 and 8-11 cannot see across it.
    np.testing.assert_allclose(image[:4], np.broadcast_to([2, 1, 0.5, 1], (4, 16, 4)), rtol=1e-6)
    np.testing.assert_allclose(image[8:], np.broadcast_to([0, 0, 0, 1], (4, 16, 4)), atol=1e-7)
    assert scene.mcengine.last_effects == (
        "Lights: 2 emissive triangles; surfaces: emission; no textures | simulated: light sampling, "
        "MIS weights | skipped: lamp hits, world lookups, transparent shadows, caustic paths, "
        "subsurface walks, light linking")


def test_frames_with_the_same_triangles_reuse_the_bvh(scene, addon):
    """Animation frames and viewport restarts: the camera moved -> the BVH is reused; the
    object moved -> it is built again (mcengine.accel_cache)."""
    scene.render.resolution_x, scene.render.resolution_y = 8, 8
    scene.cycles.samples = 1
    card = new_mesh_object("Card", [(-1, -1, -3), (1, -1, -3), (1, 1, -3), (-1, 1, -3)],
                           [(0, 1, 2, 3)])
    reused = []
    for move in (None, "camera", "object", None):
        if move == "camera":
            scene.camera.location.x += 0.1
        elif move == "object":
            card.location.x += 0.1
        bpy.ops.render.render()
        reused.append(addon.engine.last_render["stats"].extra["bvh_reused"])
    assert reused[1:] == [True, False, True]


def test_objects_without_material_render_as_cycles_renders_them(scene, render_exr):
    """Blender 5.0's Cycles shades a mesh without material, and an empty slot, as a default
    Principled BSDF, not as the 0.8 grey diffuse of its own default_surface shader (10 %
    brighter here).  Under a sun of angle 0 with no bounces, every pixel of an orthographic
    view of the plane has the same value, so one sample per pixel of each engine gives it;
    the bound is the material oracles' (float32 tables against float64)."""
    scene.render.resolution_x, scene.render.resolution_y = 8, 6
    scene.camera.data.type, scene.camera.data.ortho_scale = "ORTHO", 4.0
    scene.camera.rotation_euler = (1.2, 0.0, 0.0)     # 69 degrees off the plane's normal
    scene.camera.location = (0.0, -6.0, 2.0)
    scene.world = None
    scene.cycles.samples, scene.cycles.max_bounces = 1, 0
    scene.cycles.use_adaptive_sampling = False
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy, sun.data.angle = 3.0, 0.0
    sun.rotation_euler = (0.6, 0.2, 0.5)
    scene.collection.objects.link(sun)
    new_mesh_object("Bare", [(-9, -9, -1), (0, -9, -1), (0, 9, -1), (-9, 9, -1)], [(0, 1, 2, 3)])
    slot = new_mesh_object("Slot", [(0, -9, -1), (9, -9, -1), (9, 9, -1), (0, 9, -1)], [(0, 1, 2, 3)])
    slot.data.materials.append(None)
    ours = render_exr()
    scene.render.engine = "CYCLES"
    theirs = render_exr()
    assert theirs[..., 0].std() < 1e-4 * theirs[..., 0].mean()     # the same value everywhere
    np.testing.assert_allclose(ours, theirs, rtol=2e-3)
