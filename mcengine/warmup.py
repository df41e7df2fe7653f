"""Compile the renderer's kernels ahead of the first render, into numba's disk cache.

A render loads its kernels from the cache in a fraction of a second once
they are compiled; compiling them takes minutes (``jit``).  The add-on runs
this module in a background process when it is enabled and the cache of the
installed sources is not ready, so that the first F12 finds them compiled::

    python -m mcengine.warmup        # prints the seconds taken; exit 0 when ready

It renders a few samples of one pixel of a tiny scene with each integrator
(``warm_up_scene``: every kernel of the integrator runs), the default one first
(every shader node and closure is compiled with the shader evaluator, whatever
the scene uses), and one of a scene with what else a render may compile
(``features_scene``: motion blur, a world and a mesh light whose radiance varies, true
displacement; and the export's MikkTSpace tangents),
then marks the cache ready (``jit.cache_is_ready``).  numba compiles on one core, so a
second process (``python -m mcengine.warmup --steps STEP...``) shares the work: while this
one compiles the procedural textures' node function, it compiles the evaluator's other node
functions and the closure nodes' (which this one then finds in the cache); once this one
has compiled the rest of the evaluator, which every integrator calls, the second compiles
the other integrators while this one compiles the default integrator and the features.  The
integrators that trace light paths beside camera paths run the default integrator's kernels
too, so the second process renders them once this one has put those in the cache.  A step
``wait:NAME`` waits for step NAME of this process; otherwise each process would compile
what the other is compiling.
Compiling every integrator here matters beyond the wait: numba compiling inside a
Blender process where Cycles has rendered can crash that process (seen with bpy
5.0.1: a segfault in the next render), so a user's first Whitted render after a
Cycles one must find its kernels compiled.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import numpy as np

from . import integrators, jit
from .denoise import Denoising
from .kernels.state import VIS_ALL, VIS_CAMERA
from .scene import (
    Camera,
    Film,
    Geometry,
    Integrator,
    Light,
    Link,
    Material,
    MotionBlur,
    ObjectMotion,
    SceneDescription,
    ShaderNode,
    World,
)

__all__ = ["warm_up_scene", "features_scene", "compile_kernels", "is_compiled", "main"]

FEATURES = "features"      # the warm-up step that renders ``features_scene``
EVALUATOR = "evaluator"    # the step that compiles the shader evaluator (packing a scene)
TEXTURE_NODES = "texture-nodes"    # steps that compile node functions alone
OTHER_NODES = "other-nodes"
WAIT = "wait:"             # a step that waits for the named step's marker
# The floor of both scenes: a 2 m square at z = 0 facing up, two triangles.
_FLOOR = np.array([[[-1, -1, 0], [1, -1, 0], [1, 1, 0]], [[-1, -1, 0], [1, 1, 0], [-1, 1, 0]]],
                  np.float64)


def _marker(integrator: str):
    return jit.cache_folder() / f"kernels-compiled-{integrator}"


def is_compiled(integrator: str) -> bool:
    """True once this module has compiled ``integrator``'s kernels and the features' for
    these sources (a render of it then only loads them, while the warm-up may go on with
    the other integrators)."""
    return _marker(integrator).exists() and _marker(FEATURES).exists()


def warm_up_scene(integrator: str = integrators.DEFAULT) -> SceneDescription:
    """A floor and a ceiling (``_warm_up_material``) with a point lamp of radius 0 between
    them, seen from below the ceiling by a one-pixel camera: a few samples of
    ``integrator``, with the denoiser's guide passes.  Every kernel of the integrator runs,
    so is compiled (``tests/core/test_warm_up_scene.py``): the lamp and the mirrors make
    Path + Light Tracing trace light paths (``kernels.light_tracing.prepare``), and of its
    64 light paths many reach the floor from the ceiling's mirror and join the camera."""
    ceiling = _FLOOR[:, ::-1] + (0.0, 0.0, 2.5)       # facing down
    camera = np.eye(4)
    camera[2, 3] = 2.2
    lamp = np.eye(4)
    lamp[:3, 3] = (0.5, 0.5, 2.0)
    samples = 64 if integrators.get(integrator).light_tracing else 1
    return SceneDescription(
        denoising=Denoising(enabled=True),     # the denoiser's guide passes (not the denoiser)
        geometry=Geometry.from_triangles(np.concatenate([_FLOOR, ceiling])),
        materials=[_warm_up_material()],
        lights=[Light(type="POINT", matrix_world=lamp, radius=0.0)],
        camera=Camera(matrix_world=camera), film=Film(width=1, height=1),
        integrator=Integrator(name=integrator, samples=samples))


