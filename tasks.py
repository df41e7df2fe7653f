"""Project tasks: set up the environment and run a job in it.

    python3.11 tasks.py demo        render blend_scenes/cornell_box.blend with MC Engine and Cycles
    python3.11 tasks.py test [ARGS] run the test suite (ARGS go to pytest) in two worker
                                    processes (-n 0: in this one); tests marked slow
                                    (minutes each) only with -m slow, or all with -m ''
    python3.11 tasks.py extension   build the Blender extension zip (dist/extension/)

Needs only Python 3.11 (bpy 5.0.1, Blender 5.0 as a module, exists for 3.11 only)
and the standard library.  The first run creates ``.venv`` in the repository and
installs the project into it (``pip install -e .[test]``, which downloads bpy);
later runs skip the install unless pyproject.toml, setup.py or the set of packages
changed (a hash of them and the repository's path is kept in
``.venv/mcengine-install.sha256``).
The job then runs with the venv's Python; the exit status is the job's.

Numba's on-disk JIT cache (``cache=True``) lives next to the sources in this
editable install.  It is reused between runs of the same checkout; a fresh clone
starts cold, because numba keys cache entries on the source files' path and
modification time.
"""
from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import venv
from pathlib import Path
from typing import NoReturn

REPO = Path(__file__).resolve().parent
VENV = REPO / ".venv"
VENV_PYTHON = VENV / "bin" / "python"
INSTALL_STAMP = VENV / "mcengine-install.sha256"
# Files whose change means the installed environment may be out of date.
INSTALL_INPUTS = ("pyproject.toml", "setup.py")
# The editable install records which folders are packages; adding or removing an
# __init__.py under these needs a reinstall.
PACKAGE_ROOTS = ("mcengine", "addon")
REQUIRED_PYTHON = (3, 11)

DEMO_SCENE = REPO / "blend_scenes" / "cornell_box.blend"
DEMO_OUT = REPO / "out" / "demo"
DEMO_ENGINES = ("mcengine", "cycles")


def say(message: str) -> None:
    print(f"tasks.py: {message}", file=sys.stderr, flush=True)


def fail(message: str, code: int = 1) -> NoReturn:
    say(f"error: {message}")
    sys.exit(code)


def venv_python_version() -> tuple[int, int] | None:
    """(major, minor) of the venv's Python, or None if there is no working venv."""
    if not VENV_PYTHON.exists():
        return None
    try:
        done = subprocess.run(
            [str(VENV_PYTHON), "-c", "import sys; print(*sys.version_info[:2])"],
            capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return None
    if done.returncode != 0:
        return None
    major, minor = map(int, done.stdout.split())
    return major, minor


def install_hash() -> str:
    """Hash of what the installed environment depends on (see INSTALL_INPUTS, PACKAGE_ROOTS)."""
    digest = hashlib.sha256(str(REPO).encode())
    for name in INSTALL_INPUTS:
        path = REPO / name
        digest.update(name.encode())
        digest.update(path.read_bytes() if path.exists() else b"")
    for root in PACKAGE_ROOTS:
        for init in sorted((REPO / root).rglob("__init__.py")):
            digest.update(str(init.relative_to(REPO)).encode())
    return digest.hexdigest()


def ensure_environment() -> None:
    """Create .venv with Python 3.11 and install the project if anything changed."""
    found = venv_python_version()
    if found != REQUIRED_PYTHON:
        why = "missing" if found is None else f"has Python {found[0]}.{found[1]}"
        say(f"creating {VENV.relative_to(REPO)} ({why})")
        venv.EnvBuilder(with_pip=True, clear=True).create(VENV)
    wanted = install_hash()
    if INSTALL_STAMP.exists() and INSTALL_STAMP.read_text().strip() == wanted:
        return
    say("installing mcengine and its dependencies into .venv (the first run downloads bpy, several hundred MB)")
    pip = [str(VENV_PYTHON), "-m", "pip", "--disable-pip-version-check"]
    done = subprocess.run([*pip, "install", "--quiet", "--progress-bar", "off", "-e", f"{REPO}[test]"],
                          cwd=REPO)
    if done.returncode != 0:
        fail("pip install failed (see its output above)")
    INSTALL_STAMP.write_text(wanted + "\n")


def venv_env() -> dict[str, str]:
    env = dict(os.environ)
    env["VIRTUAL_ENV"] = str(VENV)
    env["PATH"] = f"{VENV / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    env.pop("PYTHONHOME", None)
    return env


def run_in_venv(command: list[str]) -> int:
    """Run ``command`` (a program in .venv/bin and its arguments) from the repository root."""
    program = str(VENV / "bin" / command[0])
    return subprocess.run([program, *command[1:]], cwd=REPO, env=venv_env()).returncode


def job_test(extra: list[str]) -> int:
    # The default run (CI's) leaves out the tests marked slow, unless ARGS choose markers,
    # and runs the tests in two worker processes (pytest-xdist), one per core of CI's
    # machine, each test file in one worker (its module fixtures render once), unless ARGS
    # choose the workers (-n 0: none).
    markers = [] if any(a == "-m" or a.startswith("-m") for a in extra) else ["-m", "not slow"]
    workers = ([] if any(a.startswith(("-n", "--numprocesses", "--dist")) for a in extra)
               else ["-n", "2", "--dist", "loadfile"])
    return run_in_venv(["python", "-m", "pytest", "-q", *markers, *workers, *extra])


def job_demo(extra: list[str]) -> int:
    if extra:
        fail("demo takes no arguments", 2)
    if not DEMO_SCENE.is_file():
        fail(f"demo scene missing: {DEMO_SCENE.relative_to(REPO)}")
    DEMO_OUT.mkdir(parents=True, exist_ok=True)
    written = []
    for engine in DEMO_ENGINES:
        say(f"rendering {DEMO_SCENE.relative_to(REPO)} with {engine} (samples and resolution from the file)")
        outputs = [DEMO_OUT / f"{engine}.exr", DEMO_OUT / f"{engine}.png"]
        command = ["mcengine", "render", str(DEMO_SCENE), "--engine", engine]
        for output in outputs:
            command += ["-o", str(output)]
        code = run_in_venv(command)
        if code != 0:
            return code
        written += outputs
    say("wrote " + ", ".join(str(path.relative_to(REPO)) for path in written))
    return 0


def job_extension(extra: list[str]) -> int:
    return run_in_venv(["python", "-m", "tools.build_extension", *extra])


JOBS = {"demo": job_demo, "test": job_test, "extension": job_extension}


def main(argv: list[str]) -> int:
    if not argv or argv[0] not in JOBS:
        fail(f"usage: python3.11 tasks.py {{{'|'.join(JOBS)}}} [args]", 2)
    if sys.version_info[:2] != REQUIRED_PYTHON:
        fail(f"run this with Python 3.11 (bpy 5.0.1 exists only for 3.11), not {sys.version.split()[0]}", 2)
    ensure_environment()
    return JOBS[argv[0]](argv[1:])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
