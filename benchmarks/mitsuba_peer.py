"""Mitsuba 3 as a peer in the benchmarks: the same exported scene, rendered by its LLVM variant.

The scene comes from MC Engine's own export (a :class:`mcengine.scene.SceneDescription`),
so Mitsuba gets the same triangles, materials, light, camera and resolution:

* geometry: one PLY mesh per material, triangles as exported (corner normals become
  vertex normals of unshared vertices; flat meshes use face normals);
* materials: a Diffuse BSDF, or a Principled BSDF reduced to Lambert (Specular IOR
  Level 0, no other lobe), becomes Mitsuba's ``diffuse``; any other Principled BSDF
  becomes Mitsuba's ``principled`` (base colour, metallic, roughness, and the F0 of
  Blender's IOR and Specular IOR Level). That one is only approximately Blender's BSDF:
  Disney's diffuse with retro-reflection instead of Lambert, single-scattering GGX
  without Blender's multiple-scattering compensation;
* lamps: area lights (square, rectangle, disk, ellipse) as one-sided ``rectangle`` or
  ``disk`` emitters of radiance P/(pi A), with a ``null`` BSDF so that rays pass
  through them as they pass through Blender's lamps; hidden from the camera
  (``hide_emitters``) as Blender hides lamps;
* world: a ``constant`` emitter of the world colour;
* camera: ``perspective`` with Blender's field of view and sensor fit, clipping planes;
* film: ``hdrfilm`` with a box filter (the cheapest reconstruction; the image mean does
  not depend on the filter);
* integrator: ``path`` with ``max_depth`` = max bounces + 2 (Mitsuba counts the camera
  segment and the light segment as depths), ``rr_depth`` = 3, ``independent`` sampler.

Anything else in the scene (point, spot or sun lamps, emissive meshes, textures, other
BSDF nodes, orthographic cameras, lens shift, border renders) is refused with a
:class:`PeerError` naming it, rather than rendered as a different scene.

Russian roulette is not the same in the two renderers, so the same number of paths is
not the same number of rays: Cycles (and MC Engine) decide at the third vertex and
later, before its light sample, with survival probability ``min(sqrt(max throughput), 1)``;
Mitsuba with ``rr_depth`` 3 decides after the third vertex's light sample and direction,
with ``min(max throughput * eta^2, 0.95)``. The later start makes up for the harsher rule:
on the Cornell box Mitsuba traces 5.35 rays per path, MC Engine 5.02 (``rr_depth`` 2
would start before Cycles does). ``rays_per_path`` replays Mitsuba's stopping rules on
the scene to count its rays per path.

Mitsuba runs in a child process (``python mitsuba_peer.py --serve SPEC``): drjit loads
its own libLLVM and Embree, which must not meet Blender's and numba's in one process.
The child reads one JSON request per line and answers one JSON line per render.

drjit's LLVM backend needs a libLLVM (``DRJIT_LIBLLVM_PATH``); LLVM 14 and 15 crash it
("Cannot select ... fminimum"). When the variable is unset, :func:`libllvm_candidates`
looks for the libLLVM that ships with a Rust toolchain and for system LLVMs of version
16 and newer.
"""
from __future__ import annotations

import glob
import json
import math
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

VARIANT = "llvm_ad_rgb"
RR_DEPTH = 3
PRINCIPLED_NOTE = ("Mitsuba's 'principled' plugin is only approximately Blender's Principled BSDF "
                   "(Disney diffuse with retro-reflection, single-scattering GGX)")
_LLVM_FLOOR = 16          # drjit crashes with older LLVMs
_SERVE = "--serve"


class PeerError(RuntimeError):
    """The Mitsuba peer cannot render this scene or cannot start; the message is one line."""


# -- libLLVM ---------------------------------------------------------------------------------
def libllvm_candidates() -> list[str]:
    """libLLVM shared libraries drjit may use, best first (the variable's value alone if set)."""
    given = os.environ.get("DRJIT_LIBLLVM_PATH")
    if given:
        return [given]
    found = []
    patterns = [os.path.expanduser("~/.rustup/toolchains/*/lib/libLLVM*.so*"),
                "/usr/lib/llvm-*/lib/libLLVM*.so*", "/usr/lib/x86_64-linux-gnu/libLLVM*.so*"]
    for pattern in patterns:
        for name in glob.glob(pattern):
            path = _resolve_linker_script(Path(name))
            version = _llvm_major(path.name)
            if path.is_file() and path.stat().st_size > (1 << 20) and version >= _LLVM_FLOOR:
                found.append((version, str(path)))
    found.sort(key=lambda vp: -vp[0])
    return list(dict.fromkeys(p for _v, p in found))


