"""The verdict tells wrong renders from right ones at the CI setting.

Wrong renders are MC Engine renders of a deliberately altered scene compared
with Cycles on the original; each must give "differ", in the right place and
direction.  Right renders are Cycles against Cycles with other seeds; every
scene must give "agree" (this is the false-alarm side of the test, with the
same alpha as the suite): one scene of each kind in the default run, every
scene with ``-m slow`` (two more Cycles renders a scene, about 2.5 min of the
default run's time for all of them).
"""
import bpy
import numpy as np
import pytest

from mcengine.evaluation.comparison import build_comparison

from .conftest import SCENES, options_for

CI_SCENE = "cornell_box"


def _wall_redder(scene):
    """Red wall: the red channel of its albedo 0.63 -> 0.65."""
    node = next(n for n in bpy.data.materials["Red"].node_tree.nodes if n.type == "BSDF_DIFFUSE")
    color = list(node.inputs["Color"].default_value)
    color[0] += 0.02
    node.inputs["Color"].default_value = color


def test_wall_colour_off_by_two_hundredths_is_caught(renders):
    result = renders.compare(CI_SCENE, "red wall R +0.02", _wall_redder)
    a = result.agreement
    assert result.verdict == "differ"
    assert a.frame_rejected.tolist() == [True, False, False]
    differing = a.differing_blocks()
    assert differing, "the red wall's blocks should differ"
    # Only red, only brighter, and only in the left quarter of the frame, where
    # the red wall is (x < 0.25 w at this camera).
    assert {d["channel"] for d in differing} == {"R"}
    assert all(d["t"] > 0 for d in differing)
    assert all(d["col"] < 2 for d in differing), differing


def _without_rectangle_light(scene):
    bpy.data.objects.remove(bpy.data.objects["AreaRectangle"])


def test_one_light_missing_is_caught(renders):
    result = renders.compare("light_area", "without AreaRectangle", _without_rectangle_light)
    a = result.agreement
    assert result.verdict == "differ"
    assert np.all(a.frame_rejected) and np.all(a.frame_rel_bias < 0)
    assert all(d["t"] < 0 for d in a.differing_blocks()), "a missing light only darkens"
    assert all(r["ours"] == "darker" for r in result.report["regions"])


def _dof_setting(name, value):
    def edit(scene):
        setattr(scene.camera.data.dof, name, value)
    return edit


@pytest.mark.parametrize("what,edit", [
    ("round aperture", _dof_setting("aperture_blades", 0)),
    ("no anamorphic squeeze", _dof_setting("aperture_ratio", 1.0)),
    ("pinhole camera", _dof_setting("use_dof", False)),
])
def test_depth_of_field_errors_are_caught(renders, what, edit):
    """A lens that ignores the blades or the anamorphic ratio draws bokeh of the wrong
    shape, a pinhole draws everything sharp: the blocks around them differ (measured:
    2, 3 and 8 of the 64 blocks; the frame means stay within the noise)."""
    result = renders.compare("camera_dof", what, edit)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _without_bump_map_correction(scene):
    for material in bpy.data.materials:
        material.cycles.use_bump_map_correction = False


def test_missing_bump_shadowing_is_caught(renders):
    """Without Bump Map Correction MC Engine leaves out the bump shadowing term's darkening
    of diffuse closures towards grazing light, which Cycles applies to the original: the
    normal-mapped floor under the low sun is too bright."""
    result = renders.compare("texture_normal_map", "no bump map correction",
                             _without_bump_map_correction)
    a = result.agreement
    assert result.verdict == "differ"
    assert np.all(a.frame_rejected) and np.all(a.frame_rel_bias > 0)


def _without_thin_films(scene):
    for material in bpy.data.materials:
        for node in material.node_tree.nodes if material.node_tree else ():
            if "Thin Film Thickness" in node.inputs:
                node.inputs["Thin Film Thickness"].default_value = 0.0


def test_ignored_thin_films_are_caught(renders):
    """Films left out (what MC Engine rendered before it had thin films): the spheres'
    colours are the film-free Fresnel's, which Cycles' 4x4 block means put up to 20 % of
    the frame mean away; several blocks of each sign differ."""
    result = renders.compare("material_thin_film", "no thin films", _without_thin_films)
    assert result.verdict == "differ"
    differing = result.agreement.differing_blocks()
    assert any(d["t"] > 0 for d in differing) and any(d["t"] < 0 for d in differing), differing


