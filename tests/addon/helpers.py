"""Helpers for the add-on tests: loading the add-on, a fake render session, scene builders."""
from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path
from types import SimpleNamespace

import bpy
import numpy as np
import OpenEXR

from mcengine.packing import pack_scene

ROOT = Path(__file__).resolve().parents[2]
ADDON_DIR = ROOT / "addon"
PACKAGE = "mcengine_blender"


def load_addon(name: str = PACKAGE):
    """Import the add-on package, from ``addon/`` under ``name`` if it is not installed.

    An editable install made before ``addon/__init__.py`` existed maps the name to a
    namespace package (no ``__file__``); that case also loads the folder directly.
    """
    try:
        module = importlib.import_module(name)
        if getattr(module, "__file__", None) is not None:
            return module
        for key in [k for k in sys.modules if k == name or k.startswith(name + ".")]:
            del sys.modules[key]
    except ModuleNotFoundError:
        pass
    return load_addon_from_folder(name)


def load_addon_from_folder(name: str):
    """Import ``addon/`` as a package called ``name`` (e.g. "bl_ext.repo.mcengine")."""
    spec = importlib.util.spec_from_file_location(
        name, ADDON_DIR / "__init__.py", submodule_search_locations=[str(ADDON_DIR)])
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


class GradientSession:
    """Stand-in for ``mcengine.session.RenderSession``.

    Fills a known, asymmetric image over ``passes`` passes: pixel (row r from
    the top, column c) converges to (c, r, c + 100 r, 1); after pass k of n the
    image is k/n of that (exact in float32).  Polls ``should_stop`` before
    every pass, like the real session.
    """

    passes = 4

    def __init__(self, desc):
        self.desc = desc
        x0, y0, x1, y1 = desc.film.window
        rows, cols = np.mgrid[0:y1 - y0, 0:x1 - x0].astype(np.float32)
        self.target = np.stack([cols, rows, cols + 100 * rows, np.ones_like(rows)], axis=-1)
        self._image = np.zeros_like(self.target)
        self.samples_done = 0
        self.stats = SimpleNamespace(rays_per_second=2.5e6, eta_seconds=3.0,
                                     metadata=lambda seconds, samples: {"samples": str(samples)})
        self.plan = pack_scene(desc).plan
        self.warnings = []          # what the integrator renders differently (none here)
        self.pass_images = []

    def run(self, on_pass=None, should_stop=None):
        for k in range(1, self.passes + 1):
            if should_stop is not None and should_stop():
                break
            self.samples_done = self.desc.integrator.samples * k // self.passes
            self._image = self.target * np.float32(k / self.passes)
            self.pass_images.append(self._image.copy())
            if on_pass is not None:
                on_pass(self)
        return self

    def image(self, bottom_up=False):
        return (self._image[::-1] if bottom_up else self._image).copy()

    def pass_names(self):
        return self.desc.passes.names()

    def pass_image(self, name, bottom_up=False):
        """Every render pass of the fake is a constant: its position in ``pass_names`` + 1."""
        x0, y0, x1, y1 = self.desc.film.window
        from mcengine.passes import BY_NAME, DENOISING_PASSES
        info = BY_NAME.get(name) or next((p for p in DENOISING_PASSES if p.name == name), None)
        channels = 4 if info is None else len(info.channels)
        return np.full((y1 - y0, x1 - x0, channels), self.pass_names().index(name) + 1.0,
                       np.float32)

    def denoised(self, bottom_up=False):
        """The fake's denoiser halves the image (None when denoising is off)."""
        return self.image(bottom_up) * np.float32(0.5) if self.desc.denoising.enabled else None


def export_scene(sessions):
    """Render the current scene with the fake session; return the exported SceneDescription."""
    bpy.ops.render.render()
    assert sessions, "the engine did not create a session"
    return sessions[-1].desc


def read_exr(path) -> np.ndarray:
    """(h, w, 4) float32 RGBA, top row first."""
    with OpenEXR.File(str(path)) as f:
        return np.array(f.channels()["RGBA"].pixels, np.float32)


def new_mesh_object(name, verts, faces, collection=None, materials=()):
    """Link a new mesh object built from vertex and face lists."""
    me = bpy.data.meshes.new(name)
    me.from_pydata([tuple(v) for v in verts], [], [tuple(f) for f in faces])
    for mat in materials:
        me.materials.append(mat)
    ob = bpy.data.objects.new(name, me)
    (collection or bpy.context.scene.collection).objects.link(ob)
    return ob


CUBE_VERTS = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
# Faces of CUBE_VERTS, counter-clockwise seen from outside (outward normals).
CUBE_FACES = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
