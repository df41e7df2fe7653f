"""Texture images as the kernels read them: Cycles' load conventions, two flat pools.

Every image of the scene (``SceneDescription.images``) is loaded once per render
and shared by every node that reads it.  Loading follows Cycles (scene/image.cpp,
blender/image.cpp):

* grey, grey + alpha and RGB images become RGBA (missing alpha 1); one-channel
  images stay one channel (read as (v, v, v, 1));
* straight alpha is multiplied into the colour ("associated"), in integers for 8-bit
  images (c * a // 255, as Cycles does for Blender's byte buffers), except for data
  images, channel-packed alpha and alpha mode None (whose alpha becomes 1);
* non-finite float texels become (0, 0, 0, 0);
* 8-bit images stay 8-bit (``pix8``), float images float32 (``pixf``).

``ImageTable`` holds the pools and each image's row of ``kernels.svm.data.IMG_*``
columns, and the slot of each image name for the shader compiler.
"""
from __future__ import annotations

import numpy as np

from .kernels.svm.data import (
    IMG_CHANNELS,
    IMG_FLAGS,
    IMG_FLOAT,
    IMG_HEIGHT,
    IMG_OFFSET,
    IMG_STRIDE,
    IMG_WIDTH,
    IMGF_SRGB,
    IMGF_UNASSOCIATE,
)
from .scene import Image

__all__ = ["ImageTable", "load_texels"]


def load_texels(image: Image) -> np.ndarray:
    """The texels of ``image`` as the kernels store them: (H, W, 1 or 4), uint8 or float32."""
    p = np.asarray(image.pixels)
    c = p.shape[2]
    is_float = p.dtype != np.uint8
    if is_float:
        p = p.astype(np.float32, copy=True)
        bad = ~np.all(np.isfinite(p), axis=2)
        p[bad] = 0.0
    if c == 1:
        return np.ascontiguousarray(p)
    rgba = np.empty(p.shape[:2] + (4,), p.dtype)
    if c == 2:
        rgba[..., :3] = p[..., :1]
        rgba[..., 3] = p[..., 1]
    else:
        rgba[..., :3] = p[..., :3]
        rgba[..., 3] = p[..., 3] if c == 4 else (1.0 if is_float else 255)
    if image.alpha == "NONE":
        rgba[..., 3] = 1.0 if is_float else 255
    elif image.alpha == "STRAIGHT" and image.colorspace != "data":
        if is_float:
            rgba[..., :3] *= rgba[..., 3:]
        else:
            wide = rgba.astype(np.uint32)
            rgba[..., :3] = (wide[..., :3] * wide[..., 3:]) // 255
    return rgba


class ImageTable:
    """The render's images in two pools, and each one's slot (``slots[name]``)."""

    def __init__(self, images: dict):
        self.slots: dict[str, int] = {}
        rows, bytes8, floats = [], [], []
        n8 = nf = 0
        for name, image in images.items():
            texels = load_texels(image)
            h, w, c = texels.shape
            is_float = texels.dtype == np.float32
            flags = 0
            if image.colorspace == "sRGB":
                flags |= IMGF_SRGB
            if image.colorspace != "data" and image.alpha not in ("CHANNEL_PACKED", "NONE"):
                flags |= IMGF_UNASSOCIATE
            row = np.zeros(IMG_STRIDE, np.int64)
            row[IMG_OFFSET] = nf if is_float else n8
            row[IMG_WIDTH], row[IMG_HEIGHT], row[IMG_CHANNELS] = w, h, c
            row[IMG_FLOAT] = 1 if is_float else 0
            row[IMG_FLAGS] = flags
            (floats if is_float else bytes8).append(texels.ravel())
            if is_float:
                nf += texels.size
            else:
                n8 += texels.size
            self.slots[name] = len(rows)
            rows.append(row)
        self.info = np.array(rows, np.int64).reshape(-1, IMG_STRIDE)
        self.pix8 = np.concatenate(bytes8) if bytes8 else np.zeros(0, np.uint8)
        self.pixf = np.concatenate(floats) if floats else np.zeros(0, np.float32)

    @property
    def nbytes(self) -> int:
        """Memory of the texels."""
        return int(self.pix8.nbytes + self.pixf.nbytes)
