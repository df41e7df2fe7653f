"""Bad scene data gets a SceneError naming the problem, never a crash or a wrong image.

Covers what ``SceneDescription.validate`` must refuse (non-finite or out-of-range
values anywhere), what ``SceneDescription.load`` must survive (truncated,
foreign and crafted ``.npz`` files, including one that would decompress to
gigabytes), and the memory check that refuses a render too large to fit
before any work is done.
"""
from __future__ import annotations

import io
import math
import zipfile

import numpy as np
import pytest

from mcengine import memory
from mcengine.film import Film
from mcengine.kernels.state import alloc_scratch
from mcengine.scene import Geometry, Light, SceneDescription, SceneError
from mcengine.session import RenderSession, _Buffers

from .scenes import inside_sphere_scene, plane_scene, translation


def _scene():
    return plane_scene(Light(type="POINT", matrix_world=translation(0, 0, 2), strength=(100,) * 3))


NAN, INF = math.nan, math.inf


@pytest.mark.parametrize("where,attr,value", [
    ("film", "width", 10 ** 6), ("film", "exposure", NAN), ("film", "filter_width", 0.0),
    ("film", "pixel_aspect_x", 0.0), ("world", "color", (NAN, 0, 0)),
    ("world", "color", (INF, 0, 0)), ("camera", "lens", NAN), ("camera", "clip_end", INF),
    ("camera", "matrix_world", np.diag([0.0, 1, 1, 1])), ("camera", "sensor_fit", "DIAGONAL"),
    ("light", "radius", NAN), ("light", "radius", INF), ("light", "angle", NAN),
    ("light", "size_x", -1.0), ("light", "spot_size", 4.0), ("light", "spread", NAN),
    ("integrator", "samples", 1 << 30), ("integrator", "clamp_direct", NAN),
    ("integrator", "time_limit", -1.0),
])
def test_validation_refuses_non_finite_and_out_of_range_values(where, attr, value):
    scene = _scene()
    target = scene.lights[0] if where == "light" else getattr(scene, where)
    setattr(target, attr, value)
    with pytest.raises(SceneError, match=attr):
        scene.validate()


@pytest.mark.parametrize("offsets", [[[1.5, 0.0]], [[0.1, -0.2]], [[NAN, 0.0]], [[0.1, 0.0, 0.0]],
                                     [[0.1, 0.0], [0.1, 0.0]]])
def test_validation_refuses_shadow_terminator_offsets_blender_does_not_allow(offsets):
    """Blender keeps both offsets in [0, 1] (a Shading Offset of 2 would divide by zero)."""
    scene = _scene()
    assert scene.geometry.num_objects == 1
    scene.geometry.object_terminator = np.array(offsets)
    with pytest.raises(SceneError, match="object_terminator"):
        scene.validate()


def test_saved_scene_keeps_each_objects_terminator_offsets(tmp_path):
    scene = _scene()
    scene.geometry.object_terminator = np.array([[0.4, 0.7]])
    scene.save(tmp_path / "scene.npz")
    loaded = SceneDescription.load(tmp_path / "scene.npz")
    np.testing.assert_array_equal(loaded.geometry.terminator_offsets(), [[0.4, 0.7]])


