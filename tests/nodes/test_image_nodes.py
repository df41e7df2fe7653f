"""Image Texture and Environment Texture against Cycles (harness.py).

The images are made here, small and random (fixed seed): 8-bit and float,
generated (packed in the .blend's memory) and one read from a PNG file, with
every alpha mode and the colour spaces sRGB, Non-Color and Linear Rec.709.
The planes' UVs are stretched to [-1.3, 2.2] so that every extension mode
is seen outside the image.
"""

import numpy as np
import pytest

from .harness import assert_agree, render_cases

W, H = 5, 4          # odd sizes: rows and columns cannot be confused


def _pixels(seed, alpha_low=1.0):
    rng = np.random.default_rng(seed)
    px = rng.integers(0, 256, size=(H, W, 4)).astype(np.float32) / 255.0
    px[..., 3] = np.where(rng.random((H, W)) < alpha_low, px[..., 3], 1.0)
    return px


def _image(name, *, seed=1, partial_alpha=False, colorspace="sRGB", alpha_mode="STRAIGHT",
           float_buffer=False, size=(W, H)):
    import bpy
    if name in bpy.data.images:
        return bpy.data.images[name]
    w, h = size
    img = bpy.data.images.new(name, w, h, alpha=True, float_buffer=float_buffer)
    rng = np.random.default_rng(seed)
    if float_buffer:
        px = rng.random((h, w, 4)).astype(np.float32) * 3.0
        px[..., 3] = rng.random((h, w)) if partial_alpha else 1.0
    else:
        px = rng.integers(0, 256, size=(h, w, 4)).astype(np.float32) / 255.0
        if not partial_alpha:
            px[..., 3] = 1.0
    img.pixels.foreach_set(px.ravel())
    img.pack()
    img.colorspace_settings.name = colorspace
    img.alpha_mode = alpha_mode
    return img


def _file_image(tmp_name="mc_image_test.png"):
    import tempfile
    from pathlib import Path

    import bpy
    path = Path(tempfile.gettempdir()) / tmp_name
    src = bpy.data.images.new("file source", W, H, alpha=True)
    px = np.random.default_rng(7).integers(0, 256, size=(H, W, 4)).astype(np.float32) / 255.0
    px[..., 3] = 1.0
    src.pixels.foreach_set(px.ravel())
    src.filepath_raw = str(path)
    src.file_format = "PNG"
    src.save()
    bpy.data.images.remove(src)
    return bpy.data.images.load(str(path))


def _missing_image():
    import bpy
    img = bpy.data.images.new("missing", 4, 4)
    img.source = "FILE"
    img.filepath = "/nonexistent/mc_engine_missing.png"
    return img


def _stretched_uv(ob):
    """UVs from -1.3 to 2.2 over the plane."""
    for d in ob.data.uv_layers[0].data:
        d.uv = (-1.3 + 3.5 * d.uv[0], -1.3 + 3.5 * d.uv[1])


def _tilted(ob):
    """A plane whose normal mixes all three axes (box projection blends faces)."""
    ob.rotation_euler = (0.6, 0.45, 0.3)


def _tex(make_image, output="Color", *, interpolation="Linear", extension="REPEAT",
         projection="FLAT", blend=0.0, vector=None, alpha_to_strength=False):
    def build(nt):
        node = nt.nodes.new("ShaderNodeTexImage")
        node.image = make_image()
        node.interpolation = interpolation
        node.extension = extension
        node.projection = projection
        node.projection_blend = blend
        if vector is not None:
            nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs[vector], node.inputs["Vector"])
        if alpha_to_strength:      # the Alpha output is used: Cycles unassociates the colour
            nt.links.new(node.outputs["Alpha"], nt.nodes["Emission"].inputs["Strength"])
        return node.outputs[output]
    return build


