"""numpy's BLAS (OpenBLAS), kept to one thread in a process that renders with MC Engine.

OpenBLAS starts a pool of threads on the first matrix call and lets them spin-wait for work
afterwards. In a Blender process (where the ``bpy`` module or Blender's own threads are
running) every small ``numpy.linalg`` call then costs 5-12 ms instead of microseconds: the
4 x 4 inverses and determinants of a scene export and of the scene packing made up most of
a small render's fixed cost (45 ms against Cycles' 19 ms for the Cornell box at 64 x 64,
one sample; 16 ms with one BLAS thread), and spinning threads take cores from the render's
workers. MC Engine's matrices are all tiny, so one thread loses nothing.

``use_one_thread`` sets every OpenBLAS loaded in this process (found in /proc/self/maps:
numpy's wheel ships its own, with 64-bit integer symbols) to one thread, once; it is called
before a scene is exported or packed. It changes the setting for the whole process (other
add-ons' numpy included), which README states. Elsewhere than on Linux it does nothing.
"""
from __future__ import annotations

import ctypes
from pathlib import Path

_SUFFIXES = ("64_", "")        # numpy's OpenBLAS (ILP64, suffixed symbols), then a plain one
_done = False


def _libraries() -> list[tuple[str, ctypes.CDLL, str]]:
    """(path, library, symbol suffix) of every OpenBLAS mapped into this process."""
    maps = Path("/proc/self/maps")
    if not maps.exists():
        return []
    paths = sorted({line.split()[-1] for line in maps.read_text().splitlines()
                    if "openblas" in line.rsplit("/", 1)[-1].lower() and ".so" in line})
    found = []
    for path in paths:
        try:
            library = ctypes.CDLL(path)
        except OSError:
            continue
        for suffix in _SUFFIXES:
            if hasattr(library, f"openblas_set_num_threads{suffix}"):
                found.append((path, library, suffix))
                break
    return found


def thread_counts() -> dict[str, int]:
    """Threads each OpenBLAS loaded in this process uses, by the library's path."""
    return {path: int(getattr(library, f"openblas_get_num_threads{suffix}")())
            for path, library, suffix in _libraries()}


def use_one_thread() -> None:
    """Set every OpenBLAS loaded in this process to one thread (after the first call, a
    no-op)."""
    global _done
    if _done:
        return
    import numpy  # noqa: F401  (loads numpy's OpenBLAS, if it is not loaded yet)

    for _path, library, suffix in _libraries():
        getattr(library, f"openblas_set_num_threads{suffix}")(ctypes.c_int(1))
    _done = True
