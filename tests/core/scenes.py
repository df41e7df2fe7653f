"""Small scenes with known answers, built directly as SceneDescriptions (no Blender)."""
from __future__ import annotations

import numpy as np

from mcengine.scene import Camera, Film, Geometry, Integrator, Light, Material, SceneDescription, World


def translation(x, y, z) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def look_down(height: float, x: float = 0.0, y: float = 0.0) -> np.ndarray:
    """Camera matrix at (x, y, height) looking down -Z (Blender's default camera axis)."""
    return translation(x, y, height)


def rotation_x(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    m = np.eye(4)
    m[1:3, 1:3] = [[c, -s], [s, c]]
    return m


def grid_plane(size: float, n: int = 1, z: float = 0.0, center=(0.0, 0.0)) -> np.ndarray:
    """(2 n^2, 3, 3) triangles of a square plane facing +Z, split into an n x n grid."""
    xs = np.linspace(-size / 2, size / 2, n + 1)
    tris = []
    for i in range(n):
        for j in range(n):
            a, b = (xs[i], xs[j]), (xs[i + 1], xs[j])
            c, d = (xs[i + 1], xs[j + 1]), (xs[i], xs[j + 1])
            tris.append([a, b, c])
            tris.append([a, c, d])
    t = np.array(tris, float)
    out = np.zeros(t.shape[:2] + (3,))
    out[..., 0] = t[..., 0] + center[0]
    out[..., 1] = t[..., 1] + center[1]
    out[..., 2] = z
    return out


def uv_sphere(radius: float, segments: int = 64, rings: int = 32, center=(0, 0, 0), inward=False):
    """Triangles and smooth corner normals of a UV sphere."""
    th = np.linspace(0, np.pi, rings + 1)
    ph = np.linspace(0, 2 * np.pi, segments + 1)
    def pt(i, j):
        return np.array([np.sin(th[i]) * np.cos(ph[j]), np.sin(th[i]) * np.sin(ph[j]), np.cos(th[i])])
    tris, norms = [], []
    for i in range(rings):
        for j in range(segments):
            a, b, c, d = pt(i, j), pt(i + 1, j), pt(i + 1, j + 1), pt(i, j + 1)
            for tri in ((a, b, c), (a, c, d)):
                if np.linalg.norm(np.cross(tri[1] - tri[0], tri[2] - tri[0])) < 1e-12:
                    continue
                tri = tri[::-1] if inward else tri
                tris.append([np.asarray(center) + radius * v for v in tri])
                norms.append([(-v if inward else v) for v in tri])
    return np.array(tris), np.array(norms)


def plane_scene(light: Light, *, size=0.02, albedo=1.0, samples=16, res=8, bounces=0,
                world=(0.0, 0.0, 0.0), filter_type="BOX", cam_height=5.0) -> SceneDescription:
    """A large white plane at z=0 seen from straight above by an orthographic camera.

    The camera covers a ``size`` x ``size`` patch around the origin, so every
    pixel sees (almost) the same point: the value is the plane's radiance there.
    """
    geo = Geometry.from_triangles(grid_plane(200.0))
    return SceneDescription(
        geometry=geo, materials=[Material(base_color=(albedo,) * 3)], lights=[light],
        camera=Camera(matrix_world=look_down(cam_height), type="ORTHO", ortho_scale=size,
                      clip_start=0.01, clip_end=100.0),
        world=World(color=world),
        film=Film(width=res, height=res, filter_type=filter_type, filter_width=1.0),
        integrator=Integrator(samples=samples, max_bounces=bounces, diffuse_bounces=max(bounces, 4)))


def inside_sphere_scene(*, albedo=0.5, emission=0.0, light=None, samples=32, res=16,
                        max_bounces=12, diffuse_bounces=128, segments=48) -> SceneDescription:
    """Camera at the centre of a closed unit sphere (diffuse, optionally emissive).

    The facets are flat-shaded: the furnace identities hold for any closed
    surface, but smooth shading normals lose the BSDF samples that point
    below the geometric surface (as in Cycles), a small energy loss.
    """
    tris, _ = uv_sphere(1.0, segments, segments // 2, inward=True)
    geo = Geometry.from_triangles(tris)
    return SceneDescription(
        geometry=geo,
        materials=[Material(base_color=(albedo,) * 3, emission=(emission,) * 3)],
        lights=[light] if light is not None else [],
        camera=Camera(matrix_world=np.eye(4), lens=20.0, clip_start=1e-3),
        world=World(color=(0.0, 0.0, 0.0)),
        film=Film(width=res, height=res),
        integrator=Integrator(samples=samples, max_bounces=max_bounces,
                              diffuse_bounces=diffuse_bounces))
