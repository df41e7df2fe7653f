"""Render passes in Blender: registered as Cycles registers them, exported, written, warned.

Uses the fake session (``helpers.GradientSession``: pass k of its list is the
constant k + 1, its denoiser halves the image), so these tests check the
add-on's plumbing; the passes' values are checked in tests/core/test_passes.py
and against Cycles in test_passes_cycles.py.
"""
import bpy
import numpy as np
import pytest

from mcengine.imageio import read_exr_header, read_exr_layers
from mcengine.integrators import get as get_integrator
from mcengine.passes import PASSES

from .helpers import new_mesh_object

SUPPORTED_SETTINGS = [p.setting for p in PASSES]


def _enable_all(layer):
    for setting in SUPPORTED_SETTINGS:
        setattr(layer, setting, True)
    layer.use_pass_cryptomatte_object = layer.use_pass_cryptomatte_material = True
    layer.use_pass_cryptomatte_asset = True
    layer.cycles.denoising_store_passes = True


def test_registered_passes_are_cycles_own(scene, addon):
    """For every pass MC Engine offers: Cycles' name, channels and type, in Cycles' order."""
    from cycles.engine import list_render_passes
    layer = scene.view_layers[0]
    _enable_all(layer)
    layer.pass_cryptomatte_depth = 4
    scene.cycles.use_denoising = True
    ours = addon.export.passes.result_passes(scene, layer)
    theirs = [p for p in list_render_passes(scene, layer) if p[0] in {n for n, _c, _t in ours}]
    assert ours == theirs
    assert [n for n, _c, _t in ours if n.startswith("CryptoAsset")] == ["CryptoAsset00",
                                                                        "CryptoAsset01"]


def test_view_layer_settings_are_exported(scene, fake_session):
    layer = scene.view_layers[0]
    layer.use_pass_mist = layer.use_pass_normal = True
    layer.use_pass_cryptomatte_asset = True
    layer.pass_cryptomatte_depth = 3
    layer.pass_alpha_threshold = 0.25
    scene.world = bpy.data.worlds.new("World")
    mist = scene.world.mist_settings
    mist.start, mist.depth, mist.falloff = 1.5, 12.0, "LINEAR"
    scene.world.light_settings.distance = 3.5
    mat = bpy.data.materials.new("Paint")
    mat.pass_index = 5
    parent = bpy.data.objects.new("Rig", None)
    scene.collection.objects.link(parent)
    tri = new_mesh_object("Tri", [(0, 0, -2), (1, 0, -2), (0, 1, -2)], [(0, 1, 2)], materials=[mat])
    tri.parent, tri.pass_index = parent, 9
    bpy.ops.render.render()
    desc = fake_session[-1].desc
    p = desc.passes
    assert p.enabled == ("Mist", "Normal") and p.cryptomatte == ("CryptoAsset",)
    assert (p.cryptomatte_depth, p.alpha_threshold) == (3, 0.25)
    assert (p.mist_start, p.mist_depth, p.mist_falloff) == (1.5, 12.0, "LINEAR")
    assert p.ao_distance == 3.5
    assert p.view_layer == layer.name
    (info,) = desc.geometry.object_pass_info()
    assert (info.name, info.asset) == ("Tri", "Rig")
    assert desc.geometry.object_info[0, 1] == 9        # the pass index, in Object Info
    assert [m.pass_index for m in desc.materials if m.name == "Paint"] == [5]


def test_passes_denoising_and_metadata_reach_the_file(scene, fake_session, tmp_path):
    layer = scene.view_layers[0]
    layer.use_pass_z = layer.use_pass_diffuse_color = layer.use_pass_cryptomatte_object = True
    scene.cycles.use_denoising = True
    new_mesh_object("Tri", [(0, 0, -2), (1, 0, -2), (0, 1, -2)], [(0, 1, 2)])
    settings = scene.render.image_settings
    settings.media_type = "MULTI_LAYER_IMAGE"
    settings.color_depth = "32"
    scene.render.filepath = str(tmp_path / "layers.exr")
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)
    (session,) = fake_session
    layers = read_exr_layers(tmp_path / "layers.exr")
    noisy = session.target
    np.testing.assert_array_equal(layers["ViewLayer.Noisy Image"], noisy)
    # Combined is the denoised image (the fake halves it).
    np.testing.assert_array_equal(layers["ViewLayer.Combined"], noisy * np.float32(0.5))
    names = session.pass_names()
    assert np.all(layers["ViewLayer.Depth.Z"] == names.index("Depth") + 1)
    assert np.all(layers["ViewLayer.CryptoObject01.r"] == names.index("CryptoObject01") + 1)
    header = read_exr_header(tmp_path / "layers.exr")
    key = next(k for k in header if k.endswith("/name"))
    assert header[key] == "ViewLayer.CryptoObject"
    assert '"Tri"' in header[key.replace("/name", "/manifest")]
    assert header["mcengine.ViewLayer.samples"] == str(scene.cycles.samples)


def test_unsupported_passes_are_warned(scene, fake_session, tmp_path):
    layer = scene.view_layers[0]
    layer.use_pass_ambient_occlusion = layer.use_pass_vector = True
    layer.cycles.use_pass_shadow_catcher = True
    layer.cycles.use_pass_volume_direct = True
    scene.world = None
    bpy.ops.render.render()
    desc = fake_session[-1].desc
    warnings = desc.warnings
    assert not any("Vector" in w or "Ambient" in w for w in warnings)    # both computed
    assert desc.passes.ao_distance == 10.0       # Cycles' AO distance without a world
    assert ("render passes not supported yet (Volume Direct, Shadow Catcher); they are not "
            "written") in warnings


@pytest.mark.parametrize("integrator", ["whitted", "light"])
def test_other_integrators_say_they_fill_combined_only(scene, fake_session, integrator):
    """The classic integrators and Path + Light Tracing (whose caustics the light passes
    could not hold) write Combined only, and say so."""
    layer = scene.view_layers[0]
    layer.use_pass_z = True
    scene.cycles.use_denoising = True
    scene.mcengine.integrator = get_integrator(integrator).enum_id
    bpy.ops.render.render()
    desc = fake_session[-1].desc
    assert desc.passes.names() == [] and desc.denoising.input_passes == "RGB"
    assert any("render passes need the path tracer" in w for w in desc.warnings)
    assert any("denoising guides (albedo, normal) need the path tracer" in w for w in desc.warnings)


@pytest.mark.parametrize("denoiser", ["OPENIMAGEDENOISE"])
def test_denoising_settings_are_cycles_own(scene, fake_session, denoiser):
    c = scene.cycles
    c.use_denoising = True
    c.denoiser = denoiser
    c.denoising_input_passes, c.denoising_prefilter, c.denoising_quality = "RGB_ALBEDO", "FAST", "BALANCED"
    bpy.ops.render.render()
    d = fake_session[-1].desc.denoising
    assert (d.enabled, d.input_passes, d.prefilter, d.quality) == (True, "RGB_ALBEDO", "FAST", "BALANCED")
    scene.view_layers[0].cycles.use_denoising = False     # the view layer's own switch
    bpy.ops.render.render()
    assert not fake_session[-1].desc.denoising.enabled
