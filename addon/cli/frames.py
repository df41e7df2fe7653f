"""Which frames to render and what each one's image is called, as Blender decides (no bpy).

Blender's background render takes its frames from arguments processed in
order (``source/creator/creator_args.cc``):

* ``-s F`` / ``-e F`` set the scene's start / end frame; ``+N`` and ``-N`` are
  relative to the current start (end) frame: ``-s +2`` is start + 2, ``-e -2``
  is end - 2;
* ``-j N`` sets the frame step (N >= 1), which only ``-a`` uses;
* ``-a`` renders start, start + step, ... up to end (inclusive);
* ``-f LIST`` renders a comma-separated list (no spaces) of frames and
  inclusive ranges ``A..B``; there ``+N`` is start + N and ``-N`` is
  end - N + 1 (so ``-1`` is the end frame).  A range whose start is after its
  end is ignored with a warning.

:func:`parse_frame_list` and :func:`parse_relative` check the syntax before
Blender starts; :func:`plan_frames` applies the actions to the file's frame
range once it is loaded.  A frame that appears twice is rendered once.

:func:`frame_path` names a frame's image as ``RenderSettings.frame_path``
does: the last run of ``#`` in the file name becomes the frame number, zero
padded to the run's length, with the sign in front (``-0003``).
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from .errors import CliError

__all__ = ["MIN_FRAME", "MAX_FRAME", "RelativeFrame", "FrameAction", "FramePlan",
           "parse_relative", "parse_frame_list", "parse_step", "plan_frames", "frame_path",
           "renders_several"]

# Blender's MINAFRAME and MAXFRAME.
MIN_FRAME, MAX_FRAME = -1_048_574, 1_048_574
_NUMBER = re.compile(r"([+-]?)(\d+)")


@dataclass(frozen=True)
class RelativeFrame:
    """A frame number as written: ``sign`` is "" (absolute), "+" or "-"."""

    sign: str
    value: int

    def resolve(self, plus_base: int, minus_base: int) -> int:
        """The frame: value, plus_base + value, or minus_base - value + 1 (Blender's rule)."""
        if self.sign == "+":
            return plus_base + self.value
        if self.sign == "-":
            return minus_base - self.value + 1
        return self.value

    def __str__(self) -> str:
        return f"{self.sign}{self.value}"


@dataclass(frozen=True)
class FrameAction:
    """One frame argument, in command-line order: ``kind`` is "start", "end", "step"
    (``value`` a RelativeFrame, or an int for the step), "animation" or "frames"
    (``value`` a tuple of (first, last) RelativeFrame pairs, ``text`` as given)."""

    kind: str
    value: object = None
    text: str = ""


@dataclass(frozen=True)
class FramePlan:
    """The frames to render, in order, and the frame range they leave in the scene."""

    frames: tuple[int, ...]
    start: int
    end: int
    step: int
    warnings: tuple[str, ...] = ()


def parse_relative(text: str, option: str) -> RelativeFrame:
    """``12``, ``+2`` or ``-2``; CliError otherwise."""
    match = _NUMBER.fullmatch(text)
    if match is None:
        raise CliError(f"{option} needs a frame number, +N or -N, got {text!r}")
    return RelativeFrame(match[1], int(match[2]))


def parse_step(text: str) -> int:
    """``-j``: frames to step forward, 1..MAX_FRAME."""
    if not text.isdigit() or not 1 <= int(text) <= MAX_FRAME:
        raise CliError(f"-j/--frame-jump needs a whole number of frames from 1 to {MAX_FRAME}, "
                       f"got {text!r}")
    return int(text)


def parse_frame_list(text: str) -> tuple[tuple[RelativeFrame, RelativeFrame], ...]:
    """``-f``: comma-separated frames and ``A..B`` ranges, as (first, last) pairs."""
    items = []
    for part in text.split(","):
        if not part:
            raise CliError(f"incorrect comma use in '-f {text}' (a list is written 1,3,5..7, "
                           "without spaces)")
        first, sep, last = part.partition("..")
        try:
            low = parse_relative(first, "-f")
            high = parse_relative(last, "-f") if sep else low
        except CliError:
            raise CliError(f"not a frame number in '-f {text}': {part!r} (frames are N, +N "
                           "(from the start frame) or -N (from the end), ranges A..B)") from None
        items.append((low, high))
    return tuple(items)


def renders_several(actions) -> bool:
    """True if the actions can render more than one frame (``-a``, a list or a range in
    ``-f``, or ``-f`` given twice): their images are then named with frame digits."""
    renders = [a for a in actions if a.kind in ("animation", "frames")]
    if len(renders) > 1:
        return True
    return any(a.kind == "animation" or "," in a.text or ".." in a.text for a in renders)


def plan_frames(actions, start: int, end: int, step: int) -> FramePlan:
    """Apply the frame arguments in order to the file's range (start, end, step).

    Raises CliError for a frame outside Blender's range or when nothing is left
    to render; a reversed range is left out with a warning, as Blender does.
    """
    frames: dict[int, None] = {}
    warnings = []
    for action in actions:
        if action.kind == "start":
            start = _checked(action.value.resolve(start, start - 1), "-s")
        elif action.kind == "end":
            end = _checked(action.value.resolve(end, end - 1), "-e")
        elif action.kind == "step":
            step = int(action.value)
        elif action.kind == "animation":
            frames.update(dict.fromkeys(range(start, end + 1, step)))
        else:
            for low, high in action.value:
                first = _checked(low.resolve(start, end), "-f")
                last = _checked(high.resolve(start, end), "-f")
                if first > last:
                    warnings.append(f"range {low}..{high} of '-f {action.text}' is "
                                    f"{first}..{last}, which ends before it starts: ignored")
                frames.update(dict.fromkeys(range(first, last + 1)))
    if not frames:
        raise CliError("no frame to render: " + (
            f"the scene's frame range {start}..{end} is empty" if any(
                a.kind == "animation" for a in actions) else "every range given ends before it starts"))
    return FramePlan(tuple(frames), start, end, step, tuple(warnings))


def _checked(frame: int, option: str) -> int:
    if not MIN_FRAME <= frame <= MAX_FRAME:
        raise CliError(f"{option} gives frame {frame}, outside Blender's range "
                       f"{MIN_FRAME}..{MAX_FRAME}")
    return frame


def frame_path(pattern: Path, frame: int) -> Path:
    """Replace the last run of ``#`` in the file name with the frame number, zero-padded to
    the run's length after its sign (``out_####`` -> ``out_0012``, ``out_-0003``)."""
    runs = list(re.finditer(r"#+", pattern.name))
    if not runs:
        return pattern
    last = runs[-1]
    digits = ("-" if frame < 0 else "") + str(abs(frame)).zfill(len(last[0]))
    return pattern.with_name(pattern.name[:last.start()] + digits + pattern.name[last.end():])
