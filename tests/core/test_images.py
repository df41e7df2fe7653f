"""Texture images in the scene model: Cycles' load conventions, saving and validation."""
import numpy as np
import pytest

from mcengine.images import ImageTable, load_texels
from mcengine.kernels.svm.data import IMG_CHANNELS, IMG_FLAGS, IMG_FLOAT, IMGF_SRGB, IMGF_UNASSOCIATE
from mcengine.scene import Image, Link, SceneDescription, SceneError, ShaderNode, World


def test_straight_8bit_alpha_is_associated_in_integers():
    """Cycles multiplies Blender's byte buffers as c * a // 255 (bpy 5.0.1: 128 x 128 -> 64)."""
    texels = load_texels(Image(np.array([[[128, 255, 3, 128], [200, 100, 50, 0]]], np.uint8)))
    assert texels.tolist() == [[[64, 128, 1, 128], [0, 0, 0, 0]]]


@pytest.mark.parametrize("mode, colorspace", [("PREMUL", "sRGB"), ("CHANNEL_PACKED", "sRGB"),
                                              ("STRAIGHT", "data")])
def test_alpha_left_alone(mode, colorspace):
    px = np.array([[[128, 255, 3, 128]]], np.uint8)
    assert np.array_equal(load_texels(Image(px, colorspace, mode)), px)


def test_alpha_none_reads_one_and_leaves_the_colour():
    px = np.array([[[0.5, 0.25, 2.0, 0.1]]], np.float32)
    assert load_texels(Image(px, "linear", "NONE")).tolist() == [[[0.5, 0.25, 2.0, 1.0]]]


def test_channels_become_rgba_and_grey_stays_one_channel():
    grey_alpha = np.array([[[10, 128]]], np.uint8)
    assert load_texels(Image(grey_alpha)).tolist() == [[[5, 5, 5, 128]]]
    rgb = np.array([[[0.5, 0.25, 0.125]]], np.float32)
    assert load_texels(Image(rgb, "linear", "PREMUL")).tolist() == [[[0.5, 0.25, 0.125, 1.0]]]
    grey = np.array([[[7]]], np.uint8)
    assert load_texels(Image(grey)).shape == (1, 1, 1)


def test_non_finite_float_texels_become_zero():
    px = np.array([[[np.nan, 1, 1, 1], [np.inf, 2, 2, 1], [3, 3, 3, 1]]], np.float32)
    assert load_texels(Image(px, "linear", "PREMUL")).tolist() == [
        [[0, 0, 0, 0], [0, 0, 0, 0], [3, 3, 3, 1]]]


def test_image_table_pools_and_flags():
    table = ImageTable({"a": Image(np.zeros((2, 3, 4), np.uint8)),
                        "b": Image(np.zeros((4, 5, 1), np.float32), "data", "STRAIGHT"),
                        "c": Image(np.zeros((1, 2, 3), np.uint8), "linear", "NONE")})
    assert table.slots == {"a": 0, "b": 1, "c": 2}
    assert table.pix8.size == 2 * 3 * 4 + 1 * 2 * 4 and table.pixf.size == 4 * 5
    assert table.info[:, IMG_FLOAT].tolist() == [0, 1, 0]
    assert table.info[:, IMG_CHANNELS].tolist() == [4, 1, 4]
    assert table.info[:, IMG_FLAGS].tolist() == [IMGF_SRGB | IMGF_UNASSOCIATE, 0, 0]
    assert table.nbytes == table.pix8.nbytes + table.pixf.nbytes


def test_images_and_world_graph_survive_save_and_load(tmp_path):
    px = np.arange(2 * 3 * 4, dtype=np.uint8).reshape(2, 3, 4)
    hdr = np.linspace(0, 5, 8 * 4 * 3, dtype=np.float32).reshape(8, 4, 3)
    world = World(nodes=[ShaderNode("TexEnvironment", props={"image": "sky"}),
                         ShaderNode("Background", {"Color": Link(0, "Color"), "Strength": 2.0})],
                  surface=Link(1, "Background"), sampling="MANUAL", map_resolution=64)
    scene = SceneDescription(images={"tiles": Image(px, "sRGB", "CHANNEL_PACKED"),
                                     "sky": Image(hdr, "linear", "PREMUL")}, world=world)
    scene.save(tmp_path / "s.npz")
    back = SceneDescription.load(tmp_path / "s.npz")
    assert list(back.images) == ["tiles", "sky"]
    assert np.array_equal(back.images["tiles"].pixels, px) and back.images["tiles"].alpha == "CHANNEL_PACKED"
    assert np.array_equal(back.images["sky"].pixels, hdr) and back.images["sky"].pixels.dtype == np.float32
    assert back.world == world


@pytest.mark.parametrize("image, message", [
    (Image(np.zeros((2, 2, 4), np.float64)), "uint8 or float32"),
    (Image(np.zeros((2, 2, 5), np.uint8)), "uint8 or float32"),
    (Image(np.zeros((2, 2, 4), np.uint8), colorspace="Filmic"), "colour space"),
    (Image(np.zeros((2, 2, 4), np.uint8), alpha="MULTIPLIED"), "alpha mode"),
])
def test_bad_images_are_refused(image, message):
    with pytest.raises(SceneError, match=message):
        SceneDescription(images={"bad": image}).validate()
