"""Render passes: the vocabulary, the film layout and the images read from it.

Each pass Blender shows in View Layer > Passes for Cycles has a row in
:data:`PASSES`: its name and channels as Cycles registers them
(addons_core/cycles/engine.py ``list_render_passes``), the view layer setting
that enables it, the kernel slot it accumulates in (``kernels.passes``) and how
its image is read from the per-pixel sums (Cycles' kernel/film/read.h):

``first``   the value the pixel's first sample wrote (depth, position, indices);
            depth 0 (background) reads as 1e10
``mean``    the sum over the pixel's samples divided by their number
``mist``    1 minus the mean (the kernels sum 1 - mist)
``light``   direct or indirect light divided by its colour pass (the sample
            counts cancel), times the film exposure: Combined = Σ (direct +
            indirect) × colour + emission + environment
``exposed`` the mean times the film exposure (emission, environment)
``motion``  the sum over the samples that hit a surface divided by their number
            (Vector: the kernels sum a weight of 1 per such sample); 0 where none
            did, and everywhere when motion blur is on (Cycles writes the pass
            only without motion blur)

:class:`RenderPasses` holds a render's pass settings; :func:`layout` assigns
film columns (only for the passes enabled, and the colour passes the light
passes divide by) and :func:`read` turns the film's sums into images.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from . import cryptomatte
from .kernels import passes as kp
from .kernels.camera import camera_axes, view_plane

__all__ = ["PassInfo", "PASSES", "CRYPTO_TYPES", "DENOISING_PASSES", "NOISY_IMAGE", "RenderPasses",
           "Layout", "layout", "read", "MIST_FALLOFFS",
           "cryptomatte_metadata", "kernel_data", "world_to_camera", "world_to_raster",
           "motion_corners", "bytes_per_pixel"]


class PassInfo(NamedTuple):
    name: str           # as Blender shows it (and names the EXR layer)
    channels: str       # channel ids, as Cycles registers them
    kind: str           # 'COLOR', 'VECTOR' or 'VALUE' (register_pass type)
    setting: str        # the ViewLayer property that enables it
    slot: int           # kernels.passes.P_*
    readout: str        # see the module docstring
    divide: int = -1    # 'light': the colour pass's slot


PASSES = (
    PassInfo("Depth", "Z", "VALUE", "use_pass_z", kp.P_DEPTH, "first"),
    PassInfo("Mist", "Z", "VALUE", "use_pass_mist", kp.P_MIST, "mist"),
    PassInfo("Position", "XYZ", "VECTOR", "use_pass_position", kp.P_POSITION, "first"),
    PassInfo("Normal", "XYZ", "VECTOR", "use_pass_normal", kp.P_NORMAL, "mean"),
    PassInfo("Vector", "XYZW", "VECTOR", "use_pass_vector", kp.P_VECTOR, "motion"),
    PassInfo("UV", "UVA", "VECTOR", "use_pass_uv", kp.P_UV, "mean"),
    PassInfo("Object Index", "X", "VALUE", "use_pass_object_index", kp.P_OBJECT_ID, "first"),
    PassInfo("Material Index", "X", "VALUE", "use_pass_material_index", kp.P_MATERIAL_ID, "first"),
    PassInfo("Diffuse Direct", "RGB", "COLOR", "use_pass_diffuse_direct", kp.P_DIFFUSE_DIRECT,
             "light", kp.P_DIFFUSE_COLOR),
    PassInfo("Diffuse Indirect", "RGB", "COLOR", "use_pass_diffuse_indirect",
             kp.P_DIFFUSE_INDIRECT, "light", kp.P_DIFFUSE_COLOR),
    PassInfo("Diffuse Color", "RGB", "COLOR", "use_pass_diffuse_color", kp.P_DIFFUSE_COLOR, "mean"),
    PassInfo("Glossy Direct", "RGB", "COLOR", "use_pass_glossy_direct", kp.P_GLOSSY_DIRECT,
             "light", kp.P_GLOSSY_COLOR),
    PassInfo("Glossy Indirect", "RGB", "COLOR", "use_pass_glossy_indirect", kp.P_GLOSSY_INDIRECT,
             "light", kp.P_GLOSSY_COLOR),
    PassInfo("Glossy Color", "RGB", "COLOR", "use_pass_glossy_color", kp.P_GLOSSY_COLOR, "mean"),
    PassInfo("Transmission Direct", "RGB", "COLOR", "use_pass_transmission_direct",
             kp.P_TRANSMISSION_DIRECT, "light", kp.P_TRANSMISSION_COLOR),
    PassInfo("Transmission Indirect", "RGB", "COLOR", "use_pass_transmission_indirect",
             kp.P_TRANSMISSION_INDIRECT, "light", kp.P_TRANSMISSION_COLOR),
    PassInfo("Transmission Color", "RGB", "COLOR", "use_pass_transmission_color",
             kp.P_TRANSMISSION_COLOR, "mean"),
    PassInfo("Emission", "RGB", "COLOR", "use_pass_emit", kp.P_EMISSION, "exposed"),
    PassInfo("Environment", "RGB", "COLOR", "use_pass_environment", kp.P_ENVIRONMENT, "exposed"),
    PassInfo("Ambient Occlusion", "RGB", "COLOR", "use_pass_ambient_occlusion", kp.P_AO, "mean"),
)
BY_NAME = {p.name: p for p in PASSES}

# Cryptomatte: (pass name prefix, ViewLayer setting, kernel slot, metadata layer suffix).
CRYPTO_TYPES = (
    ("CryptoObject", "use_pass_cryptomatte_object", kp.P_CRYPTO_OBJECT),
    ("CryptoMaterial", "use_pass_cryptomatte_material", kp.P_CRYPTO_MATERIAL),
    ("CryptoAsset", "use_pass_cryptomatte_asset", kp.P_CRYPTO_ASSET),
)

# Cycles' "Denoising Data" passes (view_layer.cycles.denoising_store_passes).
DENOISING_PASSES = (
    PassInfo("Denoising Normal", "XYZ", "VECTOR", "", kp.P_DENOISING_NORMAL, "mean"),
    PassInfo("Denoising Albedo", "RGB", "COLOR", "", kp.P_DENOISING_ALBEDO, "mean"),
    PassInfo("Denoising Depth", "Z", "VALUE", "", kp.P_DENOISING_DEPTH, "mean"),
)
NOISY_IMAGE = PassInfo("Noisy Image", "RGBA", "COLOR", "", -1, "")

# Mist falloff (world.mist_settings.falloff) -> the exponent Cycles applies.
MIST_FALLOFFS = {"QUADRATIC": 2.0, "LINEAR": 1.0, "INVERSE_QUADRATIC": 0.5}


@dataclass
class RenderPasses:
    """The passes of a render besides Combined, with their settings (Blender's names).

    ``enabled`` lists names of :data:`PASSES`; ``cryptomatte`` the Cryptomatte
    types ("CryptoObject", ...) with ``cryptomatte_depth`` ranks each;
    ``denoising_data`` adds Cycles' Denoising Normal, Albedo and Depth.
    Mist settings are the world's; ``alpha_threshold`` is the view layer's
    (normal and UV come from the first surface at least that opaque).  ``ao_distance``
    is how far the Ambient Occlusion pass looks: the world's AO distance (Blender's
    default, 10, without a world).
    ``view_layer`` names the Cryptomatte metadata layers.  With ``motion_blur`` on, the
    Vector pass is left at 0, as Cycles leaves it.
    """

    enabled: tuple = ()
    cryptomatte: tuple = ()
    cryptomatte_depth: int = 6
    denoising_data: bool = False
    mist_start: float = 5.0
    mist_depth: float = 25.0
    mist_falloff: str = "QUADRATIC"
    alpha_threshold: float = 0.5
    ao_distance: float = 10.0
    view_layer: str = "ViewLayer"
    motion_blur: bool = False

    def names(self) -> list[str]:
        """Every pass of the render result besides Combined, in Blender's order."""
        out = [p.name for p in PASSES if p.name in self.enabled]
        n = cryptomatte.passes_for_depth(self.cryptomatte_depth)
        for prefix, _setting, _slot in CRYPTO_TYPES:
            if prefix in self.cryptomatte:
                out += [f"{prefix}{k:02d}" for k in range(n)]
        if self.denoising_data:
            out += [p.name for p in DENOISING_PASSES]
        return out

    def check(self) -> list[str]:
        """Problems with the settings, one line each (empty when valid)."""
        problems = [f"unknown render pass {name!r}" for name in self.enabled if name not in BY_NAME]
        problems += [f"unknown Cryptomatte type {name!r}" for name in self.cryptomatte
                     if name not in {c[0] for c in CRYPTO_TYPES}]
        if self.mist_falloff not in MIST_FALLOFFS:
            problems.append(f"unknown mist falloff {self.mist_falloff!r}")
        for name in ("mist_start", "mist_depth", "alpha_threshold"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                problems.append(f"passes: {name} must be a finite number >= 0, got {value!r}")
        if not 1 <= int(self.cryptomatte_depth) <= cryptomatte.MAX_DEPTH:
            problems.append(f"passes: cryptomatte_depth must be 1..{cryptomatte.MAX_DEPTH}")
        return problems


@dataclass
class Layout:
    """Where each pass's sums live in a pixel's row of the film (``Film.passes``)."""

    columns: dict = field(default_factory=dict)   # slot -> first column
    stride: int = 0
    crypto_slots: int = 0                          # (id, weight) pairs per Cryptomatte type

    def __contains__(self, slot: int) -> bool:
        return slot in self.columns


_WIDTH = {kp.P_DEPTH: 1, kp.P_MIST: 1, kp.P_OBJECT_ID: 1, kp.P_MATERIAL_ID: 1, kp.P_VECTOR: 5,
          kp.P_DENOISING_DEPTH: 1}


def layout(passes: RenderPasses, denoising_guides: tuple = ()) -> Layout:
    """Film columns for the enabled passes (and the colour passes that light passes divide
    by, and the guide passes ``denoising_guides``: slots the denoiser reads)."""
    slots = []
    for p in PASSES:
        if p.name in passes.enabled and not (
                p.slot == kp.P_VECTOR and passes.motion_blur):
            slots.append(p.slot)
            if p.divide >= 0:
                slots.append(p.divide)
    if passes.denoising_data:
        slots += [p.slot for p in DENOISING_PASSES]
    slots += list(denoising_guides)
    out = Layout()
    col = 0
    for slot in sorted(set(slots)):
        out.columns[slot] = col
        col += _WIDTH.get(slot, 3)
    n_passes = cryptomatte.passes_for_depth(passes.cryptomatte_depth)
    for prefix, _setting, slot in CRYPTO_TYPES:
        if prefix in passes.cryptomatte:
            out.columns[slot] = col
            col += 4 * n_passes
            out.crypto_slots = 2 * n_passes
    out.stride = col
    return out


def bytes_per_pixel(passes: RenderPasses, denoising_guides: tuple = ()) -> int:
    """Film memory of the passes per pixel (float64 sums)."""
    return 8 * layout(passes, denoising_guides).stride


def read(name: str, sums: np.ndarray, count: np.ndarray, lay: Layout, exposure: float = 1.0
         ) -> np.ndarray:
    """(n, channels) float32 image of pass ``name`` from the film's pass sums (n, stride)
    and sample counts (n,)."""
    if name.startswith("Crypto"):
        return _read_crypto(name, sums, count, lay)
    info = BY_NAME.get(name) or next(p for p in DENOISING_PASSES if p.name == name)
    width = len(info.channels)
    n = count.shape[0]
    if info.slot not in lay:
        return np.zeros((n, width), np.float32)
    col = lay.columns[info.slot]
    if info.readout == "motion":
        weight = sums[:, col + 4:col + 5]
        return np.where(weight > 0.0, sums[:, col:col + 4] / np.where(weight > 0.0, weight, 1.0),
                        0.0).astype(np.float32)
    values = sums[:, col:col + min(width, 3)]
    if info.readout == "first":
        out = values.copy()
        if info.slot == kp.P_DEPTH:
            out[out == 0.0] = 1e10
        return out.astype(np.float32)
    samples = np.maximum(count, 1)[:, None].astype(np.float64)
    if info.readout == "mist":
        return np.clip(1.0 - values / samples, 0.0, 1.0).astype(np.float32)
    if info.readout == "light":
        dcol = lay.columns[info.divide]
        return (_divide_even_color(values, sums[:, dcol:dcol + 3]) * exposure).astype(np.float32)
    mean = values / samples
    if info.readout == "exposed":
        mean = mean * exposure
    return mean.astype(np.float32)


def _divide_even_color(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cycles' safe_divide_even_color: a / b per channel; a channel whose b is 0 takes the
    mean of the others' quotients (or the one other), so grey light stays grey."""
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.where(b != 0.0, a / np.where(b != 0.0, b, 1.0), 0.0)
    zero = b == 0.0
    x, y, z = q[:, 0].copy(), q[:, 1].copy(), q[:, 2].copy()
    zx, zy, zz = zero[:, 0], zero[:, 1], zero[:, 2]
    # b.x == 0
    m = zx & zy
    x[m], y[m] = z[m], z[m]
    m = zx & ~zy & zz
    x[m], z[m] = y[m], y[m]
    m = zx & ~zy & ~zz
    x[m] = 0.5 * (y[m] + z[m])
    # b.y == 0 (b.x != 0)
    m = ~zx & zy & zz
    y[m], z[m] = x[m], x[m]
    m = ~zx & zy & ~zz
    y[m] = 0.5 * (x[m] + z[m])
    # b.z == 0 only
    m = ~zx & ~zy & zz
    z[m] = 0.5 * (x[m] + y[m])
    return np.stack([x, y, z], axis=1)


def _read_crypto(name: str, sums, count, lay: Layout) -> np.ndarray:
    """One RGBA Cryptomatte pass: ranks 2k and 2k + 1 (id, coverage, id, coverage), ranks
    sorted by coverage, coverage divided by the sample count."""
    prefix, index = name[:-2], int(name[-2:])
    slot = next(s for p, _setting, s in CRYPTO_TYPES if p == prefix)
    col = lay.columns[slot]
    pairs = sums[:, col:col + 2 * lay.crypto_slots].reshape(-1, lay.crypto_slots, 2)
    order = np.argsort(-pairs[:, :, 1], axis=1, kind="stable")
    ranked = np.take_along_axis(pairs, order[:, :, None], axis=1)
    ranks = ranked[:, 2 * index:2 * index + 2].copy()
    ranks[:, :, 1] /= np.maximum(count, 1)[:, None]
    return ranks.reshape(-1, 4).astype(np.float32)


def cryptomatte_metadata(passes: RenderPasses, objects, materials, used_materials=None) -> dict:
    """Metadata fields of the enabled Cryptomatte layers ("<view layer>.CryptoObject", ...):
    the manifests list the objects' names, the materials' names (those of the indices
    ``used_materials`` when given) or the objects' assets."""
    names = {"CryptoObject": [o.name for o in objects], "CryptoAsset": [o.asset for o in objects],
             "CryptoMaterial": [m.name for m in materials]}
    if used_materials is not None:
        names["CryptoMaterial"] = [materials[k].name for k in sorted(set(used_materials))]
    fields = {}
    for prefix, _setting, _slot in CRYPTO_TYPES:
        if prefix in passes.cryptomatte:
            fields.update(cryptomatte.layer_metadata(f"{passes.view_layer}.{prefix}",
                                                     names[prefix]))
    return fields


def kernel_data(lay: Layout, passes: RenderPasses, camera_to_world: np.ndarray, ortho: bool,
                tri_uv, tri_object, mat_info, tri_motion=None, rasters=None) -> kp.PassData:
    """The kernels' :class:`kernels.passes.PassData` for a layout; ``tri_motion`` and
    ``rasters`` (world to raster now, at the previous and the next frame) for the Vector
    pass."""
    cfg = np.full(kp.PC_SIZE, -1, np.int64)
    for slot, col in lay.columns.items():
        cfg[slot] = col
    data_slots = (kp.P_DEPTH, kp.P_MIST, kp.P_POSITION, kp.P_NORMAL, kp.P_UV, kp.P_VECTOR,
                  kp.P_OBJECT_ID, kp.P_MATERIAL_ID, kp.P_DIFFUSE_COLOR, kp.P_GLOSSY_COLOR, kp.P_TRANSMISSION_COLOR,
                  kp.P_CRYPTO_OBJECT, kp.P_CRYPTO_MATERIAL, kp.P_CRYPTO_ASSET)
    light_slots = (kp.P_DIFFUSE_DIRECT, kp.P_DIFFUSE_INDIRECT, kp.P_GLOSSY_DIRECT,
                   kp.P_GLOSSY_INDIRECT, kp.P_TRANSMISSION_DIRECT, kp.P_TRANSMISSION_INDIRECT,
                   kp.P_EMISSION, kp.P_ENVIRONMENT, kp.P_DENOISING_ALBEDO)
    denoise_slots = (kp.P_DENOISING_ALBEDO, kp.P_DENOISING_NORMAL, kp.P_DENOISING_DEPTH)
    cfg[kp.PC_DATA] = int(any(s in lay for s in data_slots))
    cfg[kp.PC_LIGHT] = int(any(s in lay for s in light_slots))
    cfg[kp.PC_DENOISE] = int(any(s in lay for s in denoise_slots))
    cfg[kp.PC_SPLIT] = int(any(s in lay for s in light_slots[:6]))
    cfg[kp.PC_CRYPTO_SLOTS] = lay.crypto_slots
    cfg[kp.PC_STRIDE] = lay.stride
    fcfg = np.zeros(kp.PV_SIZE)
    fcfg[kp.PV_MIST_START] = passes.mist_start
    fcfg[kp.PV_MIST_INV_DEPTH] = 1.0 / passes.mist_depth if passes.mist_depth > 0 else 0.0
    fcfg[kp.PV_MIST_FALLOFF] = MIST_FALLOFFS[passes.mist_falloff]
    fcfg[kp.PV_ALPHA_THRESHOLD] = passes.alpha_threshold
    fcfg[kp.PV_ORTHO] = 1.0 if ortho else 0.0
    fcfg[kp.PV_AO_DISTANCE] = passes.ao_distance
    fcfg[kp.PV_CAMERA:kp.PV_CAMERA + 12] = world_to_camera(camera_to_world).reshape(-1)
    if rasters is not None:
        fcfg[kp.PV_RASTER:kp.PV_RASTER + 36] = np.asarray(rasters, np.float64).reshape(-1)
    if tri_motion is None:
        tri_motion = np.zeros((1, 2, 3, 3), np.float32)
    return kp.PassData(cfg=cfg, fcfg=fcfg, tri_uv=tri_uv, tri_object=tri_object,
                       mat_info=mat_info, tri_motion=tri_motion)


def world_to_camera(camera_to_world: np.ndarray) -> np.ndarray:
    """(3, 4) rows of Cycles' world-to-camera transform: x right, y up, z forward (the
    Blender camera looks along its local -Z), axes normalised."""
    axes = camera_axes(camera_to_world)
    rot = axes[:3, :3].T
    return np.concatenate([rot, (-rot @ axes[:3, 3])[:, None]], axis=1)


def world_to_raster(camera_to_world: np.ndarray, cam, width: int, height: int,
                    pixel_aspect=(1.0, 1.0), view_scale: float = 1.0) -> np.ndarray:
    """(3, 4) rows x, y, w of the projection of world points to raster positions (pixels,
    x right, y up from the frame's bottom-left corner: Cycles' raster space), for the camera
    ``cam`` (a ``scene.Camera``) placed at ``camera_to_world``.  ``view_scale`` scales a
    perspective camera's view plane (a focal length other than the frame's, as
    ``Camera.view_scale_motion``)."""
    half_w, half_h, shift_x, shift_y = view_plane(cam, width, height, pixel_aspect)
    to_cam = world_to_camera(camera_to_world)
    sx, sy = width / (2.0 * half_w), height / (2.0 * half_h)
    if cam.type == "ORTHO":
        depth = np.array([0.0, 0.0, 0.0, 1.0])
        view = 1.0
    else:
        depth = to_cam[2]
        view = 1.0 / view_scale
    return np.stack([sx * (view * to_cam[0] + (half_w - shift_x) * depth),
                     sy * (view * to_cam[1] + (half_h - shift_y) * depth), depth])


def motion_corners(geometry, motion) -> np.ndarray:
    """(T, 2, 3, 3) float32 world corners of every triangle at the previous and the next
    frame, from a ``scene.MotionVectors`` (None: nothing moves).  An object's vertices there
    are ``M(t) M(frame)^-1`` applied to its positions at t (deformed) or at the frame."""
    vertices = np.asarray(geometry.vertices, np.float64)
    steps = [vertices.copy(), vertices.copy()]
    for om in (motion.objects if motion is not None else ()):
        first, count = om.vertices
        for k, step in enumerate((0, -1)):
            v = vertices[first:first + count] if om.positions is None else \
                np.asarray(om.positions[step], np.float64)
            if len(om.matrices):
                m = np.asarray(om.matrices, np.float64)
                a = m[step] @ np.linalg.inv(m[len(m) // 2])
                v = v @ a[:3, :3].T + a[:3, 3]
            steps[k][first:first + count] = v
    tris = np.asarray(geometry.triangles)
    return np.ascontiguousarray(np.stack([steps[0][tris], steps[1][tris]], axis=1), np.float32)
