"""How soon the first F12 of a Blender session shows pixels (issue 11's first-render goal).

Runs in a fresh process, as Blender does after a start: imports the add-on, opens
blend_scenes/cornell_box.blend and renders 1 sample at 256 x 256 with MC Engine, then
prints the time from F12 to the end of that sample and the time spent loading (or
compiling) the kernels.  Run it once after ``python -m mcengine.warmup`` (what the add-on
starts in the background when enabled) to see the warm-cache figure, and with an empty
cache (``NUMBA_CACHE_DIR=$(mktemp -d)``) to see what the warm-up saves.

Run: python benchmarks/bench_first_render.py
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def main() -> int:
    t0 = time.perf_counter()
    import bpy  # noqa: F401  (Blender as a module)

    from mcengine_blender import engine
    from mcengine_blender.batch.render import ensure_registered, open_scene, render_scene
    ensure_registered()
    sessions = []
    real_factory = engine.session_factory

    def recording_factory(desc, threads=None):
        session = real_factory(desc, threads=threads)
        sessions.append(session)
        return session

    engine.session_factory = recording_factory
    scene = open_scene(REPO / "blend_scenes" / "cornell_box.blend")
    t1 = time.perf_counter()
    render_scene(scene, "mcengine", samples=1, resolution=(256, 256))
    t2 = time.perf_counter()
    print(f"start-up and file {t1 - t0:.2f} s; F12 to the first sample {t2 - t1:.2f} s "
          f"(kernels loaded or compiled in {sessions[0].stats.time_kernels:.2f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