def _resolve_linker_script(path: Path) -> Path:
    """A ``libLLVM-*.so`` of a few bytes is a linker script ``INPUT(real name)``: follow it."""
    try:
        if path.stat().st_size < 4096:
            match = re.search(r"INPUT\(\s*([^\s)]+)", path.read_text(errors="replace"))
            if match:
                return path.parent / match.group(1)
    except OSError:
        pass
    return path


def _llvm_major(name: str) -> int:
    match = re.search(r"libLLVM[-.]?(?:so\.)?(\d+)", name)
    return int(match.group(1)) if match else 0


# -- scene ------------------------------------------------------------------------------------
def scene_spec(desc, folder: Path) -> tuple[dict, list]:
    """A Mitsuba scene dictionary (JSON-ready; matrices as nested lists under ``to_world``) for
    ``desc``, with its meshes written as PLY files into ``folder``; and notes for the output.

    Raises :class:`PeerError` for anything the translation does not cover.
    """
    folder = Path(folder)
    notes = []
    it = desc.integrator
    if it.name != "path":
        raise PeerError(f"integrator {it.name!r}: only path tracing has a Mitsuba counterpart")
    if it.clamp_direct or it.clamp_indirect or it.filter_glossy:
        raise PeerError("clamping and Filter Glossy have no Mitsuba counterpart; turn them off")
    if min(it.diffuse_bounces, it.glossy_bounces) < it.max_bounces:
        notes.append(f"Mitsuba has one bounce limit: {it.max_bounces} (the file's per-lobe limits "
                     f"{it.diffuse_bounces}/{it.glossy_bounces} are lower)")
    spec = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": int(it.max_bounces) + 2, "rr_depth": RR_DEPTH,
                       "hide_emitters": not any(li.visible_camera for li in desc.lights)},
        "sensor": _sensor(desc),
    }
    if max(desc.world.color) > 0.0:
        spec["world"] = {"type": "constant",
                         "radiance": {"type": "rgb", "value": [float(c) for c in desc.world.color]}}
    principled = False
    g = desc.geometry
    corner_normals = g.corner_normals()
    for k, material in enumerate(desc.materials):
        mask = g.material_index == k
        if not mask.any():
            continue
        bsdf = _bsdf(material)
        principled |= bsdf["type"] == "principled"
        flat = _write_ply(folder / f"mesh_{k}.ply", g.vertices, g.triangles[mask],
                           corner_normals[mask])
        spec[f"mesh_{k}"] = {"type": "ply", "filename": str(folder / f"mesh_{k}.ply"),
                             "face_normals": flat, "bsdf": bsdf}
    for k, li in enumerate(desc.lights):
        spec[f"lamp_{k}"] = _area_lamp(li)
    if principled:
        notes.append(PRINCIPLED_NOTE)
    return spec, notes


def _sensor(desc) -> dict:
    cam, film = desc.camera, desc.film
    if cam.type != "PERSP":
        raise PeerError(f"camera type {cam.type}: only perspective cameras are translated")
    if cam.shift_x or cam.shift_y:
        raise PeerError("camera lens shift is not translated")
    if film.region is not None or film.pixel_aspect_x != film.pixel_aspect_y:
        raise PeerError("border renders and non-square pixels are not translated")
    m = np.asarray(cam.matrix_world, float)
    axes = m[:3, :3] / np.linalg.norm(m[:3, :3], axis=0)
    # Blender's camera: +X right, +Y up, looking along -Z. Mitsuba's: +X left, +Y up, along +Z.
    to_world = np.eye(4)
    to_world[:3, :3] = axes @ np.diag([-1.0, 1.0, -1.0])
    to_world[:3, 3] = m[:3, 3]
    fit = cam.sensor_fit
    if fit == "AUTO":
        sensor, axis = cam.sensor_width, "larger"
    elif fit == "HORIZONTAL":
        sensor, axis = cam.sensor_width, "x"
    else:
        sensor, axis = cam.sensor_height, "y"
    return {
        "type": "perspective", "to_world": to_world.tolist(),
        "fov": math.degrees(2.0 * math.atan(0.5 * sensor / cam.lens)), "fov_axis": axis,
        "near_clip": float(cam.clip_start), "far_clip": float(cam.clip_end),
        "sampler": {"type": "independent", "sample_count": int(desc.integrator.samples)},
        "film": {"type": "hdrfilm", "width": int(film.width), "height": int(film.height),
                 "rfilter": {"type": "box"}, "pixel_format": "rgb"},
    }


