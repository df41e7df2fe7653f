"""The viewport's Rendered mode, headless: what an edit re-exports, the progressive render,
stopping it, the view's camera, and the engine's view_update/view_draw with a fake window.

bpy has no window, so ``view_update`` and ``view_draw`` are called with a fake
context (a region's size and a ``RegionView3D``'s matrices, taken from a real
camera with ``Object.calc_matrix_camera``) and the drawing is replaced by a
recorder; everything else is the add-on's real code, and the last test uses
the real render session.
"""
from __future__ import annotations

import math
import threading
import time
from types import SimpleNamespace

import bpy
import numpy as np
import pytest

from mcengine.kernels.camera import camera_rays
from mcengine.scene import Film
from mcengine_blender import viewport

from .helpers import GradientSession, new_mesh_object

WAIT = 60.0     # seconds; generous for a loaded machine


def update(kind, ob_type=None, geometry=False, transform=False, shading=False):
    """A stand-in for one ``DepsgraphUpdate``."""
    return SimpleNamespace(id=SimpleNamespace(id_type=kind, type=ob_type),
                           is_updated_geometry=geometry, is_updated_transform=transform,
                           is_updated_shading=shading)


@pytest.mark.parametrize("updates, parts", [
    ([update("OBJECT", "MESH", transform=True)], {"objects"}),
    ([update("OBJECT", "MESH", geometry=True), update("MESH")], {"objects"}),
    ([update("OBJECT", "MESH")], set()),                       # selected, nothing changed
    ([update("MATERIAL")], {"materials"}),
    ([update("OBJECT", "LIGHT", transform=True)], {"lights"}),
    ([update("LIGHT")], {"lights"}),
    ([update("WORLD")], {"world"}),
    ([update("SCENE")], {"settings", "world"}),
    ([update("COLLECTION")], {"objects", "lights"}),
    ([update("NODETREE")], {"materials", "world"}),
    ([update("OBJECT", "CAMERA", transform=True), update("CAMERA")], set()),   # the view only
    ([update("SCREEN"), update("WORKSPACE")], set()),
    ([update("MATERIAL"), update("OBJECT", "LIGHT", shading=True)], {"materials", "lights"}),
])
def test_each_edit_re_exports_what_it_changes(addon, updates, parts):
    assert viewport.parts_to_export(updates) == parts


class SlowSession(GradientSession):
    """GradientSession whose passes take time and that stops when asked, as the real one."""

    passes = 50
    pass_seconds = 0.02
    made = []

    def __init__(self, desc):
        super().__init__(desc)
        self.passes_run = 0
        SlowSession.made.append(self)

    def run(self, on_pass=None, should_stop=None):
        for k in range(1, self.passes + 1):
            if should_stop is not None and should_stop():
                break
            time.sleep(self.pass_seconds)
            self.passes_run = k
            self.samples_done = k
            self._image = self.target * np.float32(k / self.passes)
            if on_pass is not None:
                on_pass(self)
        return self


@pytest.fixture
def slow_sessions():
    SlowSession.made = []
    return SlowSession.made


def exported(addon, desc):
    return addon.export.ExportResult(scene=desc)


def a_scene(addon):
    from mcengine.scene import SceneDescription
    return SceneDescription(film=Film(width=64, height=48))


def camera(x=0.0):
    from mcengine.scene import Camera
    m = np.eye(4)
    m[0, 3] = x
    return Camera(matrix_world=m)


def wait_for(predicate, timeout=WAIT):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.01)
    return False


