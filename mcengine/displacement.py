"""True displacement: meshes whose material says 'Displacement Only' or 'Displacement and
Bump' moved as Cycles moves them before building the BVH (scene/mesh_displace.cpp).

* Every vertex of a triangle with such a material moves once, by the displacement its
  material gives at the first such triangle that uses it, in triangle order, evaluated as at
  that triangle's corner with the vertex's smooth normal (``kernels.displace``).  Motion
  steps (deformation blur, the Vector pass) move by the same vector, as Cycles moves them.
* Normals afterwards: for method 'DISPLACEMENT', each vertex's normal becomes the
  normalised sum of the unit face normals of its displaced triangles, smooth faces take
  those at their corners and flat faces their new face normal; method 'BOTH' keeps the
  normals as they were (its bump perturbs them, starting from the undisplaced normal).
* The Texture Coordinate's Generated output keeps reading the point before displacement
  (Cycles' generated attribute), and Bump nodes (the bump of 'Displacement and Bump'
  included) evaluate their heights at the undisplaced point, normal and ray differential, as
  Cycles' bump evaluation does on such meshes: through the per-corner attributes
  ``UNDISPLACED_ATTRIBUTE`` and ``UNDISPLACED_NORMAL_ATTRIBUTE`` (``kernels.svm.bump``).

Differences from Cycles: this works on the scene's triangles in world space, per instance,
where Cycles displaces a mesh once in object space (the same result unless the displacement
reads world-space positions of an instanced mesh); faces with sharp edges or custom normals
get recomputed vertex normals as smooth faces; a tangent-space Normal Map on a displaced
surface uses the displaced normal, where Cycles uses the undisplaced one (warned at
export).  The export supplies each corner's object-space vertex normal and
whether its face is smooth (``VERTEX_NORMAL_ATTRIBUTE``, ``SMOOTH_ATTRIBUTE``); without
them, the corners' shading normals stand in for both.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .images import ImageTable
from .kernels.camera import pack_camera
from .kernels.displace import displacement_offsets
from .kernels.subsurface import no_local_bvh
from .kernels.svm import TextureData
from .packing import areas_and_normals, pack_attributes, pack_objects
from .scene import Geometry, SceneDescription
from .shaders import (
    SMOOTH_ATTRIBUTE,
    UNDISPLACED_ATTRIBUTE,
    UNDISPLACED_NORMAL_ATTRIBUTE,
    VERTEX_NORMAL_ATTRIBUTE,
    compile_displacement,
    truly_displaced,
)
from .vectors import cross, lengths


def displace(scene: SceneDescription, images: ImageTable | None = None) -> SceneDescription:
    """``scene`` with its truly displaced meshes moved (the scene itself when it has none).

    ``images``: the scene's images as the kernels read them (``packing.scene_images``), if
    the caller has loaded them already (not loaded twice: 0.06 s per 4096 x 4096 image)."""
    g = scene.geometry
    moved = np.array([truly_displaced(m) for m in scene.materials], bool)
    if not len(g.triangles) or not moved.any() or not moved[g.material_index].any():
        return scene
    tris = np.asarray(g.triangles, np.int64)
    selected = np.flatnonzero(moved[g.material_index])
    vertex, first = np.unique(tris[selected].ravel(), return_index=True)
    corner_tri = selected[first // 3]
    corner = first % 3

    matrix, texspace, _info = g.object_arrays()
    inverse = np.linalg.inv(matrix)
    obj = np.clip(np.asarray(g.object_index, np.int64), 0, max(len(matrix) - 1, 0))
    world = np.asarray(g.vertices, np.float64)
    corners = world[tris]                                                   # (T, 3, 3)
    attributes = {k: v for k, v in g.attributes.items()
                  if k not in (VERTEX_NORMAL_ATTRIBUTE, SMOOTH_ATTRIBUTE)}
    if len(matrix):
        local = (np.einsum("tij,tkj->tki", inverse[obj, :3, :3], corners) + inverse[obj, None, :3, 3])
    else:
        local = corners
    # The meshes Cycles gives undisplaced attributes: those with a displaced triangle.
    displaced_mesh = np.isin(obj, obj[selected]).astype(np.float32)
    attributes[UNDISPLACED_ATTRIBUTE] = np.concatenate(
        [local, np.broadcast_to(displaced_mesh[:, None, None], (len(tris), 3, 1))], axis=2).astype(np.float32)
    attributes[UNDISPLACED_NORMAL_ATTRIBUTE] = _object_normals(g, matrix, obj)
    # The texture space stays the undisplaced mesh's (an automatic one is not recomputed).
    before = dataclasses.replace(g, attributes=attributes, object_texspace=texspace)

    normals = _vertex_normals(g, matrix, obj, corner_tri, corner)
    if images is None:
        images = ImageTable(scene.images)
    offsets = _evaluate(scene, before, corner_tri, corner, normals, images)
    shift = np.zeros_like(world)
    shift[vertex] = offsets
    vertices = world + shift
    smooth = _smooth(g)
    recompute = np.array([truly_displaced(m) and m.displacement_method == "DISPLACEMENT"
                          for m in scene.materials], bool)[g.material_index]
    # Each vertex's object, for normals summed in object space as Cycles sums them.
    if len(matrix):
        vertex_object = np.zeros(len(world), np.int64)
        vertex_object[tris] = obj[:, None]
        frames = (inverse[vertex_object], np.linalg.inv(matrix[:, :3, :3]).transpose(0, 2, 1)[vertex_object])
    else:
        frames = None
    shading = _recomputed_normals(vertices, tris, g.corner_normals(), smooth, recompute, frames)
    # Per corner (T, 3, 3): the geometry makes them a table of 3T rows (normal_index=None).
    geometry = dataclasses.replace(before, vertices=vertices.astype(np.float32), normals=shading,
                                   normal_index=None)
    changes = {"geometry": geometry}
    for name in ("motion_blur", "motion_vectors"):
        motion = getattr(scene, name)
        if motion is not None and motion.objects:
            objects = [_moved_steps(om, shift, tris, g.object_index, smooth, recompute, frames)
                       for om in motion.objects]
            changes[name] = dataclasses.replace(motion, objects=objects)
    return dataclasses.replace(scene, **changes)


def _vertex_normals(g: Geometry, matrix, obj, corner_tri, corner) -> np.ndarray:
    """World-space unit normals at the chosen corners: the exported object-space vertex normals
    carried by the inverse transpose of their object's matrix, else the shading normals."""
    exported = g.attributes.get(VERTEX_NORMAL_ATTRIBUTE)
    if exported is None or not len(matrix):
        n = np.asarray(g.normals, np.float64)[g.normal_index[corner_tri, corner]]
    else:
        n = np.asarray(exported, np.float64)[corner_tri, corner]
        inverse_t = np.linalg.inv(matrix[:, :3, :3]).transpose(0, 2, 1)
        n = np.einsum("vij,vj->vi", inverse_t[obj[corner_tri]], n)
    length = lengths(n)[:, None]
    return np.ascontiguousarray(n / np.where(length > 0.0, length, 1.0))


