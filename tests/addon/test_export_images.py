"""Images and world graphs exported from Blender: pixels, colour spaces, alpha, warnings."""
import bpy
import numpy as np
import pytest

from .helpers import export_scene


def _textured_plane(image):
    bpy.ops.mesh.primitive_plane_add(size=1.0)
    ob = bpy.context.active_object
    mat = bpy.data.materials.new("textured")
    nt = mat.node_tree
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = image
    nt.links.new(tex.outputs["Color"], nt.nodes["Principled BSDF"].inputs["Base Color"])
    ob.data.materials.append(mat)
    return tex


def _image(name, float_buffer=False, colorspace="sRGB", alpha_mode="STRAIGHT"):
    img = bpy.data.images.new(name, 3, 2, alpha=True, float_buffer=float_buffer)
    px = np.arange(24, dtype=np.float32).reshape(2, 3, 4) / 23.0
    img.pixels.foreach_set(px.ravel())
    img.pack()              # (an unpacked generated image is regenerated blank when rendered)
    img.colorspace_settings.name = colorspace
    img.alpha_mode = alpha_mode
    return img, px


def test_8bit_image_keeps_its_bytes_and_is_shared(scene, fake_session):
    img, px = _image("bytes")
    _textured_plane(img)
    _textured_plane(img)
    desc = export_scene(fake_session)
    assert list(desc.images) == ["bytes"]
    im = desc.images["bytes"]
    assert im.pixels.dtype == np.uint8 and im.pixels.shape == (2, 3, 4)
    assert np.array_equal(im.pixels, np.rint(px * 255).astype(np.uint8))
    assert (im.colorspace, im.alpha) == ("sRGB", "STRAIGHT")
    textured = [n for m in desc.materials for n in m.nodes if n.type == "TexImage"]
    assert len(textured) == 2 and all(n.props["image"] == "bytes" for n in textured)
    assert not [w for w in desc.warnings if "image" in w]


@pytest.mark.parametrize("space, expected", [("Non-Color", "data"), ("Linear Rec.709", "linear")])
def test_8bit_colour_spaces(scene, fake_session, space, expected):
    _textured_plane(_image("img", colorspace=space)[0])
    assert export_scene(fake_session).images["img"].colorspace == expected


def test_unsupported_colour_space_is_read_as_srgb_with_a_warning(scene, fake_session):
    _textured_plane(_image("log", colorspace="Filmic Log")[0])
    desc = export_scene(fake_session)
    assert desc.images["log"].colorspace == "sRGB"
    assert any("'Filmic Log'" in w and "read as sRGB" in w for w in desc.warnings)


def test_float_image_is_linear_with_associated_alpha(scene, fake_session):
    img, px = _image("hdr", float_buffer=True, colorspace="Linear Rec.709")
    _textured_plane(img)
    im = export_scene(fake_session).images["hdr"]
    associated = px.copy()
    associated[..., :3] *= px[..., 3:]        # Blender's float buffer holds associated alpha
    assert im.pixels.dtype == np.float32 and np.allclose(im.pixels, associated, atol=1e-6)
    assert (im.colorspace, im.alpha) == ("linear", "PREMUL")


def test_missing_file_is_magenta_with_a_warning(scene, fake_session):
    img = bpy.data.images.new("gone", 4, 4)
    img.source = "FILE"
    img.filepath = "/nonexistent/mc_engine_gone.png"
    tex = _textured_plane(img)
    desc = export_scene(fake_session)
    assert desc.images == {}
    assert [n.props["image"] for m in desc.materials for n in m.nodes if n.type == "TexImage"] == [""]
    assert any(w.startswith("image 'gone'") and "magenta" in w for w in desc.warnings)
    assert tex.image is img


def test_world_graph_is_exported_with_its_image(scene, fake_session):
    img, _ = _image("sky", float_buffer=True)
    world = bpy.data.worlds.new("Sky")
    nt = world.node_tree
    env = nt.nodes.new("ShaderNodeTexEnvironment")
    env.image = img
    env.projection = "MIRROR_BALL"
    nt.links.new(env.outputs["Color"], nt.nodes["Background"].inputs["Color"])
    world.cycles.sampling_method = "MANUAL"
    world.cycles.sample_map_resolution = 256
    scene.world = world
    desc = export_scene(fake_session)
    w = desc.world
    assert [n.type for n in w.nodes] == ["Background", "TexEnvironment"]
    assert w.nodes[1].props["image"] == "sky" and w.nodes[1].props["projection"] == "MIRROR_BALL"
    assert (w.sampling, w.map_resolution) == ("MANUAL", 256)
    assert list(desc.images) == ["sky"]
    assert not [x for x in desc.warnings if x.startswith("world")]
