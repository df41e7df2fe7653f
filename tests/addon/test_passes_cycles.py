"""Render passes against Cycles' own passes, through Blender (F12 to a multilayer EXR).

Both engines render ``glass_mirror`` (diffuse floor and walls, a sharp glass sphere, a
mirror, a cube mixing diffuse and mirror, an area light, a grey world) and
``material_principled`` (Principled layers: metal, coat, sheen, rough
transmission, alpha) with every pass MC Engine computes, under the comparison's
unbiased settings.  Each pass's frame mean per channel must agree, within bounds
from the measured seed-to-seed spread (``TOLERANCE``, ``LIGHT_SPREAD``); the
diffuse, glossy and transmission light passes are compared through the light they
carry (the pass times its Color pass), which is how the split of Combined between
them shows.  Cryptomatte must produce the same ids and manifests as Cycles, and the
same object at the first rank wherever Cycles is sure of it.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import bpy
import numpy as np
import pytest

from mcengine.imageio import read_exr_header, read_exr_layers
from mcengine.passes import DENOISING_PASSES, PASSES

ROOT = Path(__file__).resolve().parents[2]
SIZE, SAMPLES = 48, 512
COLOR = {p.slot: p for p in PASSES}
# Relative bound on a pass's frame mean (of the pass's mean magnitude), from the measured
# spread between Cycles seeds (at most 1.2 % at 128 samples, less at SAMPLES) with margin;
# Depth, Position and indices come from the pixel centre and agree to float precision.
TOLERANCE = 0.04
# The light passes (Direct and Indirect) are compared through the light they carry: the pass
# times its Color pass, its term in Combined = sum of (Direct + Indirect) x Color + Emission +
# Environment.  The frame mean of the pass itself, light divided by colour pixel by pixel, is
# ruled by the few pixels whose colour is near 0: over 10 seeds of each engine its relative
# standard deviation reaches 13 % (Cycles) and 21 % (MC Engine), so one render of each cannot
# tell a wrong split from noise.  The light's reaches 1.9 %: LIGHT_SPREAD is its per-render
# relative standard deviation, measured over 10 seeds of each engine on each scene at SIZE and
# SAMPLES (the largest of the four); the bound is 4 standard deviations of the difference of
# two renders, and differences below LIGHT_FLOOR (a 40000th of Combined) count as none (MC
# Engine's Transmission Direct on material_principled is 5e-8, Cycles' 0).
LIGHT_SPREAD = {"Diffuse Direct": 0.0003, "Diffuse Indirect": 0.014, "Glossy Direct": 0.018,
                "Glossy Indirect": 0.011, "Transmission Direct": 0.0,
                "Transmission Indirect": 0.019}
LIGHT_FLOOR = 1e-5


def _render(path: Path, engine: str, blend: str, seed: int = 1) -> tuple[dict, dict]:
    from mcengine_blender.batch.settings import make_unbiased, set_image_format
    bpy.ops.wm.open_mainfile(filepath=str(ROOT / "blend_scenes" / blend), load_ui=False)
    scene = bpy.context.scene
    scene.render.engine = engine
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    make_unbiased(scene)
    scene.cycles.samples, scene.cycles.seed = SAMPLES, seed
    layer = scene.view_layers[0]
    for p in PASSES:
        setattr(layer, p.setting, True)
    layer.use_pass_cryptomatte_object = layer.use_pass_cryptomatte_material = True
    layer.use_pass_cryptomatte_asset = True
    layer.cycles.denoising_store_passes = True
    set_image_format(scene, "OPEN_EXR_MULTILAYER")
    scene.render.filepath = str(path)
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)
    return read_exr_layers(path), read_exr_header(path)


@pytest.fixture(scope="module", params=["glass_mirror.blend", "material_principled.blend"])
def renders(request, addon, tmp_path_factory):
    folder = tmp_path_factory.mktemp("passes")
    addon.register()
    ours = _render(folder / "mcengine.exr", "MCENGINE", request.param)
    cycles = _render(folder / "cycles.exr", "CYCLES", request.param)
    return ours, cycles


def _pass(layers: dict, name: str, channels: str = "rgba") -> np.ndarray:
    """(h, w, C) of one pass from read_exr_layers' groups, channels in the pass's order."""
    whole = layers.get(f"ViewLayer.{name}")
    if whole is not None:
        return whole if whole.ndim == 3 else whole[..., None]
    return np.stack([layers[f"ViewLayer.{name}.{c}"] for c in channels], axis=-1)


def _cases():
    for info in PASSES + DENOISING_PASSES:
        yield pytest.param(info, id=info.name)


@pytest.mark.parametrize("info", list(_cases()))
def test_pass_frame_means_agree_with_cycles(renders, info):
    (ours, _), (cycles, _) = renders
    a, b = _pass(ours, info.name, info.channels), _pass(cycles, info.name, info.channels)
    assert a.shape == b.shape
    if info.readout == "light":
        color = COLOR[info.divide]
        a = a * _pass(ours, color.name, color.channels)
        b = b * _pass(cycles, color.name, color.channels)
        mean_a, mean_b = a.reshape(-1, 3).mean(0), b.reshape(-1, 3).mean(0)
        bound = 4.0 * math.sqrt(2.0) * LIGHT_SPREAD[info.name] * np.abs(mean_b) + LIGHT_FLOOR
        assert np.all(np.abs(mean_a - mean_b) <= bound), \
            f"{info.name} x {color.name}: MC Engine {mean_a}, Cycles {mean_b}, bound {bound}"
        return
    if info.name == "Depth":   # the background: 1e10 in both
        assert np.array_equal(a > 1e9, b > 1e9)
        a, b = np.where(a > 1e9, 0, a), np.where(b > 1e9, 0, b)
    mean_a, mean_b = a.reshape(-1, a.shape[-1]).mean(0), b.reshape(-1, b.shape[-1]).mean(0)
    scale = max(float(np.abs(b).mean()), 0.02)   # below 8e-4 absolute, differences are noise
    np.testing.assert_allclose(mean_a, mean_b, atol=TOLERANCE * scale,
                               err_msg=f"{info.name}: MC Engine {mean_a}, Cycles {mean_b}")


def test_cryptomatte_ids_and_manifests_match_cycles(renders):
    (ours, our_header), (cycles, cycles_header) = renders
    crypto_keys = sorted(k for k in cycles_header if k.startswith("cryptomatte/"))
    for key in crypto_keys:
        if key.endswith("/manifest"):
            theirs = json.loads(cycles_header[key])
            mine = json.loads(our_header[key])
            # Cycles lists its default shaders too; every name we list is Cycles' with its hash.
            assert mine and all(theirs.get(name) == h for name, h in mine.items()), key
        else:
            assert our_header[key] == cycles_header[key], key
    for prefix in ("CryptoObject", "CryptoMaterial", "CryptoAsset"):
        a, b = _pass(ours, f"{prefix}00"), _pass(cycles, f"{prefix}00")
        sure = b[..., 1] > 0.99                       # one id covers the whole pixel in Cycles
        assert sure.mean() > 0.5
        agree = a[..., 0][sure] == b[..., 0][sure]
        assert agree.mean() > 0.98, f"{prefix}: rank 0 ids agree on {agree.mean():.1%}"
        mine = sum(_pass(ours, f"{prefix}{k:02d}")[..., c] for k in range(3) for c in (1, 3))
        theirs = sum(_pass(cycles, f"{prefix}{k:02d}")[..., c] for k in range(3) for c in (1, 3))
        assert mine.mean() == pytest.approx(theirs.mean(), rel=0.01)


def test_render_statistics_in_the_exr_header(renders):
    (_, header), _ = renders
    assert header["mcengine.ViewLayer.samples"] == str(SAMPLES)
    assert header["mcengine.ViewLayer.samples_rendered"] == str(SAMPLES)
    assert int(header["mcengine.ViewLayer.rays_per_second"]) > 0
    assert header["mcengine.ViewLayer.nonfinite_samples"] == "0"
    for key in ("total_time", "render_time", "synchronization_time"):
        minutes, seconds = header[f"mcengine.ViewLayer.{key}"].split(":")
        assert len(minutes) == 2 and len(seconds) == 5 and seconds[2] == "."


def _moving_plane(path: Path, engine: str) -> np.ndarray:
    """Vector pass of a plane that slides and turns under a camera that moves and zooms
    (Bezier keys at frames 1 and 5, frame 3 rendered), 40 x 30 pixels, 16 samples."""
    from mcengine_blender.batch.settings import set_image_format
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = engine
    scene.render.resolution_x, scene.render.resolution_y = 40, 30
    scene.render.resolution_percentage = 100
    scene.cycles.samples, scene.cycles.use_denoising = 16, False
    mesh = bpy.data.meshes.new("Plane")
    mesh.from_pydata([(-20, -20, 0), (20, -20, 0), (20, 20, 0), (-20, 20, 0)], [], [(0, 1, 2, 3)])
    plane = bpy.data.objects.new("Plane", mesh)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    for ob in (plane, cam):
        scene.collection.objects.link(ob)
    scene.camera = cam
    for frame, (loc, angle, cam_x, lens) in ((1, ((0, 0, 0), 0.0, 0.0, 50.0)),
                                             (5, ((0.8, 0.4, 1.0), 0.3, -0.4, 60.0))):
        plane.location, plane.rotation_euler = loc, (0.0, 0.0, angle)
        cam.location, cam.data.lens = (cam_x, 0.0, 10.0), lens
        plane.keyframe_insert("location", frame=frame)
        plane.keyframe_insert("rotation_euler", frame=frame)
        cam.keyframe_insert("location", frame=frame)
        cam.data.keyframe_insert("lens", frame=frame)
    scene.frame_set(3)
    scene.view_layers[0].use_pass_vector = True
    set_image_format(scene, "OPEN_EXR_MULTILAYER")
    scene.render.filepath = str(path)
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)
    return _pass(read_exr_layers(path), "Vector", "XYZW")


def test_vector_pass_matches_cycles(addon, tmp_path):
    """Per pixel: the vectors (up to 6.6 pixels, varying over the frame with the turn and
    the zoom) agree to 0.05 pixel (measured: at most 0.023, from the samples' different
    positions within the pixels, over which the vector varies by about 0.1 pixel)."""
    addon.register()
    ours = _moving_plane(tmp_path / "mcengine.exr", "MCENGINE")
    cycles = _moving_plane(tmp_path / "cycles.exr", "CYCLES")
    assert np.abs(cycles).max() > 5.0 and np.ptp(cycles[..., 0]) > 3.0
    np.testing.assert_allclose(ours, cycles, atol=0.05)
