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

__all__ = ["ImageTable", "associate_rgba8", "load_texels", "texel_layout", "unit_floats_to_bytes"]


# Rows converted at a time: blocks of about a megabyte stay in the cache through the few
# passes a conversion makes (a 4096 x 4096 RGBA image converted whole took 0.9 s, its
# temporaries a few hundred MB).
_BLOCK_TEXELS = 1 << 18


def texel_layout(image: Image) -> tuple[int, int, int, bool]:
    """(height, width, channels, is_float) of ``image`` as the kernels store it: one-channel
    images keep one channel, all others become RGBA; uint8 stays 8-bit, anything else float32."""
    p = np.asarray(image.pixels)
    h, w, c = p.shape
    return h, w, (1 if c == 1 else 4), p.dtype != np.uint8


def load_texels(image: Image, out: np.ndarray | None = None) -> np.ndarray:
    """The texels of ``image`` as the kernels store them: (H, W, 1 or 4), uint8 or float32,
    written to ``out`` (an array of that shape and type) if given."""
    h, w, channels, is_float = texel_layout(image)
    if out is None:
        out = np.empty((h, w, channels), np.float32 if is_float else np.uint8)
    p = np.asarray(image.pixels)
    rows = max(1, _BLOCK_TEXELS // max(w, 1))
    for y in range(0, h, rows):
        _convert_rows(image, p[y:y + rows], out[y:y + rows], is_float)
    return out


def _convert_rows(image: Image, p: np.ndarray, out: np.ndarray, is_float: bool) -> None:
    """Rows ``p`` of an image's pixels into the same rows of its texels ``out``."""
    c = p.shape[2]
    if is_float:
        p = p.astype(np.float32, copy=False)
        finite = np.isfinite(p)
        if not finite.all():
            p = p.copy()
            p[~finite.all(axis=2)] = 0.0
    if c == 1 or c == 4:
        out[...] = p
    elif c == 2:
        out[..., :3] = p[..., :1]
        out[..., 3] = p[..., 1]
    else:
        out[..., :3] = p
        out[..., 3] = 1.0 if is_float else 255
    if c == 1:
        return
    if image.alpha == "NONE":
        if is_float:
            out[..., 3] = 1.0
        else:
            out.view("<u4")[...] |= _ALPHA
    elif image.alpha == "STRAIGHT" and image.colorspace != "data":
        if is_float:
            out[..., :3] *= out[..., 3:]
        else:
            associate_rgba8(out)


_LOW = np.uint32(0x00FF00FF)       # two bytes of a texel word in 16-bit lanes
_ROUND = np.uint32(0x00010001)
_ALPHA = np.uint32(0xFF000000)
_EIGHT = np.uint32(8)


def associate_rgba8(rgba: np.ndarray) -> None:
    """In place: each colour byte c of the contiguous uint8 RGBA texels ``rgba`` becomes
    c * a // 255, a its alpha, as Cycles associates Blender's byte buffers.

    Computed on the texels as little-endian 32-bit words, two bytes at a time in 16-bit
    lanes (R and B, then G and A: c a <= 255^2 fits a lane), with x // 255 =
    (x + 1 + (x >> 8)) >> 8, exact for x <= 255^2 and never carrying into the next lane
    (at most 0xFF00); the alpha byte is then put back.  A few whole-array integer
    operations: numpy's per-channel multiply and integer division took 0.3 s for a
    4096 x 4096 image.
    """
    words = rgba.view("<u4")
    alpha = words >> np.uint32(24)
    rb = words & _LOW
    ga = (words >> _EIGHT) & _LOW
    for x in (rb, ga):
        x *= alpha
        x += _ROUND + ((x >> _EIGHT) & _LOW)
        x >>= _EIGHT
        x &= _LOW
    ga <<= _EIGHT
    rb |= ga
    rb &= ~_ALPHA
    alpha <<= np.uint32(24)
    rb |= alpha
    words[...] = rb


_ROUNDER = np.float32(1 << 23)     # x + 2^23 for x in [0, 2^23): x rounded, in the low bits


def unit_floats_to_bytes(values: np.ndarray) -> np.ndarray:
    """The bytes round(255 v) of float32 values v clipped to [0, 1] (Blender's byte buffer
    from its float view b / 255, ties to even as ``np.rint``), as a new uint8 array of the
    same shape; ``values`` is overwritten.  Block by block in the cache, the rounding done
    by adding 2^23 (the integer is then the float's low mantissa bits): 0.07 s for a 4096 x
    4096 RGBA image, where numpy's clip, rint and cast of the whole array took 0.15 s on
    warm memory and over a second in a fresh Blender process (three temporaries the size of
    the float image, each new memory there)."""
    flat = values.reshape(-1)
    out = np.empty(flat.shape, np.uint8)
    step = 4 * _BLOCK_TEXELS
    for a in range(0, flat.size, step):
        block = flat[a:a + step]
        np.clip(block, 0.0, 1.0, out=block)
        block *= np.float32(255.0)
        block += _ROUNDER
        out[a:a + step] = block.view("<u4")      # the low byte: the rounded value
    return out.reshape(values.shape)


class ImageTable:
    """The render's images in two pools, and each one's slot (``slots[name]``)."""

    def __init__(self, images: dict):
        self.slots: dict[str, int] = {}
        layouts = {name: texel_layout(image) for name, image in images.items()}
        rows = np.zeros((len(images), IMG_STRIDE), np.int64)
        n8 = nf = 0
        for k, (name, image) in enumerate(images.items()):
            h, w, c, is_float = layouts[name]
            flags = 0
            if image.colorspace == "sRGB":
                flags |= IMGF_SRGB
            if image.colorspace != "data" and image.alpha not in ("CHANNEL_PACKED", "NONE"):
                flags |= IMGF_UNASSOCIATE
            row = rows[k]
            row[IMG_OFFSET] = nf if is_float else n8
            row[IMG_WIDTH], row[IMG_HEIGHT], row[IMG_CHANNELS] = w, h, c
            row[IMG_FLOAT] = 1 if is_float else 0
            row[IMG_FLAGS] = flags
            if is_float:
                nf += h * w * c
            else:
                n8 += h * w * c
            self.slots[name] = k
        self.info = rows
        # One pool per type, each image converted straight into its place in it.
        self.pix8 = np.empty(n8, np.uint8)
        self.pixf = np.empty(nf, np.float32)
        for k, (name, image) in enumerate(images.items()):
            h, w, c, is_float = layouts[name]
            pool = self.pixf if is_float else self.pix8
            start = int(rows[k, IMG_OFFSET])
            load_texels(image, pool[start:start + h * w * c].reshape(h, w, c))

    @property
    def nbytes(self) -> int:
        """Memory of the texels."""
        return int(self.pix8.nbytes + self.pixf.nbytes)