def _bsdf(material) -> dict:
    from mcengine.kernels.svm.nodes import INPUTS

    nodes, surface = material.graph()
    if surface is None:
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}}
    node = nodes[surface.node]
    where = f"material '{material.name}'"
    if node.type not in ("BsdfDiffuse", "BsdfPrincipled"):
        raise PeerError(f"{where}: {node.type} has no Mitsuba counterpart in this benchmark")
    values = {name: default for name, _size, default in INPUTS[node.type]}
    for name, value in node.inputs.items():
        if not isinstance(value, (int, float, tuple, list)):
            raise PeerError(f"{where}: input '{name}' of {node.type} is linked (textures are not "
                            f"translated)")
        values[name] = value
    if node.type == "BsdfDiffuse":
        if values["Roughness"] > 1e-5:
            raise PeerError(f"{where}: Oren-Nayar roughness is not translated")
        return _diffuse(values["Color"])
    unsupported = [name for name in ("Subsurface Weight", "Transmission Weight", "Coat Weight",
                                     "Sheen Weight", "Emission Strength", "Anisotropic",
                                     "Diffuse Roughness", "Thin Film Thickness")
                   if values[name] != 0.0]
    if values["Alpha"] != 1.0:
        unsupported.append("Alpha")
    if unsupported:
        raise PeerError(f"{where}: Principled inputs {', '.join(unsupported)} are not translated")
    if values["Specular IOR Level"] == 0.0 and values["Metallic"] == 0.0:
        return _diffuse(values["Base Color"])      # Blender's Lambert form of the Principled BSDF
    ior = float(values["IOR"])
    f0 = ((ior - 1.0) / (ior + 1.0)) ** 2 * 2.0 * float(values["Specular IOR Level"])
    return {"type": "principled",
            "base_color": {"type": "rgb", "value": [float(c) for c in values["Base Color"][:3]]},
            "metallic": float(values["Metallic"]), "roughness": float(values["Roughness"]),
            # Mitsuba's F0 is 0.08 x specular (Disney's convention).
            "specular": f0 / 0.08}


def _diffuse(color) -> dict:
    return {"type": "diffuse", "reflectance": {"type": "rgb", "value": [float(c) for c in color[:3]]}}


def _area_lamp(li) -> dict:
    if li.type != "AREA":
        raise PeerError(f"lamp '{li.name}': {li.type} lamps are not translated (area lights only)")
    if li.spread < math.pi - 1e-3:
        raise PeerError(f"lamp '{li.name}': area spread is not translated")
    m = np.asarray(li.matrix_world, float)
    sx = float(li.size_x)
    sy = float(li.size_x if li.shape in ("SQUARE", "DISK") else li.size_y)
    to_world = m @ np.diag([0.5 * sx, 0.5 * sy, 1.0, 1.0])
    ellipse = li.shape in ("DISK", "ELLIPSE")
    area = float(np.linalg.norm(np.cross(to_world[:3, 0], to_world[:3, 1]))) * (
        math.pi if ellipse else 4.0)
    scale = 1.0 / (math.pi * (area if li.normalize else 1.0))
    return {"type": "disk" if ellipse else "rectangle", "to_world": to_world.tolist(),
            # Blender's area lights emit along local -Z; Mitsuba's shapes along their normal +Z.
            "flip_normals": True, "bsdf": {"type": "null"},
            "emitter": {"type": "area",
                        "radiance": {"type": "rgb", "value": [float(c) * scale for c in li.strength]}}}


