"""The Ambient Occlusion node (kernels/svm/ao.py) against closed forms: a point on a floor
beside a wall.  Against Cycles: blend_scenes/material_bevel_ao in the fidelity suite, and the
discrimination case that leaves its AO out (tests/fidelity/test_discrimination.py).

Cosine-distributed directions project to points uniform on the unit disk, so the share of
them that a wall at distance a meets within a distance D is a segment of the disk: with
c = a / D, about the floor's normal (the wall stands across half of the directions) it is
(acos c - c sqrt(1 - c^2)) / pi, about the normal facing the wall 1 - c^2."""
from __future__ import annotations

import math

import numpy as np
import pytest

from mcengine.kernels.sampling import node_key
from mcengine.kernels.state import VIS_ALL, VIS_CAMERA, VIS_SHADOW
from mcengine.kernels.subsurface import build_local_bvh
from mcengine.kernels.svm import OBJ_STRIDE, ShadingData
from mcengine.kernels.svm.ao import ao_node
from mcengine.kernels.svm.nodes import OFFSETS
from mcengine.scene import Geometry, Link, Material, ShaderNode
from mcengine.session import RenderSession
from mcengine.shaders import NO_TEXTURES

from .expect import assert_mean

WALL = 1.0       # the wall's distance from the point (along +x)
KEYS = 400       # shading points averaged (16 rays each)
_IN = OFFSETS["AmbientOcclusion"]
_OUT = 16        # first output register: Color (3), then AO


def _scene():
    """A 100 m floor quad at z = 0 (object 0) and a 100 m wall at x = WALL facing -x (object
    1), as triangles; the point lies on the floor's first triangle, off its diagonal."""
    verts = np.array([(-50, -50, 0), (50, -50, 0), (50, 50, 0), (-50, 50, 0),
                      (WALL, -50, -50), (WALL, 50, -50), (WALL, 50, 50), (WALL, -50, 50)], float)
    tris = np.array([(0, 1, 2), (0, 2, 3), (4, 7, 6), (4, 6, 5)], np.int32)
    normals = np.array([(0, 0, 1), (-1, 0, 0)], np.float32)      # the floor's and the wall's
    index = np.repeat(np.array([0, 0, 1, 1], np.int32)[:, None], 3, axis=1)
    tri_object = np.array([0, 0, 1, 1], np.int32)
    tex = NO_TEXTURES._replace(normals=normals, normal_index=index, tri_object=tri_object,
                               objects=np.zeros((2, OBJ_STRIDE)))
    local = build_local_bvh(verts, tris, tri_object, 2, [0], scene_ids=np.arange(4, dtype=np.int32))
    return verts, tris, tex, local


def _point(key, min_pdf=math.inf):
    """A camera ray's shading point on the floor at (0, -20, 0), normal +z (triangle 0)."""
    return ShadingData(0.0, -20.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, False, True,
                       True, True, False, 0, 0.0, 0.0, 0, 0, 1.0, 0, 0, 0, 0, 0, 0.0,
                       np.uint64(node_key(np.uint64(777), key)), float(min_pdf))


def _ao(distance=2.0, normal=(0.0, 0.0, 0.0), inside=False, only_local=False, global_distance=-1.0,
        min_pdf=math.inf, keys=KEYS):
    """Mean AO and Color outputs over ``keys`` shading points."""
    verts, tris, tex, local = _scene()
    regs = np.zeros(_OUT + 4)
    regs[_IN["Color"]:_IN["Color"] + 3] = (0.2, 0.5, 1.0)
    regs[_IN["Distance"]] = distance
    regs[_IN["Normal"]:_IN["Normal"] + 3] = normal
    regs[_IN["prop:samples"]] = 16
    regs[_IN["prop:inside"]] = float(inside)
    regs[_IN["prop:only_local"]] = float(only_local)
    regs[_IN["prop:global_distance"]] = global_distance
    ao = []
    for k in range(keys):
        ao_node(regs, 0, _OUT, _point(k, min_pdf), tex, verts, tris, local)
        assert regs[_OUT:_OUT + 3] == pytest.approx(regs[_OUT + 3] * np.array([0.2, 0.5, 1.0]))
        ao.append(regs[_OUT + 3])
    return float(np.mean(ao)), float(np.std(ao) / math.sqrt(keys))


def _segment(c):
    return (math.acos(c) - c * math.sqrt(1.0 - c * c)) / math.pi


@pytest.mark.parametrize("distance,global_distance", [(2.0, -1.0), (1.25, -1.0), (0.0, 4.0)])
def test_a_wall_beside_the_point_occludes_a_segment_of_the_disk(distance, global_distance):
    """About the floor's normal; a Distance of 0 takes the world's AO distance (4 m)."""
    c = WALL / (distance if global_distance < 0.0 else global_distance)
    mean, err = _ao(distance, global_distance=global_distance)
    assert mean == pytest.approx(1.0 - _segment(c), abs=max(5.0 * err, 2e-3))


def test_facing_the_wall_and_away_from_it():
    """A linked Normal facing the wall: only the rays within acos(a / D) of it reach it (1 -
    c^2 of them); Inside turns the rays away, where nothing is."""
    mean, err = _ao(2.0, normal=(2.0, 0.0, 0.0))     # normalised by the node
    assert mean == pytest.approx(0.25, abs=max(5.0 * err, 2e-3))
    assert _ao(2.0, normal=(1.0, 0.0, 0.0), inside=True, keys=20)[0] == 1.0


def test_nothing_occludes_where_it_does_not_trace():
    """Only Local: the floor alone, which its rays leave; a Distance of 0 without a world
    distance, and shadow rays or light samples (min_pdf 0): AO 1, Color the input colour."""
    assert _ao(2.0, only_local=True, keys=20)[0] == 1.0
    assert _ao(0.0, keys=20)[0] == 1.0
    assert _ao(2.0, min_pdf=0.0, keys=20)[0] == 1.0
    assert _ao(2.0, keys=20)[0] < 1.0


@pytest.mark.parametrize("hidden, expected", [(VIS_CAMERA, 0.25), (VIS_CAMERA | VIS_SHADOW, 1.0)])
def test_a_rendered_floor_is_occluded_by_what_shadow_rays_see(hidden, expected):
    """A render: an emissive floor whose colour is its AO (Distance 2) under a cover 1 m
    above, hidden from camera rays. Cosine rays meet the cover within 2 m when their cosine
    is above 1/2: the floor shows AO = 1/4. Hidden from shadow rays too (Cycles' AO rays are
    opaque shadow rays), the cover leaves the scene's hierarchy: AO = 1."""
    from .scenes import grid_plane, plane_scene
    scene = plane_scene(None, samples=256, res=8, bounces=0)
    scene.lights = []
    floor, cover = grid_plane(200.0), grid_plane(200.0, z=1.0)[:, ::-1]
    scene.geometry = Geometry.from_triangles(np.concatenate([floor, cover]), material_index=[0, 0, 1, 1],
                                             object_index=[0, 0, 1, 1], object_names=["Floor", "Cover"])
    scene.geometry.object_visibility = np.array([VIS_ALL, VIS_ALL & ~hidden], np.uint8)
    glow = Material(nodes=[ShaderNode("AmbientOcclusion", {"Distance": 2.0}),
                           ShaderNode("Emission", {"Color": Link(0, "Color"), "Strength": 1.0})],
                    surface=Link(1, "Emission"))
    scene.materials = [glow, Material(base_color=(0.0,) * 3)]
    assert_mean(RenderSession(scene).run(), expected)
