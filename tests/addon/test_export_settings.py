"""Integrator settings read from scene.cycles, and the world background."""
import addon_utils
import bpy
import pytest

from .helpers import export_scene, new_mesh_object


def test_integrator_reads_cycles_settings(scene, fake_session):
    c = scene.cycles
    c.samples, c.max_bounces, c.diffuse_bounces, c.glossy_bounces = 37, 9, 3, 2
    c.transmission_bounces, c.transparent_max_bounces, c.min_light_bounces = 5, 6, 1
    c.sample_clamp_direct, c.sample_clamp_indirect, c.time_limit, c.seed = 4.0, 2.5, 30.0, 11
    c.use_denoising = c.use_adaptive_sampling = False
    desc = export_scene(fake_session)
    i = desc.integrator
    assert (i.samples, i.max_bounces, i.diffuse_bounces, i.glossy_bounces) == (37, 9, 3, 2)
    assert (i.transmission_bounces, i.transparent_max_bounces, i.min_light_bounces) == (5, 6, 1)
    assert (i.clamp_direct, i.clamp_indirect, i.time_limit, i.seed) == (4.0, 2.5, 30.0, 11)
    assert desc.warnings == []


def test_acceleration_structure_settings_are_read(scene, fake_session):
    """Performance > Acceleration Structure, which Cycles' panel shows for MC Engine too."""
    i = export_scene(fake_session).integrator
    assert (i.use_spatial_splits, i.use_compact_bvh) == (False, False)     # Cycles' defaults
    scene.cycles.debug_use_spatial_splits = scene.cycles.debug_use_compact_bvh = True
    i = export_scene(fake_session).integrator
    assert (i.use_spatial_splits, i.use_compact_bvh) == (True, True)


def test_adaptive_sampling_and_integrator_choice(scene, fake_session):
    c = scene.cycles
    c.use_adaptive_sampling, c.adaptive_threshold, c.adaptive_min_samples = True, 0.03, 12
    scene.mcengine.integrator, scene.mcengine.depth, scene.mcengine.branching = "DISTRIBUTION", 3, 6
    i = export_scene(fake_session).integrator
    assert (i.use_adaptive_sampling, i.adaptive_threshold, i.adaptive_min_samples) == (True, pytest.approx(0.03), 12)
    assert (i.name, i.depth, i.branching) == ("distribution", 3, 6)


@pytest.mark.parametrize("pattern", ["AUTOMATIC", "TABULATED_SOBOL", "BLUE_NOISE"])
def test_sampler_follows_cycles_pattern_unless_chosen(scene, fake_session, pattern):
    """"As Cycles" (the default) exports the sampler of Cycles' pattern: scrambled Sobol
    for every pattern Blender offers; MC Engine's own choice wins over it."""
    assert scene.mcengine.sampler == "AUTOMATIC"
    scene.cycles.sampling_pattern = pattern
    assert export_scene(fake_session).integrator.sampler == "sobol"
    scene.mcengine.sampler = "INDEPENDENT"
    assert export_scene(fake_session).integrator.sampler == "independent"
    scene.mcengine.sampler = "SOBOL"
    assert export_scene(fake_session).integrator.sampler == "sobol"


def test_unknown_cycles_pattern_is_warned(scene, fake_session, monkeypatch):
    from mcengine import samplers
    monkeypatch.delitem(samplers.CYCLES_PATTERNS, "BLUE_NOISE")   # a pattern we do not know
    scene.cycles.sampling_pattern = "BLUE_NOISE"
    scene.cycles.use_denoising = False
    desc = export_scene(fake_session)
    assert desc.integrator.sampler == "sobol"
    assert desc.warnings == ["Cycles' sampling pattern 'BLUE_NOISE' is not known to MC Engine; "
                             "rendering with the Scrambled Sobol sampler"]