def test_progressive_render_restarts_on_a_new_view_and_stops_the_old_one(addon, slow_sessions):
    render = viewport.ViewportRender(SlowSession)
    calls = []

    def export(parts, previous):
        calls.append((set(parts), previous))
        return exported(addon, a_scene(addon))

    assert render.update_scene(export, set())                  # the first time: everything
    assert calls[0] == (set(addon.export.PARTS), None)
    frame = render.frame(camera(), 32, 24, preview_samples=50)
    assert frame.rendering and frame.target == 50
    assert wait_for(lambda: render.frame(camera(), 32, 24, 50).samples >= 5)
    first = render.frame(camera(), 32, 24, 50)
    assert first.image.shape == (24, 32, 4) and len(slow_sessions) == 1   # same view: same render
    # The image accumulates: pass k of n is k/n of the converged gradient (bottom row first).
    later = render.frame(camera(), 32, 24, 50)
    assert later.samples >= first.samples
    np.testing.assert_allclose(later.image, slow_sessions[0].target[::-1] * later.samples / 50,
                               rtol=1e-6)
    # A new view: a new render; the old one stops at its next poll and is never shown again.
    moved = render.frame(camera(x=1.0), 32, 24, 50)
    assert moved.image is None and moved.samples == 0           # nothing of the old view
    assert wait_for(lambda: len(slow_sessions) == 2)
    old = slow_sessions[0]
    time.sleep(0.2)
    stopped_at = old.passes_run
    assert stopped_at < SlowSession.passes
    time.sleep(0.2)
    assert old.passes_run == stopped_at                         # it stopped for good
    assert render.wait(WAIT)
    final = render.frame(camera(x=1.0), 32, 24, 50)
    assert final.samples == 50 and not final.rendering and len(slow_sessions) == 2
    np.testing.assert_allclose(final.image, slow_sessions[1].target[::-1], rtol=1e-6)


def test_an_edit_restarts_only_if_it_changed_something(addon, slow_sessions):
    render = viewport.ViewportRender(SlowSession)
    scene = a_scene(addon)
    render.update_scene(lambda parts, previous: exported(addon, scene), set())
    render.frame(camera(), 16, 16, 50)
    assert wait_for(lambda: len(slow_sessions) == 1)
    # A scene update whose settings and world export to the same values: no restart.
    assert not render.update_scene(lambda parts, previous: exported(addon, a_scene(addon)),
                                   {"settings", "world"})
    render.frame(camera(), 16, 16, 50)
    assert len(slow_sessions) == 1
    # Nothing to re-export (a selection): nothing exported at all.
    assert not render.update_scene(lambda parts, previous: pytest.fail("exported"), set())
    # A material edit restarts; so do new samples and a new size.
    assert render.update_scene(lambda parts, previous: exported(addon, scene), {"materials"})
    render.frame(camera(), 16, 16, 50)
    render.frame(camera(), 16, 16, 60)
    render.frame(camera(), 20, 16, 60)
    assert wait_for(lambda: len(slow_sessions) == 4)
    assert all(s.desc.integrator.samples in (50, 60) for s in slow_sessions)
    render.stop()


def test_an_export_failure_stops_the_render_and_is_shown(addon, slow_sessions):
    render = viewport.ViewportRender(SlowSession)
    render.update_scene(lambda parts, previous: exported(addon, a_scene(addon)), set())
    render.frame(camera(), 16, 16, 0)
    render.export_failed("the scene has no lights")
    frame = render.frame(camera(), 16, 16, 0)
    assert frame.error == "the scene has no lights" and frame.image is None
    assert viewport.status_line(frame) == "MC Engine: the scene has no lights"
    assert wait_for(lambda: len(slow_sessions) == 1)
    time.sleep(0.3)
    stopped_at = slow_sessions[0].passes_run
    time.sleep(0.2)
    assert slow_sessions[0].passes_run == stopped_at < SlowSession.passes
    # The next successful export renders again.
    render.update_scene(lambda parts, previous: exported(addon, a_scene(addon)), {"objects"})
    assert render.frame(camera(), 16, 16, 0).error == ""
    assert wait_for(lambda: len(slow_sessions) == 2)
    render.stop()


class DenoisedSession(SlowSession):
    """SlowSession whose denoised image is the converged gradient plus 1000 (told apart)."""

    passes = 8
    pass_seconds = 0.0

    def denoised(self, bottom_up=False):
        assert self.desc.denoising.enabled
        out = self.target + np.float32(1000.0)
        return out[::-1] if bottom_up else out


