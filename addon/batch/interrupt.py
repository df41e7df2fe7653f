"""Stopping batch work on request: a flag, set by a signal, read at safe points.

The command line (``mcengine_blender.cli.signals``) turns SIGINT and SIGTERM
into :func:`request` instead of Python's KeyboardInterrupt, which would be
raised wherever the main thread happens to be (inside a C extension's
import, inside Blender's render callbacks) and can crash the process.  The
work then stops where it is safe to:

* the batch tools call :func:`check` between renders, which raises
  :class:`Interrupted` (a BaseException, like KeyboardInterrupt, so that no
  ``except Exception`` swallows it);
* an MC Engine render in progress stops within a tenth of a second: the
  render session polls ``should_stop``, and :func:`install_engine_hook` makes
  the engine's sessions answer True once a stop is requested (through the
  engine's ``session_factory`` hook, without changing the engine).  The
  engine then finishes its partial image as it does for Esc.

Whoever stops in order calls :func:`acknowledge` (``check`` does), so that the
signal handler knows the stop is under way.  Nothing here imports ``bpy`` or
installs a signal handler: without the command line the flag is never set.
"""
from __future__ import annotations

import threading

__all__ = ["Interrupted", "request", "requested", "check", "acknowledge", "acknowledged",
           "reset", "install_engine_hook"]

_lock = threading.Lock()
_signum: int | None = None
_acknowledged = threading.Event()


class Interrupted(BaseException):
    """The work was stopped on request; ``signum`` is the signal that asked."""

    def __init__(self, signum: int):
        super().__init__(f"interrupted by signal {signum}")
        self.signum = signum


def request(signum: int) -> None:
    """Ask the work to stop (the first request's signal is the one kept)."""
    global _signum
    with _lock:
        if _signum is None:
            _signum = int(signum)


def requested() -> int | None:
    """The signal number of the pending stop request, None if there is none."""
    return _signum


def acknowledge() -> None:
    """Say that the work is stopping in order (the handler then waits for it)."""
    if _signum is not None:
        _acknowledged.set()


def acknowledged() -> bool:
    return _acknowledged.is_set()


def check() -> None:
    """Raise :class:`Interrupted` if a stop was requested (a safe point)."""
    signum = _signum
    if signum is not None:
        _acknowledged.set()
        raise Interrupted(signum)


def reset() -> None:
    """Forget any request (for a process that runs the command line more than once)."""
    global _signum
    with _lock:
        _signum = None
        _acknowledged.clear()


# ---------------------------------------------------------------------------
# MC Engine renders in progress
# ---------------------------------------------------------------------------

class _StoppableSession:
    """A render session whose ``run`` also stops when a stop is requested."""

    def __init__(self, session):
        self._session = session

    def __getattr__(self, name):
        return getattr(self._session, name)

    def run(self, on_pass=None, should_stop=None):
        def stop() -> bool:
            if _signum is not None:
                acknowledge()
                return True
            return bool(should_stop is not None and should_stop())

        self._session.run(on_pass=on_pass, should_stop=stop)
        return self


def _stoppable(factory):
    def make_session(scene, threads=None):
        return _StoppableSession(factory(scene, threads=threads))

    make_session.stops_on_request = True
    make_session.wrapped = factory
    return make_session


def install_engine_hook() -> None:
    """Make MC Engine's render sessions stop once a stop is requested (idempotent).

    Wraps ``engine.session_factory``, the engine's documented hook for the
    session it creates; imports the engine, hence ``bpy``.
    """
    from .. import engine
    if not getattr(engine.session_factory, "stops_on_request", False):
        engine.session_factory = _stoppable(engine.session_factory)
