"""Paths per second of MC Engine and Cycles on the Cornell box, head to head.

Both engines render blend_scenes/cornell_box.blend through
``bpy.ops.render.render`` in this process, with the file's bounces (8), no
clamping, no denoising, no adaptive sampling, the same resolution and samples,
alternating engine by engine for several rounds (this machine's speed drifts,
so only same-run ratios mean something).  A "path" is one camera sample.

Two figures per engine:

* wall: pixels x samples / wall time of the whole render call (export, BVH,
  kernel loading and Cycles' scene sync included);
* marginal: the extra paths of a full render over a 1-sample render, divided by
  the extra time, which removes each engine's fixed start-up cost.

For MC Engine it also prints the share of worker time spent inside Embree,
rays per path, and the peak resident memory of the process (Blender included)
and of the renderer's own buffers.

With ``--materials principled`` every surface is the default Principled BSDF
(roughness 0.5, Specular IOR Level 0.5, Multiscatter GGX) of its base colour,
the material a Blender user starts from.

Run: python benchmarks/bench_cornell.py [--samples N] [--resolution N] [--rounds R]
                                        [--materials file|principled]
"""
from __future__ import annotations

import argparse
import resource
import statistics
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "blend_scenes" / "cornell_box.blend"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=128)
    ap.add_argument("--resolution", type=int, default=256)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--materials", choices=("file", "principled"), default="file",
                    help="the file's Lambert materials, or every surface the default Principled "
                         "BSDF of the same base colour (the light keeps its emission)")
    args = ap.parse_args(argv)

    import bpy  # noqa: F401  (Blender as a module)

    from mcengine_blender import engine
    from mcengine_blender.batch.render import ensure_registered, open_scene, render_scene
    from mcengine_blender.batch.settings import make_unbiased

    ensure_registered()
    sessions = []
    real_factory = engine.session_factory

    def recording_factory(desc, threads=None):
        s = real_factory(desc, threads=threads)
        sessions.append(s)
        return s

    engine.session_factory = recording_factory
    res = (args.resolution, args.resolution)
    pixels = args.resolution * args.resolution

    def run(bl_engine, samples):
        scene = open_scene(SCENE)
        make_unbiased(scene)
        if args.materials == "principled":
            to_default_principled(bpy)
        return render_scene(scene, bl_engine, samples=samples, seed=0, resolution=res)

    # Warm-up: load numba's kernel cache and Cycles' kernels once.
    run("mcengine", 1)
    run("cycles", 1)
    figures = {"MCENGINE": {"wall": [], "marginal": []}, "CYCLES": {"wall": [], "marginal": []}}
    our_stats = []
    for r in range(args.rounds):
        order = ("cycles", "mcengine") if r % 2 == 0 else ("mcengine", "cycles")
        for name in order:
            one = run(name, 1)
            full = run(name, args.samples)
            f = figures[full.engine]
            f["wall"].append(pixels * args.samples / full.seconds)
            f["marginal"].append(pixels * (args.samples - 1) / max(full.seconds - one.seconds, 1e-9))
            if full.engine == "MCENGINE":
                our_stats.append(sessions[-1].stats)
            print(f"round {r + 1}: {full.engine:9s} {args.samples} spp {full.seconds:6.2f} s "
                  f"(1 spp {one.seconds:5.2f} s)", flush=True)

    med = {e: {k: statistics.median(v) for k, v in f.items()} for e, f in figures.items()}
    st = our_stats[-1]
    session = sessions[-1]
    buffers = session.buffer_bytes
    print()
    print(f"Cornell box ({args.materials} materials) {args.resolution}x{args.resolution}, "
          f"{args.samples} spp, 8 bounces, medians of {args.rounds} rounds")
    print(f"{'':12s}{'wall Mpaths/s':>15s}{'marginal Mpaths/s':>20s}")
    for e in ("MCENGINE", "CYCLES"):
        print(f"{e:12s}{med[e]['wall'] / 1e6:15.2f}{med[e]['marginal'] / 1e6:20.2f}")
    print(f"{'ratio':12s}{med['MCENGINE']['wall'] / med['CYCLES']['wall']:15.2f}"
          f"{med['MCENGINE']['marginal'] / med['CYCLES']['marginal']:20.2f}")
    print(f"MC Engine: {st.rays / st.paths:.2f} rays/path, {st.rays_per_second / 1e6:.1f} Mrays/s, "
          f"Embree {100 * st.embree_share:.0f} % of worker time, kernels loaded in "
          f"{sessions[0].stats.time_kernels:.2f} s (first render of the process), "
          f"BVH {st.time_bvh * 1e3:.0f} ms")
    print(f"memory: renderer buffers {buffers / 2**20:.0f} MiB; process peak RSS "
          f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB (Blender included)")
    return 0


def to_default_principled(bpy) -> None:
    """Replace every Diffuse or Principled surface by a default Principled BSDF (roughness
    0.5, specular 0.5, Multiscatter GGX) of the same base colour."""
    for material in bpy.data.materials:
        tree = material.node_tree
        out = tree.get_output_node("CYCLES") if tree else None
        if out is None or not out.inputs["Surface"].is_linked:
            continue
        shader = out.inputs["Surface"].links[0].from_node
        color = {"ShaderNodeBsdfDiffuse": "Color", "ShaderNodeBsdfPrincipled": "Base Color"}.get(
            shader.bl_idname)
        if color is None:
            continue
        base = tuple(shader.inputs[color].default_value)
        node = tree.nodes.new("ShaderNodeBsdfPrincipled")
        node.inputs["Base Color"].default_value = base
        tree.links.new(node.outputs[0], out.inputs["Surface"])


if __name__ == "__main__":
    sys.exit(main())
