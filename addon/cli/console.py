"""The console of the command line: Blender's log captured, progress on stderr.

* :class:`BlenderLog` captures everything Blender writes to fds 1 and 2 (its
  C log included), so only the command's own lines reach the terminal;
  :func:`engine_traceback` and :func:`warning_lines` read the captured log.
* :class:`Progress` draws a render's progress from Blender's render
  statistics: a bar redrawn in place on a terminal (as wide as the terminal
  allows), one line per 10 % otherwise (or none, when the command prints one
  line per frame of an animation).
"""
from __future__ import annotations

import contextlib
import ctypes
import os
import re
import sys
import tempfile
import time

__all__ = ["BlenderLog", "engine_traceback", "warning_lines", "Progress"]

SAMPLE_STATS = re.compile(r"Sample (\d+)/(\d+)")
# Non-TTY progress prints one line each time this fraction is crossed.
PROGRESS_LINE_STEP = 0.1
PROGRESS_BAR_WIDTH = 30


class BlenderLog:
    """Captures everything written to fds 1 and 2 (C and Python) into a file.

    Blender writes its log from C with buffered stdio, so the C buffers are
    flushed before the descriptors are restored.  ``console`` is a duplicate of
    the real stderr for the progress display, which must not be captured.
    """

    def __init__(self, passthrough: bool):
        self.passthrough = passthrough
        self.console = os.fdopen(os.dup(2), "w", buffering=1)
        self._file = tempfile.TemporaryFile(mode="w+b")

    @contextlib.contextmanager
    def capture(self):
        if self.passthrough:
            yield
            return
        _flush_all()
        saved = os.dup(1), os.dup(2)
        os.dup2(self._file.fileno(), 1)
        os.dup2(self._file.fileno(), 2)
        try:
            yield
        finally:
            _flush_all()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])

    def mark(self) -> int:
        """Current end of the log, for ``text(since=...)``."""
        self._file.seek(0, os.SEEK_END)
        return self._file.tell()

    def text(self, since: int = 0) -> str:
        """The log captured so far, from byte offset ``since``."""
        self._file.seek(since)
        return self._file.read().decode("utf-8", "replace")


def _flush_all() -> None:
    sys.stdout.flush()
    sys.stderr.flush()
    with contextlib.suppress(Exception):
        ctypes.CDLL(None).fflush(None)


def engine_traceback(log: str) -> str | None:
    """The exception line of a Python traceback in Blender's log, if any.

    Blender catches exceptions raised inside ``RenderEngine.render``, prints the
    traceback and still saves the (incomplete) image, so the log is the only
    place a crash shows up.
    """
    lines = log.splitlines()
    starts = [i for i, line in enumerate(lines) if line.startswith("Traceback (most recent call last)")]
    if not starts:
        return None
    for line in lines[starts[-1] + 1:]:
        if line and not line[0].isspace():
            return line.strip()
    return "the render engine raised an exception"


def warning_lines(log: str) -> list[str]:
    """``Warning: ...`` lines (engine reports) from Blender's log, without the prefix."""
    return [line.split(":", 1)[1].strip() for line in log.splitlines() if line.startswith("Warning:")]


class Progress:
    """Render progress on stderr from Blender's render statistics strings."""

    def __init__(self, stream, label: str, lines: bool = True):
        self.stream = stream
        self.label = label
        self.is_tty = stream.isatty()
        self.lines = lines      # not a terminal: False prints nothing (the caller reports)
        self.start = time.monotonic()
        self._lines_printed = 0  # non-TTY: number of PROGRESS_LINE_STEP steps reported
        self._drawn = False
        self.done: int | None = None   # the last sample count reported ("Sample N/M")

    def on_stats(self, stats, *_unused) -> None:
        """``bpy.app.handlers.render_stats`` callback; never raises."""
        with contextlib.suppress(Exception):
            self.update(str(stats))

    def update(self, stats: str) -> None:
        match = SAMPLE_STATS.search(stats)
        if match is None:
            if self.is_tty and not self._drawn:
                phase = stats.split("|")[-1].strip()
                self._draw(f"{self.label}: {phase}")
            return
        done, total = int(match[1]), int(match[2])
        self.done = done
        fraction = min(done / total, 1.0) if total else 0.0
        if self.is_tty:
            filled = round(fraction * PROGRESS_BAR_WIDTH)
            bar = "#" * filled + "." * (PROGRESS_BAR_WIDTH - filled)
            self._draw(f"{self.label} [{bar}] {fraction:4.0%}  sample {done}/{total}  {self._elapsed()}")
            self._drawn = True
        elif self.lines:
            steps = int(fraction / PROGRESS_LINE_STEP + 1e-9)
            if steps > self._lines_printed:
                self._lines_printed = steps
                self.stream.write(f"{self.label}: {fraction:.0%} (sample {done}/{total}, {self._elapsed()})\n")
                self.stream.flush()

    def finish(self) -> None:
        if self.is_tty:
            self.stream.write("\r\033[K")
            self.stream.flush()

    def _draw(self, text: str) -> None:
        width = max(20, _terminal_width(self.stream) - 1)
        self.stream.write("\r\033[K" + text[:width])
        self.stream.flush()

    def _elapsed(self) -> str:
        seconds = time.monotonic() - self.start
        return f"{int(seconds // 60):02d}:{seconds % 60:04.1f}"


def _terminal_width(stream) -> int:
    try:
        return os.get_terminal_size(stream.fileno()).columns
    except (OSError, ValueError):
        return 80