def test_saved_scene_keeps_its_normal_table_and_reads_files_with_normals_per_corner(tmp_path):
    """A table of normals and each corner's row survive saving; a file of the former layout,
    a normal per corner and no index, loads to the same corner normals."""
    scene = _scene()
    g = scene.geometry
    corner = g.corner_normals()
    t = g.num_triangles
    g.normals = np.concatenate([np.zeros((1, 3), np.float32), np.unique(corner.reshape(-1, 3), axis=0)])
    g.normal_index = np.array([[np.flatnonzero((g.normals == c).all(axis=1))[0] for c in tri]
                               for tri in corner], np.int32)
    assert len(g.normals) < 3 * t
    np.testing.assert_array_equal(g.corner_normals(), corner)
    scene.save(tmp_path / "table.npz")
    loaded = SceneDescription.load(tmp_path / "table.npz").geometry
    np.testing.assert_array_equal(loaded.normals, g.normals)
    np.testing.assert_array_equal(loaded.normal_index, g.normal_index)
    data = (tmp_path / "table.npz").read_bytes()
    out = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(data)) as src, zipfile.ZipFile(out, "w") as dst:
        for info in src.infolist():
            if info.filename == "normals.npy":
                dst.writestr(info.filename, _npy(corner))
            elif info.filename != "normal_index.npy":
                dst.writestr(info.filename, src.read(info))
    old = _load(tmp_path, out.getvalue()).geometry
    assert old.normals.shape == (3 * t, 3)
    np.testing.assert_array_equal(old.corner_normals(), corner)


@pytest.mark.parametrize("index", [-1, 10 ** 6])
def test_validation_refuses_corners_whose_normal_row_does_not_exist(index):
    scene = _scene()
    scene.geometry.normal_index[0, 1] = index
    with pytest.raises(SceneError, match="normal_index"):
        scene.validate()


def _saved(tmp_path, scene=None) -> bytes:
    path = tmp_path / "scene.npz"
    (scene or inside_sphere_scene(samples=1, res=4)).save(path)
    return path.read_bytes()


def _replace_member(data: bytes, name: str, payload: bytes) -> bytes:
    out = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(data)) as src, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            dst.writestr(info.filename, payload if info.filename == name else src.read(info))
    return out.getvalue()


def _npy(array) -> bytes:
    buf = io.BytesIO()
    np.save(buf, array)
    return buf.getvalue()


def _load(tmp_path, data: bytes):
    path = tmp_path / "crafted.npz"
    path.write_bytes(data)
    return SceneDescription.load(path)


@pytest.mark.parametrize("case", ["truncated", "missing member", "meta not json", "meta wrong type",
                                  "unknown field", "wrong dtype", "wrong shape", "bad indices",
                                  "nan vertices", "not a zip"])
