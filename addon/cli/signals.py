"""Ctrl-C and SIGTERM for the command line: stop in order, or end cleanly.

Installed by ``main`` before anything heavy is imported (numpy, bpy, numba).
Python's default SIGINT handler raises KeyboardInterrupt wherever the main
thread is, and raised inside a C extension's import (bpy, numba) or inside a
Blender callback it crashes the process (exit 139) or leaves Blender's state
half-torn.  Here the handler only sets a flag (:mod:`..batch.interrupt`),
which the command reads at safe points and MC Engine renders poll.

A Python signal handler runs only when the main thread executes Python, so
not while Blender blocks in a Cycles render, a file load or ``import bpy``.
A watcher thread therefore learns of the signal at once (through
``signal.set_wakeup_fd``) and gives the main thread :data:`GRACE_SECONDS` to
acknowledge that it is stopping.  If it does not (a Cycles render cannot be
cancelled from Python), or when a second signal arrives, the watcher ends
the process itself: it waits for any rename of outputs in progress
(:data:`..batch.outputs.COMMIT_LOCK`), removes the temporary files in flight
(and a frame's placeholder still empty),
this command's temporary folder and Blender's, prints one line and exits
with 130 (SIGINT) or 143 (SIGTERM).  Outputs are only ever renamed into
place once complete, so ending the process loses nothing that was there.

Temporary files: the command points ``TMPDIR`` at a folder of its own,
``mcengine-XXXXXXXX`` in the system's temporary directory, before Blender
starts, so Blender's session folder (``blender_XXXXXX``) and every other
temporary file land inside it; it is removed when the process ends.
"""
from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time

from ..batch import interrupt
from .errors import EXIT_INTERRUPTED, EXIT_TERMINATED, PROG

# Imported only once the handlers are in place (``handling``), to keep the
# time before they are as short as possible: atexit, select, shutil, tempfile
# and batch.outputs.

__all__ = ["GRACE_SECONDS", "EXIT_STATUS", "handling", "exit_status", "announce",
           "note_temporary_folder"]

#: How long the main thread has to acknowledge a stop before the process ends.
GRACE_SECONDS = 0.5
EXIT_STATUS = {signal.SIGINT: EXIT_INTERRUPTED, signal.SIGTERM: EXIT_TERMINATED}
HANDLED = tuple(EXIT_STATUS)

_folders: list[str] = []          # removed on exit: ours, then Blender's
_stderr_fd: int | None = None     # the real stderr (Blender's log capture moves fd 2)
_announced = threading.Lock()     # held for good once the one line is printed


def exit_status(signum: int) -> int:
    return EXIT_STATUS.get(signum, EXIT_INTERRUPTED)


def message(signum: int) -> str:
    return f"{PROG}: interrupted" if signum == signal.SIGINT else f"{PROG}: terminated"


def announce(signum: int) -> None:
    """Print the one line that says the command was stopped (once, from any thread)."""
    if not _announced.acquire(blocking=False):
        return
    line = message(signum) + "\n"
    fd = _stderr_fd if _stderr_fd is not None else 2
    with contextlib.suppress(OSError):
        if os.isatty(fd):
            line = "\r\033[K" + line      # over a progress bar
        os.write(fd, line.encode())


def note_temporary_folder(path) -> None:
    """Remove ``path`` too if the process has to end early (Blender's temporary folder)."""
    if path:
        _folders.append(str(path))


def _handler(signum, _frame) -> None:
    interrupt.request(signum)


def _outputs():
    """batch.outputs if it was imported (it holds the temporary files in flight)."""
    return sys.modules.get(f"{__package__.rpartition('.')[0]}.batch.outputs")


def _remove_temporaries() -> None:
    import shutil
    outputs = _outputs()
    if outputs is not None:
        outputs.remove_pending()
    for folder in reversed(_folders):
        shutil.rmtree(folder, ignore_errors=True)


def _end_now(signum: int) -> None:
    """End the process from the watcher thread: no rename half-done, no temporary left."""
    outputs = _outputs()
    with outputs.COMMIT_LOCK if outputs is not None else contextlib.nullcontext():
        _remove_temporaries()
        announce(signum)
        os._exit(exit_status(signum))


def _watch(read_fd: int, stop: threading.Event) -> None:
    """Wait for signals; end the process unless the main thread stops in order in time."""
    import select
    count, deadline = 0, None
    while not stop.is_set():
        timeout = None if deadline is None else max(0.0, deadline - time.monotonic())
        try:
            ready, _, _ = select.select([read_fd], [], [], timeout)
        except (OSError, ValueError):
            return
        if stop.is_set():
            return
        if ready:
            try:
                data = os.read(read_fd, 64)
            except OSError:
                return
            signums = [b for b in data if b in HANDLED]
            if not signums:
                continue
            for signum in signums:
                interrupt.request(signum)
            count += len(signums)
            if count > 1:
                _end_now(interrupt.requested())
            deadline = time.monotonic() + GRACE_SECONDS
        elif deadline is not None:
            deadline = None
            if not interrupt.acknowledged():
                _end_now(interrupt.requested())


def _private_tmpdir() -> str:
    """A temporary folder for this command, removed at exit.

    Registered with atexit before bpy is imported, so it runs after Blender's
    own exit handler, which empties Blender's session folder inside it.
    """
    import atexit
    import shutil
    import tempfile
    path = tempfile.mkdtemp(prefix="mcengine-", dir=tempfile.gettempdir())
    atexit.register(shutil.rmtree, path, True)
    return path


@contextlib.contextmanager
def handling(restore: bool = True):
    """Handle SIGINT and SIGTERM for the duration of the command (main thread only).

    Yields the command's temporary folder.  With ``restore``, the previous
    handlers and ``TMPDIR`` are put back afterwards, for a process that does
    other things (tests); the ``mcengine`` process itself keeps its handlers
    (that only set the flag) until it exits, so that a late signal cannot
    raise KeyboardInterrupt in Blender's exit handlers.
    """
    global _stderr_fd
    interrupt.reset()
    previous = {signum: signal.signal(signum, _handler) for signum in HANDLED}
    import tempfile
    if _announced.locked():
        _announced.release()
    read_fd, write_fd = os.pipe()
    os.set_blocking(write_fd, False)
    previous_wakeup = signal.set_wakeup_fd(write_fd, warn_on_full_buffer=False)
    if _stderr_fd is None:
        with contextlib.suppress(OSError):
            _stderr_fd = os.dup(2)
    stop = threading.Event()
    watcher = threading.Thread(target=_watch, args=(read_fd, stop), name="mcengine-signals",
                               daemon=True)
    watcher.start()
    saved_env, saved_tempdir = os.environ.get("TMPDIR"), tempfile.tempdir
    folder = _private_tmpdir()
    _folders.insert(0, folder)
    os.environ["TMPDIR"] = folder
    tempfile.tempdir = folder
    try:
        yield folder
    finally:
        signal.set_wakeup_fd(previous_wakeup)
        stop.set()
        with contextlib.suppress(OSError):
            os.write(write_fd, b"\0")
        watcher.join(1.0)
        for fd in (read_fd, write_fd):
            with contextlib.suppress(OSError):
                os.close(fd)
        if restore:
            for signum, handler in previous.items():
                signal.signal(signum, handler if handler is not None else signal.SIG_DFL)
            tempfile.tempdir = saved_tempdir
            if saved_env is None:
                os.environ.pop("TMPDIR", None)
            else:
                os.environ["TMPDIR"] = saved_env
        _folders.clear()
