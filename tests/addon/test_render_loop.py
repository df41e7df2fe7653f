"""The render loop (F12) with a fake session: pixels, orientation, progress, Esc, errors."""
from types import SimpleNamespace

import bpy
import numpy as np
import pytest

from mcengine.scene import SceneError

from .helpers import GradientSession, new_mesh_object


def test_render_result_equals_the_session_image(scene, fake_session, render_exr):
    image = render_exr()
    (session,) = fake_session
    assert image.shape == (6, 8, 4)
    np.testing.assert_array_equal(image, session.target)  # top row first, left column first
    assert image[0, 7, 0] == 7 and image[5, 0, 1] == 5  # asymmetric: orientation is checked


@pytest.fixture
def published(addon, monkeypatch):
    """Snapshots of the Combined pass (read back, top row first) at every progressive update."""
    snapshots = []
    real = addon.engine.MCEngine._publish

    def publish(self, result, session, progress):
        real(self, result, session, progress)
        rect = result.layers[0].passes["Combined"].rect
        pixels = np.empty(len(rect) * 4, np.float32)
        rect.foreach_get(pixels)
        snapshots.append(pixels.reshape(result.resolution_y, result.resolution_x, 4)[::-1])

    monkeypatch.setattr(addon.engine.MCEngine, "_publish", publish)
    return snapshots


def test_progressive_updates_show_every_pass(scene, fake_session, published, render_exr):
    render_exr()
    (session,) = fake_session
    assert len(published) == GradientSession.passes
    for shown, expected in zip(published, session.pass_images):
        np.testing.assert_array_equal(shown, expected)
    assert published[0][0, 7, 0] == 7 / 4  # the first pass is a quarter of the final value


def test_fixed_thread_count_reaches_the_session(scene, fake_session):
    bpy.ops.render.render()
    scene.render.threads_mode, scene.render.threads = "FIXED", 3
    bpy.ops.render.render()
    assert [s.threads for s in fake_session] == [None, 3]


def test_stop_after_the_first_pass_keeps_the_partial_image(scene, fake_session, published, addon,
                                                          monkeypatch, render_exr):
    monkeypatch.setattr(addon.engine.MCEngine, "_stop_requested", lambda self: len(published) >= 1)
    image = render_exr()
    (session,) = fake_session
    assert len(published) == 1 and session.samples_done == scene.cycles.samples // 4
    np.testing.assert_array_equal(image, session.pass_images[0])


@pytest.mark.parametrize("crop", [True, False])
def test_border_render_result_size(scene, fake_session, render_exr, crop):
    r = scene.render
    r.resolution_x = r.resolution_y = 10
    r.use_border, r.use_crop_to_border = True, crop
    r.border_min_x, r.border_min_y, r.border_max_x, r.border_max_y = 0.1, 0.3, 0.7, 0.7
    image = render_exr()
    (session,) = fake_session
    x0, y0, x1, y1 = session.desc.film.region
    assert (x0, y0, x1, y1) == (1, 3, 7, 7)
    if crop:
        np.testing.assert_array_equal(image, session.target)
    else:
        assert image.shape == (10, 10, 4)
        np.testing.assert_array_equal(image[y0:y1, x0:x1], session.target)
        assert not image[:y0].any() and not image[y1:].any()


def test_effects_line_is_stored_and_shown_in_the_panel(scene, fake_session, addon):
    mat = bpy.data.materials.new("Glow")
    mat.node_tree.nodes["Principled BSDF"].inputs["Emission Strength"].default_value = 1.0
    new_mesh_object("Tri", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)], materials=[mat])
    scene.collection.objects.link(bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN")))
    panel_lines = _panel_text(addon, scene)
    assert panel_lines == ["Not rendered yet"]
    bpy.ops.render.render()
    parts = ["Lights: 1 sun, 1 emissive triangle; surfaces: diffuse, rough glossy, emission; "
             "no textures",
             "simulated: light sampling, lamp hits, MIS weights, caustic paths",
             "skipped: world lookups, transparent shadows, subsurface walks, light linking"]
    assert scene.mcengine.last_effects == " | ".join(parts)
    assert scene.mcengine.last_ignored == ""
    assert _panel_text(addon, scene) == [parts[0], "Simulated: " + parts[1][len("simulated: "):],
                                         "Skipped: " + parts[2][len("skipped: "):]]


def _panel_text(addon, scene, operators=None, props=None):
    """The labels the MC Engine render panel draws (with a recording stand-in layout);
    the operator buttons' ids go to ``operators`` and the property names to ``props``
    if given."""
    lines = []

    class Layout:
        def column(self, **_):
            return self

        row = column

        def label(self, text="", **_):
            lines.append(text)

        def operator(self, idname, **_):
            if operators is not None:
                operators.append(idname)

        def prop(self, data, name, **_):
            if props is not None:
                props.append(name)

    panel = SimpleNamespace(layout=Layout())
    addon.ui.MCENGINE_RENDER_PT_engine.draw(panel, SimpleNamespace(scene=scene))
    return lines


def _render_error(capfd):
    """Run F12 and return the ERROR text Blender raises, checking no traceback was printed."""
    with pytest.raises(RuntimeError) as err:
        bpy.ops.render.render()
    out, errout = capfd.readouterr()
    assert "Traceback" not in out + errout
    return str(err.value)


def test_invalid_scene_reports_one_error(scene, fake_session, capfd):
    scene.camera.data.type = "PANO"
    message = _render_error(capfd)
    assert message.splitlines()[0] == ("Error: MC Engine: camera 'Camera' is panoramic; MC Engine "
                                       "renders perspective and orthographic cameras only")
    assert fake_session == []


def test_scene_error_from_the_core_reports_one_error(scene, addon, monkeypatch, capfd):
    def refuse(desc, threads=None):
        raise SceneError("film region (0, 0, 9, 9) is empty or outside the 8x6 frame")

    monkeypatch.setattr(addon.engine, "session_factory", refuse)
    message = _render_error(capfd)
    assert message.splitlines()[0] == \
        "Error: MC Engine: film region (0, 0, 9, 9) is empty or outside the 8x6 frame"


def test_core_failure_while_rendering_reports_one_error(scene, addon, monkeypatch, capfd):
    class Crashing(GradientSession):
        def run(self, on_pass=None, should_stop=None):
            self.passes = 1
            super().run(on_pass, should_stop)
            raise MemoryError("out of memory in pass 2")

    sessions = []
    monkeypatch.setattr(addon.engine, "session_factory",
                        lambda d, threads: sessions.append(Crashing(d)) or sessions[-1])
    message = _render_error(capfd)
    assert message.splitlines()[0] == \
        "Error: MC Engine: failed while rendering: MemoryError: out of memory in pass 2"


def test_stats_line(addon):
    line = addon.engine.stats_line
    assert line(12, 64, SimpleNamespace(rays_per_second=3.14e6, eta_seconds=4.4)) == \
        "Sample 12/64 | 3.1 Mrays/s | Remaining 00:04"
    assert line(1, 64, SimpleNamespace(rays_per_second=0.0, eta_seconds=float("nan"))) == "Sample 1/64"
    assert line(2, 8, object()) == "Sample 2/8"
    assert line(2, 8, SimpleNamespace(eta_seconds=3725)) == "Sample 2/8 | Remaining 1:02:05"
    assert line(2, 8, SimpleNamespace(nonfinite=12345)) == \
        "Sample 2/8 | 12,345 non-finite samples dropped"