def test_fast_gi_is_warned(scene, fake_session):
    scene.cycles.use_denoising = False
    scene.cycles.use_fast_gi = True
    assert export_scene(fake_session).warnings == [
        "Fast GI Approximation is not supported; rendering full global illumination"]


def test_texture_limit_and_culling_are_warned(scene, fake_session):
    """Texture Limit and camera culling change what Cycles renders; each is warned.  Culling
    only where an object has it on: the scene's switch alone culls nothing."""
    scene.cycles.use_camera_cull = scene.cycles.use_distance_cull = True
    assert export_scene(fake_session).warnings == []
    scene.cycles.texture_limit_render = "1024"
    new_mesh_object("Far", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)]).cycles.use_camera_cull = True
    assert export_scene(fake_session).warnings == [
        "Texture Limit (1024 px) is not supported; images are read at full size",
        "Camera Culling is not supported; the culled objects are rendered"]


def test_shadow_caustics_are_warned_with_a_light_a_caster_and_a_receiver(scene, fake_session):
    light = bpy.data.objects.new("Key", bpy.data.lights.new("Key", "POINT"))
    scene.collection.objects.link(light)
    light.data.cycles.is_caustics_light = True
    glass = new_mesh_object("Glass", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)])
    glass.cycles.is_caustics_caster = True
    assert export_scene(fake_session).warnings == []      # no receiver: Cycles has no MNEE
    glass.cycles.is_caustics_receiver = True
    assert export_scene(fake_session).warnings == [
        "Shadow Caustics are not supported yet; those caustics are left to path tracing "
        "(a few bright samples, not Cycles' focused light)"]


def test_view_layer_samples_override(scene, fake_session):
    scene.cycles.samples = 64
    bpy.context.view_layer.samples = 5
    assert export_scene(fake_session).integrator.samples == 5
    scene.cycles.use_layer_samples = "IGNORE"
    assert export_scene(fake_session).integrator.samples == 64


def _lookup3_hash_uint2(kx, ky):
    """Cycles' hash_uint2, written out statement by statement as in util/hash.h."""
    m = 0xFFFFFFFF

    def rot(x, k):
        return ((x << k) | (x >> (32 - k))) & m

    a = b = c = (0xDEADBEEF + (2 << 2) + 13) & m
    b = (b + ky) & m
    a = (a + kx) & m
    c ^= b
    c = (c - rot(b, 14)) & m
    a ^= c
    a = (a - rot(c, 11)) & m
    b ^= a
    b = (b - rot(a, 25)) & m
    c ^= b
    c = (c - rot(b, 16)) & m
    a ^= c
    a = (a - rot(c, 4)) & m
    b ^= a
    b = (b - rot(a, 14)) & m
    c ^= b
    c = (c - rot(b, 24)) & m
    return c


def test_animated_seed_is_hashed_with_the_frame(scene, fake_session, addon):
    scene.cycles.seed, scene.cycles.use_animated_seed = 3, True
    seeds = []
    for frame in (1, 2):
        scene.frame_set(frame)
        seeds.append(export_scene(fake_session).integrator.seed)
    assert seeds == [_lookup3_hash_uint2(1, 3), _lookup3_hash_uint2(2, 3)]
    assert seeds[0] != seeds[1]
    for kx, ky in ((0, 0), (0xFFFFFFFF, 7), (12345, 0x80000000)):
        assert addon.export.settings.hash_uint2(kx, ky) == _lookup3_hash_uint2(kx, ky)


def test_sampling_with_motion_blur_warns_nothing(scene, fake_session):
    scene.cycles.samples = 16
    scene.render.use_motion_blur = True        # supported: no warning
    warnings = export_scene(fake_session).warnings
    assert warnings == []