def _warm_up_material() -> Material:
    """Diffuse, a mirror and a little transparency: caustics for light tracing, and shadow
    rays that test for transparent surfaces (``kernels.shadows.advance_shadows``)."""
    nodes, surface = Material(base_color=(0.4, 0.4, 0.4), mirror_color=(0.4, 0.4, 0.4)).graph()
    nodes.append(ShaderNode("BsdfTransparent", {"Color": (0.1, 0.1, 0.1)}))
    nodes.append(ShaderNode("AddShader", {"Shader": surface, "Shader_001": Link(len(nodes) - 1, "BSDF")}))
    return Material(nodes=nodes, surface=Link(len(nodes) - 1, "Shader"))


def features_scene() -> SceneDescription:
    """What a render may compile besides its integrator's kernels, rendered by the default
    integrator (``tests/core/test_warm_up_scene.py`` checks each runs): a world whose
    radiance varies (its importance map is baked, ``kernels.background``), a square that
    emits a gradient (a mesh light whose emission varies: ``kernels.shading.emission_estimates``
    weighs it) and moves while the shutter is open (motion blur: ``kernels.motion``) hidden
    from the camera (rays with visibility masks: ``kernels.intersect.ray_masks``), above
    the warm-up's floor, which a texture displaces (``kernels.displace``)."""
    lamp = _FLOOR[:, ::-1] * 0.2 + (0.0, 0.0, 1.0)         # facing down
    gradient = [ShaderNode("TexGradient")]
    emission = Material(name="lamp", nodes=gradient + [ShaderNode("Emission", {"Color": Link(0, "Color")})],
                        surface=Link(1, "Emission"))
    world = World(nodes=gradient + [ShaderNode("Background", {"Color": Link(0, "Color")})],
                  surface=Link(1, "Background"))
    steps = np.stack([np.eye(4)] * 3)
    steps[:, 0, 3] = (-0.1, 0.0, 0.1)
    camera = np.eye(4)
    camera[2, 3] = 0.5
    geometry = Geometry.from_triangles(np.concatenate([_FLOOR, lamp]), material_index=[0, 0, 1, 1],
                                       object_index=[0, 0, 1, 1], object_names=["floor", "lamp"])
    geometry.object_visibility = np.array([VIS_ALL, VIS_ALL & ~VIS_CAMERA], np.uint8)
    return SceneDescription(
        geometry=geometry,
        materials=[_displaced_material(), emission], world=world,
        motion_blur=MotionBlur(objects=[ObjectMotion(object=1, vertices=(6, 6), matrices=steps)]),
        camera=Camera(matrix_world=camera), film=Film(width=1, height=1),
        integrator=Integrator(samples=4))


def _displaced_material() -> Material:
    """Diffuse, displaced by a little of a gradient texture ('Displacement Only')."""
    nodes = [ShaderNode("TexGradient"), ShaderNode("Displacement", {"Height": Link(0, "Fac"), "Scale": 0.01}),
             ShaderNode("BsdfDiffuse")]
    return Material(name="floor", nodes=nodes, surface=Link(2, "BSDF"), displacement=Link(1, "Displacement"),
                    displacement_method="DISPLACEMENT")


