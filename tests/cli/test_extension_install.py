"""The user's path: build the extension zip, install it into Blender, render with it.

What this proves
----------------
The zip from ``python -m tools.build_extension`` installs through Blender's own
operator (``extensions.package_install_files``) into an empty user folder, the
add-on enables, "MCENGINE" becomes a render engine, and a small render of
``blend_scenes/cornell_box.blend`` comes out finite and not black, using only
what the extension brings.

The render runs in a child Python that sees bpy and bpy's own requirements
(numpy, zstandard, requests, ...: what Blender's bundled Python has) through a
folder of symlinks, started with ``-I -S`` so neither this project's editable
install nor anything else in the venv's site-packages is on its path.  The
child checks that numba, embreex, OpenEXR and mcengine cannot be imported before
the install, and reports where they were imported from after the render: all
must come from the extension's ``site-packages`` in the temporary user folder.
``BLENDER_USER_RESOURCES`` points Blender's user folders (config, extensions)
there, so the developer's own Blender setup is never touched.
"""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import textwrap
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
CORNELL_BOX = REPO / "blend_scenes" / "cornell_box.blend"
BUNDLED = ["mcengine", "numba", "llvmlite", "embreex", "OpenEXR", "pyoidn", "cffi"]
# The render denoises (Cycles' denoising settings), so Open Image Denoise loads too.  embreex
# is not imported: the renderer loads the Embree library its wheel ships (checked below).
USED_BY_EVERY_RENDER = {"mcengine", "numba", "pyoidn"}
RESOLUTION = 32
SAMPLES = 4

CHILD = textwrap.dedent("""
    import importlib, importlib.util, json, sys
    site, zip_path, blend, out = sys.argv[1:5]
    bundled = json.loads(sys.argv[5])
    sys.path.append(site)
    report = {"importable_before": [m for m in bundled + ["mcengine_blender"]
                                    if importlib.util.find_spec(m) is not None]}
    import bpy
    report["extensions_dir"] = bpy.utils.user_resource("EXTENSIONS")
    result = bpy.ops.extensions.package_install_files(
        filepath=zip_path, repo="user_default", enable_on_install=True)
    report["install"] = sorted(result)
    report["addons"] = sorted(bpy.context.preferences.addons.keys())
    report["engines"] = sorted(getattr(cls, "bl_idname", "") for cls in bpy.types.RenderEngine.__subclasses__())
    if blend:
        bpy.ops.wm.open_mainfile(filepath=blend, load_ui=False)
    scene = bpy.context.scene
    scene.render.engine = "MCENGINE"
    report["engine_set"] = scene.render.engine
    scene.render.resolution_x = scene.render.resolution_y = int(sys.argv[6])
    scene.render.resolution_percentage = 100
    scene.cycles.samples = int(sys.argv[7])
    scene.cycles.use_denoising = True
    scene.view_layers[0].cycles.use_denoising = True
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)
    report["used_by_render"] = [m for m in bundled if m in sys.modules]
    report["modules"] = {m: importlib.import_module(m).__file__ for m in bundled}
    from mcengine.kernels import embree
    report["embree_packets"] = embree._library is not None
    report["embree_library"] = embree.library_path()
    print("REPORT " + json.dumps(report))
""")


def _canonical(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def bpy_runtime_entries() -> list[Path]:
    """Top-level site-packages entries of bpy and its requirements, recursively.

    These stand for Blender's bundled Python; nothing else from the venv is
    visible to the child.
    """
    seen, todo = set(), ["bpy"]
    while todo:
        name = _canonical(todo.pop())
        if name in seen:
            continue
        seen.add(name)
        for requirement in metadata.distribution(name).requires or []:
            if "extra ==" not in requirement:
                todo.append(re.match(r"[A-Za-z0-9_.-]+", requirement)[0])
    entries = set()
    for name in seen:
        dist = metadata.distribution(name)
        for file in dist.files or []:
            top = file.parts[0]
            if top not in ("..", "__pycache__") and not top.endswith(".dist-info"):
                entries.add(Path(dist.locate_file(top)))
    return sorted(entries)


def child_environment(user: Path, home: Path) -> dict[str, str]:
    """This environment with Blender's user folders (and HOME) moved to temporary ones."""
    env = {key: value for key, value in os.environ.items() if not key.startswith("BLENDER_")}
    env.update(BLENDER_USER_RESOURCES=str(user), HOME=str(home))
    return env


@pytest.mark.slow
@pytest.mark.timeout(1800)  # wheel download on a cold cache + numba compiling every kernel
def test_extension_installs_and_renders_with_its_own_wheels(tmp_path):
    built = subprocess.run([sys.executable, "-m", "tools.build_extension", "--out", str(tmp_path / "dist")],
                           cwd=REPO, capture_output=True, text=True, timeout=900)
    assert built.returncode == 0, built.stderr
    zip_path = Path(built.stdout.strip().splitlines()[-1])
    assert zip_path.name == "mcengine-0.1.0.zip" and zip_path.is_file()

    site = tmp_path / "blender-python"
    site.mkdir()
    for entry in bpy_runtime_entries():
        (site / entry.name).symlink_to(entry)
    user = tmp_path / "user"
    out = tmp_path / "render.exr"
    blend = str(CORNELL_BOX) if CORNELL_BOX.is_file() else ""
    child = tmp_path / "child.py"
    child.write_text(CHILD)
    done = subprocess.run(
        [sys.executable, "-I", "-S", str(child), str(site), str(zip_path), blend, str(out),
         json.dumps(BUNDLED), str(RESOLUTION), str(SAMPLES)],
        cwd=tmp_path, capture_output=True, text=True, timeout=1500,
        env=child_environment(user, home=tmp_path))
    reports = [line for line in done.stdout.splitlines() if line.startswith("REPORT ")]
    assert done.returncode == 0 and reports, done.stdout[-3000:] + done.stderr[-3000:]
    report = json.loads(reports[-1][len("REPORT "):])

    assert report["importable_before"] == [], "the child can see the venv's packages"
    extensions = Path(report["extensions_dir"])
    assert extensions == user / "extensions"
    assert report["install"] == ["FINISHED"]
    assert "bl_ext.user_default.mcengine" in report["addons"]
    assert "MCENGINE" in report["engines"]
    assert report["engine_set"] == "MCENGINE"
    wheels_site = extensions / ".local" / "lib" / "python3.11" / "site-packages"
    assert USED_BY_EVERY_RENDER <= set(report["used_by_render"]), report["used_by_render"]
    for module, file in report["modules"].items():
        assert Path(file).is_relative_to(wheels_site), f"{module} imported from {file}"
    # The render traced in packets through the Embree library of the extension's embreex wheel.
    assert report["embree_packets"]
    assert Path(report["embree_library"]).is_relative_to(wheels_site / "embreex.libs")

    import OpenEXR
    with OpenEXR.File(str(out)) as exr:
        rgba = exr.parts[0].channels["RGBA"].pixels
    assert rgba.shape == (RESOLUTION, RESOLUTION, 4)
    assert np.isfinite(rgba).all()
    assert rgba[..., :3].mean() > 0.01, "black image"
