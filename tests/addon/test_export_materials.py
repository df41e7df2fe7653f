"""Material export: Principled / Diffuse / Emission values and one warning per unsupported material."""
import bpy
import pytest

from .helpers import export_scene, new_mesh_object


def exported(sessions, mat):
    """(Material, warnings about it) after rendering a triangle that uses ``mat``."""
    new_mesh_object("Tri", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)], materials=[mat])
    desc = export_scene(sessions)
    (m,) = [m for m in desc.materials if m.name == mat.name]
    return m, [w for w in desc.warnings if w.startswith(f"material '{mat.name}'")]


def principled(name, **inputs):
    mat = bpy.data.materials.new(name)
    node = mat.node_tree.nodes["Principled BSDF"]
    for key, value in inputs.items():
        node.inputs[key.replace("_", " ")].default_value = value
    return mat


def replace_surface(mat, bl_idname):
    """Make a new shader node the material's surface; returns the node."""
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    node = tree.nodes.new(bl_idname)
    tree.links.new(node.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    return node


def test_principled_without_specular_is_exact(scene, fake_session):
    mat = principled("Matte", Base_Color=(0.2, 0.4, 0.6, 1), Specular_IOR_Level=0.0,
                     Emission_Color=(1, 0.5, 0.25, 1), Emission_Strength=4.0)
    m, warnings = exported(fake_session, mat)
    assert m.base_color == pytest.approx((0.2, 0.4, 0.6))
    assert m.emission == pytest.approx((4, 2, 1))
    assert warnings == []


def test_principled_lobes_are_named_in_one_warning(scene, fake_session):
    mat = principled("Wall", Metallic=1.0)
    m, warnings = exported(fake_session, mat)
    assert warnings == ["material 'Wall': Principled BSDF specular layer (Specular IOR Level 0.5), "
                        "Metallic 1 not supported yet; rendered as Lambert diffuse with base colour "
                        "(0.8, 0.8, 0.8)"]
    assert m.base_color == pytest.approx((0.8, 0.8, 0.8))
    assert scene.mcengine.last_ignored.split(", ")[:2] == ["specular", "metallic"]


def test_texture_into_base_color_gives_exactly_one_warning(scene, fake_session):
    mat = principled("Wood", Base_Color=(0.5, 0.25, 0.1, 1), Specular_IOR_Level=0.0)
    noise = mat.node_tree.nodes.new("ShaderNodeTexNoise")
    mat.node_tree.links.new(noise.outputs["Color"], mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    m, warnings = exported(fake_session, mat)
    assert m.base_color == pytest.approx((0.5, 0.25, 0.1))
    assert warnings == ["material 'Wood': Noise Texture into Principled BSDF 'Base Color' not supported "
                        "yet; rendered as Lambert diffuse with base colour (0.5, 0.25, 0.1) "
                        "(unlinked value of 'Base Color')"]


def test_diffuse_bsdf(scene, fake_session):
    mat = bpy.data.materials.new("Clay")
    node = replace_surface(mat, "ShaderNodeBsdfDiffuse")
    node.inputs["Color"].default_value = (0.3, 0.2, 0.1, 1)
    m, warnings = exported(fake_session, mat)
    assert (m.base_color, m.emission) == (pytest.approx((0.3, 0.2, 0.1)), (0, 0, 0))
    assert warnings == []


def test_rough_diffuse_is_warned_as_oren_nayar(scene, fake_session):
    mat = bpy.data.materials.new("Chalk")
    replace_surface(mat, "ShaderNodeBsdfDiffuse").inputs["Roughness"].default_value = 0.5
    _, warnings = exported(fake_session, mat)
    assert len(warnings) == 1 and "Diffuse BSDF Roughness 0.5 (Oren-Nayar)" in warnings[0]


def test_emission_shader(scene, fake_session):
    mat = bpy.data.materials.new("Lamp")
    node = replace_surface(mat, "ShaderNodeEmission")
    node.inputs["Color"].default_value = (1, 0.5, 0.25, 1)
    node.inputs["Strength"].default_value = 5.0
    m, warnings = exported(fake_session, mat)
    assert (m.base_color, m.emission) == ((0, 0, 0), pytest.approx((5, 2.5, 1.25)))
    assert warnings == []


def test_other_shaders_fall_back_to_grey_diffuse(scene, fake_session):
    mat = bpy.data.materials.new("Velvet")
    replace_surface(mat, "ShaderNodeBsdfSheen")
    m, warnings = exported(fake_session, mat)
    assert m.base_color == (0.8, 0.8, 0.8)
    assert warnings == ["material 'Velvet': Sheen BSDF surface shader not supported yet; rendered as "
                        "Lambert diffuse with base colour (0.8, 0.8, 0.8)"]


@pytest.mark.parametrize("bl_idname,attr", [("ShaderNodeBsdfAnisotropic", "mirror_color"),
                                            ("ShaderNodeBsdfGlass", "glass_color"),
                                            ("ShaderNodeBsdfRefraction", "refraction_color")])
def test_sharp_glossy_glass_and_refraction(scene, fake_session, bl_idname, attr):
    mat = bpy.data.materials.new("Sharp")
    node = replace_surface(mat, bl_idname)
    node.inputs["Color"].default_value = (0.9, 0.5, 0.25, 1.0)
    node.inputs["Roughness"].default_value = 0.0
    if "IOR" in node.inputs:
        node.inputs["IOR"].default_value = 1.33
    m, warnings = exported(fake_session, mat)
    assert getattr(m, attr) == pytest.approx((0.9, 0.5, 0.25))
    assert m.base_color == (0.0, 0.0, 0.0)
    assert m.ior == pytest.approx(1.33 if attr != "mirror_color" else 1.5)
    assert warnings == []


def test_rough_glass_is_rendered_sharp_with_a_warning(scene, fake_session):
    mat = bpy.data.materials.new("Frosted")
    node = replace_surface(mat, "ShaderNodeBsdfGlass")
    node.inputs["Roughness"].default_value = 0.3
    m, warnings = exported(fake_session, mat)
    assert m.glass_color == (1.0, 1.0, 1.0)
    assert warnings == ["material 'Frosted': Glass BSDF Roughness 0.3 not supported yet; rendered as "
                        "sharp glass of colour (1, 1, 1)"]


def test_mix_and_add_shaders_sum_weighted_closures(scene, fake_session):
    mat = bpy.data.materials.new("Mixed")
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (1.0, 0.0, 0.0, 1.0)
    glossy = tree.nodes.new("ShaderNodeBsdfAnisotropic")   # "Glossy BSDF"
    glossy.inputs["Roughness"].default_value = 0.0
    emit = tree.nodes.new("ShaderNodeEmission")
    emit.inputs["Strength"].default_value = 2.0
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs[0].default_value = 0.25
    tree.links.new(diffuse.outputs[0], mix.inputs[1])
    tree.links.new(glossy.outputs[0], mix.inputs[2])
    add = tree.nodes.new("ShaderNodeAddShader")
    tree.links.new(mix.outputs[0], add.inputs[0])
    tree.links.new(emit.outputs[0], add.inputs[1])
    tree.links.new(add.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    m, warnings = exported(fake_session, mat)
    assert m.base_color == pytest.approx((0.75, 0.0, 0.0))
    assert m.mirror_color == pytest.approx((0.2, 0.2, 0.2))   # 0.25 x default colour 0.8
    assert m.emission == pytest.approx((2.0, 2.0, 2.0))
    assert warnings == []


def test_empty_surface_is_black(scene, fake_session):
    mat = bpy.data.materials.new("Nothing")
    mat.node_tree.nodes.remove(mat.node_tree.nodes["Principled BSDF"])
    m, warnings = exported(fake_session, mat)
    assert (m.base_color, m.emission, warnings) == ((0, 0, 0), (0, 0, 0), [])


def test_reroutes_are_followed_and_muted_links_ignored(scene, fake_session):
    mat = bpy.data.materials.new("Routed")
    tree = mat.node_tree
    diffuse = replace_surface(mat, "ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.1, 0.2, 0.3, 1)
    reroute = tree.nodes.new("NodeReroute")
    tree.links.new(diffuse.outputs[0], reroute.inputs[0])
    link = tree.links.new(reroute.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    m, _ = exported(fake_session, mat)
    assert m.base_color == pytest.approx((0.1, 0.2, 0.3))
    link.is_muted = True
    desc = export_scene(fake_session)
    assert [x.base_color for x in desc.materials if x.name == "Routed"] == [(0, 0, 0)]


def test_output_for_eevee_only_is_not_used(scene, fake_session):
    mat = principled("Split", Base_Color=(0.1, 0.1, 0.1, 1), Specular_IOR_Level=0.0)
    tree = mat.node_tree
    tree.nodes["Material Output"].target = "EEVEE"
    cycles_out = tree.nodes.new("ShaderNodeOutputMaterial")
    cycles_out.target = "CYCLES"
    emission = tree.nodes.new("ShaderNodeEmission")
    tree.links.new(emission.outputs[0], cycles_out.inputs["Surface"])
    m, _ = exported(fake_session, mat)
    assert (m.base_color, m.emission) == ((0, 0, 0), (1, 1, 1))