def _subsurface_as_diffuse(scene):
    """Every subsurface radius below Cycles' 1e-8 limit: the closures become Lambert."""
    for material in bpy.data.materials:
        for node in material.node_tree.nodes if material.node_tree else ():
            for name in ("Subsurface Scale", "Scale"):
                if name in node.inputs and node.type in ("BSDF_PRINCIPLED", "SUBSURFACE_SCATTERING"):
                    node.inputs[name].default_value = 0.0


def test_subsurface_rendered_as_diffuse_is_caught(renders):
    """Subsurface as Lambert of its colour (Cycles' zero-radius limit, what MC Engine
    rendered before it walked): no light through Suzanne's ears and the slab, harder
    shading; blocks differ."""
    result = renders.compare("material_subsurface", "subsurface as diffuse", _subsurface_as_diffuse)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _without_holdouts(scene):
    bpy.data.objects["Held"].is_holdout = False
    for layer in scene.view_layers:
        layer.layer_collection.children["Masked"].holdout = False


def test_ignored_holdouts_are_caught(renders):
    """Holdout objects rendered as ordinary ones (what MC Engine did before it had them):
    the two spheres, black in Cycles' image, show their colours; only brighter blocks."""
    result = renders.compare("holdout_objects", "no holdouts", _without_holdouts)
    assert result.verdict == "differ"
    differing = result.agreement.differing_blocks()
    assert differing and all(d["t"] > 0 for d in differing), differing


def _every_ray_sees_everything(scene):
    for ob in scene.objects:
        for ray in ("camera", "diffuse", "glossy", "transmission", "shadow"):
            setattr(ob, f"visible_{ray}", True)
    for layer in scene.view_layers:
        layer.layer_collection.children["Indirect"].indirect_only = False


def test_ignored_ray_visibility_is_caught(renders):
    """Every object seen by every ray (what MC Engine rendered before it honoured Ray
    Visibility): the camera-hidden balls, the box behind the pane and the panel show, the
    box casts its shadow; blocks differ."""
    result = renders.compare("ray_visibility", "every ray sees everything",
                             _every_ray_sees_everything)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _displacement_as_bump(scene):
    for name in ("Terrain", "Rock"):
        bpy.data.materials[name].displacement_method = "BUMP"


def test_displacement_rendered_as_bump_is_caught(renders):
    """Meshes left where they are and only bumped (the 'Bump Only' method), where Cycles
    moves them: the terrain's relief and the rock's silhouette change; blocks differ."""
    result = renders.compare("material_displacement", "displacement as bump", _displacement_as_bump)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _unlinked(material, socket_owner, socket):
    def edit(scene):
        tree = bpy.data.materials[material].node_tree
        node = next(n for n in tree.nodes if n.bl_idname == socket_owner)
        for link in list(node.inputs[socket].links):
            tree.links.remove(link)
    return edit


@pytest.mark.parametrize("what,edit", [
    ("Suzanne not bumped", _unlinked("Suzanne", "ShaderNodeBsdfPrincipled", "Normal")),
    ("Ball without displacement as bump", _unlinked("Ball", "ShaderNodeOutputMaterial", "Displacement")),
])
def test_missing_bump_is_caught(renders, what, edit):
    """Without its Bump node, or its displacement as bump, a surface is shaded smooth: the
    blocks over it differ."""
    result = renders.compare("texture_bump", what, edit)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _read_as(image, colorspace):
    def edit(scene):
        bpy.data.images[image].colorspace_settings.name = colorspace
    return edit


@pytest.mark.parametrize("what,edit", [
    ("normal map missing", _unlinked("SuzanneMaps", "ShaderNodeBsdfPrincipled", "Normal")),
    ("roughness map read as sRGB", _read_as("suzanne_roughness.png", "sRGB")),
    ("colour map read as Non-Color", _read_as("suzanne_color.png", "Non-Color")),
])
def test_texture_map_errors_are_caught(renders, what, edit):
    """The image-textured Suzanne without its normal map (measured: frame R +7.6 %), or with
    an image decoded in the wrong colour space (the roughness map as sRGB: frame within
    0.7 %, but 7 blocks; the colour map as Non-Color: +13 to +27 %): the blocks differ."""
    result = renders.compare("texture_suzanne_maps", what, edit)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _no_motion_blur(scene):
    scene.render.use_motion_blur = False


