"""The command line is safe with the user's data: faults injected into real runs.

* a write that fails part-way (a file-size limit, as on a full disk): the
  previous image is kept byte for byte, exit 1, one line;
* SIGINT at several moments (start-up, while bpy and the kernels load,
  mid-render) and SIGTERM: exit 130 / 143 with one line, no traceback, no
  crash, the previous image intact, no temporary file left in the output
  folder or in the temporary directory;
* an output that is the scene file itself (same path, symbolic or hard
  link): refused before rendering, exit 2, the scene untouched;
* ``compare`` interrupted, or unable to write its files: exit 130 / 1, the
  previous report intact, nothing left behind.

Every run has a temporary directory of its own (``TMPDIR``), checked empty
afterwards.  The command runs as a subprocess, as a user runs it.
"""
from __future__ import annotations

import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mcengine_blender.cli.errors import EXIT_BAD_INPUT, EXIT_INTERRUPTED, EXIT_RENDER_FAILED

REPO = Path(__file__).resolve().parents[2]
MCENGINE = Path(sys.executable).with_name("mcengine")
LIGHT_POINT = REPO / "blend_scenes" / "light_point.blend"
CORNELL_BOX = REPO / "blend_scenes" / "cornell_box.blend"
TIMEOUT = 300  # seconds; a run takes a few, a cold kernel cache a minute more
EXIT_TERMINATED = 143
PREVIOUS = b"the previous image, which must survive\n" * 100
# A render that takes seconds: progress lines (one per 10 %) come while it runs.
LONG_RENDER = ["--resolution", "64x64", "--samples", "2000"]
SMALL_RENDER = ["--resolution", "32x32", "--samples", "4"]


@pytest.fixture
def tmpdir_env(tmp_path):
    """A temporary directory of the run's own, to check that nothing is left in it."""
    folder = tmp_path / "tmp"
    folder.mkdir()
    return folder


