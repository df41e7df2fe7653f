"""The warm-up's scenes (mcengine.warmup) run every kernel of each integrator and those a
scene's features call for, so the background compile leaves none to be compiled by a
user's first render, in a Blender process where Cycles may have rendered (numba compiling
there crashed it)."""
from __future__ import annotations

import functools

import numpy as np
import pytest
from numba import typeof, types

from mcengine import background, displacement, integrators, packing
from mcengine.kernels import classic, intersect, light_tracing, motion, path, shading, shadows, state
from mcengine.kernels.surface import SurfacePoint
from mcengine.session import RenderSession
from mcengine.shaders import evaluator_argument_types
from mcengine.warmup import (
    OTHER_NODES,
    TEXTURE_NODES,
    _node_functions,
    _runs_default,
    features_scene,
    warm_up_scene,
)


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


@pytest.mark.parametrize("name", sorted(set(integrators.NAMES) - {integrators.DEFAULT}))
def test_the_second_compile_process_waits_for_the_default_kernels_it_runs(name, monkeypatch):
    """The warm-up's second process renders an integrator that runs the default one's
    kernels only after waiting for the first to compile them (its step ``wait:path``, for
    the integrators ``_runs_default`` names): else both would compile them."""
    assert integrators.DEFAULT == "path"
    called = []
    for kernel in _kernels(path):
        def record(*args, _fn=getattr(path, kernel)):
            called.append(_fn)
            return _fn(*args)
        monkeypatch.setattr(path, kernel, record)
    RenderSession(warm_up_scene(name), threads=1).run()
    assert bool(called) == _runs_default(name)


def test_the_features_render_runs_the_kernels_of_what_it_shows(monkeypatch):
    """The world's importance bake, the mesh light's emission estimates, the moving
    objects' BVH and their intersection kernels, the rays' visibility masks (the lamp is
    hidden from the camera), the floor's true displacement: each
    compiled at a first render that needs it (about 2 minutes in all) if the warm-up did
    not run it."""
    called = set()
    for module, name in ((background, "bake_background"), (packing, "emission_estimates"),
                         (motion, "build_bvh"), (intersect, "moving_closest"),
                         (intersect, "moving_occluded"), (path, "ray_masks"),
                         (displacement, "displacement_offsets")):
        def record(*args, _fn=getattr(module, name), _key=name):
            called.add(_key)
            return _fn(*args)
        monkeypatch.setattr(module, name, record)
    RenderSession(features_scene(), threads=1).run()
    assert called == {"bake_background", "emission_estimates", "build_bvh", "moving_closest",
                      "moving_occluded", "ray_masks", "displacement_offsets"}


def test_functions_compiled_alone_get_the_evaluators_argument_types():
    """The warm-up compiles some of the evaluator's functions on their own
    (``compile_node_functions``), for the types that the shader evaluator then calls them
    with, so that it finds them in the cache: a worker's registers and closure list, indices
    and weights as the evaluator makes them (int64, float64), the ``ShadingData`` that
    ``shading_data`` builds and the scene's textures, or their addresses (``jit.by_ref``);
    other types would compile copies that nothing uses."""
    sc = packing.pack_scene(warm_up_scene()).sc
    scratch = state.alloc_scratch(sc)
    sp = SurfacePoint(*[0.5] * len(SurfacePoint._fields))
    sd = shading.shading_data.py_func(sp, 0.0, 0.0, -1.0, True, True, True, False, 3, 0.2, 0.3, 1,
                                      0, 1.0, (0, 0, 0, 0, 0), 0.0)
    index, weight = typeof(np.int64(0)), typeof(scratch.regs[0] * 1.0)
    real = {"code": index, "b": index, "c": index, "n": index, "regs": typeof(scratch.regs),
            "cl": typeof(scratch.cl), "mix_weight": weight, "w": weight,
            "cr": weight, "cg": weight, "cb": weight, "sd": typeof(sd),
            "sd_ref": types.CPointer(typeof(sd)), "tex_ref": types.CPointer(typeof(sc.tex))}
    functions = _node_functions(OTHER_NODES) + _node_functions(TEXTURE_NODES)
    assert {f.__name__ for f in functions} >= {"eval_input_node", "eval_image_node", "principled"}
    for function in functions:
        code = function.py_func.__code__
        expected = tuple(real[name] for name in code.co_varnames[:code.co_argcount])
        assert evaluator_argument_types(function) == expected, function.__name__