def _write_ply(path: Path, vertices, triangles, normals) -> bool:
    """Write triangles as a binary PLY of unshared vertices; True if the normals are flat."""
    p = vertices[triangles].reshape(-1, 3).astype(np.float32)
    n = normals.reshape(-1, 3).astype(np.float32)
    t = len(triangles)
    face = np.cross(p[1::3] - p[0::3], p[2::3] - p[0::3])
    face /= np.maximum(np.linalg.norm(face, axis=1, keepdims=True), 1e-30)
    flat = bool(np.all(np.einsum("tcj,tj->tc", n.reshape(t, 3, 3), face) > 1.0 - 1e-5))
    props = ["x", "y", "z"] + ([] if flat else ["nx", "ny", "nz"])
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {3 * t}"]
    header += [f"property float {name}" for name in props]
    header += [f"element face {t}", "property list uchar int vertex_indices", "end_header", ""]
    verts = p if flat else np.concatenate([p, n], axis=1)
    faces = np.zeros(t, np.dtype([("n", "u1"), ("i", "<i4", 3)]))
    faces["n"] = 3
    faces["i"] = np.arange(3 * t, dtype=np.int32).reshape(t, 3)
    with open(path, "wb") as f:
        f.write("\n".join(header).encode())
        f.write(np.ascontiguousarray(verts, "<f4").tobytes())
        f.write(faces.tobytes())
    return flat


# -- the parent's side -----------------------------------------------------------------------
class MitsubaPeer:
    """A child process holding the loaded Mitsuba scene; :meth:`render` times one render.

    Use as a context manager; ``libllvm`` is the library the child runs with.
    """

    def __init__(self, spec: dict, folder: Path):
        self.spec_path = Path(folder) / "mitsuba_scene.json"
        self.spec_path.write_text(json.dumps(spec))
        self._child = None
        self.libllvm = None
        self.load_seconds = 0.0

    def __enter__(self) -> "MitsubaPeer":
        try:
            import mitsuba  # noqa: F401  (only to say clearly when it is missing)
        except ImportError:
            raise PeerError("Mitsuba 3 is not installed: pip install -e '.[bench]' (or pass "
                            "--no-mitsuba)") from None
        tried = []
        for lib in libllvm_candidates():
            reply = self._start(lib)
            if reply.get("ready"):
                self.libllvm, self.load_seconds = lib, reply["load_seconds"]
                return self
            tried.append(f"{lib}: {reply.get('error', 'no answer')}")
            self.close()
        where = "; ".join(tried) if tried else "none found"
        raise PeerError(f"drjit's LLVM backend did not start ({where}). Set DRJIT_LIBLLVM_PATH "
                        f"to a libLLVM.so of LLVM {_LLVM_FLOOR} or newer (LLVM 14/15 crash drjit; "
                        f"the lib/libLLVM.so.* of a Rust toolchain works)")

    def __exit__(self, *exc) -> None:
        self.close()

    def _start(self, lib: str) -> dict:
        env = dict(os.environ, DRJIT_LIBLLVM_PATH=lib)
        self._child = subprocess.Popen([sys.executable, __file__, _SERVE, str(self.spec_path)],
                                       stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                       stderr=subprocess.PIPE, text=True, env=env)
        return self._answer()

    def _answer(self) -> dict:
        line = self._child.stdout.readline()
        if not line:
            err = self._child.stderr.read().strip().splitlines()
            return {"error": err[-1] if err else f"exit status {self._child.wait()}"}
        return json.loads(line)

    def render(self, spp: int, seed: int, save: Path | None = None) -> dict:
        """Render ``spp`` samples per pixel: ``seconds`` (wall, image read back), ``compile``
        (drjit's code generation and LLVM compile within it), ``kernels`` (their run time)."""
        self._child.stdin.write(json.dumps({"spp": spp, "seed": seed,
                                            "save": str(save) if save else None}) + "\n")
        self._child.stdin.flush()
        reply = self._answer()
        if "error" in reply:
            raise PeerError(f"Mitsuba render failed: {reply['error']}")
        return reply

    def rays_per_path(self, spp: int = 4) -> float:
        """Rays per path Mitsuba's path integrator traces here (its stopping rules replayed)."""
        self._child.stdin.write(json.dumps({"count_rays": spp}) + "\n")
        self._child.stdin.flush()
        reply = self._answer()
        if "error" in reply:
            raise PeerError(f"Mitsuba ray count failed: {reply['error']}")
        return reply["rays_per_path"]

    def close(self) -> None:
        if self._child is not None:
            if self._child.poll() is None:
                self._child.stdin.close()
                try:
                    self._child.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    self._child.kill()
                    self._child.wait()
            self._child = None


