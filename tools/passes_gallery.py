"""Render passes and denoising, pictured: the figures of README's *Render passes* section.

Usage, from the repository root with the project's environment::

    python -m tools.passes_gallery [--scene glass_mirror] [--size 128] [--out docs]

Exports ``blend_scenes/<scene>.blend`` through the add-on with some of Cycles'
passes and denoising on, renders it with MC Engine at 16 samples per pixel and
once at 1024 (the reference), and writes

* ``passes.png``: Combined and a few passes of the 16-sample render (Depth,
  Normal, Diffuse Color, Diffuse Direct, Glossy Direct, Denoising Albedo, and the
  first Cryptomatte rank of the objects, one colour per id);
* ``denoising.png``: the 16-sample image, the same denoised (Open Image
  Denoise with the albedo and normal guides), and the 1024-sample reference,
  with each one's relMSE against the reference.

Colours are shown through the sRGB curve (no view transform), depth and
normals remapped to [0, 1].  About a minute on two cores.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
PASSES = ("Depth", "Normal", "Diffuse Color", "Diffuse Direct", "Glossy Direct")
NOISY, REFERENCE = 16, 1024


def _export(name: str, size: int):
    import bpy

    from mcengine_blender import export
    from mcengine_blender.batch.render import ensure_registered, open_scene
    ensure_registered()
    scene = open_scene(ROOT / "blend_scenes" / f"{name}.blend")
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.cycles.use_denoising = True
    scene.cycles.denoising_input_passes = "RGB_ALBEDO_NORMAL"
    layer = scene.view_layers[0]
    layer.use_pass_z = layer.use_pass_normal = layer.use_pass_diffuse_color = True
    layer.use_pass_diffuse_direct = layer.use_pass_glossy_direct = True
    layer.use_pass_cryptomatte_object = True
    layer.cycles.use_denoising = layer.cycles.denoising_store_passes = True
    return export.export(bpy.context.evaluated_depsgraph_get()).scene


def _srgb(linear):
    x = np.clip(np.asarray(linear, np.float64)[..., :3], 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def _depth(d):
    d = d[..., 0]
    seen = d < 1e9
    lo, hi = (d[seen].min(), d[seen].max()) if seen.any() else (0.0, 1.0)
    out = np.where(seen, 1.0 - (d - lo) / max(hi - lo, 1e-9), 0.0)
    return np.repeat(out[..., None], 3, axis=-1)


def _ids(crypto):
    """One colour per Cryptomatte id of the first rank (hue from the id's bits)."""
    ids = np.ascontiguousarray(crypto[..., 0], np.float32).view(np.uint32)
    rgb = np.stack([(ids >> s & 0xFF) / 255.0 for s in (0, 8, 16)], axis=-1)
    return np.where(ids[..., None] == 0, 0.0, 0.25 + 0.75 * rgb)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="glass_mirror")
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--out", type=Path, default=ROOT / "docs")
    args = parser.parse_args(argv)
    from mcengine.evaluation.stats import relmse
    from mcengine.session import RenderSession

    desc = _export(args.scene, args.size)
    desc.integrator.seed, desc.integrator.samples = 1, REFERENCE
    reference = RenderSession(desc).run().image()
    desc.integrator.seed, desc.integrator.samples = 2, NOISY
    session = RenderSession(desc).run()
    noisy, denoised = session.image(), session.denoised()

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    tiles = [("Combined (16 spp)", _srgb(noisy)), ("Depth", _depth(session.pass_image("Depth"))),
             ("Normal", 0.5 + 0.5 * session.pass_image("Normal"))]
    tiles += [(name, _srgb(session.pass_image(name))) for name in PASSES[2:]]
    tiles += [("Denoising Albedo", _srgb(session.pass_image("Denoising Albedo"))),
              ("CryptoObject00", _ids(session.pass_image("CryptoObject00")))]
    args.out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(2, 4, figsize=(8.0, 4.4), dpi=100)
    for ax, (title, image) in zip(axes.flat, tiles):
        ax.imshow(np.clip(image, 0, 1), interpolation="nearest")
        ax.set_title(title, fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    fig.savefig(args.out / "passes.png", facecolor="white")
    plt.close(fig)

    fig, axes = plt.subplots(1, 3, figsize=(7.5, 2.9), dpi=100)
    for ax, (title, image) in zip(axes, (
            (f"16 spp, relMSE {relmse(noisy, reference):.3f}", noisy),
            (f"denoised, relMSE {relmse(denoised, reference):.4f}", denoised),
            ("reference, 1024 spp", reference))):
        ax.imshow(_srgb(image), interpolation="nearest")
        ax.set_title(title, fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    fig.savefig(args.out / "denoising.png", facecolor="white")
    print(args.out / "passes.png", args.out / "denoising.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