def test_viewport_denoising_shows_denoised_images_from_the_start_sample(addon, slow_sessions):
    from mcengine.denoise import Denoising
    gate = threading.Event()
    render = viewport.ViewportRender(lambda desc: (gate.wait(WAIT), DenoisedSession(desc))[1])
    render.update_scene(lambda parts, previous: exported(addon, a_scene(addon)), set())
    shown = []
    on = Denoising(enabled=True, input_passes="RGB_ALBEDO", prefilter="FAST", quality="BALANCED")
    render.frame(camera(), 16, 16, 8, on, denoise_from=5)
    job = render._job
    publish = job._publish
    job._publish = lambda session: (publish(session), shown.append(job.frame()))
    gate.set()                                          # the session starts after the spy is in
    assert render.wait(WAIT)
    assert [f.samples for f in shown] == list(range(1, 9))
    target = slow_sessions[0].target[::-1]
    for f in shown:
        denoised = np.allclose(f.image, target + 1000.0)
        assert denoised == (f.samples >= 5), f.samples
    assert slow_sessions[0].desc.denoising == on
    # Denoising off: the same view and samples restart the render, which shows noisy images.
    render.frame(camera(), 16, 16, 8)
    assert wait_for(lambda: len(slow_sessions) == 2) and render.wait(WAIT)
    final = render.frame(camera(), 16, 16, 8)
    assert not slow_sessions[1].desc.denoising.enabled
    np.testing.assert_allclose(final.image, target, rtol=1e-6)


def test_viewport_denoising_reads_the_viewport_settings(scene, addon):
    from mcengine.denoise import available
    scene.cycles.use_denoising = True                   # F12's switch: not the viewport's
    scene.cycles.use_preview_denoising = False
    assert not addon.export.passes.preview_denoising(scene)[0].enabled
    scene.cycles.use_preview_denoising = True
    scene.cycles.preview_denoising_input_passes = "RGB_ALBEDO_NORMAL"
    scene.cycles.preview_denoising_prefilter = "NONE"
    scene.cycles.preview_denoising_quality = "FAST"
    scene.cycles.preview_denoising_start_sample = 4
    bpy.context.view_layer.cycles.use_denoising = False  # the view layer's: F12 only, as Cycles
    denoising, start = addon.export.passes.preview_denoising(scene)
    assert available() is None          # pyoidn is a dependency: the setting must not be lost
    assert denoising.enabled and start == 4
    assert (denoising.input_passes, denoising.prefilter, denoising.quality) == \
        ("RGB_ALBEDO_NORMAL", "NONE", "FAST")


def test_preview_samples_zero_renders_until_stopped(addon):
    it = viewport.viewport_integrator(a_scene(addon).integrator, 0)
    assert it.samples == viewport.UNLIMITED_SAMPLES and it.time_limit == 0
    frame = viewport.Frame(image=np.zeros((1, 1, 4)), samples=7, target=it.samples,
                                 rendering=True)
    assert viewport.status_line(frame) == "Sample 7"


# ---------------------------------------------------------------------------
# The view's camera
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("setup", [
    dict(type="PERSP", lens=35.0, shift_x=0.1, shift_y=-0.2, sensor_fit="AUTO"),
    dict(type="PERSP", lens=80.0, shift_x=-0.3, shift_y=0.05, sensor_fit="VERTICAL"),
    dict(type="ORTHO", ortho_scale=7.0, shift_x=0.2, shift_y=0.1, sensor_fit="AUTO"),
])
@pytest.mark.parametrize("size", [(64, 40), (40, 64)])
def test_view_camera_shoots_the_rays_of_the_scene_camera(scene, addon, setup, size):
    """The projection Blender computes for a camera (what the viewport's camera view uses)
    gives the exported camera's rays, through every corner and the centre."""
    cam = scene.camera
    for name, value in setup.items():
        setattr(cam.data, name, value)
    cam.data.clip_start, cam.data.clip_end = 0.3, 80.0
    cam.location, cam.rotation_euler = (1.0, -2.0, 3.0), (math.pi / 3, 0.1, 0.4)
    scene.unit_settings.scale_length = 0.5
    scene.render.resolution_x, scene.render.resolution_y = size
    depsgraph = bpy.context.evaluated_depsgraph_get()
    width, height = size
    projection = cam.evaluated_get(depsgraph).calc_matrix_camera(depsgraph, x=width, y=height)
    view = cam.matrix_world.normalized().inverted()
    ctx = addon.export.ExportContext(scene)
    reference = addon.export.camera.export_camera(ctx, depsgraph)
    ours = addon.export.camera.camera_from_view(view, projection, ctx.unit_scale)
    film = Film(width=width, height=height)
    rx, ry = np.array([0, width, 0, width, width / 2]), np.array([0, 0, height, height, height / 2])
    for a, b in zip(camera_rays(reference, film, rx, ry), camera_rays(ours, film, rx, ry)):
        np.testing.assert_allclose(a, b, rtol=2e-5, atol=2e-5)   # Blender's float32 matrices