@pytest.fixture
def out_dir(tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    return folder


def env_with(tmpdir: Path) -> dict:
    return {**os.environ, "TMPDIR": str(tmpdir)}


def run_cli(*args, tmpdir: Path, preexec_fn=None, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([str(MCENGINE), *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=TIMEOUT, stdin=subprocess.DEVNULL,
                          env=env_with(tmpdir), preexec_fn=preexec_fn)


def spawn(*args, tmpdir: Path) -> subprocess.Popen:
    return subprocess.Popen([str(MCENGINE), *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, stdin=subprocess.DEVNULL,
                            env=env_with(tmpdir))


def catches_sigterm(pid: int) -> bool:
    """True once the process has its own SIGTERM handler (/proc/PID/status SigCgt).

    Python catches SIGINT from its first instruction but never SIGTERM, so this
    says that the command's handlers are installed: before that moment, Python
    itself is still starting and the command cannot have done anything.
    """
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    match = re.search(r"^SigCgt:\s*([0-9a-f]+)$", text, re.MULTILINE)
    return bool(match) and bool(int(match[1], 16) & (1 << (signal.SIGTERM - 1)))


def signal_at(proc: subprocess.Popen, seconds: float, signum: int, started: float) -> None:
    """Send ``signum`` ``seconds`` after ``started``, but not before the command handles
    signals (or 5 s have passed: a command without handlers gets the signal anyway)."""
    deadline = time.monotonic() + 5
    while not catches_sigterm(proc.pid) and time.monotonic() < deadline:
        assert proc.poll() is None, "the command ended before the signal"
        time.sleep(0.002)
    remaining = started + seconds - time.monotonic()
    if remaining > 0:
        time.sleep(remaining)
    proc.send_signal(signum)


def signal_at_line(proc: subprocess.Popen, pattern: str, signum: int) -> list[str]:
    """Send ``signum`` (0: none) when stderr shows a line matching ``pattern``; returns the
    lines read."""
    lines = []
    for line in proc.stderr:
        lines.append(line)
        if re.search(pattern, line):
            if signum:
                proc.send_signal(signum)
            return lines
    raise AssertionError(f"the command ended without printing {pattern!r}:\n{''.join(lines)}")


def finish(proc: subprocess.Popen, stderr_so_far=()) -> tuple[int, str, str]:
    out, err = proc.communicate(timeout=TIMEOUT)
    return proc.returncode, out, "".join(stderr_so_far) + err


def assert_stopped(code: int, out: str, err: str, expected: int = EXIT_INTERRUPTED) -> None:
    """Exit status 128 + signal, the one line, no traceback, no crash, nothing on stdout."""
    word = "interrupted" if expected == EXIT_INTERRUPTED else "terminated"
    assert code == expected, f"exit status {code}\n{err}"
    assert "Traceback" not in err and "Fatal Python error" not in err, err
    assert out == ""
    own = [line for line in err.splitlines() if line.startswith("mcengine:")]
    assert own == [f"mcengine: {word}"], err


def assert_nothing_left(out_dir: Path, tmpdir: Path, expected: set[str]) -> None:
    """Only the expected files in the output folder, nothing in the temporary directory."""
    assert {p.name for p in out_dir.iterdir()} == expected
    assert list(tmpdir.iterdir()) == []


def assert_one_line_error(done, exit_code: int, *fragments: str) -> None:
    lines = done.stderr.splitlines()
    assert done.returncode == exit_code, done.stderr
    assert "Traceback" not in done.stderr + done.stdout
    assert done.stdout == ""
    own = [line for line in lines if line.startswith("mcengine:")]
    assert len(own) == 1 and own[0].startswith("mcengine: error: "), done.stderr
    for fragment in fragments:
        assert fragment in own[0], done.stderr


@pytest.fixture(scope="module")
def warm_kernels(tmp_path_factory):
    """One plain render first: compiling the kernels (a cold cache) writes cache files,
    which a file-size limit must not get in the way of."""
    folder = tmp_path_factory.mktemp("warm")
    done = run_cli("render", LIGHT_POINT, "--resolution", "8x8", "--samples", "1",
                   "-o", folder / "warm.exr", tmpdir=folder)
    assert done.returncode == 0, done.stderr


def file_size_limit(limit: int):
    """preexec_fn: files may not grow past ``limit`` bytes; write() then fails with EFBIG
    (SIGXFSZ, which would kill the process, is ignored), as on a full disk."""
    def limit_writes():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return limit_writes


# ---------------------------------------------------------------------------
# A write that fails part-way
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("name, limit", [
    ("shot.exr", 8000),     # the 64x64 float EXR is ~50 kB, its PNG ~12 kB
    ("shot.png", 4000),
])
def test_failed_write_keeps_the_previous_image(name, limit, out_dir, tmpdir_env, warm_kernels):
    target = out_dir / name
    target.write_bytes(PREVIOUS)
    done = run_cli("render", LIGHT_POINT, "--resolution", "64x64", "--samples", "4",
                   "-o", target, tmpdir=tmpdir_env, preexec_fn=file_size_limit(limit))
    assert_one_line_error(done, EXIT_RENDER_FAILED, f"cannot save {target}", "unchanged")
    assert target.read_bytes() == PREVIOUS
    assert_nothing_left(out_dir, tmpdir_env, {name})


def test_second_output_failing_keeps_both_previous_images(out_dir, tmpdir_env, warm_kernels):
    """The outputs of one render are replaced together or not at all."""
    png, exr = out_dir / "shot.png", out_dir / "shot.exr"
    png.write_bytes(PREVIOUS)
    exr.write_bytes(PREVIOUS)
    done = run_cli("render", LIGHT_POINT, "--resolution", "64x64", "--samples", "4",
                   "-o", png, "-o", exr, tmpdir=tmpdir_env, preexec_fn=file_size_limit(20000))
    assert_one_line_error(done, EXIT_RENDER_FAILED, f"cannot save {exr}")
    assert png.read_bytes() == PREVIOUS and exr.read_bytes() == PREVIOUS
    assert_nothing_left(out_dir, tmpdir_env, {"shot.png", "shot.exr"})


def test_outputs_are_replaced_with_the_previous_files_permissions(out_dir, tmpdir_env):
    target, new = out_dir / "shot.exr", out_dir / "new.png"
    target.write_bytes(PREVIOUS)
    target.chmod(0o640)
    done = run_cli("render", LIGHT_POINT, *SMALL_RENDER, "-o", target, "-o", new,
                   tmpdir=tmpdir_env)
    assert done.returncode == 0, done.stderr
    assert target.read_bytes() != PREVIOUS
    assert target.stat().st_mode & 0o777 == 0o640
    umask = os.umask(0)
    os.umask(umask)
    assert new.stat().st_mode & 0o777 == 0o666 & ~umask
    assert_nothing_left(out_dir, tmpdir_env, {"shot.exr", "new.png"})


# ---------------------------------------------------------------------------
# SIGINT and SIGTERM
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("seconds", [0.05, 0.3, 1.0])
def test_sigint_during_start_up(seconds, out_dir, tmpdir_env):
    """While numpy, bpy and the kernels load: a clean stop, never a crash (it was exit 139)."""
    target = out_dir / "shot.exr"
    target.write_bytes(PREVIOUS)
    started = time.monotonic()
    proc = spawn("render", CORNELL_BOX, *LONG_RENDER, "-o", target, tmpdir=tmpdir_env)
    signal_at(proc, seconds, signal.SIGINT, started)
    assert_stopped(*finish(proc))
    assert target.read_bytes() == PREVIOUS
    assert_nothing_left(out_dir, tmpdir_env, {"shot.exr"})


def test_sigint_mid_render_keeps_the_previous_image(out_dir, tmpdir_env):
    target = out_dir / "shot.exr"
    target.write_bytes(PREVIOUS)
    proc = spawn("render", CORNELL_BOX, *LONG_RENDER, "-o", target, tmpdir=tmpdir_env)
    lines = signal_at_line(proc, r"^MCENGINE: \d+%", signal.SIGINT)
    sent = time.monotonic()
    assert_stopped(*finish(proc, lines))
    assert time.monotonic() - sent < 5   # the render stops, it does not run to its end
    assert target.read_bytes() == PREVIOUS
    assert_nothing_left(out_dir, tmpdir_env, {"shot.exr"})


def test_sigint_mid_render_keeps_a_partial_image_on_request(out_dir, tmpdir_env):
    from mcengine.imageio import read_exr
    target = out_dir / "shot.exr"
    target.write_bytes(PREVIOUS)
    proc = spawn("render", CORNELL_BOX, *LONG_RENDER, "-o", target, "--keep-partial",
                 tmpdir=tmpdir_env)
    lines = signal_at_line(proc, r"^MCENGINE: \d+%", signal.SIGINT)
    code, out, err = finish(proc, lines)
    assert code == EXIT_INTERRUPTED, err
    assert "Traceback" not in err and out == ""
    partial = out_dir / "shot.partial.exr"
    assert "kept the partial image" in err and str(partial) in err
    assert err.splitlines()[-1] == "mcengine: interrupted"
    assert target.read_bytes() == PREVIOUS
    image = read_exr(partial)
    assert image.shape == (64, 64, 4) and image[..., :3].max() > 0
    assert_nothing_left(out_dir, tmpdir_env, {"shot.exr", "shot.partial.exr"})


def test_sigterm_mid_render(out_dir, tmpdir_env):
    target = out_dir / "shot.exr"
    target.write_bytes(PREVIOUS)
    proc = spawn("render", CORNELL_BOX, *LONG_RENDER, "-o", target, tmpdir=tmpdir_env)
    lines = signal_at_line(proc, r"^MCENGINE: \d+%", signal.SIGTERM)
    assert_stopped(*finish(proc, lines), expected=EXIT_TERMINATED)
    assert target.read_bytes() == PREVIOUS
    assert_nothing_left(out_dir, tmpdir_env, {"shot.exr"})


def test_sigint_during_a_cycles_render_ends_it(out_dir, tmpdir_env):
    """Cycles cannot be stopped from Python: the command ends the process itself, at once.

    Cycles reports its samples only at the end of a small background render,
    so the signal goes 3 s in: after loading (about 1 s), long before the end
    (a minute on an idle machine; the command ends half a second later).
    """
    target = out_dir / "shot.exr"
    target.write_bytes(PREVIOUS)
    started = time.monotonic()
    proc = spawn("render", CORNELL_BOX, "--engine", "cycles", "--resolution", "64x64",
                 "--samples", "20000", "-o", target, tmpdir=tmpdir_env)
    signal_at(proc, 3.0, signal.SIGINT, started)
    sent = time.monotonic()
    code, out, err = finish(proc)
    assert_stopped(code, out, err)
    assert time.monotonic() - sent < 3
    assert "CYCLES: 100%" not in err     # stopped mid-render
    assert target.read_bytes() == PREVIOUS
    assert_nothing_left(out_dir, tmpdir_env, {"shot.exr"})


# ---------------------------------------------------------------------------
# The scene is never an output
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("how", ["default output", "same path", "symbolic link", "hard link",
                                 "frame digits"])
def test_output_that_is_the_scene_is_refused(how, tmp_path, tmpdir_env):
    folder = tmp_path / "scenes"
    folder.mkdir()
    # A .blend named shot.exr: its default output, ./shot.exr, is itself.
    scene = folder / ("shot_0001.exr" if how == "frame digits" else "shot.exr")
    shutil.copyfile(LIGHT_POINT, scene)
    before = scene.read_bytes()
    args = ["render", scene, *SMALL_RENDER]
    if how == "same path":
        args += ["-o", scene]
    elif how == "symbolic link":
        (folder / "link.exr").symlink_to(scene)
        args += ["-o", folder / "link.exr"]
    elif how == "hard link":
        os.link(scene, folder / "hard.exr")
        args += ["-o", folder / "hard.exr"]
    elif how == "frame digits":   # known only once the file's frame (1) is read
        args += ["-o", folder / "shot_####.exr"]
    done = run_cli(*args, tmpdir=tmpdir_env, cwd=folder)
    assert_one_line_error(done, EXIT_BAD_INPUT, "is the scene file", "overwrite")
    assert scene.read_bytes() == before
    assert list(tmpdir_env.iterdir()) == []


def test_output_folder_check_uses_the_frame_number(out_dir, tmpdir_env):
    """'#' becomes the frame first; then shot_0001.exr is found to be a folder."""
    (out_dir / "shot_0001.exr").mkdir()
    for extra in ([], ["--frame", "1"]):
        done = run_cli("render", LIGHT_POINT, *SMALL_RENDER, *extra, "-o", out_dir / "shot_####.exr",
                       tmpdir=tmpdir_env)
        assert_one_line_error(done, EXIT_BAD_INPUT, f"output path is a folder: {out_dir / 'shot_0001.exr'}")


# ---------------------------------------------------------------------------
# compare
# ---------------------------------------------------------------------------

COMPARE = ["--resolution", "32x32", "--samples", "2000"]
REPORT_FILES = {"report.json": b'{"verdict": "agree"}\n', "mcengine.exr": PREVIOUS}


def previous_report(folder: Path) -> None:
    for name, data in REPORT_FILES.items():
        (folder / name).write_bytes(data)


@pytest.mark.parametrize("engine", ["MC Engine", "Cycles"])
def test_compare_interrupted_leaves_nothing(engine, out_dir, tmpdir_env):
    """Mid MC Engine render (its first progress line), or mid Cycles render: 0.3 s after
    MC Engine's second render ends, Cycles' first (1 to 3 s) is under way."""
    previous_report(out_dir)
    proc = spawn("compare", LIGHT_POINT, *COMPARE, "--out", out_dir, tmpdir=tmpdir_env)
    if engine == "MC Engine":
        lines = signal_at_line(proc, r"^\[1/4\] mcengine: \d+%", signal.SIGINT)
    else:
        lines = signal_at_line(proc, r"^\[2/4\] mcengine: 100%", 0)
        time.sleep(0.3)
        proc.send_signal(signal.SIGINT)
    sent = time.monotonic()
    code, out, err = finish(proc, lines)
    assert_stopped(code, out, err)
    assert time.monotonic() - sent < 3
    assert "[4/4]" not in err       # no render started after the signal, none finished
    for name, data in REPORT_FILES.items():
        assert (out_dir / name).read_bytes() == data
    assert_nothing_left(out_dir, tmpdir_env, set(REPORT_FILES))


def test_compare_does_not_create_its_folder_before_failing(tmp_path, tmpdir_env):
    out = tmp_path / "new" / "folder"
    done = run_cli("compare", LIGHT_POINT, "--resolution", "4x4", "--out", out, tmpdir=tmpdir_env)
    assert_one_line_error(done, EXIT_BAD_INPUT, "too small")
    assert not (tmp_path / "new").exists()


def test_compare_that_cannot_write_keeps_the_previous_report(out_dir, tmpdir_env, warm_kernels):
    """The renders fit in the file-size limit, side_by_side.png does not: nothing is replaced."""
    previous_report(out_dir)
    done = run_cli("compare", LIGHT_POINT, "--resolution", "16x16", "--samples", "8",
                   "--out", out_dir, tmpdir=tmpdir_env, preexec_fn=file_size_limit(24000))
    assert_one_line_error(done, EXIT_RENDER_FAILED, f"cannot write the files of {out_dir}")
    for name, data in REPORT_FILES.items():
        assert (out_dir / name).read_bytes() == data
    assert_nothing_left(out_dir, tmpdir_env, set(REPORT_FILES))


# ---------------------------------------------------------------------------
# What the command says, and how files are checked (in-process, no bpy)
# ---------------------------------------------------------------------------

TIME_LIMITED = """
import sys
import bpy
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
bpy.context.scene.cycles.time_limit = 1.0
bpy.ops.wm.save_as_mainfile(filepath=sys.argv[2])
"""


def test_summary_line_reports_the_samples_rendered_under_a_time_limit(out_dir, tmpdir_env):
    blend = out_dir / "limited.blend"
    made = subprocess.run([sys.executable, "-c", TIME_LIMITED, str(LIGHT_POINT), str(blend)],
                          capture_output=True, text=True, timeout=TIMEOUT)
    assert made.returncode == 0, made.stderr
    done = run_cli("render", blend, "--samples", "1000000", "--resolution", "16x16",
                   "-o", out_dir / "shot.exr", tmpdir=tmpdir_env)
    assert done.returncode == 0, done.stderr
    match = re.search(r"with MCENGINE, 16x16, (\d+) of 1000000 samples, in", done.stderr)
    assert match, done.stderr
    assert 0 < int(match[1]) < 1000000


def test_png_check_finds_every_kind_of_damage(tmp_path):
    import numpy as np

    from mcengine.imageio import write_png
    from mcengine_blender.batch.outputs import OutputError, verify, verify_png
    path = tmp_path / "a.png"
    write_png(path, np.linspace(0, 1, 24 * 16 * 4).reshape(16, 24, 4))
    assert verify_png(path) == (24, 16)
    good = path.read_bytes()
    damaged = {
        "empty": b"",
        "truncated": good[:len(good) // 2],
        "no IEND": good[:-12],
        "flipped bit": good[:60] + bytes([good[60] ^ 1]) + good[61:],
        "trailing bytes": good + b"\0",
        "not a PNG": b"GIF89a" + good[6:],
    }
    for what, data in damaged.items():
        path.write_bytes(data)
        with pytest.raises(OutputError):
            verify(path)
            pytest.fail(f"{what}: accepted")


def test_exr_check_finds_a_truncated_file(tmp_path):
    import numpy as np

    from mcengine.imageio import write_exr
    from mcengine_blender.batch.outputs import OutputError, verify
    path = tmp_path / "a.exr"
    write_exr(path, np.ones((16, 24, 4), np.float32))
    assert verify(path) == (24, 16)
    data = path.read_bytes()
    for size in (0, 10, len(data) // 2, len(data) - 1):
        path.write_bytes(data[:size])
        with pytest.raises(OutputError):
            verify(path)
