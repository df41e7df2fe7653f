"""Paths per second of MC Engine, Cycles and Mitsuba 3 on the Cornell box, head to head.

MC Engine and Cycles render blend_scenes/cornell_box.blend through
``bpy.ops.render.render`` in this process, with the file's bounces (8), no
clamping, no denoising, no adaptive sampling, the same resolution and samples.
Mitsuba 3 (``llvm_ad_rgb``, in a child process: see mitsuba_peer.py) renders the
scene MC Engine exported, so geometry, materials, light, camera and resolution
are the same.  Engines alternate render by render for several rounds (this
machine's speed drifts, so only same-run ratios mean something).  A "path" is
one camera sample.

Two figures per engine:

* wall: pixels x samples / wall time of the whole render call (export, BVH,
  kernel loading and Cycles' scene sync included; for Mitsuba the render call
  on the loaded scene);
* marginal: the extra paths of a full render over a 1-sample render, divided by
  the extra time, which removes each engine's fixed start-up cost.  Mitsuba's
  JIT compile is excluded: warm-up renders at both sample counts compile its
  kernels before the rounds, and what drjit's kernel history still counts as
  code generation in a timed render is subtracted.

It also prints rays per path (MC Engine's counters; Mitsuba's by replaying its
stopping rules, as its Russian roulette differs), for MC Engine the share of
worker time spent inside Embree and the peak resident memory of the process
(Blender included) and of the renderer's own buffers, and each engine's frame
mean, as a check that all rendered the same scene.

With ``--materials principled`` every surface is the default Principled BSDF
(roughness 0.5, Specular IOR Level 0.5, Multiscatter GGX) of its base colour,
the material a Blender user starts from (Mitsuba's ``principled`` plugin is
only approximately the same BSDF).  With ``--materials textured`` every surface is that
Principled BSDF with an image texture (256 x 256, 8-bit sRGB, packed) as Base Color and a
tangent-space normal map (256 x 256, Non-Color) through a Normal Map node, on each face's
0..1 UVs: what a textured asset costs per hit (Mitsuba is left out: its peer scene is built
from constant materials).

Mitsuba comes from the optional ``bench`` extra (``pip install -e '.[bench]'``);
drjit needs a libLLVM >= 16, found on its own or named by DRJIT_LIBLLVM_PATH.

MC Engine renders with ``--sampler`` (default ``sobol``, what a user gets; Mitsuba
and Cycles' path counts do not depend on it); ``benchmarks/bench_sampler.py``
compares the samplers' error per second.

Run: python benchmarks/bench_cornell.py [--samples N] [--resolution N] [--rounds R]
                                        [--materials file|principled|textured] [--no-mitsuba]
                                        [--sampler sobol|independent]
"""
from __future__ import annotations

import argparse
import contextlib
import resource
import statistics
import sys
import tempfile
from pathlib import Path

import mitsuba_peer
import numpy as np

