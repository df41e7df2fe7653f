"""Material export: shader graphs copied node by node, and one warning per unsupported material."""
import bpy
import pytest

from mcengine.kernels.svm.nodes import INPUTS
from mcengine.scene import Link

from .helpers import export_scene, new_mesh_object


def exported(sessions, mat):
    """(Material, warnings about it) after rendering a triangle that uses ``mat``."""
    new_mesh_object("Tri", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)], materials=[mat])
    desc = export_scene(sessions)
    (m,) = [m for m in desc.materials if m.name == mat.name]
    return m, [w for w in desc.warnings if w.startswith(f"material '{mat.name}'")]


def surface(m):
    """The node the material output receives."""
    return m.nodes[m.surface.node]


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


def test_principled_inputs_and_distribution_are_copied(scene, fake_session):
    mat = principled("Plastic", Base_Color=(0.2, 0.4, 0.6, 1), Roughness=0.3, Metallic=0.25,
                     Coat_Weight=0.5, Coat_Tint=(1, 0.5, 0.5, 1), Sheen_Weight=0.2,
                     Emission_Color=(1, 0.5, 0.25, 1), Emission_Strength=4.0)
    mat.node_tree.nodes["Principled BSDF"].distribution = "GGX"
    m, warnings = exported(fake_session, mat)
    node = surface(m)
    assert node.type == "BsdfPrincipled" and node.props["distribution"] == "GGX"
    # Every input, but the Tangent: left to the core's compiler, as Cycles links its default.
    assert set(node.inputs) == {socket.name for socket in INPUTS["BsdfPrincipled"]
                                if not socket.name.startswith("prop:")} - {"Tangent"}
    assert node.inputs["Base Color"] == pytest.approx((0.2, 0.4, 0.6))
    assert (node.inputs["Roughness"], node.inputs["Metallic"], node.inputs["Coat Weight"]) == \
        pytest.approx((0.3, 0.25, 0.5))
    assert node.inputs["Coat Tint"] == pytest.approx((1, 0.5, 0.5))
    assert node.inputs["Emission Strength"] == 4.0
    assert warnings == []


