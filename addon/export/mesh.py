"""Evaluated mesh instances -> world-space :class:`mcengine.scene.Geometry`.

Every ``depsgraph.object_instances`` entry whose evaluated data is a Mesh is
exported (this is Cycles' rule: curves, text, metaballs and geometry-node
output reach the depsgraph as mesh instances; hair curves, point clouds and
volumes are warned about).  Modifiers are applied because the objects are
evaluated; instances (collections, geometry nodes, vertex/face instancing)
arrive as separate entries with their own ``matrix_world``.

A mesh is read once in object space with ``foreach_get`` (its triangles as Blender's
``loop_triangles``, computed from its faces when they are triangles and quads,
``corner_normals`` for the shading normals, so flat, smooth and custom normals
all come out as Blender shows them, every UV map and colour attribute) and cached
under its evaluated data block and material slots, per-corner values as tables plus
each corner's row (never whole (T, 3, C) arrays).  All instances of all meshes are
then written straight into one final Geometry, block by block (see
:func:`_place_instances`).

Transform conventions: positions ``p' = s * (M p)`` with ``s`` the unit scale
(metres per Blender unit); shading normals by the inverse transpose of M's
3x3 part, renormalised.  When det(M) < 0 (mirroring) the triangle winding is
flipped so the geometric normal stays on the same side as the shading normal.
"""
from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np

from mcengine.kernels.lights import LIGHT_SETS_ALL
from mcengine.kernels.state import (
    VIS_CAMERA,
    VIS_DIFFUSE,
    VIS_GLOSSY,
    VIS_SCATTER,
    VIS_SHADOW,
    VIS_TRANSMISSION,
)
from mcengine.kernels.svm.nodes import TANGENT_PREFIX
from mcengine.kernels.tangents import mikktspace
from mcengine.mesh_attributes import pointiness, random_per_island, sphere_uv
from mcengine.parallel import map_threads, take
from mcengine.scene import Geometry, ObjectPassInfo, auto_texspace_size
from mcengine.shaders import (
    DEFAULT_COLOR_ATTRIBUTE,
    GEOMETRY_ATTRIBUTES,
    SMOOTH_ATTRIBUTE,
    VERTEX_NORMAL_ATTRIBUTE,
)
from mcengine.tessellation import corner_triangles
from mcengine.vectors import cross, lengths

from .settings import hash_uint2

__all__ = ["LocalMesh", "MeshCollector", "read_local_mesh", "transform_instances"]

# Evaluated object data types Cycles renders but mcengine cannot yet.
_UNSUPPORTED_DATA = {"CURVES": "hair curves", "POINTCLOUD": "point clouds", "VOLUME": "volume objects"}
# The note on a mesh without UV maps whose normal maps' tangents come from the sphere
# mapping (``_add_tangents``) across that mapping's seam, where they were seen to differ from
# Cycles' (a bumpy grid, tests/nodes/test_normal_nodes.py, 29 % of its pixels; why is not
# known: the same sphere UVs give Cycles' tangents away from the seam).
SPHERE_SEAM = "meshes without a UV map across the sphere mapping's seam"
# Fallback text of each per-object note.
_OBJECT_NOTES = {
    "hair curves": "these objects are skipped",
    "point clouds": "these objects are skipped",
    "volume objects": "these objects are skipped",
    "shadow catcher": "these objects render as normal objects",
    "particle hair": "their strands are not rendered",
    SPHERE_SEAM: "their normal maps' tangents near it (object space x = 0, y < 0) may differ "
                 "from Cycles' (elsewhere they agree)",
}
# Object.visible_* flags and the rays they let see the object (Cycles' object_ray_visibility).
_RAYS = {"camera": VIS_CAMERA, "diffuse": VIS_DIFFUSE, "glossy": VIS_GLOSSY,
         "transmission": VIS_TRANSMISSION, "volume_scatter": VIS_SCATTER, "shadow": VIS_SHADOW}
# Object names listed in one warning line; the rest are counted.
_MAX_LISTED = 5
# Swapping corners 1 and 2 reverses a triangle's winding.
_FLIP = [0, 2, 1]
# Triangles per block of _place_instances (float64 temporaries of a few MB).
_BLOCK = 1 << 15


@dataclass
class LocalMesh:
    """One evaluated mesh in object space, ready to be instanced.

    vertices        (V, 3) float32  vertex positions
    triangles       (T, 3) int32    vertex indices per triangle
    normals         CornerTable (C = 3) shading normals (per vertex, face or corner: the
                    mesh's normals domain)
    material_index  (T,) int32      index into the scene's material table
    attributes      name -> CornerTable: every UV map and colour attribute by name, and
                    the other attributes the materials read
    uv_name         name of the default (active render) UV map in ``attributes``, or None
    texspace        (2, 3) float64  generated texture space: centre and half-size
    tangents_failed why tangents some Normal Map reads are missing ("" if none are)

    Per-corner values are gathered block by block when the instances are placed,
    never as whole (T, 3, C) arrays; without a UV map the exported UVs stay
    untouched zero pages (no memory).
    """

    vertices: np.ndarray
    triangles: np.ndarray
    normals: CornerTable
    material_index: np.ndarray
    attributes: dict
    uv_name: str | None
    texspace: np.ndarray
    tangents_failed: str = ""