def _env(make_image, projection="EQUIRECTANGULAR", vector="Generated", interpolation="Linear"):
    def build(nt):
        node = nt.nodes.new("ShaderNodeTexEnvironment")
        node.image = make_image()
        node.projection = projection
        node.interpolation = interpolation
        if vector is not None:
            nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs[vector], node.inputs["Vector"])
        return node.outputs["Color"]
    return build


def _rgb():
    return _image("rgb 8-bit")


def _rgba():
    return _image("rgba 8-bit", seed=2, partial_alpha=True)


def _mode(mode):
    return lambda: _image(f"rgba {mode}", seed=3, partial_alpha=True, alpha_mode=mode)


def _space(space):
    return lambda: _image(f"rgba {space}", seed=4, partial_alpha=True, colorspace=space)


def _float():
    return _image("rgba float", seed=5, partial_alpha=True, float_buffer=True)


def _hdr():
    return _image("environment", seed=6, float_buffer=True, size=(16, 8))


def _hdr_20():
    """20 texels across: the plane's diagonal (u = 3/8) falls on texel centres, not on a
    boundary between two (which float rounding decides differently in the two engines)."""
    return _image("environment 20", seed=6, float_buffer=True, size=(20, 10))


CASES = {
    **{f"{interp} {ext}": (_tex(_rgb, interpolation=interp, extension=ext), _stretched_uv)
       for interp in ("Closest", "Linear", "Cubic") for ext in ("REPEAT", "EXTEND", "CLIP", "MIRROR")},
    "smart renders cubic": (_tex(_rgb, interpolation="Smart", extension="EXTEND"), _stretched_uv),
    "sphere projection": _tex(_rgb, projection="SPHERE", vector="Generated"),
    "tube projection": _tex(_rgb, projection="TUBE", vector="Generated"),
    "box projection": (_tex(_rgb, projection="BOX", vector="Object"), _tilted),
    "box projection blend 0.3": (_tex(_rgb, projection="BOX", blend=0.3, vector="Object"), _tilted),
    "box projection blend 1": (_tex(_rgb, projection="BOX", blend=1.0, vector="Object"), _tilted),
    "straight alpha: colour": _tex(_rgba, interpolation="Closest"),
    "straight alpha: alpha": _tex(_rgba, "Alpha", interpolation="Closest"),
    "straight alpha: colour, alpha used": _tex(_rgba, alpha_to_strength=True),
    **{f"{mode}: colour{', alpha used' if used else ''}": _tex(_mode(mode), alpha_to_strength=used)
       for mode in ("PREMUL", "CHANNEL_PACKED", "NONE") for used in (False, True)},
    "alpha NONE: alpha": _tex(_mode("NONE"), "Alpha"),
    **{f"{space}: colour{', alpha used' if used else ''}": _tex(_space(space), alpha_to_strength=used)
       for space in ("Non-Color", "Linear Rec.709") for used in (False, True)},
    "float: colour": _tex(_float),
    "float: alpha": _tex(_float, "Alpha"),
    "float: colour, alpha used": _tex(_float, alpha_to_strength=True),
    "file image": _tex(_file_image, interpolation="Cubic"),
    "missing file": _tex(_missing_image),
    "no image": _tex(lambda: None),
    "environment equirectangular": _env(_hdr),
    "environment equirectangular closest": _env(_hdr_20, interpolation="Closest"),
    "environment at the position": _env(_hdr, vector=None),
    "environment mirror ball": _env(_hdr, projection="MIRROR_BALL"),
    "environment mirror ball, normal": (_env(_hdr, projection="MIRROR_BALL", vector="Normal"), _tilted),
}


@pytest.fixture(scope="module")
def images():
    return render_cases(CASES)


@pytest.mark.parametrize("name", list(CASES))
def test_image_node_agrees_with_cycles(images, name):
    ref, ours = images[name]
    assert np.abs(ref).max() > 0
    # Closest lookups and clipped edges jump between texels: a pixel centre may land on
    # either side of a boundary in the two engines.
    assert_agree(name, ref, ours, edge_fraction=0.03)