def test_without_cycles_the_defaults_are_used_with_one_warning(scene, fake_session, addon):
    from mcengine.scene import Film, Integrator

    addon_utils.disable("cycles")
    try:
        assert not hasattr(scene, "cycles")
        desc = export_scene(fake_session)
    finally:
        addon_utils.enable("cycles", default_set=True)
        addon.register()
    assert desc.integrator == Integrator()
    assert (desc.film.filter_type, desc.film.filter_width) == (Film().filter_type, Film().filter_width)
    assert [w for w in desc.warnings if "Cycles add-on is disabled" in w] == [
        "the Cycles add-on is disabled: MC Engine reads samples, bounces, clamping, seed, time limit "
        "and pixel filter from Cycles' settings; using MC Engine defaults instead"]


def world_with_background(color, strength):
    world = bpy.data.worlds.new("Sky")
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*color, 1)
    bg.inputs["Strength"].default_value = strength
    bpy.context.scene.world = world
    return world


def test_world_background(scene, fake_session):
    world_with_background((0.2, 0.4, 0.6), 2.0)
    desc = export_scene(fake_session)
    assert desc.world.color == pytest.approx((0.4, 0.8, 1.2)) and desc.world.visible_camera
    assert not any(w.startswith("world") for w in desc.warnings)


def test_non_finite_world_is_black_with_a_warning(scene, fake_session):
    world_with_background((0.2, 0.4, 0.6), float("nan"))
    desc = export_scene(fake_session)
    assert desc.world.color == (0, 0, 0)
    assert any(w.startswith("world 'Sky'") and "not finite" in w for w in desc.warnings)


def test_no_world_is_black(scene, fake_session):
    scene.world = None
    assert export_scene(fake_session).world.color == (0, 0, 0)


def test_world_ray_visibility(scene, fake_session):
    """World > Settings > Ray Visibility: each switch exported, none warned."""
    visibility = world_with_background((1, 1, 1), 1.0).cycles_visibility
    visibility.camera, visibility.glossy = False, False
    desc = export_scene(fake_session)
    w = desc.world
    assert (w.visible_camera, w.visible_diffuse, w.visible_glossy, w.visible_transmission) == \
        (False, True, False, True)
    visibility.camera, visibility.glossy = True, True
    visibility.diffuse, visibility.transmission = False, False
    w = export_scene(fake_session).world
    assert (w.visible_camera, w.visible_diffuse, w.visible_glossy, w.visible_transmission) == \
        (True, False, True, False)
    assert not [x for x in desc.warnings if "visibility" in x]


def test_sky_texture_hosek_wilkie_uses_the_unlinked_value(scene, fake_session):
    """The default Sky Texture (Multiple Scattering) is exported with its settings, the
    Preetham type with its Sun Direction; Hosek / Wilkie is named in the warning and its
    consumer keeps its unlinked value."""
    world = world_with_background((0.1, 0.2, 0.3), 1.0)
    sky = world.node_tree.nodes.new("ShaderNodeTexSky")
    sky.sun_elevation = 0.3
    world.node_tree.links.new(sky.outputs["Color"], world.node_tree.nodes["Background"].inputs["Color"])
    desc = export_scene(fake_session)
    exported = [n for n in desc.world.nodes if n.type == "TexSky"]
    assert len(exported) == 1 and exported[0].props["sun_elevation"] == pytest.approx(0.3)
    assert not [w for w in desc.warnings if w.startswith("world")]
    sky.sky_type = "PREETHAM"
    sky.sun_direction = (0.6, 0.0, 0.8)
    desc = export_scene(fake_session)
    exported = [n for n in desc.world.nodes if n.type == "TexSky"]
    assert len(exported) == 1 and exported[0].props["sun_direction"] == pytest.approx((0.6, 0.0, 0.8))
    assert not [w for w in desc.warnings if w.startswith("world")]
    sky.sky_type = "HOSEK_WILKIE"
    desc = export_scene(fake_session)
    assert not [n for n in desc.world.nodes if n.type == "TexSky"]
    assert [w for w in desc.warnings if w.startswith("world")] == [
        "world 'Sky': Sky Texture into Background 'Color' not supported yet; "
        "unlinked value of Background 'Color' used"]