@dataclass
class CornerTable:
    """Per-corner values stored once per vertex, face or corner of a mesh.

    table  (K, C) float32  the values
    index  (T, 3) int      row of ``table`` of each triangle corner
    """

    table: np.ndarray
    index: np.ndarray

    def corners(self, a0: int, a1: int) -> np.ndarray:
        """(a1 - a0, 3, C) float32 values of triangles a0..a1-1 (``np.take``: a third of the
        time of fancy indexing on rows of a few floats)."""
        return np.take(self.table, self.index[a0:a1], axis=0)


class MeshCollector:
    """Collects mesh instances during the depsgraph walk, then builds the Geometry.

    Parameters
    ----------
    ctx : ExportContext
    materials : MaterialTable
        Maps each object's material slots to scene material indices.
    view_layer : bpy.types.ViewLayer, optional
        The depsgraph's view layer, where an object's collections may make it a holdout.
    links : linking.LightLinks, optional
        The objects' light sets (light linking); without, none is linked.
    """

    def __init__(self, ctx, materials, view_layer=None, links=None):
        self._ctx = ctx
        self._materials = materials
        self._links = links
        self._view_layer = view_layer
        self._override = getattr(view_layer, "material_override", None)
        self._layer_flags: dict = {}              # by (question, original object): asked once
        self._meshes: dict[tuple, LocalMesh | None] = {}
        self._matrices: dict[tuple, list] = {}
        self._names: dict[tuple, list] = {}
        self._infos: dict[tuple, list] = {}
        self._passes: dict[tuple, list] = {}
        self._tags: dict[tuple, list] = {}
        self._terminators: dict[tuple, list] = {}
        self._visibility: dict[tuple, list] = {}
        self._light_sets: dict[tuple, list] = {}    # (receiver set, light sets) per instance
        # What the instances of one object under one instancer share (``_source``), by
        # (object, its data, instancer) address; None: not rendered.
        self._sources: dict[tuple, tuple | None] = {}
        # Per geometry object, after geometry(): (tag, (first vertex, count), LocalMesh, slots, matrix).
        self.layout: list = []
        # Names of the objects with settings the renderer ignores, by feature (see _OBJECT_NOTES).
        self._noted: dict[str, list] = {}

    def add(self, inst, name: str, tag=None) -> None:
        """Register one depsgraph instance (non-mesh data is ignored or noted).

        What an instance shares with every other instance of its object under the same
        instancer (its mesh, material slots, Object Info but the random id, passes, ray
        visibility, light sets) is worked out for the first of them only
        (``_source``): a scatter of 10,000 instances took 52 us each, nearly all of it
        reading the same object settings again.

        Parameters
        ----------
        inst : bpy.types.DepsgraphObjectInstance
        name : str
            Name of the instance for messages.
        tag : object, optional
            Returned with the instance's place in the geometry (``layout``).
        """
        ob = inst.object
        parent = inst.parent if inst.is_instance else None
        data = ob.data
        source_key = (ob.as_pointer(), data.as_pointer() if data is not None else 0,
                      parent.as_pointer() if parent is not None else 0)
        if source_key not in self._sources:
            self._sources[source_key] = self._source(inst)
        source = self._sources[source_key]
        if source is None:
            return
        key, info_tail, passes, terminator, visibility, light_sets = source
        self._matrices[key].append(np.array(inst.matrix_world, np.float64))
        self._names[key].append(name)
        random_id = inst.random_id if inst.is_instance else object_random_id(ob.name)
        self._infos[key].append([float(random_id & 0xFFFFFFFF), *info_tail])
        self._passes[key].append(passes)
        self._tags[key].append(tag)
        self._terminators[key].append(terminator)
        self._visibility[key].append(visibility)
        self._light_sets[key].append(light_sets)

    def _source(self, inst):
        """What the instances of ``inst``'s object under its instancer share: (mesh key,
        Object Info after the random id, pass info, shadow terminator offsets, ray
        visibility, light sets), or None when its data is not rendered (noted if it is
        unsupported)."""
        ob = inst.object
        if ob.type in _UNSUPPORTED_DATA:
            self._note(_UNSUPPORTED_DATA[ob.type], ob.name)
            return None
        if not isinstance(ob.data, bpy.types.Mesh):
            return None
        if getattr(ob, "is_shadow_catcher", False):
            self._note("shadow catcher", ob.name)
        if any(ps.settings.render_type == "PATH" for ps in getattr(ob, "particle_systems", ())):
            self._note("particle hair", ob.name)
        slots = tuple(self._materials.index(m) for m in slot_materials(ob, self._override))
        key = (ob.data.as_pointer(), slots)
        if key not in self._meshes:
            self._meshes[key] = read_local_mesh(ob, slots, self._materials.attribute_names(),
                                                self._materials.tangent_maps(slots or (0,)))
            mesh = self._meshes[key]
            if mesh is not None and mesh.tangents_failed:
                self._note(mesh.tangents_failed, ob.name)
            self._matrices[key], self._names[key], self._infos[key] = [], [], []
            self._passes[key], self._tags[key], self._terminators[key] = [], [], []
            self._visibility[key], self._light_sets[key] = [], []
        if self._meshes[key] is None:
            return None
        return (key, (float(ob.pass_index), *(float(c) for c in ob.color)),
                object_pass_info(ob, self._holdout(inst)),
                (ob.shadow_terminator_geometry_offset, ob.shadow_terminator_shading_offset),
                self._ray_visibility(inst),
                (self._links.receiver_set(ob), self._links.light_sets(ob)) if self._links
                else (0, LIGHT_SETS_ALL))

    def geometry(self) -> Geometry:
        """All collected instances as one world-space Geometry (also emits the object notes)."""
        for feature, names in self._noted.items():
            self._ctx.warn(f"{feature} not supported yet ({listed(names)}); {_OBJECT_NOTES[feature]}",
                           feature)
        parts = [(mesh, np.stack(self._matrices[key]), self._names[key],
                  np.array(self._infos[key], np.float64))
                 for key, mesh in self._meshes.items() if mesh is not None]
        geometry = _place_all(parts, self._ctx.unit_scale)
        geometry.object_passes = [info for key, mesh in self._meshes.items() if mesh is not None
                                  for info in self._passes[key]]
        geometry.object_terminator = np.array(
            [t for key, mesh in self._meshes.items() if mesh is not None
             for t in self._terminators[key]], np.float64).reshape(-1, 2)
        geometry.object_visibility = np.array(
            [v for key, mesh in self._meshes.items() if mesh is not None
             for v in self._visibility[key]], np.uint8)
        light_sets = [v for key, mesh in self._meshes.items() if mesh is not None
                      for v in self._light_sets[key]]
        if any(v != (0, LIGHT_SETS_ALL) for v in light_sets):
            geometry.object_receiver_set = np.array([v[0] for v in light_sets], np.uint8)
            geometry.object_light_sets = np.array([v[1] for v in light_sets], np.uint64)
        # The instances' places in the geometry, in the order _place_all writes them.
        self.layout = []
        first = 0
        for key, mesh in self._meshes.items():
            if mesh is not None:
                count = mesh.vertices.shape[0]
                for tag, matrix in zip(self._tags[key], self._matrices[key]):
                    self.layout.append((tag, (first, count), mesh, key[1], matrix))
                    first += count
        return geometry

    def _holdout(self, inst) -> bool:
        """Whether the instance is a holdout: its object's (an instance's: its instancer's)
        own setting or its collection's in the view layer (Cycles' blender/object.cpp asks the
        same of Blender; the original object and view layer answer, evaluated ones do not)."""
        return self._layer_flag(inst, "holdout_get", "is_holdout")

    def _ray_visibility(self, inst) -> int:
        """The rays that see the instance (``VIS_*`` bits; Cycles' blender/object.cpp): its
        object's Ray Visibility, an instance's also its instancer's, and not camera rays in
        an Indirect Only collection."""
        visibility = object_ray_visibility(inst.object)
        if inst.is_instance and inst.parent is not None:
            visibility &= object_ray_visibility(inst.parent)
        if self._indirect_only(inst):
            visibility &= ~VIS_CAMERA
        return visibility

    def _indirect_only(self, inst) -> bool:
        """Whether the instance's collection is Indirect Only in the view layer (for Cycles
        only where it is not a holdout)."""
        return not self._holdout(inst) and self._layer_flag(inst, "indirect_only_get", None)

    def _layer_flag(self, inst, question: str, own: str | None) -> bool:
        """The view layer's answer to ``Object.<question>`` for the instance's object (an
        instance's: its instancer's); where it is not in the view layer, its own flag ``own``."""
        ob = (inst.parent if inst.is_instance else inst.object).original
        key = (question, ob.as_pointer())
        if key not in self._layer_flags:
            answer = None
            if self._view_layer is not None:
                try:
                    answer = bool(getattr(ob, question)(view_layer=self._view_layer))
                except RuntimeError:  # not in the view layer (Blender reports it)
                    pass
            self._layer_flags[key] = bool(own and getattr(ob, own, False)) if answer is None else answer
        return self._layer_flags[key]

    def _note(self, feature: str, object_name: str) -> None:
        names = self._noted.setdefault(feature, [])
        if object_name not in names:
            names.append(object_name)


