"""The background kernel compile (addon/warmup.py, mcengine/warmup.py): it runs only in
Blender with a window, marks the cache ready, and a render waits for it instead of
compiling beside it."""
from __future__ import annotations

import importlib
import subprocess
import sys
import time

import pytest

import mcengine.warmup
from mcengine import integrators, jit


@pytest.fixture
def warmup(addon):
    module = importlib.import_module(addon.__name__ + ".warmup")
    yield module
    module.stop()


@pytest.mark.timeout(1800)      # compiles the kernels when the cache is cold
def test_warm_up_compiles_and_marks_the_cache_ready():
    marker = jit.cache_folder() / "kernels-compiled"
    marker.unlink(missing_ok=True)
    for name in integrators.NAMES:
        (jit.cache_folder() / f"kernels-compiled-{name}").unlink(missing_ok=True)
    assert not jit.cache_is_ready() and not any(map(mcengine.warmup.is_compiled, integrators.NAMES))
    done = subprocess.run([sys.executable, "-m", "mcengine.warmup"], capture_output=True,
                          text=True, timeout=1800)
    assert done.returncode == 0, done.stderr
    assert "kernels compiled in" in done.stdout and jit.cache_is_ready()
    assert all(map(mcengine.warmup.is_compiled, integrators.NAMES))
    again = subprocess.run([sys.executable, "-m", "mcengine.warmup"], capture_output=True,
                           text=True, timeout=600)
    assert again.returncode == 0 and "already compiled" in again.stdout


def test_nothing_starts_in_background_mode(warmup):
    """Tests, the command line and render farms (blender -b) compile at their first render."""
    assert not warmup.start() and not warmup.running() and warmup.status() == ""


def _sleeper(monkeypatch, seconds):
    real = subprocess.Popen

    def popen(args, **kwargs):
        assert args[1:] == ["-m", "mcengine.warmup"] and kwargs["env"]["PYTHONPATH"]
        return real([sys.executable, "-c", f"import time; time.sleep({seconds})"], **kwargs)
    monkeypatch.setattr(subprocess, "Popen", popen)


def test_a_render_waits_for_the_background_compile(warmup, monkeypatch):
    _sleeper(monkeypatch, 1.0)
    assert warmup.start(force=True) and warmup.running()
    assert not warmup.start(force=True)                  # one at a time
    lines = []
    assert warmup.status().startswith("Waiting for the kernels being compiled")
    t0 = time.monotonic()
    assert warmup.wait(lambda: False, lines.append)
    assert time.monotonic() - t0 > 0.5 and not warmup.running() and warmup.status() == ""
    assert lines and lines[0].endswith("(0:00 so far)")


def test_a_cancelled_render_stops_waiting(warmup, monkeypatch):
    _sleeper(monkeypatch, 30.0)
    warmup.start(force=True)
    t0 = time.monotonic()
    assert not warmup.wait(lambda: time.monotonic() - t0 > 0.3)
    assert time.monotonic() - t0 < 5.0 and warmup.running()
    warmup.stop()
    assert not warmup.running()


def test_a_render_waits_only_for_its_integrators_kernels(warmup, monkeypatch):
    """The warm-up compiles the default integrator first: a render of it need not wait for
    the others."""
    _sleeper(monkeypatch, 30.0)
    monkeypatch.setattr(mcengine.warmup, "is_compiled", lambda name: name == integrators.DEFAULT)
    warmup.start(force=True)
    t0 = time.monotonic()
    assert warmup.wait(lambda: False, integrator=integrators.DEFAULT)
    assert time.monotonic() - t0 < 1.0 and warmup.running()
    assert not warmup.wait(lambda: time.monotonic() - t0 > 0.5, integrator="whitted")
    assert warmup.running()
    warmup.stop()


def test_f12_waits_for_the_background_compile(scene, addon, fake_session, warmup, monkeypatch):
    """The engine's render waits for its integrator's kernels (showing the wait in the status
    bar), then renders."""
    _sleeper(monkeypatch, 1.0)
    monkeypatch.setattr(mcengine.warmup, "is_compiled", lambda name: False)
    warmup.start(force=True)
    import bpy
    real_wait, lines, sessions_when_done, asked = warmup.wait, [], [], []

    def spying_wait(should_stop, on_wait=None, poll=0.1, integrator=None):
        asked.append(integrator)
        done = real_wait(should_stop, lambda line: (lines.append(line), on_wait(line)), poll,
                         integrator)
        sessions_when_done.append(len(fake_session))
        return done
    monkeypatch.setattr(warmup, "wait", spying_wait)
    bpy.ops.render.render()
    assert lines and lines[0].startswith("Waiting for the kernels being compiled")
    assert asked == [integrators.DEFAULT]        # the scene's integrator: the default one
    assert sessions_when_done == [0] and len(fake_session) == 1 and not warmup.running()
