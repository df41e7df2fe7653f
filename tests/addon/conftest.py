"""Fixtures for the add-on tests: bpy in-process, a fresh empty scene per test.

* ``addon``: the add-on package (``mcengine_blender``, see ``helpers.load_addon``).
* ``scene``: factory settings with an empty scene, the add-on registered,
  "MC Engine" selected, a camera at the origin looking down -Z, 8x6 pixels, no denoising.
* ``fake_session``: replaces the core's RenderSession by ``helpers.GradientSession``
  and returns the list of sessions created, so tests see the exported
  SceneDescription (``sessions[-1].desc``) and what the engine wrote.
* ``render_exr``: F12 with ``write_still`` to a 32-bit EXR, read back top row first.
"""
import bpy
import pytest

from .helpers import GradientSession, load_addon, read_exr


@pytest.fixture(scope="session")
def addon():
    module = load_addon()
    yield module
    module.unregister()


@pytest.fixture
def scene(addon):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon.register()
    sc = bpy.context.scene
    sc.render.engine = "MCENGINE"
    sc.render.resolution_x, sc.render.resolution_y = 8, 6
    sc.render.resolution_percentage = 100
    sc.cycles.use_denoising = False   # on in the factory settings; tests that denoise say so
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    sc.collection.objects.link(cam)
    sc.camera = cam
    return sc


@pytest.fixture
def fake_session(addon, monkeypatch):
    sessions = []

    def factory(desc, threads=None):
        sessions.append(GradientSession(desc))
        sessions[-1].threads = threads
        return sessions[-1]

    monkeypatch.setattr(addon.engine, "session_factory", factory)
    return sessions


@pytest.fixture
def render_exr(tmp_path):
    def render():
        sc = bpy.context.scene
        sc.render.image_settings.file_format = "OPEN_EXR"
        sc.render.image_settings.color_depth = "32"
        sc.render.filepath = str(tmp_path / "render.exr")
        bpy.ops.render.render(write_still=True)
        return read_exr(tmp_path / "render.exr")
    return render