def _no_deformation_blur(scene):
    for ob in scene.objects:
        ob.cycles.use_deform_motion = False


def _shutter_at(position):
    def edit(scene):
        scene.render.motion_blur_position = position
    return edit


@pytest.mark.parametrize("name,what,edit", [
    ("motion_transform", "shutter closed", _no_motion_blur),
    ("motion_transform", "shutter opening at the frame", _shutter_at("START")),
    ("motion_camera", "camera still", _no_motion_blur),
    ("motion_deform", "no deformation blur", _no_deformation_blur),
])
def test_motion_blur_errors_are_caught(renders, name, what, edit):
    """Sharp objects, a shutter in the wrong place, a still camera or meshes blurred only by
    their transforms: the blocks where things move differ."""
    result = renders.compare(name, what, edit)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


# The scenes whose Cycles-against-Cycles check runs by default: one of each kind (the
# others are marked slow; material_rough_glass and world_hdri_interior, the two longest at
# 23 and 12 s, since material_displacement joined the suite: material_principled and
# world_sky stand for their kinds).
SELF_CHECK_DEFAULT = {"cornell_box", "light_area", "light_sun", "caustics", "camera_dof",
                      "material_principled", "texture_suzanne_maps",
                      "motion_deform", "holdout_objects", "world_sky"}


def test_the_default_self_checks_name_scenes():
    assert SELF_CHECK_DEFAULT <= {p.stem for p in SCENES}


@pytest.mark.parametrize("blend", [
    pytest.param(p, marks=() if p.stem in SELF_CHECK_DEFAULT else pytest.mark.slow) for p in SCENES],
    ids=lambda p: p.stem)
def test_cycles_agrees_with_itself_across_seeds(blend, renders):
    name = blend.stem
    options = options_for(name)
    other = renders.runs(name, "cycles", first_seed=1 + options.seeds)
    result = build_comparison(f"{name} (Cycles vs Cycles)", other, renders.runs(name, "cycles"),
                              grid=options.grid, alpha=options.alpha)
    assert result.verdict == "agree", result.agreement.summary()


def _checker_squares_swapped(scene):
    """The floor's two checker colours exchanged, as a checker counted from the wrong
    origin (or coordinates off by one square) would draw it."""
    node = next(n for n in bpy.data.materials["Floor"].node_tree.nodes if n.type == "TEX_CHECKER")
    first = tuple(node.inputs["Color1"].default_value)
    node.inputs["Color1"].default_value = node.inputs["Color2"].default_value
    node.inputs["Color2"].default_value = first


def _byte_colours_undecoded(scene):
    """Every byte colour attribute's 8-bit sRGB values taken as linear, as a reader that
    forgets to decode them would take them."""
    for ob in scene.objects:
        if ob.type != "MESH":
            continue
        for attr in ob.data.color_attributes:
            if attr.data_type == "BYTE_COLOR":
                for corner in attr.data:
                    corner.color = corner.color_srgb


@pytest.mark.parametrize("name,what,edit", [
    ("texture_checker_lights", "checker colours swapped", _checker_squares_swapped),
    ("attribute_vertex_colors", "byte colours not decoded from sRGB", _byte_colours_undecoded),
])
def test_texture_errors_are_caught(renders, name, what, edit):
    """A checker floor off by one square, vertex-painted colours read without their sRGB
    decoding: the blocks over those surfaces differ."""
    result = renders.compare(name, what, edit)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _unlinked(scene):
    for ob in scene.objects:
        if ob.light_linking.receiver_collection is not None:
            ob.light_linking.receiver_collection = None


def test_ignored_light_linking_is_caught(renders):
    """Every light reaching every object (what MC Engine rendered before it honoured light
    linking): the blue ball in the key light, the rims and the sun on every object, the
    panel on the red and green balls; blocks differ."""
    result = renders.compare("light_linking", "every light lights everything", _unlinked)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _falloff_left_out(scene):
    """The panel's Light Falloff removed (what MC Engine rendered before it evaluated the
    node: the Emission's unlinked Strength)."""
    tree = scene.objects["Panel"].active_material.node_tree
    emission = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeEmission")
    for link in list(emission.inputs["Strength"].links):
        tree.links.remove(link)


def _wireframe_left_out(scene):
    tree = scene.objects["Wire"].active_material.node_tree
    mix = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeMixShader")
    for link in list(mix.inputs["Fac"].links):
        tree.links.remove(link)


