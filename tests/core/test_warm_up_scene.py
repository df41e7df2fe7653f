"""The warm-up's scene (mcengine.warmup) runs every kernel of each integrator, so the
background compile leaves none to be compiled by a user's first render, in a Blender
process where Cycles may have rendered (numba compiling there crashed it)."""
from __future__ import annotations

import functools

import pytest

from mcengine import integrators
from mcengine.kernels import classic, light_tracing, path, shadows
from mcengine.session import RenderSession
from mcengine.warmup import warm_up_scene


def _kernels(module) -> list[str]:
    """Names of the stage kernels (``jit.kernel``: released GIL) defined in ``module``."""
    return [name for name, value in vars(module).items()
            if getattr(value, "targetoptions", {}).get("nogil")
            and value.py_func.__module__ == module.__name__]


@pytest.mark.parametrize("name", integrators.NAMES)
def test_the_warm_up_render_runs_every_kernel_of_the_integrator(name, monkeypatch):
    info = integrators.get(name)
    modules = [light_tracing] if info.light_tracing else []
    modules += [path if info.kernel_code == 0 else classic, shadows]    # as RenderSession._classic
    called = set()
    expected = set()
    for module in modules:
        for kernel in _kernels(module):
            expected.add(f"{module.__name__}.{kernel}")

            def record(*args, _fn=getattr(module, kernel), _key=f"{module.__name__}.{kernel}"):
                called.add(_key)
                return _fn(*args)
            monkeypatch.setattr(module, kernel, functools.wraps(getattr(module, kernel))(record))
    assert len(expected) >= 4
    RenderSession(warm_up_scene(name), threads=1).run()
    assert called == expected, f"not run: {sorted(expected - called)}"
