"""Suite-wide pytest settings: markers, and the kernels compiled before Blender tests
(fixtures live next to their tests)."""
import fcntl
import hashlib
import subprocess
import sys
import tempfile
from pathlib import Path

# Test folders whose tests render with Cycles and MC Engine in one Blender process (in-process
# bpy, or the command line's own process).
_BLENDER_FOLDERS = {"addon", "cli", "nodes", "fidelity"}


def pytest_configure(config):
    config.addinivalue_line(
        "markers",
        "slow: takes minutes (e.g. builds and installs the Blender extension); left out of "
        "tasks.py test's default run (CI's), run with -m slow or -m ''")


def pytest_collection_finish(session):
    """Compile every integrator's kernels in a separate process (``python -m mcengine.warmup``;
    seconds once the cache is ready) before tests that render in Blender: numba compiling in
    a process where Cycles has rendered crashed it (a segfault in ``bpy.ops.render.render``
    on a fresh clone's cold cache).  Here, not in a fixture, so no test's timeout counts the
    minutes of a cold compile.  The workers of a parallel run (pytest-xdist, as ``tasks.py
    test`` runs the suite) take turns: the first compiles, the others then find the cache
    ready, rather than compiling the same kernels at the same time."""
    if session.config.option.collectonly:
        return
    root = session.config.rootpath
    if any(_BLENDER_FOLDERS & set(item.path.relative_to(root).parts) for item in session.items):
        key = hashlib.sha256(str(root).encode()).hexdigest()[:16]
        with open(Path(tempfile.gettempdir()) / f"mcengine-tests-warmup-{key}.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)         # released when the file is closed
            subprocess.run([sys.executable, "-m", "mcengine.warmup"], check=True,
                           stdout=subprocess.DEVNULL)