def object_ray_visibility(ob) -> int:
    """An object's Object > Visibility > Ray Visibility switches as ``VIS_*`` bits."""
    return sum(bit for ray, bit in _RAYS.items() if getattr(ob, f"visible_{ray}", True))


def slot_materials(ob, override=None) -> list:
    """The Blender materials of an object's slots (None: an empty slot), as Cycles reads them
    (blender/mesh.cpp, find_used_shaders): with the view layer's Material Override, that
    material in every slot, and in one slot for an object without any."""
    if override is not None:
        return [override] * max(len(ob.material_slots), 1)
    return [s.material for s in ob.material_slots]


def listed(names) -> str:
    """Object names for a warning: the first few quoted, and how many more."""
    more = f" and {len(names) - _MAX_LISTED} more" if len(names) > _MAX_LISTED else ""
    return ", ".join(f"'{n}'" for n in names[:_MAX_LISTED]) + more


def read_local_mesh(ob, slot_materials, wanted=(), tangents=()) -> LocalMesh | None:
    """Read an evaluated object's mesh in object space (None if it has no triangles).

    Parameters
    ----------
    ob : bpy.types.Object
        Evaluated object whose data is a Mesh.
    slot_materials : tuple of int
        Scene material index of each material slot (empty: default surface).
    wanted : collection of str
        Names of generic attributes some material reads (UV maps and colour
        attributes are always read).
    tangents : collection of str
        UV maps ("" the default one) whose MikkTSpace tangents some Normal Map reads.
    """
    me = ob.to_mesh()
    try:
        t = len(me.loops) - 2 * len(me.polygons)
        if t == 0:
            return None
        corner_verts = _corner_vertices(me)
        vertices = _get(me.vertices, "co", np.float32, len(me.vertices) * 3).reshape(-1, 3)
        loops, polygons = _corner_triangles(me, corner_verts, vertices)
        triangles = take(corner_verts, loops).reshape(t, 3)
        corners = loops.reshape(t, 3)
        normals = _shading_normals(me, vertices, corners, triangles, polygons)
        mat = _triangle_materials(me, slot_materials, polygons)
        uv_layer = _render_uv_layer(me)
        attributes = _corner_attributes(me, corners, triangles, polygons, wanted)
        attributes.update(_derived_attributes(me, vertices, triangles, polygons, wanted))
        tangents_failed = _add_tangents(me, vertices, triangles, normals, tangents, uv_layer,
                                        attributes)
        texspace = _texspace(ob)
    finally:
        ob.to_mesh_clear()
    return LocalMesh(vertices=vertices, triangles=triangles, normals=normals,
                     material_index=mat, attributes=attributes,
                     uv_name=None if uv_layer is None else uv_layer.name, texspace=texspace,
                     tangents_failed=tangents_failed)