def _compile(steps) -> None:
    """Run each step: render an integrator's ``warm_up_scene`` or ``features_scene``, compile
    the shader evaluator or some of its node functions, or wait (``WAIT``)."""
    from .packing import pack_scene
    from .session import RenderSession
    from .shaders import compile_node_functions
    for step in steps:
        if step.startswith(WAIT):
            _wait_for(step[len(WAIT):])
            continue
        if step == EVALUATOR:
            pack_scene(warm_up_scene())
        elif step in (TEXTURE_NODES, OTHER_NODES):
            compile_node_functions(_node_functions(step))
        else:
            scene = features_scene() if step == FEATURES else warm_up_scene(step)
            RenderSession(scene, threads=1).run()
            if step == FEATURES:
                _compile_tangents()
        _marker(step).touch()


def _compile_tangents() -> None:
    """The MikkTSpace tangents the export computes for normal maps (``kernels.tangents``), on
    one triangle."""
    from .kernels.tangents import mikktspace
    corners = np.eye(3, dtype=np.float32)
    mikktspace(corners, [(0, 1, 2)], np.ones((3, 3), np.float32), corners[:, :2])


def _node_functions(step: str) -> list:
    """The functions a ``*_NODES`` step compiles: the procedural textures' node function, or
    those that the evaluator calls before or after it (the other node functions and the
    closure nodes', in the order it compiles them)."""
    from .kernels.svm import (
        closure_nodes,
        color_nodes,
        image_nodes,
        input_nodes,
        math_nodes,
        normal_nodes,
        texture_nodes,
        vector_nodes,
    )
    if step == TEXTURE_NODES:
        return [texture_nodes.eval_texture_node]
    return [input_nodes.eval_input_node, math_nodes.eval_math_node,
            color_nodes.eval_color_node, image_nodes.eval_image_node,
            vector_nodes.eval_vector_node, normal_nodes.eval_normal_node,
            closure_nodes.principled, closure_nodes.glossy, closure_nodes.metallic,
            closure_nodes.glass]


def _runs_default(integrator: str) -> bool:
    """Whether ``integrator`` also runs the default integrator's kernels (light tracing
    traces the camera paths with the path tracer's)."""
    return integrator != integrators.DEFAULT and integrators.get(integrator).light_tracing


def _wait_for(step: str, poll: float = 0.5) -> None:
    """Until the process that started this one has done ``step`` (it ends this one if it
    stops first; if it is killed, this one ends too)."""
    parent = os.getppid()
    while not _marker(step).exists():
        if os.getppid() != parent:
            raise SystemExit("mcengine.warmup: the compile that started this one has ended")
        time.sleep(poll)


def compile_kernels() -> float:
    """Compile (or load) every integrator's kernels, the default one first, and the
    features'; seconds taken.

    A second process shares the work (the module's docstring says how); this one compiles
    the features after the path tracer (about 50 s)."""
    start = time.perf_counter()
    others = sorted(set(integrators.NAMES) - {integrators.DEFAULT})
    helper_steps = [OTHER_NODES, WAIT + EVALUATOR,
                    *[name for name in others if not _runs_default(name)],
                    WAIT + integrators.DEFAULT, *[name for name in others if _runs_default(name)]]
    helper = None
    try:
        helper = subprocess.Popen([sys.executable, "-m", "mcengine.warmup", "--steps",
                                   *helper_steps],
                                  stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
        _compile([TEXTURE_NODES, EVALUATOR, integrators.DEFAULT, FEATURES])
        if helper.wait() != 0:
            raise RuntimeError(f"compiling the kernels of {', '.join(others)} failed "
                               f"(exit status {helper.returncode})")
    finally:
        if helper is not None and helper.poll() is None:     # this process was stopped
            helper.terminate()
    jit.mark_cache_ready()
    return time.perf_counter() - start


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    # The add-on ends the background compile with SIGTERM: end the helper process too.
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    if args[:1] == ["--steps"]:
        _compile(args[1:])
        return 0
    if jit.cache_is_ready():
        print("mcengine: kernels already compiled")
        return 0
    seconds = compile_kernels()
    print(f"mcengine: kernels compiled in {seconds:.1f} s into {jit.cache_folder()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
