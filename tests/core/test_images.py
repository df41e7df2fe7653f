"""Texture images in the scene model: Cycles' load conventions, saving and validation."""
import numpy as np
import pytest

from mcengine import images
from mcengine.images import ImageTable, associate_rgba8, load_texels, unit_floats_to_bytes
from mcengine.kernels.svm.data import IMG_CHANNELS, IMG_FLAGS, IMG_FLOAT, IMG_OFFSET, IMGF_SRGB, IMGF_UNASSOCIATE
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


def test_bytes_are_associated_as_integer_division_for_every_colour_and_alpha():
    """Every (colour, alpha) pair, in each colour channel, gives c * a // 255."""
    c, a = (v.ravel() for v in np.meshgrid(np.arange(256), np.arange(256)))
    rgba = np.stack([c, 255 - c, c[::-1], a], axis=1).astype(np.uint8).reshape(256, 256, 4)
    want = rgba.astype(np.int64)
    want[..., :3] = want[..., :3] * want[..., 3:] // 255
    associate_rgba8(rgba)
    np.testing.assert_array_equal(rgba, want)


def test_unit_floats_become_the_bytes_numpy_rounds_them_to(monkeypatch):
    """Blender's float view of a byte image back to its bytes, block by block (here blocks of
    4 values, the last one short): round(255 clip(v, 0, 1)), ties to even as np.rint; every
    byte's own value b / 255 and the half-way points between bytes included."""
    monkeypatch.setattr(images, "_BLOCK_TEXELS", 1)
    rng = np.random.default_rng(3)
    v = np.concatenate([np.arange(256) / 255.0, (np.arange(255) + 0.5) / 255.0,
                        rng.uniform(-1.0, 2.0, 1001)]).astype(np.float32).reshape(-1, 1, 1)
    want = np.rint(np.clip(v, 0.0, 1.0) * np.float32(255.0)).astype(np.uint8)
    got = unit_floats_to_bytes(v.copy())
    assert got.dtype == np.uint8 and got.shape == v.shape
    np.testing.assert_array_equal(got, want)


def _reference_texel(px, channels_in, is_float, alpha, colorspace):
    """One texel as the load conventions of the module docstring say, written out per texel."""
    v = [float(x) for x in px] if is_float else [int(x) for x in px]
    if is_float and not all(np.isfinite(v)):
        v = [0.0] * channels_in
    if channels_in == 1:
        return v
    one = 1.0 if is_float else 255
    rgb, a = ((v[:1] * 3, v[1]) if channels_in == 2 else
              (v[:3], v[3] if channels_in == 4 else one))
    if alpha == "NONE":
        a = one
    elif alpha == "STRAIGHT" and colorspace != "data":
        rgb = [x * a for x in rgb] if is_float else [x * a // 255 for x in rgb]
    return rgb + [a]


@pytest.mark.parametrize("channels", [1, 2, 3, 4])
@pytest.mark.parametrize("is_float", [False, True])
@pytest.mark.parametrize("alpha, colorspace", [("STRAIGHT", "sRGB"), ("STRAIGHT", "data"),
                                               ("PREMUL", "linear"), ("NONE", "sRGB"),
                                               ("CHANNEL_PACKED", "sRGB")])
def test_texels_converted_in_blocks_match_the_conventions_texel_by_texel(
        monkeypatch, channels, is_float, alpha, colorspace):
    """Images are converted a block of rows at a time (here 3 rows of 7, a last block of 2):
    every texel as the conventions give it alone, and the source pixels left unchanged."""
    monkeypatch.setattr(images, "_BLOCK_TEXELS", 21)
    rng = np.random.default_rng(channels + 10 * is_float)
    if is_float:
        px = rng.uniform(-0.5, 4.0, (8, 7, channels)).astype(np.float32)
        px[1, 2, 0], px[5, 6, -1], px[7, 0, 0] = np.nan, np.inf, -np.inf
    else:
        px = rng.integers(0, 256, (8, 7, channels), dtype=np.uint8)
    source = px.copy()
    got = load_texels(Image(px, colorspace, alpha))
    want = [[_reference_texel(px[y, x], channels, is_float, alpha, colorspace)
             for x in range(7)] for y in range(8)]
    assert got.dtype == (np.float32 if is_float else np.uint8)
    np.testing.assert_array_equal(got, np.array(want, got.dtype))
    np.testing.assert_array_equal(px, source)


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


def test_texels_in_the_pool_after_an_odd_sized_image_are_converted_alike():
    """An RGBA image after a one-channel image of 9 texels starts at a byte offset that is
    no multiple of 4: its words are unaligned, its texels the same as loaded alone."""
    px = np.random.default_rng(5).integers(0, 256, (5, 7, 4), dtype=np.uint8)
    table = ImageTable({"grey": Image(np.full((3, 3, 1), 7, np.uint8)), "straight": Image(px),
                        "none": Image(px, "sRGB", "NONE")})
    start = table.info[1, IMG_OFFSET]
    assert start % 4 == 1
    for k, alpha in ((1, "STRAIGHT"), (2, "NONE")):
        offset = table.info[k, IMG_OFFSET]
        np.testing.assert_array_equal(table.pix8[offset:offset + px.size].reshape(px.shape),
                                      load_texels(Image(px, "sRGB", alpha)))


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


def test_srgb_decoding_follows_the_curve_it_tabulates():
    """The kernels decode 8-bit sRGB texels through a table of the curve's power segment: at
    most 2.3e-8 from the exact curve, 2.8e-6 of it relatively (the segment's dark end);
    above 1 (a colour divided by alpha), below 0 and NaN as the formula gives them."""
    from mcengine.kernels.svm.image_nodes import srgb_to_linear
    c = np.concatenate([np.linspace(-0.1, 1.3, 140_001), [0.04045, np.nextafter(1.0, 0.0), 1.0],
                        np.nextafter(0.04045, 1.0) + np.arange(1, 4097) / 4096])
    exact = np.where(c < 0.04045, np.maximum(c, 0.0) / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    ours = np.array([srgb_to_linear(x) for x in c])
    assert np.abs(ours - exact).max() <= 2.3e-8
    assert (np.abs(ours - exact) / np.maximum(exact, 1e-300)).max() <= 2.8e-6
    assert srgb_to_linear(1.0) == 1.0 and srgb_to_linear(-0.5) == 0.0
    assert np.isnan(srgb_to_linear(np.nan))