# ---------------------------------------------------------------------------
# The engine's viewport methods, with a fake window
# ---------------------------------------------------------------------------

class FakeEngine:
    """Just what view_update and view_draw use of a RenderEngine."""

    def __init__(self, addon):
        engine = addon.engine.MCEngine
        self._viewport = engine._viewport.__get__(self)
        self.view_update = engine.view_update.__get__(self)
        self.view_draw = engine.view_draw.__get__(self)
        self.stats, self.redraws = "", 0

    def get_preview_pixel_size(self, scene):
        return 2

    def update_stats(self, stats, info):
        self.stats = info

    def tag_redraw(self):
        self.redraws += 1


class Depsgraph:
    """The real evaluated depsgraph with the updates of an edit."""

    def __init__(self, updates=()):
        self._real = bpy.context.evaluated_depsgraph_get()
        self.updates = list(updates)

    def __getattr__(self, name):
        return getattr(self._real, name)


def window_of(cam, width, height):
    """A region of this size looking through ``cam`` (the camera view, zoomed to fit)."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    projection = cam.evaluated_get(depsgraph).calc_matrix_camera(depsgraph, x=width, y=height)
    region_data = SimpleNamespace(view_matrix=cam.matrix_world.normalized().inverted(),
                                  window_matrix=projection)
    return SimpleNamespace(region=SimpleNamespace(width=width, height=height),
                           region_data=region_data)


@pytest.fixture
def drawn(addon, monkeypatch):
    """Records draw_frame's calls instead of drawing (there is no GPU)."""
    calls = []
    monkeypatch.setattr(addon.engine, "draw_frame",
                        lambda engine, scene, image, w, h: calls.append((image, w, h)))
    return calls


