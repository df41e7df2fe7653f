"""Render .blend files with Cycles as stored and report per-channel means.

Usage::

    .venv/bin/python blend_scenes/render_cycles.py OUT_DIR [FILE.blend ...]

Without files, every ``blend_scenes/*.blend`` is rendered.  For each file the
image is written twice into OUT_DIR: ``<name>.exr`` (32-bit float, scene
linear, the reference for comparisons) and ``<name>.png`` (8-bit, view
transform applied, for looking at).  The render settings are the ones saved
in the file; nothing is overridden.  One line per file gives the mean linear
R, G, B over the image, the fraction of pixels whose mean RGB lies in the
well-exposed range [0.02, 2], and the render time.
"""
import sys
import time
from pathlib import Path

import bpy
import numpy as np

HERE = Path(__file__).resolve().parent
# The range of linear values counted as "well exposed" in the report.
EXPOSED_MIN, EXPOSED_MAX = 0.02, 2.0


def render(blend_path, out_dir):
    """Render one file; return (mean RGB (3,), exposed fraction, seconds)."""
    bpy.ops.wm.open_mainfile(filepath=str(blend_path))
    scene = bpy.context.scene
    name = Path(blend_path).stem
    start = time.perf_counter()
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = str(Path(out_dir) / f"{name}.exr")
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - start
    image = bpy.data.images["Render Result"]
    png = Path(out_dir) / f"{name}.png"
    image.save_render(str(png), scene=_png_scene(scene))
    rgb = _read_exr_rgb(scene.render.filepath)
    luminance = rgb.mean(axis=2)
    exposed = float(np.mean((luminance >= EXPOSED_MIN) & (luminance <= EXPOSED_MAX)))
    return rgb.reshape(-1, 3).mean(axis=0), exposed, seconds


def _png_scene(scene):
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_depth = "8"
    return scene


def _read_exr_rgb(path):
    """(H, W, 3) float32 linear RGB of an EXR, read back through Blender."""
    image = bpy.data.images.load(path)
    w, h = image.size
    pixels = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(h, w, 4)[..., :3]


def main(argv):
    if not argv:
        print(f"usage: {sys.executable} {__file__} OUT_DIR [FILE.blend ...]", file=sys.stderr)
        return 2
    out_dir = Path(argv[0])
    out_dir.mkdir(parents=True, exist_ok=True)
    files = [Path(p) for p in argv[1:]] or sorted(HERE.glob("*.blend"))
    for path in files:
        if not path.is_file():
            print(f"error: no such file: {path}", file=sys.stderr)
            return 1
    for path in files:
        try:
            mean, exposed, seconds = render(path, out_dir)
        except RuntimeError as error:  # how bpy reports unreadable files and failed renders
            print(f"error: {path}: {str(error).strip()}", file=sys.stderr)
            return 1
        print(f"{path.stem:22s} mean RGB {mean[0]:.4f} {mean[1]:.4f} {mean[2]:.4f}  "
              f"exposed {100 * exposed:5.1f} %  {seconds:6.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
