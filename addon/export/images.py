"""Blender images -> :class:`mcengine.scene.Image`, read once per export.

The pixels come from Blender's own image buffer (``Image.pixels``, read with
``foreach_get``), so packed, generated and file images alike arrive as Blender
loaded them: 8-bit images as their bytes (straight alpha, in the image's colour
space), float images as Blender's float buffer (scene linear, alpha already
multiplied in), as Cycles reads them through Blender (blender/image.cpp).

Colour spaces of 8-bit images: sRGB is decoded by the renderer after
interpolation, Non-Color (and other data spaces) and the scene-linear spaces are
read as stored; other spaces are warned and read as sRGB.  An image that cannot
be read (a missing file, no pixels) is warned and left out: the nodes reading it
render magenta, as in Cycles.
"""
from __future__ import annotations

import numpy as np

from mcengine.images import unit_floats_to_bytes
from mcengine.scene import Image

__all__ = ["export_image"]

# 8-bit colour spaces that are the scene's linear space (no conversion).
_LINEAR_SPACES = ("Linear Rec.709", "Working Space")
_SRGB_SPACES = ("sRGB",)


def export_image(ctx, image) -> str:
    """Add ``image`` to ``ctx.images`` once; its name there ("" when it cannot be read)."""
    if image is None:
        return ""
    # The original data-block: an evaluated copy may lack the pixels set from Python.
    image = getattr(image, "original", None) or image
    key = image.name_full
    if key in ctx.images:
        return key
    try:
        converted = _convert(ctx, image)
    except (RuntimeError, ValueError, TypeError) as exc:
        ctx.warn(f"image '{key}' could not be read ({exc}); rendered magenta", "images")
        return ""
    if converted is None:
        ctx.warn(f"image '{key}' has no pixels (missing file?); rendered magenta", "images")
        return ""
    ctx.images[key] = converted
    return key


def _convert(ctx, image) -> Image | None:
    if image.source not in ("FILE", "GENERATED"):
        ctx.warn(f"image '{image.name_full}': {image.source.lower()} images are not supported "
                 f"yet; its current frame or first tile is used", "images")
    w, h = image.size
    if w <= 0 or h <= 0 or (not image.has_data and not _load(image)):
        return None
    n = len(image.pixels)
    if n == 0 or n % (w * h):
        return None
    channels = n // (w * h)
    values = np.empty(n, np.float32)
    image.pixels.foreach_get(values)
    values = values.reshape(h, w, channels)
    settings = image.colorspace_settings
    is_data = bool(settings.is_data)
    alpha = image.alpha_mode
    if image.is_float:
        colorspace = "data" if is_data else "linear"
        if alpha == "STRAIGHT":
            alpha = "PREMUL"          # Blender's float buffers hold associated alpha
        return Image(pixels=values, colorspace=colorspace, alpha=alpha)
    pixels = unit_floats_to_bytes(values)
    if is_data:
        colorspace = "data"
    elif settings.name in _LINEAR_SPACES:
        colorspace = "linear"
    else:
        colorspace = "sRGB"
        if settings.name not in _SRGB_SPACES:
            ctx.warn(f"image '{image.name_full}': colour space '{settings.name}' of an 8-bit image "
                     f"is not supported yet; read as sRGB", "image colour spaces")
    if alpha == "PREMUL":
        alpha = "STRAIGHT"            # Blender's byte buffers hold straight alpha
    return Image(pixels=pixels, colorspace=colorspace, alpha=alpha)


def _load(image) -> bool:
    """Ask Blender to load the image's buffer; whether it has pixels now."""
    try:
        _ = image.pixels[0]           # reading the pixels makes Blender load the buffer
    except (RuntimeError, IndexError):
        return False
    return bool(image.has_data)
