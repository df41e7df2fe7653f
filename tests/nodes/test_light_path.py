"""The Light Path node through light transport, against Cycles by the fidelity statistics.

One scene (built here): a diffuse floor lit by an area light, a mirror behind a row of
cards, and a card behind a glass pane.  Each card's shader depends on the ray that
reaches it, the way people use Light Path:

* an emitter that is blue to camera rays and red to everything else (seen directly it
  is blue, in the mirror and on the floor it lights red: light samples of its emission
  and rays that hit it must both see "not a camera ray");
* an emitter whose strength follows Ray Length and whose colour follows Ray Depth (a
  light sample counts one bounce more, as Cycles does, so both ways of finding it agree);
* a card white to camera rays, green to diffuse rays, magenta to singular ones (what the
  floor's bounce light and the mirror show);
* a card cyan to reflection rays and red otherwise, another whose colour follows Glossy
  Depth, one behind glass that follows Is Transmission Ray and Transmission Depth;
* a card over the floor that is orange to the camera and lets shadow rays through (Is
  Shadow Ray): no shadow under it;
* a card seen through a transparent one, whose colour follows Transparent Depth.

Both engines render it twice (two seeds); ``compare_scene`` tests frame and 8 x 8 block
means per channel (Welch t-tests, Holm, alpha 1e-3), and the frame noise must be low
enough that a 5 % error would be found.
"""
import math

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

from mcengine.evaluation.comparison import POWER_BIAS, detectable_bias  # noqa: E402
from mcengine_blender.batch.comparison import CompareOptions, compare_scene  # noqa: E402

OPTIONS = CompareOptions(samples=256, resolution=(80, 60), seeds=2, alpha=1e-3)