def _object_normals(g: Geometry, matrix, obj) -> np.ndarray:
    """(T, 3, 3) object-space vertex normals at the corners before displacement: the
    exported ones, else the shading normals carried back by their object's matrix."""
    exported = g.attributes.get(VERTEX_NORMAL_ATTRIBUTE)
    if exported is not None:
        return np.asarray(exported, np.float32)
    n = g.corner_normals().astype(np.float64)
    if len(matrix):
        n = np.einsum("tji,tkj->tki", matrix[obj, :3, :3], n)       # M^T n
    return _unit(n).astype(np.float32)


def _evaluate(scene: SceneDescription, g: Geometry, corner_tri, corner, normals,
              images: ImageTable) -> np.ndarray:
    """The displacement vectors at the chosen corners (``kernels.displace``)."""
    layout, attr = pack_attributes(g)
    ops, ranges, results, init, base = [], [], [], {}, 0
    for m in scene.materials:
        start = len(ops)
        reg = -1
        if truly_displaced(m):
            program, reg = compile_displacement(m, layout, base, images.slots)
            ops.extend(program.ops)
            init.update(program.init)
            base += program.registers
        ranges.append([start, len(ops)])
        results.append(reg)
    registers = np.zeros(max(base, 1))
    if init:
        registers[np.fromiter(init.keys(), np.int64)] = np.fromiter(init.values(), float)
    verts = np.asarray(g.vertices, np.float64)
    tris = np.ascontiguousarray(g.triangles, np.int32)
    _area, ng = areas_and_normals(verts, tris)
    tex = TextureData(attr=attr, normals=np.ascontiguousarray(g.normals, np.float32),
                      normal_index=np.ascontiguousarray(g.normal_index, np.int32),
                      tri_object=np.ascontiguousarray(g.object_index, np.int32),
                      objects=pack_objects(g), camera=pack_camera(scene.camera, scene.film, scene.motion_blur),
                      images=images.info, pix8=images.pix8, pixf=images.pixf)
    out = np.zeros((len(corner_tri), 3))
    displacement_offsets(np.array(ops, np.int32).reshape(-1, 4), np.array(ranges, np.int32).reshape(-1, 2),
                         np.array(results, np.int64), registers, tex, verts, tris, no_local_bvh(), ng,
                         np.ascontiguousarray(g.material_index, np.int32),
                         corner_tri.astype(np.int32), corner.astype(np.int32), normals, out)
    return out


