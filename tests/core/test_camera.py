"""Camera rays against directions computed by hand from Blender's conventions.

Reference numbers (cycles-conventions.md section 4, measured with Cycles):
a 50 mm lens on a 36 mm sensor sees a half-width of 3.6 m at 10 m whatever
the aspect (AUTO fit uses the larger dimension); shift 0.1 moves the view
centre by 0.72 m at 10 m on both axes; VERTICAL fit with a 24 mm sensor
height gives a half-height of 2.4 m.
"""
import numpy as np
import pytest

from mcengine.kernels.camera import camera_rays
from mcengine.scene import Camera, Film

from .scenes import translation


def hit_plane(cam, film, rx, ry, depth=10.0):
    """Points where rays through raster (rx, ry) meet the plane at `depth` in front."""
    o, d, _ = camera_rays(cam, film, rx, ry)
    t = (depth - (-(o[:, 2] - cam.matrix_world[2, 3]))) / -d[:, 2]
    return o + t[:, None] * d


@pytest.mark.parametrize("w,h", [(64, 32), (32, 64)])
def test_auto_fit_uses_sensor_width_on_the_larger_dimension(w, h):
    cam = Camera(matrix_world=np.eye(4), lens=50.0, sensor_width=36.0)
    film = Film(width=w, height=h)
    p = hit_plane(cam, film, [0.0, w, w / 2], [h / 2, h / 2, 0.0])
    half_larger = 3.6
    if w > h:
        assert p[0, 0] == pytest.approx(-half_larger) and p[1, 0] == pytest.approx(half_larger)
        assert p[2, 1] == pytest.approx(half_larger * h / w)     # top edge: +Y
    else:
        assert p[2, 1] == pytest.approx(half_larger)
        assert p[1, 0] == pytest.approx(half_larger * w / h)


def test_vertical_fit_and_shift():
    cam = Camera(matrix_world=np.eye(4), lens=50.0, sensor_height=24.0, sensor_fit="VERTICAL")
    p = hit_plane(cam, Film(width=64, height=32), [32.0], [0.0])
    assert p[0, 1] == pytest.approx(2.4)
    cam = Camera(matrix_world=np.eye(4), lens=50.0, shift_x=0.1, shift_y=0.1)
    p = hit_plane(cam, Film(width=64, height=32), [32.0], [16.0])
    assert p[0, :2] == pytest.approx([0.72, 0.72])


def test_pixel_aspect_changes_the_fit():
    cam = Camera(matrix_world=np.eye(4), lens=50.0)
    # 32x32 pixels of aspect 2:1 are a 64:32 frame: the width gets the sensor.
    p = hit_plane(cam, Film(width=32, height=32, pixel_aspect_x=2.0), [32.0, 16.0], [16.0, 0.0])
    assert p[0, 0] == pytest.approx(3.6) and p[1, 1] == pytest.approx(1.8)


def test_camera_transform_and_clip_planes():
    # Camera at (1, 2, 3) rotated to look along +Y (Blender: rotate 90 deg about X).
    m = translation(1, 2, 3)
    m[:3, :3] = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]
    cam = Camera(matrix_world=m, lens=50.0, clip_start=0.5, clip_end=20.0)
    film = Film(width=100, height=100)
    o, d, tmax = camera_rays(cam, film, [50.0, 0.0], [50.0, 0.0])
    assert d[0] == pytest.approx([0, 1, 0])
    assert o[0] == pytest.approx([1, 2.5, 3])                 # on the near plane
    assert tmax[0] == pytest.approx(19.5)
    # Corner ray: its origin is on the near plane too (a plane, not a sphere).
    assert (o[1] - [1, 2, 3]) @ [0, 1, 0] == pytest.approx(0.5)
    assert (o[1] + tmax[1] * d[1] - [1, 2, 3]) @ [0, 1, 0] == pytest.approx(20.0)
    # Top-left corner ray goes left (-X) and up (+Z).
    assert d[1][0] < 0 and d[1][2] > 0
    assert np.linalg.norm(d, axis=1) == pytest.approx([1, 1])


def test_camera_scale_is_ignored():
    m = translation(0, 0, 0) @ np.diag([3.0, 3.0, 3.0, 1.0])
    a = camera_rays(Camera(matrix_world=m), Film(width=8, height=8), [0.0], [0.0])[1]
    b = camera_rays(Camera(matrix_world=np.eye(4)), Film(width=8, height=8), [0.0], [0.0])[1]
    assert a == pytest.approx(b)


def test_orthographic_camera():
    cam = Camera(matrix_world=translation(0, 0, 5), type="ORTHO", ortho_scale=4.0, clip_start=1.0)
    o, d, _ = camera_rays(cam, Film(width=40, height=20), [0.0, 40.0, 20.0], [10.0, 10.0, 0.0])
    assert d == pytest.approx(np.tile([0, 0, -1.0], (3, 1)))
    assert o[:, 0] == pytest.approx([-2.0, 2.0, 0.0])
    assert o[2, 1] == pytest.approx(1.0)
    assert o[:, 2] == pytest.approx([4.0, 4.0, 4.0])
