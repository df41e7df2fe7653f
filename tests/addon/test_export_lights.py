"""Lamp export: every light type's parameters in Cycles' units."""
import math

import bpy
import numpy as np
import pytest

from .helpers import export_scene


def lamp(scene, kind, name="Lamp", collection=None, **settings):
    data = bpy.data.lights.new(name, kind)
    for key, value in settings.items():
        setattr(data, key, value)
    ob = bpy.data.objects.new(name, data)
    (collection or scene.collection).objects.link(ob)
    return ob


def only_light(sessions):
    desc = export_scene(sessions)
    assert len(desc.lights) == 1
    return desc.lights[0], desc.warnings


def test_point_light(scene, fake_session):
    ob = lamp(scene, "POINT", energy=100.0, color=(1, 0.5, 0.25), exposure=1.0,
              shadow_soft_size=0.3, use_soft_falloff=False, use_shadow=False)
    ob.data.cycles.use_multiple_importance_sampling = False
    ob.data.cycles.max_bounces = 7
    ob.visible_camera, ob.visible_glossy = True, False
    ob.location = (1, 2, 3)
    li, _ = only_light(fake_session)
    assert li.type == "POINT" and li.name == "Lamp"
    assert li.strength == pytest.approx((200, 100, 50))
    assert li.radius == pytest.approx(0.3) and li.soft_falloff is False
    assert (li.cast_shadow, li.use_mis, li.max_bounces) == (False, False, 7)
    assert (li.visible_camera, li.visible_diffuse, li.visible_glossy, li.visible_transmission) == \
        (True, True, False, True)
    np.testing.assert_allclose(li.matrix_world[:3, 3], (1, 2, 3))


def test_spot_light(scene, fake_session):
    ob = lamp(scene, "SPOT", energy=50.0, spot_size=0.8, spot_blend=0.3, shadow_soft_size=0.1)
    ob.rotation_euler = (0.3, 0.2, 0.1)
    bpy.context.view_layer.update()
    li, _ = only_light(fake_session)
    assert (li.type, li.spot_size, li.spot_blend) == ("SPOT", pytest.approx(0.8), pytest.approx(0.3))
    assert li.radius == pytest.approx(0.1) and li.soft_falloff is True
    np.testing.assert_allclose(li.matrix_world, np.array(ob.matrix_world), atol=1e-7)


def test_square_spot_renders_round_without_a_warning(scene, fake_session):
    """Cycles ignores Square (an EEVEE setting; its image is the same with it on): so does
    MC Engine, and it is not a difference to warn of."""
    lamp(scene, "SPOT", spot_size=0.8, use_square=True)
    li, warnings = only_light(fake_session)
    assert li.spot_size == pytest.approx(0.8) and not [w for w in warnings if "square" in w]


def test_sun_light(scene, fake_session):
    lamp(scene, "SUN", energy=3.0, angle=math.radians(10))
    li, _ = only_light(fake_session)
    assert li.type == "SUN" and li.strength == pytest.approx((3, 3, 3))
    assert li.angle == pytest.approx(math.radians(10))
    assert (li.visible_camera, li.cast_shadow, li.use_mis) == (False, True, True)  # 5.0 defaults


@pytest.mark.parametrize("shape,size,size_y,expected", [
    ("RECTANGLE", 2.0, 0.5, (2.0, 0.5)),
    ("ELLIPSE", 2.0, 0.5, (2.0, 0.5)),
    ("SQUARE", 1.5, 0.25, (1.5, 1.5)),
    ("DISK", 1.5, 0.25, (1.5, 1.5)),
])
def test_area_light(scene, fake_session, shape, size, size_y, expected):
    ob = lamp(scene, "AREA", energy=100.0, shape=shape, size=size, size_y=size_y,
              spread=math.radians(60), normalize=False)
    ob.scale = (2, 1, 1)
    li, _ = only_light(fake_session)
    assert (li.shape, li.size_x, li.size_y) == (shape, *map(pytest.approx, expected))
    assert li.spread == pytest.approx(math.radians(60)) and li.normalize is False
    np.testing.assert_allclose(np.linalg.norm(li.matrix_world[:3, :3], axis=0), (2, 1, 1))