def test_view_update_and_view_draw_render_the_view(scene, addon, fake_session, drawn,
                                                   monkeypatch):
    exports = []
    real_export = addon.export.export

    def counting_export(depsgraph, **kwargs):
        exports.append(kwargs["parts"])
        return real_export(depsgraph, **kwargs)

    monkeypatch.setattr(addon.export, "export", counting_export)
    gate, fake_factory = threading.Event(), addon.engine.session_factory

    def gated_factory(desc, threads=None):      # the session is ready when the test says so
        gate.wait(WAIT)
        return fake_factory(desc, threads=threads)

    monkeypatch.setattr(addon.engine, "session_factory", gated_factory)
    scene.cycles.preview_samples = 8
    scene.camera.location = (0, 0, 5)
    scene.cycles.use_denoising = bpy.context.view_layer.use_pass_z = True    # F12's, not the view's
    bpy.context.view_layer.update()
    engine = FakeEngine(addon)
    engine.view_update(None, Depsgraph())
    context = window_of(scene.camera, 40, 30)
    engine.view_draw(context, Depsgraph())
    # Still preparing: nothing drawn, the status says so, and another redraw is asked for.
    assert not drawn and engine.redraws == 1 and engine.stats.startswith("Preparing renderer")
    gate.set()
    assert wait_for(lambda: fake_session) and engine._viewport().wait(WAIT)
    engine.view_draw(context, Depsgraph())
    image, w, h = drawn[-1]
    assert (w, h) == (40, 30) and image.shape == (15, 20, 4)     # pixel size 2
    assert engine.stats == "Sample 8/8" and engine.redraws == 1  # finished: no more redraws
    desc = fake_session[-1].desc
    assert desc.integrator.samples == 8 and (desc.film.width, desc.film.height) == (20, 15)
    assert desc.passes.names() == [] and not desc.denoising.enabled     # Combined only
    np.testing.assert_allclose(desc.camera.matrix_world[:3, 3], (0, 0, 5), atol=1e-6)
    assert len(exports) == 1
    # Moving the view restarts the render without exporting; a material edit exports the
    # materials (and restarts).
    scene.camera.location = (1, 0, 5)
    bpy.context.view_layer.update()
    engine.view_draw(window_of(scene.camera, 40, 30), Depsgraph())
    assert wait_for(lambda: len(fake_session) == 2) and len(exports) == 1
    np.testing.assert_allclose(fake_session[-1].desc.camera.matrix_world[:3, 3], (1, 0, 5),
                               atol=1e-6)
    engine.view_update(None, Depsgraph([update("MATERIAL")]))
    engine.view_draw(window_of(scene.camera, 40, 30), Depsgraph())
    assert exports[-1] == {"materials"}
    assert wait_for(lambda: len(fake_session) == 3)
    # A selection (an object update without changes) neither exports nor restarts.
    engine.view_update(None, Depsgraph([update("OBJECT", "MESH")]))
    engine.view_draw(window_of(scene.camera, 40, 30), Depsgraph())
    time.sleep(0.2)
    assert len(exports) == 2 and len(fake_session) == 3


def test_view_draw_reports_an_export_failure_in_the_viewport(scene, addon, fake_session, drawn,
                                                             monkeypatch):
    def broken(depsgraph, **kwargs):
        raise addon.export.ExportError("the scene cannot be rendered")

    monkeypatch.setattr(addon.export, "export", broken)
    engine = FakeEngine(addon)
    engine.view_update(None, Depsgraph())
    engine.view_draw(window_of(scene.camera, 16, 16), Depsgraph())
    assert engine.stats == "MC Engine: the scene cannot be rendered"
    assert not drawn and not fake_session and engine.redraws == 0


def test_the_camera_view_renders_what_f12_renders(scene, addon, render_exr, drawn):
    """Through the scene camera, at the render size, with as many preview samples as render
    samples and the same seed, the viewport's render is F12's image (the real session)."""
    scene.render.resolution_x, scene.render.resolution_y = 24, 16
    scene.cycles.samples = scene.cycles.preview_samples = 4
    scene.cycles.use_denoising = scene.cycles.use_adaptive_sampling = False
    scene.camera.location, scene.camera.rotation_euler = (0.3, -0.2, 6.0), (0.05, -0.04, 0.2)
    mat = bpy.data.materials.new("Glow")
    node = mat.node_tree.nodes["Principled BSDF"]
    node.inputs["Base Color"].default_value = (0.6, 0.3, 0.1, 1)
    node.inputs["Emission Color"].default_value = (1, 0.5, 0.25, 1)
    node.inputs["Emission Strength"].default_value = 0.5
    new_mesh_object("Card", [(-2, -1, 0), (2, -1, 0), (2, 2, 1), (-2, 2, 1)], [(0, 1, 2, 3)],
                    materials=[mat])
    bpy.context.view_layer.update()
    f12 = render_exr()[::-1]            # bottom row first, as the viewport draws
    engine = FakeEngine(addon)
    engine.get_preview_pixel_size = lambda scene: 1
    engine.view_update(None, Depsgraph())
    context = window_of(scene.camera, 24, 16)
    engine.view_draw(context, Depsgraph())
    assert engine._viewport().wait(WAIT)
    engine.view_draw(context, Depsgraph())
    image = drawn[-1][0]
    assert image.shape == f12.shape
    assert image[..., :3].max() > 0.1
    np.testing.assert_allclose(image, f12, atol=1e-4)
