"""World shader graphs against Cycles: the background seen by camera rays.

A wide-angle camera looks at the world alone (no objects).  With one sample
per pixel and a 0.01 px filter both engines evaluate the world's shader for
the ray through each pixel centre, so the images agree to float rounding
except where a pixel centre falls on a texel boundary (Closest).
"""

import numpy as np
import pytest

from .harness import assert_agree, pixel_centre_scene, render_both


def _env_image(name="sky", size=(32, 16), seed=11):
    import bpy
    if name in bpy.data.images:
        return bpy.data.images[name]
    w, h = size
    img = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
    rng = np.random.default_rng(seed)
    px = rng.random((h, w, 4)).astype(np.float32) * 2.0
    px[..., 3] = 1.0
    img.pixels.foreach_set(px.ravel())
    img.pack()
    return img


def _scene():
    import bpy
    scene = pixel_centre_scene(48, 32)
    cam_data = bpy.data.cameras.new("cam")
    cam_data.lens = 9.0
    cam = bpy.data.objects.new("cam", cam_data)
    cam.rotation_euler = (1.2, 0.0, 0.6)
    scene.collection.objects.link(cam)
    scene.camera = cam
    world = bpy.data.worlds.new("world")
    scene.world = world
    nt = world.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputWorld")
    return scene, nt, out


def _env(nt, projection="EQUIRECTANGULAR", interpolation="Linear"):
    node = nt.nodes.new("ShaderNodeTexEnvironment")
    node.image = _env_image()
    node.projection = projection
    node.interpolation = interpolation
    return node


def _background(nt, color=None, strength=1.0):
    bg = nt.nodes.new("ShaderNodeBackground")
    bg.inputs["Strength"].default_value = strength
    if color is not None:
        nt.links.new(color, bg.inputs["Color"])
    return bg


def _simple(projection="EQUIRECTANGULAR", interpolation="Linear"):
    def build(nt, out):
        bg = _background(nt, _env(nt, projection, interpolation).outputs["Color"], 1.5)
        nt.links.new(bg.outputs["Background"], out.inputs["Surface"])
    return build


def _strength_from_texture(nt, out):
    bg = _background(nt)
    bg.inputs["Color"].default_value = (0.2, 0.5, 0.9, 1.0)
    nt.links.new(_env(nt).outputs["Color"], bg.inputs["Strength"])
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])


def _mix(nt, out):
    a = _background(nt, _env(nt).outputs["Color"])
    b = _background(nt, strength=0.7)
    b.inputs["Color"].default_value = (1.0, 0.3, 0.1, 1.0)
    mix = nt.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.3
    nt.links.new(a.outputs["Background"], mix.inputs[1])
    nt.links.new(b.outputs["Background"], mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])


def _add_emission(nt, out):
    a = _background(nt, _env(nt, "MIRROR_BALL").outputs["Color"])
    e = nt.nodes.new("ShaderNodeEmission")
    e.inputs["Color"].default_value = (0.1, 0.2, 0.05, 1.0)
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(a.outputs["Background"], add.inputs[0])
    nt.links.new(e.outputs["Emission"], add.inputs[1])
    nt.links.new(add.outputs["Shader"], out.inputs["Surface"])


def _generated_vector(nt, out):
    env = _env(nt)
    nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["Generated"], env.inputs["Vector"])
    bg = _background(nt, env.outputs["Color"])
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])


CASES = {
    "equirectangular": _simple(),
    "equirectangular closest": _simple(interpolation="Closest"),
    "equirectangular cubic": _simple(interpolation="Cubic"),
    "mirror ball": _simple("MIRROR_BALL"),
    "strength from a texture": _strength_from_texture,
    "mix of two backgrounds": _mix,
    "background plus emission": _add_emission,
    "generated coordinates are the direction": _generated_vector,
}


@pytest.fixture(scope="module")
def images():
    out = {}
    for name, build in CASES.items():
        scene, nt, world_out = _scene()
        build(nt, world_out)
        rendered = render_both(scene)
        out[name] = (rendered["CYCLES"], rendered["MCENGINE"])
    return out


@pytest.mark.parametrize("name", list(CASES))
def test_world_agrees_with_cycles(images, name):
    ref, ours = images[name]
    assert ref.std() > 0.01        # the world varies over the frame
    assert_agree(name, ref, ours, edge_fraction=0.03)