def test_loading_a_damaged_file_is_a_scene_error(tmp_path, case):
    data = _saved(tmp_path)
    if case == "truncated":
        data = data[:len(data) // 2]
    elif case == "missing member":
        out = io.BytesIO()
        with zipfile.ZipFile(io.BytesIO(data)) as src, zipfile.ZipFile(out, "w") as dst:
            for info in src.infolist():
                if info.filename != "normals.npy":
                    dst.writestr(info.filename, src.read(info))
        data = out.getvalue()
    elif case == "meta not json":
        data = _replace_member(data, "meta.npy", _npy(np.frombuffer(b"{oops", np.uint8)))
    elif case == "meta wrong type":
        data = _replace_member(data, "meta.npy", _npy(np.frombuffer(b'{"lights": 3}', np.uint8)))
    elif case == "unknown field":
        z = np.load(io.BytesIO(data))
        meta = bytes(z["meta"]).decode().replace('"name": "Light"', '"name": "Light", "bogus": 1')
        meta = meta.replace('"samples":', '"colour": 1, "samples":')
        data = _replace_member(data, "meta.npy", _npy(np.frombuffer(meta.encode(), np.uint8)))
    elif case == "wrong dtype":
        data = _replace_member(data, "triangles.npy", _npy(np.array([["a", "b", "c"]])))
    elif case == "wrong shape":
        data = _replace_member(data, "vertices.npy", _npy(np.zeros((4, 2), np.float32)))
    elif case == "bad indices":
        z = np.load(io.BytesIO(data))
        data = _replace_member(data, "triangles.npy", _npy(z["triangles"] + 10 ** 6))
    elif case == "nan vertices":
        z = np.load(io.BytesIO(data))
        data = _replace_member(data, "vertices.npy", _npy(z["vertices"] * np.nan))
    else:
        data = b"PK\x03\x04 but not really a zip file"
    with pytest.raises(SceneError):
        _load(tmp_path, data)


def test_loading_refuses_a_file_that_would_not_fit_in_memory(tmp_path, monkeypatch):
    """A small crafted file that decompresses to far more than the memory available (here
    64 MiB, so that the file is quick to make): refused from the array headers alone,
    before anything is decompressed."""
    data = _saved(tmp_path)
    big = np.zeros((10_000_000, 3), np.float32)    # 120 MB of zeros, ~120 kB deflated
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        with z.open("vertices.npy", "w", force_zip64=True) as f:
            np.lib.format.write_array_header_1_0(f, np.lib.format.header_data_from_array_1_0(big))
            chunk = bytes(1 << 24)
            for _ in range(big.nbytes // len(chunk)):
                f.write(chunk)
        with zipfile.ZipFile(io.BytesIO(data)) as src:
            for info in src.infolist():
                if info.filename != "vertices.npy":
                    z.writestr(info.filename, src.read(info))
    assert len(buf.getvalue()) < 1 << 20
    monkeypatch.setattr(memory, "available", lambda: 1 << 26)
    with pytest.raises(SceneError, match="memory"):
        _load(tmp_path, buf.getvalue())


def test_a_render_that_cannot_fit_is_refused_before_any_work(monkeypatch):
    scene = _scene()
    scene.film.width = scene.film.height = 16384
    monkeypatch.setattr(memory, "available", lambda: 5 << 30)
    with pytest.raises(SceneError, match=r"not enough memory: this render needs about 2\d\.\d\d GiB"):
        RenderSession(scene)


def test_memory_estimate_counts_what_a_render_allocates():
    scene = _scene()
    scene.film.width, scene.film.height = 640, 480
    session = RenderSession(scene, threads=2).run()
    film_arrays = sum(a.nbytes for a in session.film.arrays)
    assert memory.estimate(640 * 480, 0, 0).film == film_arrays + session.active.nbytes
    # bytes_for (used before allocating) equals what the two workers allocated for their
    # paths (the film's one-element render-pass array aside: this render has no passes);
    # each worker also holds a scratch copy of the scene's closures and registers.
    scratch = sum(a.nbytes for a in alloc_scratch(session.sc))
    assert session.film.passes.nbytes == 8
    assert session.buffer_bytes - film_arrays - 8 == 2 * (_Buffers.bytes_for(session.batch_size, False)
                                                          + scratch)


def test_film_read_out_is_exact_and_flips_without_copies():
    film = Film(5, 70_000 // 5 + 3)          # more than one read-out block
    rng = np.random.default_rng(1)
    film.sum[:] = rng.random(film.sum.shape)
    film.count[:] = rng.integers(0, 4, film.count.size)
    expect = (film.sum / np.maximum(film.count, 1)[:, None]).astype(np.float32)
    expect[:, :3] = (film.sum[:, :3] / np.maximum(film.count, 1)[:, None] * 2.0).astype(np.float32)
    img = film.image(2.0)
    np.testing.assert_array_equal(img.reshape(-1, 4), expect)
    flipped = film.image(2.0, bottom_up=True)
    assert flipped.flags.c_contiguous
    np.testing.assert_array_equal(flipped, img[::-1])
    plain = (film.sum / np.maximum(film.count, 1)[:, None]).astype(np.float32)
    np.testing.assert_array_equal(film.image().reshape(-1, 4), plain)


def test_materials_used_are_those_some_triangle_has():
    """Ascending, each once, whatever the order and gaps of the triangles' indices; none
    without triangles."""
    positions = np.zeros((6, 3, 3))
    g = Geometry.from_triangles(positions, material_index=np.array([4, 1, 4, 0, 1, 4]))
    assert g.materials_used() == [0, 1, 4]
    assert Geometry.from_triangles(positions[:1], material_index=np.array([2])).materials_used() == [2]
    assert Geometry().materials_used() == []