@pytest.mark.parametrize("what,edit", [("Light Falloff left out", _falloff_left_out),
                                       ("Wireframe left out", _wireframe_left_out)])
def test_left_out_nodes_are_caught(renders, what, edit):
    """material_nodes_extra without its Light Falloff (the panel at its unlinked Strength
    1 instead of 4 t / (1 + 0.5 / t^2)) or its Wireframe (the sphere half and half): blocks
    differ."""
    result = renders.compare("material_nodes_extra", what, edit)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _bevel_left_out(scene):
    """The Block's Bevel unlinked from its Principled Normal (what MC Engine rendered before
    it evaluated the node: sharp edges)."""
    tree = scene.objects["Block"].active_material.node_tree
    bsdf = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    for link in list(bsdf.inputs["Normal"].links):
        tree.links.remove(link)


def test_left_out_bevel_is_caught(renders):
    """material_bevel_ao with sharp edges on the Block (its highlights along the rounded edges
    gone): blocks differ."""
    result = renders.compare("material_bevel_ao", "Bevel left out of the Block", _bevel_left_out)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _ao_own_object_only(scene):
    """The floor's Ambient Occlusion meeting only the floor (Only Local: no occlusion at
    all, what a node that traced nothing would give)."""
    tree = scene.objects["Floor"].active_material.node_tree
    next(n for n in tree.nodes if n.bl_idname == "ShaderNodeAmbientOcclusion").only_local = True


def test_ao_that_ignores_the_scene_is_caught(renders):
    """material_bevel_ao without the boxes' occlusion of the floor: the floor around them
    lighter; blocks differ."""
    result = renders.compare("material_bevel_ao", "AO of the floor alone", _ao_own_object_only)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _wall_washer_turned_back(scene):
    """The WallWasher lamp turned -30 degrees about Z instead of +30: its profile as a renderer
    that took directions into the lamp's frame by the matrix instead of its transpose would
    shine."""
    scene.objects["WallWasher"].rotation_euler[2] = -scene.objects["WallWasher"].rotation_euler[2]


def test_a_turned_ies_profile_is_caught(renders):
    """light_ies with the wall washer's brighter side turned 60 degrees: blocks differ."""
    result = renders.compare("light_ies", "wall washer turned back", _wall_washer_turned_back)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _toon_block_diffuse(scene):
    """The Block's glossy toon read as diffuse toon (a lobe about the normal instead of the
    reflected view)."""
    node = next(n for n in bpy.data.materials["BlockToon"].node_tree.nodes if n.type == "BSDF_TOON")
    node.component = "DIFFUSE"


def test_a_toon_lobe_about_the_wrong_axis_is_caught(renders):
    """material_toon with the Block's highlight lobe about its normal: blocks differ."""
    result = renders.compare("material_toon", "glossy toon as diffuse", _toon_block_diffuse)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _hair_sphere_along_latitudes(scene):
    """The Sphere's strands along its latitudes (a Tangent node, radial about Z) instead of
    its triangles' dPdv: what a renderer that took another edge or dPdu would shine."""
    tree = bpy.data.materials["SphereHair"].node_tree
    hair = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfHair")
    tangent = tree.nodes.new("ShaderNodeTangent")
    tangent.direction_type, tangent.axis = "RADIAL", "Z"
    tree.links.new(tangent.outputs["Tangent"], hair.inputs["Tangent"])


def test_a_hair_strand_along_the_wrong_edge_is_caught(renders):
    """material_hair with the sphere's highlights turned along its latitudes: blocks differ."""
    result = renders.compare("material_hair", "sphere strands along latitudes",
                             _hair_sphere_along_latitudes)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()


def _window_not_moved(scene):
    """The Window's portal with nothing linked to its Position: what a renderer that sent the
    ray on from the shading point, ignoring the Position, would give."""
    tree = bpy.data.materials["Window"].node_tree
    portal = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfRayPortal")
    for link in list(portal.inputs["Position"].links):
        tree.links.remove(link)


def test_a_portal_that_ignores_its_position_is_caught(renders):
    """material_ray_portal with the window showing what lies behind it instead of the view
    from 1.5 m higher: blocks differ."""
    result = renders.compare("material_ray_portal", "window not moved", _window_not_moved)
    assert result.verdict == "differ"
    assert result.agreement.differing_blocks()