def test_temperature_colour(scene, fake_session):
    ob = lamp(scene, "POINT", energy=10.0, color=(1, 1, 0.5), use_temperature=True, temperature=3000)
    tint = np.array(ob.data.temperature_color)
    assert not np.allclose(tint, 1)  # a real tint, so the product below is meaningful
    li, _ = only_light(fake_session)
    np.testing.assert_allclose(li.strength, 10 * np.array([1, 1, 0.5]) * tint, rtol=1e-6)


def test_light_node_tree(scene, fake_session):
    """A constant node tree is folded into the strength (Emission colour x strength, also
    from value nodes and shader mixes); one that varies over the lamp is warned and left
    out."""
    ob = lamp(scene, "POINT", energy=10.0)
    ob.data.use_nodes = True
    tree = ob.data.node_tree
    emission = tree.nodes["Emission"]
    li, warnings = only_light(fake_session)
    assert li.strength == pytest.approx((10, 10, 10)) and not any("light node" in w for w in warnings)
    emission.inputs["Color"].default_value = (0.5, 1, 1, 1)
    emission.inputs["Strength"].default_value = -2.0            # negative: light removed
    li, _ = only_light(fake_session)
    assert li.strength == pytest.approx((-10, -20, -20))
    emission.inputs["Strength"].default_value = 2.0
    li, _ = only_light(fake_session)
    assert li.strength == pytest.approx((10, 20, 20))
    rgb = tree.nodes.new("ShaderNodeRGB")
    rgb.outputs[0].default_value = (0.5, 0.25, 1.0, 1.0)
    tree.links.new(rgb.outputs[0], emission.inputs["Color"])
    times = tree.nodes.new("ShaderNodeMath")
    times.operation = "MULTIPLY"
    times.inputs[0].default_value, times.inputs[1].default_value = 3.0, 2.0
    tree.links.new(times.outputs[0], emission.inputs["Strength"])
    li, warnings = only_light(fake_session)
    assert li.strength == pytest.approx((30, 15, 60)) and not any("light node" in w for w in warnings)
    # Half of it through a Mix Shader with a Transparent BSDF (which emits nothing).
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.5
    tree.links.new(emission.outputs[0], mix.inputs[1])
    tree.links.new(tree.nodes.new("ShaderNodeBsdfTransparent").outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], tree.get_output_node("CYCLES").inputs["Surface"])
    li, _ = only_light(fake_session)
    assert li.strength == pytest.approx((15, 7.5, 30))
    # A Blackbody colour: as the same node gives an emissive material (tested against Cycles).
    from mcengine.scene import Link, Material, ShaderNode
    from mcengine.shaders import ShaderTable
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    blackbody.inputs["Temperature"].default_value = 3000.0
    tree.links.new(blackbody.outputs[0], emission.inputs["Color"])
    li, _ = only_light(fake_session)
    same = ShaderTable([Material(nodes=[ShaderNode("Blackbody", {"Temperature": 3000.0}),
                                        ShaderNode("Emission", {"Color": Link(0, "Color"), "Strength": 1.0})],
                                 surface=Link(1, "Emission"))]).emission[0]
    np.testing.assert_allclose(li.strength, 10 * 6 * 0.5 * same, rtol=1e-6)
    assert not np.allclose(same, same[0])           # a real colour
    # Varying over the lamp: a texture on its coordinates.
    noise = tree.nodes.new("ShaderNodeTexNoise")
    tree.links.new(noise.outputs["Fac"], emission.inputs["Strength"])
    li, warnings = only_light(fake_session)
    assert li.strength == pytest.approx((10, 10, 10))
    assert ("light 'Lamp': light node tree (Mix Shader shader) not supported yet; rendered "
            "without its node tree (Emission strength 1)") in warnings
    tree.links.new(emission.outputs[0], tree.get_output_node("CYCLES").inputs["Surface"])
    _, warnings = only_light(fake_session)
    assert ("light 'Lamp': light node tree (Blackbody into Emission 'Color', Noise Texture into "
            "Emission 'Strength') not supported yet; rendered without its node tree (Emission "
            "strength 1)") in warnings