def object_pass_info(ob, holdout: bool = False) -> ObjectPassInfo:
    """What the film and render passes need of an object besides its Object Info (Cycles'
    blender/object.cpp): its name, the name of its topmost parent (the Cryptomatte asset; its
    own without a parent), whether its mesh has a UV map, and ``holdout``."""
    root = ob
    while root.parent is not None:
        root = root.parent
    uv_layers = getattr(ob.data, "uv_layers", None)
    return ObjectPassInfo(name=ob.name, asset=root.name,
                          has_uv=bool(uv_layers is not None and len(uv_layers)), holdout=holdout)


def transform_instances(mesh: LocalMesh, matrices, unit_scale: float, names,
                        infos=None) -> Geometry:
    """Place N instances of a local mesh in world space.

    Parameters
    ----------
    mesh : LocalMesh
        T triangles over V vertices.
    matrices : (N, 4, 4) float
        Object-to-world matrices, in Blender units.
    unit_scale : float
        Metres per Blender unit.
    names : list of str
        N object names (for messages).
    infos : (N, 6) float, optional
        Object Info per instance: random id, pass index, colour RGBA (zeros if None).

    Returns
    -------
    Geometry
        N*T triangles; instance i owns triangles [i*T, (i+1)*T).
    """
    return _place_all([(mesh, np.asarray(matrices, np.float64), list(names), infos)], unit_scale)


def _place_all(parts, unit_scale: float) -> Geometry:
    """Parts (mesh, matrices, names, infos or None) as one Geometry, as
    ``Geometry.concatenate`` of their :func:`transform_instances` would give it (an
    attribute some mesh lacks is zero there), but with one allocation of the final
    arrays and every instance written in place (no per-part arrays, no concatenation copy).

    Each instance's shading normals are its mesh's normal table (per vertex, face or corner)
    transformed and normalised once per row (:func:`_normal_rows`); when every mesh has
    vertex normals, the geometry's ``normal_index`` is its ``triangles`` array itself.
    """
    if not parts:
        return Geometry()
    sizes = {}
    for mesh, _m, _names, _infos in parts:
        for name, values in mesh.attributes.items():
            sizes[name] = max(sizes.get(name, 0), values.table.shape[1])
    t_all = sum(len(m) * mesh.triangles.shape[0] for mesh, m, _n, _i in parts)
    v_all = sum(len(m) * mesh.vertices.shape[0] for mesh, m, _n, _i in parts)
    o_all = sum(len(m) for _mesh, m, _n, _i in parts)
    per_corner = [_per_corner_normals(mesh, m) for mesh, m, _n, _i in parts]
    k_all = sum(len(m) * (3 * mesh.triangles.shape[0] if corner else len(mesh.normals.table))
                for (mesh, m, _n, _i), corner in zip(parts, per_corner))
    triangles = np.empty((t_all, 3), np.int32)
    shared = not any(per_corner) and all(mesh.normals.index is mesh.triangles
                                         for mesh, _m, _n, _i in parts)
    # Zeros only where values may be missing (untouched zero pages cost no memory).
    uvs = np.zeros((t_all, 3, 2), np.float32)
    # A UV map that is every mesh's default where any mesh has it is the default UVs
    # themselves: one array, not two equal ones (24 bytes per triangle).
    same_as_uvs = {name for name, c in sizes.items() if c == 2 and all(
        mesh.uv_name == name or (mesh.uv_name is None and name not in mesh.attributes)
        for mesh, _m, _n, _i in parts)}
    out = Geometry(vertices=np.empty((v_all, 3), np.float32),
                   triangles=triangles,
                   normals=np.empty((k_all, 3), np.float32),
                   normal_index=triangles if shared else np.empty((t_all, 3), np.int32),
                   uvs=uvs,
                   material_index=np.empty(t_all, np.int32),
                   object_index=np.empty(t_all, np.int32),
                   object_names=[name for _mesh, _m, names, _i in parts for name in names],
                   attributes={name: uvs if name in same_as_uvs else np.zeros((t_all, 3, c), np.float32)
                               for name, c in sizes.items()},
                   object_matrix=np.empty((o_all, 4, 4)), object_texspace=np.empty((o_all, 2, 3)),
                   object_info=np.zeros((o_all, 6)))
    t0 = v0 = n0 = o0 = 0
    for (mesh, matrices, _names, infos), corner in zip(parts, per_corner):
        n = len(matrices)
        n0 = _place_instances(mesh, matrices, unit_scale, out, t0, v0, n0, o0, corner, shared)
        if infos is not None:
            out.object_info[o0:o0 + n] = np.asarray(infos, np.float64).reshape(n, 6)
        t0 += n * mesh.triangles.shape[0]
        v0 += n * mesh.vertices.shape[0]
        o0 += n
    return out