def _material(name, build):
    """A material whose Surface is what ``build(nt, light_path)`` returns."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    path = nt.nodes.new("ShaderNodeLightPath")
    nt.links.new(build(nt, path), out.inputs["Surface"])
    return mat


def _shader(nt, idname, color, strength=None, **inputs):
    node = nt.nodes.new(idname)
    node.inputs["Color"].default_value = (*color, 1.0)
    if strength is not None:
        node.inputs["Strength"].default_value = strength
    for key, value in inputs.items():
        node.inputs[key].default_value = value
    return node.outputs[0]


def _mix_shader(nt, fac, a, b):
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(fac, mix.inputs["Fac"])
    nt.links.new(a, mix.inputs[1])
    nt.links.new(b, mix.inputs[2])
    return mix.outputs["Shader"]


def _mix_color(nt, fac, a, b, clamp=True):
    """Colour a + fac (b - a) (fac clamped to [0, 1] with ``clamp``)."""
    mix = nt.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.clamp_factor = clamp
    nt.links.new(fac, mix.inputs["Factor"])
    next(s for s in mix.inputs if s.identifier == "A_Color").default_value = (*a, 1.0)
    next(s for s in mix.inputs if s.identifier == "B_Color").default_value = (*b, 1.0)
    return next(s for s in mix.outputs if s.identifier == "Result_Color")


def _diffuse_of(nt, color):
    node = nt.nodes.new("ShaderNodeBsdfDiffuse")
    nt.links.new(color, node.inputs["Color"])
    return node.outputs[0]


def _camera_emitter(nt, lp):
    red = _shader(nt, "ShaderNodeEmission", (1.0, 0.15, 0.1), 6.0)
    blue = _shader(nt, "ShaderNodeEmission", (0.1, 0.3, 1.0), 6.0)
    return _mix_shader(nt, lp.outputs["Is Camera Ray"], red, blue)


def _length_emitter(nt, lp):
    emit = nt.nodes.new("ShaderNodeEmission")
    nt.links.new(_mix_color(nt, lp.outputs["Ray Depth"], (1.0, 1.0, 1.0), (0.2, 1.0, 0.3)),
                 emit.inputs["Color"])
    strength = nt.nodes.new("ShaderNodeMix")          # 0.8 x the ray's length
    strength.clamp_factor = False
    nt.links.new(lp.outputs["Ray Length"], strength.inputs["Factor"])
    next(s for s in strength.inputs if s.identifier == "B_Float").default_value = 0.8
    nt.links.new(next(s for s in strength.outputs if s.identifier == "Result_Float"),
                 emit.inputs["Strength"])
    return emit.outputs[0]


def _ray_kind_card(nt, lp):
    by_diffuse = _mix_shader(nt, lp.outputs["Is Diffuse Ray"],
                             _shader(nt, "ShaderNodeBsdfDiffuse", (0.9, 0.9, 0.9)),
                             _shader(nt, "ShaderNodeBsdfDiffuse", (0.1, 0.9, 0.1)))
    return _mix_shader(nt, lp.outputs["Is Singular Ray"], by_diffuse,
                       _shader(nt, "ShaderNodeBsdfDiffuse", (0.9, 0.1, 0.9)))


def _reflection_card(nt, lp):
    return _diffuse_of(nt, _mix_color(nt, lp.outputs["Is Reflection Ray"], (0.9, 0.1, 0.1),
                                      (0.1, 0.8, 0.9)))


def _glossy_depth_card(nt, lp):
    return _diffuse_of(nt, _mix_color(nt, lp.outputs["Glossy Depth"], (0.9, 0.6, 0.1),
                                      (0.1, 0.2, 0.9)))


def _transmission_card(nt, lp):
    half = nt.nodes.new("ShaderNodeMix")              # fac = Transmission Depth / 2
    half.clamp_factor = False
    nt.links.new(lp.outputs["Transmission Depth"], half.inputs["Factor"])
    next(s for s in half.inputs if s.identifier == "B_Float").default_value = 0.5
    by_depth = _mix_color(nt, next(s for s in half.outputs if s.identifier == "Result_Float"),
                          (0.9, 0.9, 0.2), (0.2, 0.9, 0.9))
    return _mix_shader(nt, lp.outputs["Is Transmission Ray"],
                       _shader(nt, "ShaderNodeBsdfDiffuse", (0.9, 0.3, 0.3)), _diffuse_of(nt, by_depth))


def _shadow_card(nt, lp):
    return _mix_shader(nt, lp.outputs["Is Shadow Ray"],
                       _shader(nt, "ShaderNodeBsdfDiffuse", (0.9, 0.45, 0.1)),
                       _shader(nt, "ShaderNodeBsdfTransparent", (1.0, 1.0, 1.0)))


def _transparent_depth_card(nt, lp):
    return _diffuse_of(nt, _mix_color(nt, lp.outputs["Transparent Depth"], (0.9, 0.9, 0.9),
                                      (0.9, 0.2, 0.6)))


def _plain(idname, color, **inputs):
    return lambda nt, lp: _shader(nt, idname, color, **inputs)


def _add(name, material, location, rotation=(math.pi / 2, 0.0, 0.0), size=0.7):
    bpy.ops.mesh.primitive_plane_add(size=size, location=location, rotation=rotation)
    ob = bpy.context.active_object
    ob.name = name
    ob.data.materials.append(material)
    return ob


def _scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = OPTIONS.resolution
    scene.view_settings.view_transform = "Standard"
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world
    cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
    cam.location = (0.0, -6.0, 2.4)
    cam.rotation_euler = (math.radians(75), 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    light = bpy.data.objects.new("key", bpy.data.lights.new("key", "AREA"))
    light.data.energy = 600.0
    light.data.size = 1.5
    light.location = (0.5, -1.5, 4.5)
    scene.collection.objects.link(light)
    _add("floor", _material("floor", _plain("ShaderNodeBsdfDiffuse", (0.6, 0.6, 0.6))),
         (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), size=10.0)
    _add("mirror", _material("mirror", _plain("ShaderNodeBsdfGlossy", (0.9, 0.9, 0.9),
                                              Roughness=0.0)),
         (0.0, 2.5, 1.6), size=5.0)
    cards = [("camera emitter", _camera_emitter), ("length emitter", _length_emitter),
             ("ray kind", _ray_kind_card), ("reflection", _reflection_card),
             ("glossy depth", _glossy_depth_card), ("transmission", _transmission_card)]
    for k, (name, build) in enumerate(cards):
        x = -2.0 + 0.8 * k
        _add(name, _material(name, build), (x, 0.0, 0.8 + 0.5 * (k % 2)))
    # A glass pane in front of the transmission card, a transparent one before the next card.
    _add("glass", _material("glass", _plain("ShaderNodeBsdfGlass", (1.0, 1.0, 1.0),
                                            Roughness=0.0, IOR=1.45)),
         (2.0, -0.5, 1.3), size=0.9)
    _add("transparent depth", _material("transparent depth", _transparent_depth_card),
         (2.6, 0.0, 0.8), size=0.6)
    _add("veil", _material("veil", _plain("ShaderNodeBsdfTransparent", (0.8, 0.8, 0.8))),
         (2.6, -0.4, 0.8), size=0.35)
    _add("shadow card", _material("shadow card", _shadow_card), (-0.3, -1.6, 1.2),
         (0.0, 0.0, 0.0), size=0.8)
    return scene


@pytest.mark.slow
def test_light_path_through_light_transport_agrees_with_cycles():
    comparison = compare_scene(_scene(), OPTIONS, name="light path")
    a = comparison.agreement
    assert np.all(detectable_bias(a) <= POWER_BIAS), \
        f"a {100 * POWER_BIAS:.0f} % error would be missed: detectable {detectable_bias(a)}"
    assert comparison.verdict == "agree", a.summary() + " " + repr(a.differing_blocks()[:5])
