"""Blender's frame options (-f, -a, -s, -e, -j) and frame-numbered names, without Blender.

The rules are those of Blender's ``creator_args.cc`` (``parse_int_relative``,
``parse_int_range_relative_clamp_n``, the ``-s``/``-e``/``-j``/``-a``/``-f``
handlers) and ``RE_RenderAnim``: arguments act in order, ``+N`` counts from
the start frame and ``-N`` from the end (``-1`` is the end frame) in ``-f``,
from the current start (end) frame in ``-s`` (``-e``); a reversed range is
ignored with a warning.  ``tests/addon/test_frame_names.py`` checks the
names against Blender's own ``RenderSettings.frame_path``.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from mcengine_blender.cli.args import _output_for, parse_args
from mcengine_blender.cli.errors import CliError
from mcengine_blender.cli.frames import frame_path, plan_frames

REPO = Path(__file__).resolve().parents[2]
BLEND = REPO / "blend_scenes" / "light_point.blend"


def plan(tmp_path, *options, start=1, end=10, step=1):
    """Parse a command line with ``options`` and plan it against the range start..end."""
    request = parse_args(["render", str(BLEND), "-o", str(tmp_path / "x_####"), *options])
    return plan_frames(request.frame_actions, start, end, step)


@pytest.mark.parametrize("options, frames", [
    (["-f", "4"], [4]),
    (["-f", "1,3,5..7"], [1, 3, 5, 6, 7]),
    (["-f", "+0"], [1]),                          # start + 0
    (["-f", "+2"], [3]),
    (["-f", "-1"], [10]),                         # end - 1 + 1: the end frame
    (["-f", "-3"], [8]),
    (["-f", "+2..-2"], [3, 4, 5, 6, 7, 8, 9]),
    (["-f", "-1..-3"], []),                       # 10..8: reversed, ignored (see below)
    (["-f", "9..12"], [9, 10, 11, 12]),           # a list may leave the scene's range
    (["-f", "3,1,3"], [3, 1]),                    # in order, each frame once
    (["-f", "2", "-f", "5"], [2, 5]),
    (["-a"], list(range(1, 11))),
    (["-j", "3", "-a"], [1, 4, 7, 10]),
    (["-s", "4", "-e", "6", "-a"], [4, 5, 6]),
    (["-s", "+2", "-e", "-3", "-a"], [3, 4, 5, 6, 7]),   # start + 2, end - 3
    (["-s", "-2", "-e", "+1", "-j", "4", "-a"], [-1, 3, 7, 11]),
    (["-s", "5", "-f", "+1"], [6]),               # -f's +N counts from the new start
    (["-e", "20", "-f", "-1"], [20]),
    (["-s", "1", "-e", "2", "-a", "-s", "8", "-e", "9", "-a"], [1, 2, 8, 9]),
    (["-f", "5", "-a", "-j", "2", "-f", "+0"], [5, 1, 2, 3, 4, 6, 7, 8, 9, 10]),
])
def test_frames_as_blender_orders_them(tmp_path, options, frames):
    if not frames:
        with pytest.raises(CliError, match="no frame to render"):
            plan(tmp_path, *options)
        return
    assert list(plan(tmp_path, *options).frames) == frames


def test_reversed_range_is_ignored_with_a_warning(tmp_path):
    result = plan(tmp_path, "-f", "2,7..5,3")
    assert result.frames == (2, 3)
    assert result.warnings == ("range 7..5 of '-f 2,7..5,3' is 7..5, which ends before it "
                               "starts: ignored",)


def test_plan_leaves_the_range_it_set(tmp_path):
    result = plan(tmp_path, "-s", "3", "-e", "+5", "-j", "2", "-a")
    assert (result.start, result.end, result.step) == (3, 15, 2)


@pytest.mark.parametrize("options, fragment", [
    (["-f", "1,,3"], "incorrect comma use"),
    (["-f", ",1"], "incorrect comma use"),
    (["-f", "1,"], "incorrect comma use"),
    (["-f", "1.."], "not a frame number"),
    (["-f", "..3"], "not a frame number"),
    (["-f", "1...3"], "not a frame number"),
    (["-f", "1-3"], "not a frame number"),
    (["-f", "a"], "not a frame number"),
    (["-f", "+-2"], "not a frame number"),
    (["-f", "1, 2"], "not a frame number"),
    (["-s", "x", "-a"], "-s/--frame-start needs a frame number"),
    (["-e", "1.5", "-a"], "-e/--frame-end needs a frame number"),
    (["-j", "0", "-a"], "-j/--frame-jump needs a whole number"),
    (["-j", "-2", "-a"], "-j/--frame-jump needs a whole number"),
    (["-a", "-s", "3"], "put -s before -a/-f"),
    (["-e", "3"], "put -e before -a/-f"),
    (["-f", "1", "-j", "2"], "put -j before -a/-f"),
    (["--no-overwrite"], "apply to frames given with -f or -a"),
    (["-f", "2000000"], "outside Blender's range"),
])
def test_bad_frame_options_are_one_line_errors(tmp_path, options, fragment):
    with pytest.raises(CliError, match=None) as error:
        plan(tmp_path, *options)
    assert fragment in str(error.value)
    assert "\n" not in str(error.value)


def test_relative_frame_outside_blenders_range_is_refused(tmp_path):
    with pytest.raises(CliError, match="-s gives frame -1048575"):
        plan(tmp_path, "-s", "-1048576", "-a")


def test_end_relative_values_are_not_taken_for_options(tmp_path):
    """``-f -1..-3``, ``-s -2``: Blender reads the next argument whatever it looks like."""
    for spelling in (["-f", "-2..-1"], ["--frame", "-2..-1"], ["--render-frame", "-2..-1"],
                     ["-f-2..-1"], ["--frame=-2..-1"]):
        assert list(plan(tmp_path, *spelling).frames) == [9, 10], spelling


@pytest.mark.parametrize("options, several", [
    ([], False), (["-f", "3"], False), (["-f", "+3"], False), (["-f", "3..3"], True),
    (["-f", "3,4"], True), (["-f", "3", "-f", "4"], True), (["-a"], True),
])
def test_names_get_frame_digits_when_several_frames_can_render(tmp_path, options, several):
    request = parse_args(["render", str(BLEND), "-o", str(tmp_path / "shot.png"), *options])
    assert request.several_frames is several
    name = request.outputs[0].pattern.name
    assert name == ("shot####.png" if several else "shot.png")


def test_default_output_of_an_animation_is_numbered(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    request = parse_args(["-b", str(BLEND), "-a"])
    assert request.outputs[0].pattern == tmp_path / "light_point_####.exr"


@pytest.mark.parametrize("raw, fmt, several, frame, expected", [
    ("out", "OPEN_EXR", True, 5, "out0005.exr"),        # Blender: four digits appended
    ("out", "PNG", True, 12345, "out12345.png"),
    ("out", "OPEN_EXR", True, -3, "out-0003.exr"),
    ("out.png", None, True, 7, "out0007.png"),           # before a known extension
    ("out_####", None, True, -3, "out_-0003.exr"),
    ("x_##_y", None, True, 5, "x_05_y.exr"),
    ("x_##_y", None, False, -3, "x_-03_y.exr"),
    ("shot.EXR", None, True, 2, "shot0002.EXR"),
    ("out", None, False, 5, "out.exr"),                  # one frame: the name as given
])
def test_frame_numbered_names(tmp_path, raw, fmt, several, frame, expected):
    output = _output_for(str(tmp_path / raw), fmt, tmp_path, several)
    assert frame_path(output.pattern, frame) == tmp_path / expected