def _per_corner_normals(mesh: LocalMesh, matrices) -> bool:
    """Whether a mesh's instances get a normal per triangle corner instead of transformed rows
    of its table: when a row of the table, or of its transformed copy under a singular
    matrix, has zero length (such a corner takes its triangle's normal, ``_unit_normals``)."""
    table = mesh.normals.table
    if len(table) and not lengths(table).all():
        return True
    return bool(np.any(np.linalg.det(np.asarray(matrices, np.float64)[:, :3, :3]) == 0.0))


def _place_instances(mesh: LocalMesh, matrices, unit_scale: float, out: Geometry, t0: int, v0: int,
                     n0: int, o0: int, per_corner: bool, shared: bool) -> int:
    """Write N instances of ``mesh`` into ``out`` from triangle t0, vertex v0, normal row n0 and
    object o0 on (see :func:`transform_instances`; Object Info is left to the caller); returns
    the normal row after them. ``per_corner``: a normal row per triangle corner
    (``_per_corner_normals``); ``shared``: ``out.normal_index`` is ``out.triangles``.

    The per-triangle arrays are computed in blocks of about ``_BLOCK`` triangles (a
    range of one instance's triangles, or several whole instances) written straight
    into ``out``, so the float64 temporaries stay small: large fresh temporaries cost
    more in page faults than the arithmetic on them (5x faster at a million triangles).
    The blocks run on threads (``mcengine.parallel.map_threads``).
    """
    m = np.asarray(matrices, np.float64)
    n, v, t = m.shape[0], mesh.vertices.shape[0], mesh.triangles.shape[0]
    lin = m[:, :3, :3]
    pos = (np.matmul(mesh.vertices[None], lin.transpose(0, 2, 1)) + m[:, None, :3, 3]) * unit_scale
    # Rows of the cofactor matrix cof(M) = det(M) M^-T, from the columns a, b, c.
    a, b, c = lin[:, :, 0], lin[:, :, 1], lin[:, :, 2]
    cof = np.stack([cross(b, c), cross(c, a), cross(a, b)], axis=2)
    det = np.einsum("ni,ni->n", a, cof[:, :, 0])
    flip = det < 0
    # sign(det) * cof is M^-T up to a positive factor, which renormalising removes.
    cof[flip] *= -1.0
    pos = pos.reshape(-1, 3)
    out.vertices[v0:v0 + n * v] = pos
    out.material_index[t0:t0 + n * t] = np.tile(mesh.material_index, n)
    out.object_index[t0:t0 + n * t] = np.repeat(np.arange(o0, o0 + n, dtype=np.int32), t)
    out.object_matrix[o0:o0 + n] = m
    out.object_matrix[o0:o0 + n, :3, :] *= unit_scale
    out.object_texspace[o0:o0 + n] = mesh.texspace
    rows = 3 * t if per_corner else len(mesh.normals.table)      # normal rows per instance
    if not per_corner:
        _normal_rows(mesh.normals.table, cof, out.normals[n0:n0 + n * rows])
    step, blocks = _blocks(n, t)
    # The blocks write disjoint rows of ``out``: on threads (numpy releases the GIL).
    map_threads(lambda b: _transform_block(mesh, out, pos, cof[b[0]:b[1]], flip[b[0]:b[1]], b[0],
                                           b[2], min(t, b[2] + step), t0, v0, n0, rows,
                                           per_corner, shared), blocks)
    return n0 + n * rows