from mcengine import samplers

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "blend_scenes" / "cornell_box.blend"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=128)
    ap.add_argument("--resolution", type=int, default=256)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--materials", choices=("file", "principled", "textured"), default="file",
                    help="the file's Lambert materials, or every surface the default Principled "
                         "BSDF of the same base colour (the light keeps its emission)")
    ap.add_argument("--sampler", choices=samplers.NAMES, default=samplers.DEFAULT,
                    help=f"MC Engine's sampler (default: {samplers.DEFAULT})")
    ap.add_argument("--no-mitsuba", action="store_true",
                    help="leave Mitsuba 3 out (it needs the 'bench' extra: pip install -e '.[bench]')")
    args = ap.parse_args(argv)
    args.no_mitsuba = args.no_mitsuba or args.materials == "textured"
    if not args.no_mitsuba:
        try:
            import mitsuba  # noqa: F401
        except ImportError:
            print("bench_cornell: Mitsuba 3 is not installed: pip install -e '.[bench]' "
                  "(or pass --no-mitsuba)", file=sys.stderr)
            return 2

    import bpy  # noqa: F401  (Blender as a module)

    from mcengine_blender import engine
    from mcengine_blender.batch.render import ensure_registered, open_scene, render_scene
    from mcengine_blender.batch.settings import make_unbiased

    ensure_registered()
    sessions, scenes = [], []
    real_factory = engine.session_factory

    def recording_factory(desc, threads=None):
        s = real_factory(desc, threads=threads)
        sessions.append(s)
        scenes.append(desc)
        return s

    engine.session_factory = recording_factory
    res = (args.resolution, args.resolution)
    pixels = args.resolution * args.resolution

    def run(bl_engine, samples):
        scene = open_scene(SCENE)
        make_unbiased(scene)
        scene.mcengine.sampler = samplers.get(args.sampler).enum_id
        if args.materials in ("principled", "textured"):
            to_default_principled(bpy)
        if args.materials == "textured":
            to_textured(bpy)
        return render_scene(scene, bl_engine, samples=samples, seed=0, resolution=res)

    # Warm-up: load numba's kernel cache and Cycles' kernels once.
    run("mcengine", 1)
    run("cycles", 1)
    with contextlib.ExitStack() as stack:
        peer = None
        if not args.no_mitsuba:
            folder = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="bench_mitsuba_")))
            try:
                spec, notes = mitsuba_peer.scene_spec(scenes[-1], folder)
                peer = stack.enter_context(mitsuba_peer.MitsubaPeer(spec, folder))
            except mitsuba_peer.PeerError as exc:
                print(f"bench_cornell: {exc}", file=sys.stderr)
                return 2
            warm = [peer.render(1, 0), peer.render(args.samples, 0)]
        engines = ["CYCLES", "MCENGINE"] + (["MITSUBA"] if peer else [])
        figures = {e: {"wall": [], "marginal": []} for e in engines}
        images, our_stats = {}, []
        for r in range(args.rounds):
            order = engines[r % len(engines):] + engines[:r % len(engines)]
            for name in order:
                if name == "MITSUBA":
                    save = folder / "mitsuba.npy"
                    one, full = peer.render(1, r + 1), peer.render(args.samples, r + 1, save)
                    # The kernels were compiled by the warm-up renders; what drjit still spends
                    # on tracing and code generation in a timed render is taken out.
                    t_one, t_full = (one["seconds"] - one["compile"], full["seconds"] - full["compile"])
                    images[name] = np.load(save)
                else:
                    one, full = run(name.lower(), 1), run(name.lower(), args.samples)
                    t_one, t_full = one.seconds, full.seconds
                    images[name] = full.image[..., :3]
                    if name == "MCENGINE":
                        our_stats.append(sessions[-1].stats)
                f = figures[name]
                f["wall"].append(pixels * args.samples / t_full)
                f["marginal"].append(pixels * (args.samples - 1) / max(t_full - t_one, 1e-9))
                print(f"round {r + 1}: {name:9s} {args.samples} spp {t_full:6.2f} s "
                      f"(1 spp {t_one:5.2f} s)", flush=True)
        mitsuba_rays = peer.rays_per_path() if peer else None

    med = {e: {k: statistics.median(v) for k, v in f.items()} for e, f in figures.items()}
    st = our_stats[-1]
    session = sessions[-1]
    buffers = session.buffer_bytes
    print()
    print(f"Cornell box ({args.materials} materials) {args.resolution}x{args.resolution}, "
          f"{args.samples} spp, 8 bounces, medians of {args.rounds} rounds, MC Engine's "
          f"sampler {args.sampler}")
    print(f"{'':12s}{'wall Mpaths/s':>15s}{'marginal Mpaths/s':>20s}{'rays/path':>12s}"
          f"{'marginal Mrays/s':>18s}  (Cycles: the same paths as MC Engine)")
    # Cycles traces the same light paths as MC Engine (same rules); its rays are not counted.
    rays = {"MCENGINE": st.rays / st.paths, "CYCLES": st.rays / st.paths, "MITSUBA": mitsuba_rays}
    for e in engines:
        print(f"{e:12s}{med[e]['wall'] / 1e6:15.2f}{med[e]['marginal'] / 1e6:20.2f}{rays[e]:12.2f}"
              f"{med[e]['marginal'] * rays[e] / 1e6:18.2f}")
    for other in engines[:1] + engines[2:]:
        print(f"{'MC / ' + other.lower():12s}{med['MCENGINE']['wall'] / med[other]['wall']:15.2f}"
              f"{med['MCENGINE']['marginal'] / med[other]['marginal']:20.2f}{'':12s}"
              f"{med['MCENGINE']['marginal'] * rays['MCENGINE'] / (med[other]['marginal'] * rays[other]):18.2f}")
    print(f"MC Engine: {st.rays / st.paths:.2f} rays/path, {st.rays_per_second / 1e6:.1f} Mrays/s, "
          f"Embree {100 * st.embree_share:.0f} % of worker time, kernels loaded in "
          f"{sessions[0].stats.time_kernels:.2f} s (first render of the process), "
          f"BVH {st.time_bvh * 1e3:.0f} ms")
    print(f"memory: renderer buffers {buffers / 2**20:.0f} MiB; process peak RSS "
          f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB (Blender included)")
    if peer:
        print(f"Mitsuba 3 {mitsuba_peer.VARIANT} (libLLVM {peer.libllvm}): scene loaded in "
              f"{peer.load_seconds:.2f} s; its wall time is the render call alone. JIT compile "
              f"excluded: warm-up renders at 1 and {args.samples} spp ({warm[0]['seconds']:.2f} s "
              f"and {warm[1]['seconds']:.2f} s) compiled both kernels (code generation and LLVM "
              f"{warm[0]['compile'] + warm[1]['compile']:.2f} s by drjit's kernel history; kernels "
              f"in drjit's disk cache load without compiling), and each timed render's own code "
              f"generation (tracing, milliseconds) is subtracted")
        print("Mitsuba: rays/path counted by replaying its path integrator's stopping rules. "
              "Its Russian roulette differs (after sampling at the third vertex, survival "
              "min(throughput, 0.95); Cycles and MC Engine: at the third vertex, "
              "min(sqrt(throughput), 1)), so compare Mrays/s as well as Mpaths/s")
        for note in notes:
            print(f"Mitsuba: {note}")
    print_agreement(images)
    return 0


def print_agreement(images: dict) -> None:
    """Frame means and the largest difference of 4x4 block means, against MC Engine's image:
    a check that every engine rendered the same scene (not a statistical test)."""
    ours = images["MCENGINE"]
    h, w = ours.shape[:2]

    def blocks(im):
        return im[:h // 4 * 4, :w // 4 * 4].reshape(4, h // 4, 4, w // 4, 3).mean(axis=(1, 3))

    print("image check (same scene?): frame mean RGB, and vs MC Engine the frame mean's "
          "difference and the largest 4x4-block difference")
    for name, im in images.items():
        mean = im.reshape(-1, 3).mean(axis=0)
        line = f"  {name:9s} mean ({mean[0]:.4f}, {mean[1]:.4f}, {mean[2]:.4f})"
        if name != "MCENGINE":
            rel = mean.sum() / ours.reshape(-1, 3).mean(axis=0).sum() - 1.0
            block = np.abs(blocks(im) - blocks(ours)).max() / blocks(ours).mean()
            line += f"  frame {100 * rel:+.1f} %, worst block {100 * block:.1f} % of the mean"
        print(line)


def _packed_image(bpy, name: str, pixels: np.ndarray, colorspace: str):
    h, w = pixels.shape[:2]
    image = bpy.data.images.new(name, w, h, alpha=True)
    image.colorspace_settings.name = colorspace
    image.pixels.foreach_set(np.ascontiguousarray(pixels, np.float32).ravel())
    image.pack()
    return image


def to_textured(bpy, size: int = 256) -> None:
    """Feed every Principled BSDF an image texture as Base Color and a normal map (tiles with
    bevelled edges), on UVs that map each face to 0..1."""
    y, x = (np.mgrid[0:size, 0:size] + 0.5) / size * 8.0         # 8 x 8 tiles
    fx, fy = x - np.floor(x) - 0.5, y - np.floor(y) - 0.5
    tile = (np.floor(x) + np.floor(y)) % 2
    albedo = np.stack([0.25 + 0.5 * tile, 0.3 + 0.3 * tile, 0.2 + 0.4 * (1 - tile),
                       np.ones_like(tile)], axis=-1)
    slope = 4.0 * np.clip(np.abs(np.stack([fx, fy])) - 0.35, 0.0, None) * np.sign(np.stack([fx, fy]))
    n = np.stack([-slope[0], -slope[1], np.ones_like(fx)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    normal = np.concatenate([0.5 + 0.5 * n, np.ones_like(tile)[..., None]], axis=-1)
    color_image = _packed_image(bpy, "bench_albedo", albedo, "sRGB")
    normal_image = _packed_image(bpy, "bench_normal", normal, "Non-Color")
    for ob in bpy.data.objects:
        if ob.type == "MESH" and not ob.data.uv_layers:
            ob.data.uv_layers.new(name="UVMap")
    for material in bpy.data.materials:
        tree = material.node_tree
        for node in list(tree.nodes) if tree else ():
            if node.bl_idname != "ShaderNodeBsdfPrincipled":
                continue
            tex = tree.nodes.new("ShaderNodeTexImage")
            tex.image = color_image
            tree.links.new(tex.outputs["Color"], node.inputs["Base Color"])
            ntex = tree.nodes.new("ShaderNodeTexImage")
            ntex.image = normal_image
            nmap = tree.nodes.new("ShaderNodeNormalMap")
            tree.links.new(ntex.outputs["Color"], nmap.inputs["Color"])
            tree.links.new(nmap.outputs["Normal"], node.inputs["Normal"])


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