def _smooth(g: Geometry) -> np.ndarray:
    """(T,) bool: which triangles are smooth-shaded (the export's flag; without it, those whose
    corner normals differ from one another)."""
    flag = g.attributes.get(SMOOTH_ATTRIBUTE)
    if flag is not None:
        return np.asarray(flag)[:, 0, 0] > 0.5
    n = g.corner_normals()
    return np.abs(n - n[:, :1]).max(axis=(1, 2)) > 1e-6


def _unit(v):
    length = lengths(v)[..., None]
    return v / np.where(length > 0.0, length, 1.0)


def _recomputed_normals(vertices, tris, normals, smooth, recompute, frames=None) -> np.ndarray:
    """Corner normals after displacement (see the module docstring): those of the triangles in
    ``recompute`` rebuilt from ``vertices``, the others as they were.  ``frames`` = (each
    vertex's world -> object matrix, its object's normal matrix): smooth normals are summed
    from unit face normals in object space, as Cycles does, then brought to world space."""
    out = normals.copy()
    if not recompute.any():
        return out
    own = tris[recompute]
    p = vertices[own]
    face = _unit(cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]))
    local = vertices if frames is None else (
        np.einsum("vij,vj->vi", frames[0][:, :3, :3], vertices) + frames[0][:, :3, 3])
    q = local[own]
    summed = np.zeros((len(vertices), 3))
    local_face = _unit(cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]))
    for k in range(3):
        np.add.at(summed, own[:, k], local_face)
    vertex_normal = _unit(summed)
    if frames is not None:
        # Cycles keeps a displaced mesh in object space and interpolates these normals there:
        # carried to world space unnormalised, they interpolate to the same direction.
        vertex_normal = np.einsum("vij,vj->vi", frames[1], vertex_normal)
    rebuilt = np.where(smooth[recompute, None, None], vertex_normal[own], face[:, None, :])
    out[recompute] = rebuilt.astype(np.float32)
    return out


def _moved_steps(om, shift, tris, object_index, smooth, recompute, frames):
    """An :class:`ObjectMotion` whose deformation steps moved by the displacement of its
    vertices, their normals recomputed as the frame's."""
    if om.positions is None:
        return om
    first, count = om.vertices
    positions = np.asarray(om.positions, np.float64) + shift[first:first + count][None]
    normals = om.normals
    own = np.flatnonzero(np.asarray(object_index) == om.object)
    if normals is not None and recompute[own].any():
        local = tris[own] - first
        steps = None if frames is None else (frames[0][first:first + count], frames[1][first:first + count])
        normals = np.stack([_recomputed_normals(step, local, np.asarray(n, np.float32), smooth[own],
                                                recompute[own], steps)
                            for step, n in zip(positions, normals)])
    return dataclasses.replace(om, positions=positions.astype(np.float32), normals=normals)