def _blocks(n: int, rows: int) -> tuple[int, list]:
    """About ``_BLOCK`` rows at a time of N instances of ``rows`` rows each: several whole
    instances per block, or ranges of one instance's rows.  Returns (step, blocks): each
    block (i0, i1, r0) is instances i0..i1-1 from row r0, ``step`` rows (fewer at the end)."""
    per_block = max(1, _BLOCK // max(rows, 1))       # whole instances per block
    step = max(rows, 1) if per_block > 1 else _BLOCK
    return step, [(i0, min(n, i0 + per_block), r0) for i0 in range(0, n, per_block)
                  for r0 in range(0, rows, step)]


def _normal_rows(table, cof, out):
    """``out`` (N K, 3) float32: the rows of a mesh's normal table (K, 3) transformed by each of
    N instances' ``cof`` and normalised, as :func:`_unit_normals` computes them for a corner
    (no row has zero length: ``_per_corner_normals``); in blocks on threads."""
    k_rows = len(table)
    step, blocks = _blocks(len(cof), k_rows)

    def block(b):
        i0, i1, r0 = b
        r1 = min(k_rows, r0 + step)
        rows = np.matmul(table[r0:r1].astype(np.float64)[None], cof[i0:i1].transpose(0, 2, 1))
        rows = rows / lengths(rows)[..., None]
        if i1 - i0 == 1:
            out[i0 * k_rows + r0:i0 * k_rows + r1] = rows[0]
        else:
            out[i0 * k_rows:i1 * k_rows] = rows.reshape(-1, 3)

    map_threads(block, blocks)


def _transform_block(mesh, out, pos, cof, flip, i0, a0, a1, t0, v0, n0, rows_per, per_corner,
                     shared):
    """Triangles a0..a1-1 of instances i0..i0+k-1 (k = len(cof)) into ``out`` at rows
    t0 + [i0*T + a0, (i0+k-1)*T + a1), contiguous because a block is either one
    instance's range or whole instances; ``pos`` holds the instances' vertices.  Normal rows
    start at n0, ``rows_per`` per instance: with ``per_corner`` this block writes its
    corners' (three per triangle, in triangle order), else the instances' tables are
    written already and the block writes where its corners' rows are (unless ``shared``)."""
    k, v, t = len(cof), mesh.vertices.shape[0], mesh.triangles.shape[0]
    tris = np.broadcast_to(mesh.triangles[a0:a1], (k, a1 - a0, 3)) + \
        (np.arange(i0, i0 + k) * v)[:, None, None]
    rows = slice(t0 + i0 * t + a0, t0 + (i0 + k - 1) * t + a1)
    any_flip = flip.any()
    if per_corner:
        normals = np.matmul(mesh.normals.corners(a0, a1).reshape(1, -1, 3).astype(np.float64),
                            cof.transpose(0, 2, 1)).reshape(k, a1 - a0, 3, 3)
    elif not shared:
        index = np.broadcast_to(mesh.normals.index[a0:a1], (k, a1 - a0, 3)) + \
            (n0 + np.arange(i0, i0 + k) * rows_per)[:, None, None]
    if any_flip:
        tris[flip] = tris[flip][:, :, _FLIP]
        if per_corner:
            normals[flip] = normals[flip][:, :, _FLIP]
        elif not shared:
            index[flip] = index[flip][:, :, _FLIP]
    for name, values in mesh.attributes.items():
        corners = np.broadcast_to(values.corners(a0, a1), (k, a1 - a0, 3, values.table.shape[1]))
        if any_flip:
            corners = corners.copy()
            corners[flip] = corners[flip][:, :, _FLIP]
        corners = corners.reshape(-1, 3, values.table.shape[1])
        out.attributes[name][rows, :, :values.table.shape[1]] = corners
        if name == mesh.uv_name and out.attributes[name] is not out.uvs:
            out.uvs[rows] = corners
    tris = tris.reshape(-1, 3)
    out.triangles[rows] = tris + v0
    if per_corner:
        first = n0 + 3 * (i0 * t + a0)           # the block's corners, in triangle order
        count = 3 * (rows.stop - rows.start)
        out.normals[first:first + count] = _unit_normals(normals.reshape(-1, 3, 3), pos,
                                                         tris).reshape(-1, 3)
        out.normal_index[rows] = np.arange(first, first + count, dtype=np.int32).reshape(-1, 3)
    elif not shared:
        out.normal_index[rows] = index.reshape(-1, 3)


def _unit_normals(normals, pos, tris):
    """Normalise (T, 3, 3) corner normals; zero ones become the geometric normal."""
    length = lengths(normals)[..., None]
    bad = length[..., 0] == 0
    if np.any(bad):
        p = pos[tris]
        ng = cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        ng_len = lengths(ng)[:, None]
        ng = np.where(ng_len > 0, ng / np.where(ng_len > 0, ng_len, 1.0), [0.0, 0.0, 1.0])
        normals = np.where(bad[..., None], ng[:, None, :], normals)
        length = np.where(bad[..., None], 1.0, length)
    return normals / length


def _get(collection, attr, dtype, size):
    out = np.empty(size, dtype)
    collection.foreach_get(attr, out)
    return out


def _corner_triangles(me, corner_verts, vertices):
    """Blender's triangles of ``me``: the corner of each triangle corner, (T * 3,) int32, and
    the face of each triangle, (T,) int32.

    ``loop_triangles`` has no raw array access (0.5 s for 4 million triangles), so for faces
    of 3 and 4 corners the triangles are computed as Blender computes them
    (:mod:`mcengine.tessellation`); only a mesh with a larger face reads Blender's.
    """
    faces, corners = len(me.polygons), len(me.loops)
    starts = None if corners == 3 * faces else _get(me.polygons, "loop_start", np.int32, faces)
    found = corner_triangles(starts, corners, corner_verts, vertices)
    if found is not None:
        return found
    t = corners - 2 * faces
    return (_get(me.loop_triangles, "loops", np.int32, t * 3),
            _get(me.loop_triangle_polygons, "value", np.int32, t))


def _corner_vertices(me):
    """Vertex index of every corner, (L,) int32.

    Read from the ``.corner_vert`` attribute when it exists (Blender >= 3.6 stores
    corners that way; 100x faster than ``loops.vertex_index``).
    """
    attr = me.attributes.get(".corner_vert")
    if attr is not None:
        return _get(attr.data, "value", np.int32, len(me.loops))
    return _get(me.loops, "vertex_index", np.int32, len(me.loops))


def _polygon_values(me, name, dtype):
    """A face attribute of every polygon, (P,) ``dtype`` (zeros without the attribute)."""
    attr = me.attributes.get(name)
    if attr is None:
        return np.zeros(len(me.polygons), dtype)
    return _get(attr.data, "value", dtype, len(me.polygons))


def _triangle_materials(me, slot_materials, polygons):
    """(T,) int32 scene material of every triangle, from its face's material slot.

    Cycles clamps out-of-range slot indices to the last slot, so a mesh with one slot or
    none (material 0) needs no face's index; otherwise each face's material is worked out
    once, then read per triangle.
    """
    if len(set(slot_materials)) <= 1:
        return np.full(len(polygons), slot_materials[0] if slot_materials else 0, np.int32)
    slot = np.clip(_polygon_values(me, "material_index", np.int32), 0, len(slot_materials) - 1)
    return take(np.asarray(slot_materials, np.int32)[slot], polygons)


def _shading_normals(me, vertices, corners, triangles, polygons) -> CornerTable:
    """Shading normals of the triangle corners, as Cycles shades them.

    Cycles shades a smooth triangle with the vertex normals and a flat one (a face of
    Shade Flat) with its own geometric normal; only sharp edges or custom normals make
    it read ``corner_normals`` (it asks for Blender's normals domain with sharp faces
    handled by the renderer).  So a mesh whose faces are all smooth, all flat, or a mix
    of both without sharp edges gets vertex normals on its smooth triangles and the
    triangle's normal on its flat ones (measured on a non-planar quad: Cycles' Normal is
    its True Normal, not the polygon's normal; on a quad beside a smooth one, the
    vertex normals include the flat face); a degenerate triangle keeps its polygon's.
    """
    domain = me.normals_domain
    if domain == "CORNER" and not me.has_custom_normals and not _any(me, "sharp_edge", "EDGE"):
        domain = "MIXED"
    if domain == "CORNER":
        return CornerTable(_get(me.corner_normals, "vector", np.float32,
                                len(me.loops) * 3).reshape(-1, 3), corners)
    vertex = _get(me.vertex_normals, "vector", np.float32, len(me.vertices) * 3).reshape(-1, 3)
    if domain == "POINT":
        return CornerTable(vertex, triangles)
    p = vertices.astype(np.float64)[triangles]
    flat = cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    length = lengths(flat)[:, None]
    polygon = _get(me.polygon_normals, "vector", np.float32, len(me.polygons) * 3).reshape(-1, 3)
    flat = np.where(length > 0.0, flat / np.where(length > 0.0, length, 1.0), polygon[polygons])
    own = _face_corners(np.arange(len(triangles)))
    if domain == "FACE":
        return CornerTable(flat.astype(np.float32), own)
    sharp = _polygon_values(me, "sharp_face", bool)[polygons]
    return CornerTable(np.concatenate([vertex, flat.astype(np.float32)]),
                       np.where(sharp[:, None], len(vertex) + own, triangles))


def _any(me, name, domain) -> bool:
    """Whether a boolean attribute of ``domain`` is True anywhere."""
    attr = me.attributes.get(name)
    if attr is None or attr.domain != domain:
        return False
    n = len(attr.data)
    return bool(n and _get(attr.data, "value", bool, n).any())


def _face_corners(polygons):
    """(T, 3) polygon index of every triangle corner (a view, no copy)."""
    return np.broadcast_to(polygons[:, None], (len(polygons), 3))


def _render_uv_layer(me):
    """The UV map Cycles uses as the default UV: the active *render* map, else the active one."""
    for layer in me.uv_layers:
        if layer.active_render:
            return layer
    return me.uv_layers.active


# Attribute data types the shader nodes can read, and their component counts.
_ATTRIBUTE_TYPES = {"FLOAT": 1, "INT": 1, "BOOLEAN": 1, "INT8": 1, "FLOAT2": 2, "INT32_2D": 2,
                    "FLOAT_VECTOR": 3, "FLOAT_COLOR": 4, "BYTE_COLOR": 4, "QUATERNION": 4}
_VALUE_FIELD = {1: "value", 2: "vector", 3: "vector", 4: "color"}


def object_random_id(name: str) -> int:
    """The random id Cycles gives an object that is not an instance (blender/object.cpp):
    hash_uint2 of the hash of the object's name (a signed-char string hash) and 0."""
    h = 0
    for byte in name.encode("utf-8"):
        h = (h * 37 + (byte - 256 if byte >= 128 else byte)) & 0xFFFFFFFF
    return hash_uint2(h, 0)


def _corner_attributes(me, corners, triangles, polygons, wanted) -> dict:
    """Every UV map and colour attribute, and the wanted generic attributes, of the
    triangle corners: name -> CornerTable of C components.  Byte colours come out linear
    (Blender decodes them per corner, as Cycles does before interpolating).

    ``corners``, ``triangles``: (T, 3) corner and vertex index of every triangle corner;
    ``polygons``: (T,) polygon of every triangle."""
    out = {}
    for layer in me.uv_layers:
        uv = _get(layer.uv, "vector", np.float32, len(me.loops) * 2).reshape(-1, 2)
        out[layer.name] = CornerTable(uv, corners)
    colors = {a.name for a in me.color_attributes}
    for attr in me.attributes:
        name = attr.name
        if name in out or name.startswith(".") or (name not in colors and name not in wanted):
            continue
        size = _ATTRIBUTE_TYPES.get(attr.data_type)
        domain = {"POINT": triangles, "CORNER": corners, "FACE": _face_corners(polygons)}.get(attr.domain)
        if size is None or domain is None:
            continue
        count = len(attr.data)
        if attr.data_type in ("FLOAT_COLOR", "BYTE_COLOR"):
            field_name = "color"
        elif attr.data_type == "QUATERNION":
            field_name = "value"
        else:
            field_name = _VALUE_FIELD[size]
        values = _get(attr.data, field_name, np.float32, count * size).reshape(count, size)
        out[name] = CornerTable(values, domain)
    default = getattr(me.color_attributes, "default_color_name", "")
    if default in colors and default in out:
        out[DEFAULT_COLOR_ATTRIBUTE] = out[default]
    return out


def _derived_attributes(me, vertices, triangles, polygons, wanted) -> dict:
    """The attributes Cycles derives from the mesh for the Geometry node that some material
    reads (``wanted``): Pointiness per vertex, Random Per Island per triangle; and for true
    displacement (``mcengine.displacement``) the vertex normals and which faces are smooth."""
    out = {}
    if VERTEX_NORMAL_ATTRIBUTE in wanted:
        normals = _get(me.vertex_normals, "vector", np.float32, len(vertices) * 3).reshape(-1, 3)
        out[VERTEX_NORMAL_ATTRIBUTE] = CornerTable(normals, triangles)
        smooth = ~_polygon_values(me, "sharp_face", bool)[polygons]
        out[SMOOTH_ATTRIBUTE] = CornerTable(smooth.astype(np.float32)[:, None],
                                            _face_corners(np.arange(len(triangles))))
    names = GEOMETRY_ATTRIBUTES
    if names["Pointiness"] in wanted or names["Random Per Island"] in wanted:
        edges = _get(me.edges, "vertices", np.int32, len(me.edges) * 2).reshape(-1, 2)
    if names["Pointiness"] in wanted:
        normals = _get(me.vertex_normals, "vector", np.float32, len(vertices) * 3).reshape(-1, 3)
        values = pointiness(vertices, normals, edges)
        out[names["Pointiness"]] = CornerTable(values[:, None], triangles)
    if names["Random Per Island"] in wanted:
        values = random_per_island(len(vertices), edges, triangles[:, 0])
        out[names["Random Per Island"]] = CornerTable(values[:, None], _face_corners(np.arange(len(triangles))))
    return out


def _add_tangents(me, vertices, triangles, normals, maps, default_layer, attributes) -> str:
    """Add the MikkTSpace tangent and sign of each UV map in ``maps`` ("" the default map)
    to ``attributes`` as ``tangent:<map>`` (4 components, object space, per corner).

    Cycles runs MikkTSpace on the triangles (``loop_triangles``), with the mesh's shading
    normals (flat faces: each triangle's own normal), so the tangents are those Blender's
    MikkTSpace computes for a mesh of those triangles (``kernels.tangents``: the same bits as
    ``Mesh.calc_tangents`` on such a mesh, but computed in one order, where Blender's
    threads make them vary in the last bit on meshes of more than 10,000 faces); on a mesh of
    quads it would pair the triangles differently.  The default map of a mesh without UV
    maps is, as in Cycles (blender/mesh.cpp, mikk_compute_tangents), the generated
    coordinates mapped to a sphere: ``sphere_uv`` of each vertex's object-space position.  A
    named map the mesh lacks is left out, as in Cycles (the normal stays unchanged).  Returns
    what went wrong, for a note: "" or ``SPHERE_SEAM``, a mesh the sphere mapping's seam
    crosses."""
    layers = {}
    for name in maps:
        layer = default_layer if name == "" else me.uv_layers.get(name)
        if layer is not None:
            layers[name] = attributes[layer.name]
        elif name == "":
            layers[name] = CornerTable(sphere_uv(vertices), triangles)
    if not layers:
        return ""
    note = ""
    if "" in layers and default_layer is None:
        u = layers[""].corners(0, len(triangles))[:, :, 0]
        if np.any(u.max(axis=1) - u.min(axis=1) > 0.5):     # a triangle spans the seam
            note = SPHERE_SEAM
    t = len(triangles)
    corner_normals = normals.corners(0, t)
    for name, table in layers.items():
        values = mikktspace(vertices, triangles, corner_normals, table.corners(0, t))
        attributes[TANGENT_PREFIX + name] = CornerTable(values, np.arange(3 * t).reshape(t, 3))
    return note


def _texspace(ob) -> np.ndarray:
    """The mesh's texture space (centre, half-size) in object space, as Cycles reads it."""
    data = ob.data
    loc = np.array(getattr(data, "texspace_location", (0.0, 0.0, 0.0)), np.float64)
    size = np.array(getattr(data, "texspace_size", (1.0, 1.0, 1.0)), np.float64)
    return auto_texspace_size(np.stack([loc, size]))
