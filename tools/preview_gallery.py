"""The preview icons of a material, a light and a world, by MC Engine and by Cycles.

Usage, from the repository root with the project's environment::

    python -m tools.preview_gallery [--out docs/previews.png]

Renders each icon the way Blender's Properties editor asks for it (Blender's
preview scene, ``bpy.ops.ed.lib_id_generate_preview``), once with MC Engine
and once with Cycles, and writes them as a 2 x 3 grid with labels: the
picture in README's *Previews* section.  About half a minute (Cycles' icons
take most of it).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _subjects(bpy):
    """A Principled material, a warm point light and a blue sky, named for the columns."""
    mat = bpy.data.materials.new("material")
    mat.use_nodes = True
    principled = mat.node_tree.nodes["Principled BSDF"]
    principled.inputs["Base Color"].default_value = (0.8, 0.15, 0.1, 1.0)
    principled.inputs["Roughness"].default_value = 0.3
    light = bpy.data.lights.new("light", "POINT")
    light.color = (1.0, 0.55, 0.3)
    light.energy = 5.0
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.2, 0.4, 1.0, 1.0)
    return [mat, light, world]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "previews.png")
    args = parser.parse_args(argv)
    import bpy

    sys.path.insert(0, str(ROOT / "tests" / "addon"))
    from helpers import load_addon
    addon = load_addon()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon.register()
    from mcengine_blender.preview import render_icon
    rows = {}
    for engine, label in (("MCENGINE", "MC Engine"), ("CYCLES", "Cycles")):
        bpy.context.scene.render.engine = engine
        rows[label] = [render_icon(idblock)[::-1] for idblock in _subjects(bpy)]

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 3, figsize=(6.0, 4.3), dpi=100)
    for r, (label, icons) in enumerate(rows.items()):
        for c, (icon, title) in enumerate(zip(icons, ("material", "light", "world"))):
            ax = axes[r, c]
            ax.imshow(np.clip(icon[..., :3], 0, 1), interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            if r == 0:
                ax.set_title(title, fontsize=10)
            if c == 0:
                ax.set_ylabel(label, fontsize=10)
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, facecolor="white")
    print(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