def test_unsupported_texture_into_base_color_gives_exactly_one_warning(scene, fake_session):
    mat = principled("Wood", Base_Color=(0.5, 0.25, 0.1, 1))
    info = mat.node_tree.nodes.new("ShaderNodeHairInfo")
    mat.node_tree.links.new(info.outputs["Is Strand"],
                            mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    m, warnings = exported(fake_session, mat)
    assert surface(m).inputs["Base Color"] == pytest.approx((0.5, 0.25, 0.1))
    assert warnings == ["material 'Wood': Curves Info into Principled BSDF 'Base Color' not "
                        "supported yet; unlinked value of Principled BSDF 'Base Color' used"]
    assert "HairInfo node" in scene.mcengine.last_ignored


@pytest.mark.parametrize("change", ["translation", "scale", "use_min", "mapping_x", "mapping"])
def test_a_texture_nodes_texture_mapping_is_warned(scene, fake_session, change):
    """The legacy Texture Mapping of a texture node (its sidebar; Cycles applies it) is not
    evaluated: any change from the identity is named, the default is not."""
    mat = principled("Cloud")
    tree = mat.node_tree
    noise = tree.nodes.new("ShaderNodeTexNoise")
    tree.links.new(noise.outputs["Fac"], tree.nodes["Principled BSDF"].inputs["Roughness"])
    _, warnings = exported(fake_session, mat)
    assert warnings == []
    mapping = noise.texture_mapping
    value = {"translation": (0.5, 0.0, 0.0), "scale": (2.0, 1.0, 1.0), "use_min": True,
             "mapping_x": "Y", "mapping": "SPHERE"}[change]
    setattr(mapping, change, value)
    _, warnings = exported(fake_session, mat)
    assert warnings == ["material 'Cloud': Noise Texture Texture Mapping (the node's sidebar) not "
                        "supported yet; Noise Texture read at its unmapped coordinates"]


def test_linked_texture_is_copied_with_its_properties(scene, fake_session):
    mat = principled("Tiles")
    tree = mat.node_tree
    checker = tree.nodes.new("ShaderNodeTexChecker")
    checker.inputs["Scale"].default_value = 7.0
    coords = tree.nodes.new("ShaderNodeTexCoord")
    reroute = tree.nodes.new("NodeReroute")
    tree.links.new(coords.outputs["UV"], reroute.inputs[0])
    tree.links.new(reroute.outputs[0], checker.inputs["Vector"])
    tree.links.new(checker.outputs["Fac"], tree.nodes["Principled BSDF"].inputs["Roughness"])
    m, warnings = exported(fake_session, mat)
    link = surface(m).inputs["Roughness"]
    assert isinstance(link, Link) and link.socket == "Fac"
    tex = m.nodes[link.node]
    assert tex.type == "TexChecker" and tex.inputs["Scale"] == 7.0
    vector = tex.inputs["Vector"]
    assert isinstance(vector, Link) and vector.socket == "UV" and m.nodes[vector.node].type == "TexCoord"
    assert warnings == []


@pytest.mark.parametrize("distance,expected", [(0.0, 3.5), (0.25, -1.0)])
def test_ambient_occlusion_reads_the_worlds_distance_for_a_distance_of_0(scene, fake_session,
                                                                         distance, expected):
    """Cycles' AO node takes the world's AO distance (World > Light Settings) where its own
    Distance is 0 and unlinked: the export writes it (or -1) as ``global_distance``."""
    scene.world = bpy.data.worlds.new("World")
    scene.world.light_settings.distance = 3.5
    mat = principled("Dirt")
    tree = mat.node_tree
    ao = tree.nodes.new("ShaderNodeAmbientOcclusion")
    ao.inputs["Distance"].default_value = distance
    ao.samples, ao.only_local = 5, True
    tree.links.new(ao.outputs["AO"], tree.nodes["Principled BSDF"].inputs["Roughness"])
    m, warnings = exported(fake_session, mat)
    node = m.nodes[surface(m).inputs["Roughness"].node]
    assert node.type == "AmbientOcclusion" and node.inputs["Distance"] == distance
    assert (node.props["global_distance"], node.props["samples"], node.props["only_local"]) == \
        (expected, 5.0, 1.0)
    assert warnings == []


def test_an_ies_texture_carries_its_profile_and_whether_its_vector_is_implicit(scene, fake_session,
                                                                              tmp_path):
    """The IES Texture's table is its profile packed for the kernel; unlinked, its Vector is
    the implicit one (Incoming in object space); a file Cycles cannot read gives Cycles' 100
    everywhere, warned (not per material: the node's file is what is wrong)."""
    import numpy as np

    from mcengine.ies import FAILED_PROFILE, parse_ies
    text = ("IESNA\nTILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n300 100\n")
    block = bpy.data.texts.new("p.ies")
    block.write(text)
    mat = principled("Lamp shade")
    tree = mat.node_tree
    ies = tree.nodes.new("ShaderNodeTexIES")
    ies.ies = block
    tree.links.new(ies.outputs["Fac"], tree.nodes["Principled BSDF"].inputs["Roughness"])
    m, warnings = exported(fake_session, mat)
    node = m.nodes[surface(m).inputs["Roughness"].node]
    assert node.type == "TexIES" and node.props["implicit_vector"] == 1.0
    np.testing.assert_array_equal(node.props["table"], parse_ies(text).packed())
    assert warnings == []
    coords = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(coords.outputs["Normal"], ies.inputs["Vector"])
    ies.mode, ies.filepath = "EXTERNAL", str(tmp_path / "gone.ies")
    m, _ = exported(fake_session, mat)
    node = m.nodes[surface(m).inputs["Roughness"].node]
    assert node.props["implicit_vector"] == 0.0
    np.testing.assert_array_equal(node.props["table"], FAILED_PROFILE.packed())
    assert any(w.startswith("IES Texture 'IES Texture' could not be read ([Errno 2]") and
               w.endswith("rendered as Cycles renders it, 100 x Strength in every direction")
               for w in export_scene(fake_session).warnings)


def test_node_groups_are_flattened(scene, fake_session):
    group = bpy.data.node_groups.new("Tint", "ShaderNodeTree")
    group.interface.new_socket("In", in_out="INPUT", socket_type="NodeSocketColor")
    group.interface.new_socket("Out", in_out="OUTPUT", socket_type="NodeSocketColor")
    g_in = group.nodes.new("NodeGroupInput")
    g_out = group.nodes.new("NodeGroupOutput")
    inner = group.nodes.new("ShaderNodeTexChecker")
    group.links.new(g_in.outputs[0], inner.inputs["Color1"])
    group.links.new(inner.outputs["Color"], g_out.inputs[0])
    mat = principled("Grouped")
    tree = mat.node_tree
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    node.inputs[0].default_value = (0.1, 0.2, 0.3, 1.0)
    tree.links.new(node.outputs[0], tree.nodes["Principled BSDF"].inputs["Base Color"])
    m, warnings = exported(fake_session, mat)
    link = surface(m).inputs["Base Color"]
    tex = m.nodes[link.node]
    assert tex.type == "TexChecker" and link.socket == "Color"
    assert tex.inputs["Color1"] == pytest.approx((0.1, 0.2, 0.3))
    assert warnings == []


def test_diffuse_bsdf_with_roughness(scene, fake_session):
    mat = bpy.data.materials.new("Clay")
    node = replace_surface(mat, "ShaderNodeBsdfDiffuse")
    node.inputs["Color"].default_value = (0.3, 0.2, 0.1, 1)
    node.inputs["Roughness"].default_value = 0.5
    m, warnings = exported(fake_session, mat)
    assert surface(m).type == "BsdfDiffuse"
    assert surface(m).inputs["Color"] == pytest.approx((0.3, 0.2, 0.1))
    assert surface(m).inputs["Roughness"] == 0.5
    assert warnings == []


def test_emission_shader(scene, fake_session):
    mat = bpy.data.materials.new("Lamp")
    node = replace_surface(mat, "ShaderNodeEmission")
    node.inputs["Color"].default_value = (1, 0.5, 0.25, 1)
    node.inputs["Strength"].default_value = 5.0
    m, warnings = exported(fake_session, mat)
    assert surface(m).type == "Emission"
    assert (surface(m).inputs["Color"], surface(m).inputs["Strength"]) == \
        (pytest.approx((1, 0.5, 0.25)), 5.0)
    assert warnings == []


@pytest.mark.parametrize("bl_idname,kind", [("ShaderNodeBsdfAnisotropic", "BsdfGlossy"),
                                            ("ShaderNodeBsdfGlass", "BsdfGlass"),
                                            ("ShaderNodeBsdfRefraction", "BsdfRefraction"),
                                            ("ShaderNodeBsdfTranslucent", "BsdfTranslucent"),
                                            ("ShaderNodeBsdfTransparent", "BsdfTransparent"),
                                            ("ShaderNodeBsdfSheen", "BsdfSheen"),
                                            ("ShaderNodeHoldout", "Holdout")])
def test_every_bsdf_node_is_copied(scene, fake_session, bl_idname, kind):
    mat = bpy.data.materials.new("Node")
    node = replace_surface(mat, bl_idname)
    if "Color" in node.inputs:
        node.inputs["Color"].default_value = (0.9, 0.5, 0.25, 1.0)
    if "Roughness" in node.inputs:
        node.inputs["Roughness"].default_value = 0.2
    if "IOR" in node.inputs:
        node.inputs["IOR"].default_value = 1.33
    m, warnings = exported(fake_session, mat)
    out = surface(m)
    assert out.type == kind
    if "Color" in out.inputs:
        assert out.inputs["Color"] == pytest.approx((0.9, 0.5, 0.25))
    if "IOR" in out.inputs:
        assert out.inputs["IOR"] == pytest.approx(1.33)
    if hasattr(node, "distribution") and kind != "BsdfSheen":
        assert out.props["distribution"] == node.distribution
    assert warnings == []


def test_unsupported_shaders_fall_back_to_grey_diffuse(scene, fake_session):
    mat = bpy.data.materials.new("Strands")
    replace_surface(mat, "ShaderNodeBsdfHairPrincipled")
    m, warnings = exported(fake_session, mat)
    assert surface(m).type == "BsdfDiffuse" and surface(m).inputs["Color"] == (0.8, 0.8, 0.8)
    assert warnings == ["material 'Strands': Principled Hair BSDF surface shader not supported "
                        "yet; Principled Hair BSDF rendered as 0.8 grey diffuse"]


@pytest.mark.parametrize("fresnel", ["F82", "PHYSICAL_CONDUCTOR"])
def test_metallic_node_is_copied_with_its_fresnel_type(scene, fake_session, fresnel):
    mat = bpy.data.materials.new("Gold")
    node = replace_surface(mat, "ShaderNodeBsdfMetallic")
    node.fresnel_type = fresnel
    # the other type's inputs are unavailable (not found by name), but still copied
    sockets = {s.identifier: s for s in node.inputs}
    sockets["Base Color"].default_value = (1.0, 0.8, 0.3, 1)
    sockets["Edge Tint"].default_value = (1.0, 0.9, 0.7, 1)
    sockets["IOR"].default_value = (0.18, 0.42, 1.37)
    sockets["Extinction"].default_value = (3.42, 2.35, 1.77)
    sockets["Roughness"].default_value = 0.35
    m, warnings = exported(fake_session, mat)
    out = surface(m)
    assert out.type == "BsdfMetallic" and out.props["fresnel_type"] == fresnel
    assert out.inputs["Base Color"] == pytest.approx((1.0, 0.8, 0.3))
    assert out.inputs["Edge Tint"] == pytest.approx((1.0, 0.9, 0.7))
    assert out.inputs["IOR"] == pytest.approx((0.18, 0.42, 1.37))
    assert out.inputs["Extinction"] == pytest.approx((3.42, 2.35, 1.77))
    assert out.inputs["Roughness"] == pytest.approx(0.35)
    assert warnings == []


def test_subsurface_is_exported_with_its_method_unwarned(scene, fake_session):
    mat = principled("Skin", Subsurface_Weight=0.5, Subsurface_Anisotropy=0.25,
                     Thin_Film_Thickness=300.0)
    out, warnings = exported(fake_session, mat)
    assert warnings == []                       # random walk and thin film: as Cycles renders them
    node = surface(out)
    assert node.inputs["Subsurface Weight"] == 0.5
    assert node.inputs["Subsurface Anisotropy"] == 0.25
    assert node.inputs["Subsurface IOR"] == pytest.approx(1.4)
    assert node.props["subsurface_method"] == "RANDOM_WALK"
    assert node.inputs["Thin Film Thickness"] == 300.0 and node.inputs["Thin Film IOR"] == pytest.approx(1.33)

    mat.node_tree.nodes["Principled BSDF"].subsurface_method = "BURLEY"
    wax = principled("Wax")
    replace_surface(wax, "ShaderNodeSubsurfaceScattering").falloff = "BURLEY"
    for material, kind, prop in ((mat, "BsdfPrincipled", "subsurface_method"),
                                 (wax, "SubsurfaceScattering", "falloff")):
        out, warnings = exported(fake_session, material)
        assert warnings == []
        assert surface(out).type == kind and surface(out).props[prop] == "BURLEY"


@pytest.mark.parametrize("bl_idname,anisotropy", [("ShaderNodeBsdfPrincipled", "Anisotropic"),
                                                  ("ShaderNodeBsdfMetallic", "Anisotropy"),
                                                  ("ShaderNodeBsdfAnisotropic", "Anisotropy")])
def test_anisotropy_along_the_default_tangent_is_not_warned(scene, fake_session, bl_idname, anisotropy):
    """An unlinked Tangent is left out: the core links Cycles' default there (Geometry's
    radial tangent about object Z)."""
    mat = bpy.data.materials.new("Brushed")
    node = replace_surface(mat, bl_idname)
    node.inputs[anisotropy].default_value = 0.5
    m, warnings = exported(fake_session, mat)
    assert "Tangent" not in surface(m).inputs and warnings == []


def test_mix_and_add_shaders_are_links_between_nodes(scene, fake_session):
    mat = bpy.data.materials.new("Mixed")
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    glossy = tree.nodes.new("ShaderNodeBsdfAnisotropic")   # "Glossy BSDF"
    emit = tree.nodes.new("ShaderNodeEmission")
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs[0].default_value = 0.25
    tree.links.new(diffuse.outputs[0], mix.inputs[1])
    tree.links.new(glossy.outputs[0], mix.inputs[2])
    add = tree.nodes.new("ShaderNodeAddShader")
    tree.links.new(mix.outputs[0], add.inputs[0])
    tree.links.new(emit.outputs[0], add.inputs[1])
    tree.links.new(add.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    m, warnings = exported(fake_session, mat)
    out = surface(m)
    assert out.type == "AddShader"
    mixed = m.nodes[out.inputs["Shader"].node]
    assert mixed.type == "MixShader" and mixed.inputs["Fac"] == 0.25
    assert m.nodes[mixed.inputs["Shader"].node].type == "BsdfDiffuse"
    assert m.nodes[mixed.inputs["Shader_001"].node].type == "BsdfGlossy"
    assert m.nodes[out.inputs["Shader_001"].node].type == "Emission"
    assert all(isinstance(v, Link) for v in out.inputs.values())
    assert warnings == []


def test_empty_surface_is_black(scene, fake_session):
    mat = bpy.data.materials.new("Nothing")
    mat.node_tree.nodes.remove(mat.node_tree.nodes["Principled BSDF"])
    m, warnings = exported(fake_session, mat)
    assert (m.nodes, m.surface, m.base_color, warnings) == ([], None, (0, 0, 0), [])


def test_reroutes_muted_links_and_muted_nodes(scene, fake_session):
    mat = bpy.data.materials.new("Routed")
    tree = mat.node_tree
    diffuse = replace_surface(mat, "ShaderNodeBsdfDiffuse")
    emit = tree.nodes.new("ShaderNodeEmission")
    mix = tree.nodes.new("ShaderNodeMixShader")
    tree.links.new(diffuse.outputs[0], mix.inputs[1])
    tree.links.new(emit.outputs[0], mix.inputs[2])
    reroute = tree.nodes.new("NodeReroute")
    tree.links.new(mix.outputs[0], reroute.inputs[0])
    link = tree.links.new(reroute.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    m, _ = exported(fake_session, mat)
    assert surface(m).type == "MixShader"
    mix.mute = True            # a muted Mix Shader passes its first shader through
    m, _ = exported(fake_session, mat)
    assert surface(m).type == "BsdfDiffuse"
    link.is_muted = True
    desc = export_scene(fake_session)
    assert [x.surface for x in desc.materials if x.name == "Routed"] == [None]


def test_output_for_eevee_only_is_not_used(scene, fake_session):
    mat = principled("Split")
    tree = mat.node_tree
    tree.nodes["Material Output"].target = "EEVEE"
    cycles_out = tree.nodes.new("ShaderNodeOutputMaterial")
    cycles_out.target = "CYCLES"
    emission = tree.nodes.new("ShaderNodeEmission")
    tree.links.new(emission.outputs[0], cycles_out.inputs["Surface"])
    m, _ = exported(fake_session, mat)
    assert surface(m).type == "Emission"


def test_material_settings_cycles_reads(scene, fake_session):
    mat = principled("Leaf")
    mat.use_transparent_shadow = False
    mat.cycles.use_bump_map_correction = False
    m, _ = exported(fake_session, mat)
    assert (m.use_transparent_shadow, m.use_bump_map_correction) == (False, False)


@pytest.mark.parametrize("method", ["BUMP", "BOTH", "DISPLACEMENT"])
def test_displacement_is_exported_with_its_method(scene, fake_session, method):
    """The output's Displacement is kept with the material's method: Cycles' automatic bump
    ('Bump Only'), true displacement ('Displacement Only') or both, without a warning."""
    mat = principled(f"Displaced {method}")
    mat.displacement_method = method
    tree = mat.node_tree
    noise = tree.nodes.new("ShaderNodeTexNoise")
    disp = tree.nodes.new("ShaderNodeDisplacement")
    tree.links.new(noise.outputs["Fac"], disp.inputs["Height"])
    tree.links.new(disp.outputs["Displacement"], tree.nodes["Material Output"].inputs["Displacement"])
    m, warnings = exported(fake_session, mat)
    assert m.displacement_method == method
    assert m.nodes[m.displacement.node].type == "Displacement"
    assert m.nodes[m.nodes[m.displacement.node].inputs["Height"].node].type == "TexNoise"
    assert warnings == []


def test_a_tangent_normal_map_on_a_displaced_surface_is_warned(scene, fake_session):
    """A tangent-space Normal Map in a 'Displacement Only' material (whose normals are
    recomputed) is warned; under 'Displacement and Bump' (normals kept) it is not, nor a
    Bump node."""
    for method, warned in (("DISPLACEMENT", True), ("BOTH", False)):
        mat = principled(f"Normal mapped {method}")
        mat.displacement_method = method
        tree = mat.node_tree
        noise = tree.nodes.new("ShaderNodeTexNoise")
        disp = tree.nodes.new("ShaderNodeDisplacement")
        normal_map = tree.nodes.new("ShaderNodeNormalMap")
        bump = tree.nodes.new("ShaderNodeBump")
        tree.links.new(noise.outputs["Fac"], disp.inputs["Height"])
        tree.links.new(noise.outputs["Color"], normal_map.inputs["Color"])
        tree.links.new(noise.outputs["Fac"], bump.inputs["Height"])
        tree.links.new(normal_map.outputs["Normal"], bump.inputs["Normal"])
        tree.links.new(bump.outputs["Normal"], tree.nodes["Principled BSDF"].inputs["Normal"])
        tree.links.new(disp.outputs["Displacement"], tree.nodes["Material Output"].inputs["Displacement"])
        _m, warnings = exported(fake_session, mat)
        assert bool(warnings) == warned, warnings
        if warned:
            assert "tangent-space Normal Map on a displaced surface" in warnings[0]


@pytest.mark.parametrize("bl_idname,distribution", [("ShaderNodeBsdfAnisotropic", "ASHIKHMIN_SHIRLEY"),
                                                    ("ShaderNodeBsdfSheen", "ASHIKHMIN")])
def test_ashikhmin_distributions_are_exported_unwarned(scene, fake_session, bl_idname, distribution):
    mat = principled("Ashikhmin")
    replace_surface(mat, bl_idname).distribution = distribution
    out, warnings = exported(fake_session, mat)
    assert warnings == []
    assert surface(out).props["distribution"] == distribution


def test_portal_depth_is_warned_where_a_material_reads_it(scene, fake_session):
    """Light Path's Portal Depth reads 0 (portals are not counted): a material that reads it
    is named in a warning; one that reads only Ray Depth is not."""
    mat = bpy.data.materials.new("Portals")
    mix = replace_surface(mat, "ShaderNodeMixShader")
    light_path = mat.node_tree.nodes.new("ShaderNodeLightPath")
    link = mat.node_tree.links.new(light_path.outputs["Ray Depth"], mix.inputs["Fac"])
    _, warnings = exported(fake_session, mat)
    assert not [w for w in warnings if "Portal Depth" in w]
    mat.node_tree.links.remove(link)
    mat.node_tree.links.new(light_path.outputs["Portal Depth"], mix.inputs["Fac"])
    _, warnings = exported(fake_session, mat)
    assert [w for w in warnings if "Portal Depth" in w], warnings