# -- the child's side ------------------------------------------------------------------------
def _serve(spec_path: str) -> int:
    t0 = time.perf_counter()
    try:
        import drjit as dr
        import mitsuba as mi
        mi.set_variant(VARIANT)
        dr.set_flag(dr.JitFlag.KernelHistory, True)
        spec = json.loads(Path(spec_path).read_text())
        scene = mi.load_dict(_to_mitsuba(spec, mi))
        np.asarray(mi.render(scene, spp=1, seed=0))        # initialises the backend end to end
        dr.kernel_history()
    except Exception as exc:   # reported to the parent as one line
        _reply({"error": f"{type(exc).__name__}: {exc}".splitlines()[0]})
        return 1
    _reply({"ready": True, "load_seconds": time.perf_counter() - t0})
    for line in sys.stdin:
        request = json.loads(line)
        try:
            if "count_rays" in request:
                _reply({"rays_per_path": _count_rays(mi, dr, scene, spec["integrator"]["max_depth"],
                                                         request["count_rays"])})
                continue
            t = time.perf_counter()
            image = np.asarray(mi.render(scene, spp=request["spp"], seed=request["seed"]))
            seconds = time.perf_counter() - t
            history = dr.kernel_history()
            compile_ms = sum(k.get("codegen_time", 0.0) + k.get("backend_time", 0.0) for k in history)
            run_ms = sum(k.get("execution_time", 0.0) for k in history)
            if request.get("save"):
                np.save(request["save"], image)
            _reply({"seconds": seconds, "compile": compile_ms / 1e3, "kernels": run_ms / 1e3})
        except Exception as exc:
            _reply({"error": f"{type(exc).__name__}: {exc}".splitlines()[0]})
    return 0


def _reply(obj) -> None:
    sys.stdout.write(json.dumps(obj) + "\n")
    sys.stdout.flush()


def _to_mitsuba(spec, mi):
    """JSON scene -> Mitsuba's dictionary (``to_world`` lists become transforms)."""
    if isinstance(spec, dict):
        return {k: (mi.ScalarTransform4f(np.asarray(v, float)) if k == "to_world" else _to_mitsuba(v, mi))
                for k, v in spec.items()}
    return spec


def _count_rays(mi, dr, scene, max_depth: int, spp: int) -> float:
    """Mean rays per path of Mitsuba's ``path`` integrator on ``scene``, by replaying its
    control flow (src/integrators/path.cpp): a closest-hit ray per vertex reached, a shadow
    ray per vertex that samples an emitter (smooth BSDF, depth + 1 < max_depth), and Russian
    roulette after each vertex's BSDF sample once depth >= rr_depth."""
    sensor = scene.sensors()[0]
    res = sensor.film().crop_size()
    n = int(res[0] * res[1] * spp)
    sampler = mi.load_dict({"type": "independent"})
    sampler.seed(1, n)
    idx = dr.arange(mi.UInt32, n)
    pos = mi.Point2f(mi.Float(idx % int(res[0])), mi.Float((idx // int(res[0])) % int(res[1])))
    pos += sampler.next_2d()
    ray, _w = sensor.sample_ray(0.0, 0.5, pos / mi.ScalarVector2f(res), mi.Point2f(0.5))
    rays = mi.Float(1.0)            # the camera ray
    throughput = mi.Spectrum(1.0)
    eta = mi.Float(1.0)
    depth = mi.UInt32(0)
    si = scene.ray_intersect(ray)
    active = si.is_valid()
    ctx = mi.BSDFContext()
    for _ in range(max_depth + 1):
        if not dr.any(active):
            break
        active_next = active & (depth + 1 < max_depth)
        bsdf = si.bsdf(ray)
        smooth = mi.has_flag(bsdf.flags(), mi.BSDFFlags.Smooth)
        rays += dr.select(active_next & smooth, 1.0, 0.0)
        bs, weight = bsdf.sample(ctx, si, sampler.next_1d(), sampler.next_2d(), active_next)
        throughput[active_next] *= weight
        eta[active_next] *= bs.eta
        depth[active_next] += 1
        q = dr.minimum(dr.max(throughput) * eta * eta, 0.95)
        rr = depth >= RR_DEPTH
        survive = sampler.next_1d() < q
        throughput[active_next & rr] *= dr.rcp(q)
        active = active_next & (~rr | survive) & (dr.max(throughput) != 0.0)
        ray = si.spawn_ray(si.to_world(bs.wo))
        rays += dr.select(active, 1.0, 0.0)
        si = scene.ray_intersect(ray, active)
        active &= si.is_valid()
    return float(np.mean(np.asarray(rays)))


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == _SERVE:
        sys.exit(_serve(sys.argv[2]))
    sys.exit(f"usage: {Path(__file__).name} {_SERVE} SCENE.json (started by the benchmarks)")
