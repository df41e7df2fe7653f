"""Compile the kernels in the background when the add-on is enabled (``mcengine.warmup``).

The first render after installing would otherwise spend minutes compiling
before its first pixel.  When the add-on is registered in Blender with a
window (not in background mode: tests, the command line and render farms
compile on their first render as before), :func:`start` runs
``python -m mcengine.warmup`` in a child process of low priority with
Blender's own Python; it returns at once if the kernels of the installed
sources are already compiled.  A render started meanwhile waits for it
(:func:`wait`, which shows how long it has been compiling) instead of
compiling the same kernels a second time beside it.
"""
from __future__ import annotations

import os
import subprocess
import sys
import time

__all__ = ["start", "running", "elapsed", "wait", "status", "stop"]

_process: subprocess.Popen | None = None
_started = 0.0


def _lower_priority() -> None:
    try:
        os.nice(10)
    except OSError:
        pass


def start(force: bool = False) -> bool:
    """Start the background compile (once); True if it was started.

    Only in Blender with a window, unless ``force``."""
    global _process, _started
    import bpy
    if (bpy.app.background and not force) or running():
        return False
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    try:
        _process = subprocess.Popen(
            [sys.executable, "-m", "mcengine.warmup"], env=env, stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            preexec_fn=_lower_priority if os.name == "posix" else None)
    except OSError:          # no Python to run: the first render compiles, as before
        _process = None
        return False
    _started = time.monotonic()
    return True


def running() -> bool:
    return _process is not None and _process.poll() is None


def elapsed() -> float:
    """Seconds since the background compile started."""
    return time.monotonic() - _started


def status() -> str:
    """One line for the status bar while the background compile runs ("" otherwise)."""
    if not running():
        return ""
    minutes, seconds = divmod(int(elapsed()), 60)
    return (f"Waiting for the kernels being compiled in the background since the add-on was "
            f"enabled ({minutes}:{seconds:02d} so far)")


def wait(should_stop, on_wait=None, poll: float = 0.1, integrator: str | None = None) -> bool:
    """Wait while the background compile runs (with ``integrator``, only until that
    integrator's kernels are compiled: the compile goes on with the others); False if
    ``should_stop()`` ended the wait.

    ``on_wait(status_line)`` is called about once a second."""
    from mcengine.warmup import is_compiled
    last = -1
    while running() and not (integrator is not None and is_compiled(integrator)):
        if should_stop():
            return False
        if on_wait is not None and int(elapsed()) != last:
            last = int(elapsed())
            on_wait(status())
        time.sleep(poll)
    return True


def stop() -> None:
    """End the background compile (the add-on is disabled)."""
    global _process
    if running():
        _process.terminate()
    _process = None
