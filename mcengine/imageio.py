"""Image files: linear float OpenEXR for data, 8-bit PNG for people.

Arrays are (h, w, C) with the top row first, as stored in EXR files.  PNG
output applies Blender's "Standard" view transform (the sRGB curve, values
clipped to [0, 1]); the EXR is the scene-linear truth.
"""
from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np


class ImageError(ValueError):
    """An image could not be read or written; the message says why."""


def write_exr(path, rgba) -> None:
    """Write (h, w, 3|4) linear float data as a 32-bit float EXR (ZIP compressed)."""
    import OpenEXR
    img = np.ascontiguousarray(rgba, np.float32)
    if img.ndim != 3 or img.shape[2] not in (3, 4):
        raise ImageError(f"expected an (h, w, 3|4) image, got shape {img.shape}")
    name = "RGBA" if img.shape[2] == 4 else "RGB"
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    try:
        with OpenEXR.File(header, {name: img}) as f:
            f.write(str(path))
    except Exception as exc:  # OpenEXR raises plain exceptions on I/O errors
        raise ImageError(f"cannot write {path}: {exc}") from None


def read_exr(path) -> np.ndarray:
    """(h, w, 4) float32 RGBA from an EXR written by us or by Blender (alpha 1 if absent)."""
    import OpenEXR
    try:
        with OpenEXR.File(str(path)) as f:
            channels = {k: np.asarray(v.pixels) for k, v in f.channels().items()}
    except Exception as exc:
        raise ImageError(f"cannot read {path}: {exc}") from None
    for name in ("RGBA", "RGB"):
        if name in channels:
            img = channels[name].astype(np.float32)
            break
    else:
        # Separate channels, possibly with a layer prefix ("Combined.R").
        def find(c):
            for k, v in channels.items():
                if k == c or k.endswith("." + c):
                    return v
            return None
        rgb = [find(c) for c in "RGB"]
        if any(c is None for c in rgb):
            raise ImageError(f"{path}: no R, G, B channels (found {sorted(channels)})")
        a = find("A")
        img = np.stack(rgb + ([a] if a is not None else []), axis=-1).astype(np.float32)
    if img.shape[2] == 3:
        img = np.concatenate([img, np.ones(img.shape[:2] + (1,), np.float32)], axis=-1)
    return img


def read_exr_layers(path) -> dict:
    """Every channel group of an EXR, single- or multi-part (a multilayer file written by
    Blender: one part per pass), decoded in full: name ("ViewLayer.Depth.Z", or
    "ViewLayer.Combined" for its RGBA) -> (h, w) or (h, w, C) float32 array."""
    import OpenEXR
    try:
        with OpenEXR.File(str(path), separate_channels=False) as f:
            layers = {}
            for part in f.parts:
                for name, channel in part.channels.items():
                    layers[name] = np.asarray(channel.pixels, np.float32)
    except Exception as exc:
        raise ImageError(f"cannot read {path}: {exc}") from None
    if not layers:
        raise ImageError(f"{path}: no channels")
    return layers


def read_exr_header(path) -> dict:
    """The first part's header of an EXR: metadata name -> value (strings as str)."""
    import OpenEXR
    try:
        with OpenEXR.File(str(path), header_only=True) as f:
            header = dict(f.parts[0].header)
    except Exception as exc:
        raise ImageError(f"cannot read {path}: {exc}") from None
    return {k: (v.decode() if isinstance(v, bytes) else v) for k, v in header.items()}


def linear_to_srgb(x) -> np.ndarray:
    """The sRGB transfer curve (Blender's Standard view), input clipped to [0, 1]."""
    x = np.clip(np.asarray(x, np.float64), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def to_display(rgba, exposure: float = 0.0) -> np.ndarray:
    """(h, w, 4) uint8 for display: Standard view, exposure in stops, alpha kept."""
    img = np.asarray(rgba, np.float64)
    rgb = linear_to_srgb(img[..., :3] * 2.0 ** exposure)
    a = np.clip(img[..., 3:4], 0.0, 1.0) if img.shape[2] == 4 else np.ones(img.shape[:2] + (1,))
    return np.round(np.concatenate([rgb, a], axis=-1) * 255.0).astype(np.uint8)


def write_png(path, image, exposure: float = 0.0) -> None:
    """Write a PNG: float images go through ``to_display``; uint8 are written as they are."""
    img = np.asarray(image)
    if img.dtype != np.uint8:
        img = to_display(img if img.shape[2] == 4 else
                         np.concatenate([img, np.ones(img.shape[:2] + (1,))], axis=-1), exposure)
    h, w, c = img.shape
    color_type = {3: 2, 4: 6}[c]
    raw = b"".join(b"\x00" + img[y].tobytes() for y in range(h))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, color_type, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
    try:
        Path(path).write_bytes(png)
    except OSError as exc:
        raise ImageError(f"cannot write {path}: {exc.strerror}") from None