def test_light_falloff_in_a_lamp_tree(scene, fake_session):
    """Light Falloff's Quadratic without Smooth is its Strength at every distance (Cycles'
    svm_node_light_falloff): the tree folds and scales the lamp.  With Smooth, or through
    Linear or Constant, it varies over the lamp: warned and left out."""
    ob = lamp(scene, "SPOT", energy=10.0)
    ob.data.use_nodes = True
    tree = ob.data.node_tree
    falloff = tree.nodes.new("ShaderNodeLightFalloff")
    falloff.inputs["Strength"].default_value = 25.0
    tree.links.new(falloff.outputs["Quadratic"], tree.nodes["Emission"].inputs["Strength"])
    li, warnings = only_light(fake_session)
    assert li.strength == pytest.approx((250, 250, 250)) and not any("light node" in w for w in warnings)
    falloff.inputs["Smooth"].default_value = 0.5
    li, warnings = only_light(fake_session)
    assert li.strength == pytest.approx((10, 10, 10))
    assert any("light node tree (Light Falloff into Emission 'Strength')" in w for w in warnings)
    falloff.inputs["Smooth"].default_value = 0.0
    tree.links.new(falloff.outputs["Linear"], tree.nodes["Emission"].inputs["Strength"])
    li, warnings = only_light(fake_session)
    assert li.strength == pytest.approx((10, 10, 10))
    assert any("light node tree (Light Falloff into Emission 'Strength')" in w for w in warnings)


IES_TEXT = ("IESNA:LM-63-2002\n[TEST] export\nTILT=NONE\n1 -1 2 3 1 1 2 0 0 0\n1 1 0\n"
            "0 45 90\n0\n100 50 0\n")


def _ies_lamp(scene, mode="INTERNAL", source=None):
    """A point lamp whose IES Texture's Factor, times 3 (a Math node), is the Strength."""
    ob = lamp(scene, "POINT", energy=10.0)
    ob.data.use_nodes = True
    tree = ob.data.node_tree
    ies = tree.nodes.new("ShaderNodeTexIES")
    ies.mode = mode
    if mode == "INTERNAL":
        text = bpy.data.texts.new("profile.ies")
        text.write(IES_TEXT if source is None else source)
        ies.ies = text
    else:
        ies.filepath = source
    times = tree.nodes.new("ShaderNodeMath")
    times.operation = "MULTIPLY"
    times.inputs[1].default_value = 3.0
    tree.links.new(ies.outputs["Fac"], times.inputs[0])
    tree.links.new(times.outputs[0], tree.nodes["Emission"].inputs["Strength"])
    return ob, ies, times


def test_an_ies_texture_becomes_the_lamps_profile(scene, fake_session, tmp_path):
    """The Factor scaling the emission: the tree at Factor 1 times the IES node's Strength is
    the lamp's strength, the file (a Text, or a file by path) its profile."""
    from mcengine.ies import CANDELA_TO_WATTS
    ob, ies, times = _ies_lamp(scene)
    ies.inputs["Strength"].default_value = 0.5
    li, warnings = only_light(fake_session)
    assert li.strength == pytest.approx((15, 15, 15))
    assert not any("IES" in w or "light node" in w for w in warnings)
    np.testing.assert_allclose(li.ies.intensity[0], np.float32([200, 100, 0]) * np.float32(CANDELA_TO_WATTS),
                               rtol=1e-6)     # the candela multiplier 2
    path = tmp_path / "profile.ies"
    path.write_text(IES_TEXT.replace("100 50 0", "10 5 0"))
    ies.mode, ies.filepath = "EXTERNAL", str(path)
    li, warnings = only_light(fake_session)
    assert li.ies.intensity[0, 0] == pytest.approx(20 * CANDELA_TO_WATTS, rel=1e-6)
    assert not any("IES" in w or "light node" in w for w in warnings)


