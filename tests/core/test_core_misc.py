"""Core boundaries: no Blender import, scene files, validation, image files, warps."""
import math

import numpy as np
import pytest

from mcengine.imageio import ImageError, read_exr, write_exr, write_png
from mcengine.kernels.sampling import disk_concentric, disk_polar, filter_offset, filter_table
from mcengine.scene import SceneDescription, SceneError

from .expect import chi2_uniform_disk, render
from .scenes import inside_sphere_scene


def test_saved_scene_renders_identically(tmp_path):
    scene = inside_sphere_scene(albedo=0.6, emission=0.4, samples=4, res=8)
    scene.warnings.append("example warning")
    path = tmp_path / "scene.npz"
    scene.save(path)
    loaded = SceneDescription.load(path)
    assert loaded.warnings == ["example warning"]
    assert np.array_equal(render(scene).image(), render(loaded).image())


def test_loading_garbage_is_a_scene_error(tmp_path):
    p = tmp_path / "x.npz"
    p.write_bytes(b"not a zip")
    with pytest.raises(SceneError, match="not a saved mcengine scene"):
        SceneDescription.load(p)


@pytest.mark.parametrize("mutate,message", [
    (lambda s: setattr(s.geometry, "vertices", s.geometry.vertices * np.nan), "NaN"),
    (lambda s: setattr(s.integrator, "samples", 0), "samples"),
    (lambda s: setattr(s.film, "region", (4, 4, 2, 8)), "region"),
    (lambda s: s.materials.__setitem__(0, type(s.materials[0])(base_color=(1, -1, 0))), "base_color"),
    (lambda s: setattr(s.camera, "type", "PANO"), "not supported"),
])
def test_validation_names_the_problem(mutate, message):
    scene = inside_sphere_scene(samples=1, res=8)
    mutate(scene)
    with pytest.raises(SceneError, match=message):
        scene.validate()


def test_exr_round_trip_and_png(tmp_path):
    img = np.random.default_rng(0).random((5, 7, 4)).astype(np.float32) * 10
    write_exr(tmp_path / "a.exr", img)
    assert np.array_equal(read_exr(tmp_path / "a.exr"), img)
    write_png(tmp_path / "a.png", img)
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ImageError, match="cannot write"):
        write_exr(tmp_path / "missing" / "a.exr", img)


def test_disk_sampling_is_uniform_and_the_naive_map_is_not():
    """The lecture's example: r = sqrt(u) is uniform on the disk, r = u crowds the centre."""
    from scipy.stats import chi2
    u = np.random.default_rng(3).random((200_000, 2))
    def crit(dof):
        return chi2.ppf(1 - 1e-4, dof)
    for warp in (disk_polar, disk_concentric):
        pts = np.array([warp(a, b) for a, b in u])
        stat, dof = chi2_uniform_disk(pts)
        assert stat < crit(dof), (warp.__name__, stat)
    naive = np.stack([u[:, 0] * np.cos(2 * math.pi * u[:, 1]), u[:, 0] * np.sin(2 * math.pi * u[:, 1])], 1)
    stat, dof = chi2_uniform_disk(naive)
    assert stat > 100 * crit(dof)


def test_blackman_harris_table_matches_cycles_edge_profile():
    # Cycles (cycles-conventions.md section 4): a vertical edge renders 0.1190 in
    # the pixel next to it with Blackman-Harris 1.5, and 0.2798 / 0.0354 with width 3.
    u = np.random.default_rng(5).random(400_000)
    for width, one, two in ((1.5, 0.1190, None), (3.0, 0.2798, 0.0354)):
        t = filter_table("BLACKMAN_HARRIS", width)
        off = np.array([filter_offset(t, x) for x in u])
        assert abs((off > 1).mean() - one) < 0.003
        if two is not None:
            assert abs((off > 2).mean() - two) < 0.002


def test_accounting_names_dropped_non_finite_samples_only_when_there_are_some():
    from mcengine.session import RenderStats
    stats = RenderStats(camera_rays=100, time_render=1.0)
    assert "non-finite" not in stats.accounting(10)
    stats.nonfinite = 1234
    assert stats.accounting(10).endswith(" | 1,234 non-finite samples dropped")


def test_the_default_uv_map_is_packed_without_a_copy():
    """The shaders' attribute array is the geometry's own UVs when there is nothing else to
    pack (a copy costs 92 MiB at 4M triangles); with a named attribute it holds both."""
    from mcengine.packing import pack_attributes
    from mcengine.scene import Geometry

    from .scenes import grid_plane

    geo = Geometry.from_triangles(grid_plane(2.0, n=4))
    geo.uvs = np.random.default_rng(0).random((geo.num_triangles, 3, 2)).astype(np.float32)
    layout, attr = pack_attributes(geo)
    assert np.shares_memory(attr, geo.uvs) and layout.offsets == {"": (0, 2)}
    geo.attributes = {"Col": np.ones((geo.num_triangles, 3, 4), np.float32)}
    layout, attr = pack_attributes(geo)
    assert attr.shape == (geo.num_triangles, 3, 6) and layout.offsets == {"": (0, 2), "Col": (2, 4)}
    np.testing.assert_array_equal(attr[:, :, :2], geo.uvs)
    # A named UV map equal to the default UVs (the same array, or equal values as a loaded
    # file gives them) is read from the default's columns; one that differs is packed.
    other = geo.uvs.copy()
    other[0, 0, 0] += 1.0
    geo.attributes = {"UVMap": geo.uvs, "Copy": geo.uvs.copy(), "Other": other}
    layout, attr = pack_attributes(geo)
    assert layout.offsets == {"": (0, 2), "UVMap": (0, 2), "Copy": (0, 2), "Other": (2, 2)}
    np.testing.assert_array_equal(attr[:, :, 2:4], other)
    geo.attributes = {"UVMap": geo.uvs}
    layout, attr = pack_attributes(geo)
    assert np.shares_memory(attr, geo.uvs) and layout.offsets == {"": (0, 2), "UVMap": (0, 2)}