def test_ies_textures_cycles_cannot_read_give_100_and_a_warning(scene, fake_session, tmp_path):
    ob, ies, _ = _ies_lamp(scene, "EXTERNAL", str(tmp_path / "missing.ies"))
    li, warnings = only_light(fake_session)
    assert li.ies is None and li.strength == pytest.approx((3000, 3000, 3000))
    assert any(w.startswith("light 'Lamp': IES Texture 'IES Texture' could not be read (") and
               w.endswith("rendered as Cycles renders it, 100 x Strength in every direction")
               for w in warnings), warnings
    ies.mode, ies.ies = "INTERNAL", bpy.data.texts.new("empty")
    li, warnings = only_light(fake_session)
    assert li.ies is None and li.strength == pytest.approx((3000, 3000, 3000))
    assert any("could not be read (no TILT= line" in w for w in warnings)


def test_an_ies_texture_used_otherwise_is_warned_and_left_out(scene, fake_session):
    """Not proportional to the Factor (Add instead of Multiply), or with a linked Vector: the
    tree is left out (Emission strength 1), warned."""
    ob, ies, times = _ies_lamp(scene)
    times.operation = "ADD"
    li, warnings = only_light(fake_session)
    assert li.ies is None and li.strength == pytest.approx((10, 10, 10))
    assert ("light 'Lamp': the emission is not proportional to IES Texture 'IES Texture' (not "
            "supported yet); rendered without its node tree (Emission strength 1)") in warnings
    times.operation = "MULTIPLY"
    coords = ob.data.node_tree.nodes.new("ShaderNodeTexCoord")
    ob.data.node_tree.links.new(coords.outputs["Normal"], ies.inputs["Vector"])
    li, warnings = only_light(fake_session)
    assert li.ies is None and li.strength == pytest.approx((10, 10, 10))
    assert any("IES Texture 'IES Texture' with a linked Vector or Strength" in w for w in warnings)


def test_portals_are_skipped_with_a_warning(scene, fake_session):
    lamp(scene, "AREA", name="Window").data.cycles.is_portal = True
    desc = export_scene(fake_session)
    assert desc.lights == []
    assert any(w.startswith("light 'Window' is a light portal") for w in desc.warnings)


def test_instanced_lights(scene, fake_session):
    col = bpy.data.collections.new("Lamps")
    lamp(scene, "POINT", name="Bulb", collection=col)
    for x in (0, 4):
        empty = bpy.data.objects.new(f"Fixture{x}", None)
        empty.instance_type, empty.instance_collection = "COLLECTION", col
        empty.location = (x, 0, 0)
        scene.collection.objects.link(empty)
    desc = export_scene(fake_session)
    assert sorted(li.matrix_world[0, 3] for li in desc.lights) == [0, 4]
    assert sorted(li.name for li in desc.lights) == ["Fixture0/Bulb", "Fixture4/Bulb"]


def test_unit_scale_converts_lengths_and_keeps_irradiance(scene, fake_session):
    scene.unit_settings.scale_length = 0.01
    lamp(scene, "POINT", name="Bulb", energy=100.0, shadow_soft_size=10.0).location = (100, 0, 0)
    lamp(scene, "AREA", name="Panel", energy=100.0, shape="RECTANGLE", size=50.0, size_y=20.0)
    desc = export_scene(fake_session)
    bulb, panel = sorted(desc.lights, key=lambda li: li.name)
    assert bulb.radius == pytest.approx(0.1) and bulb.matrix_world[0, 3] == pytest.approx(1.0)
    assert (panel.size_x, panel.size_y) == (pytest.approx(0.5), pytest.approx(0.2))
    # Power x scale^2: the same irradiance as Cycles, which ignores the unit scale.
    assert bulb.strength == pytest.approx((0.01, 0.01, 0.01)) == panel.strength
    assert not [w for w in desc.warnings if "unit scale" in w]


def test_negative_lamps_are_kept_and_non_finite_ones_skipped_with_a_warning(scene, fake_session):
    """Cycles renders negative lamps as negative light (the core does too); a lamp whose
    strength is not finite is skipped, with a warning naming it."""
    lamp(scene, "POINT", name="Sink", energy=-100.0)
    lamp(scene, "POINT", name="Broken", energy=math.inf)
    desc = export_scene(fake_session)
    assert [li.name for li in desc.lights] == ["Sink"]
    assert desc.lights[0].strength == pytest.approx((-100, -100, -100))
    assert any("'Broken'" in w and "not finite" in w for w in desc.warnings)
