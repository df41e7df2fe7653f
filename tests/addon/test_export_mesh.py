"""Mesh export: world-space triangles, normals, UVs, instancing, materials per triangle."""
import importlib
import math

import bpy
import numpy as np
import pytest

from mcengine.kernels.state import VIS_ALL, VIS_CAMERA, VIS_DIFFUSE, VIS_GLOSSY, VIS_SHADOW, VIS_TRANSMISSION
from mcengine.shaders import DEFAULT_COLOR_ATTRIBUTE
from mcengine.tessellation import corner_triangles

from .helpers import CUBE_FACES, CUBE_VERTS, export_scene, new_mesh_object

TRI = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]


def corners(geometry):
    """(T, 3, 3) world positions of the triangle corners."""
    return geometry.vertices[geometry.triangles].astype(np.float64)


def geometric_normals(geometry):
    p = corners(geometry)
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def test_triangle_with_known_transform(scene, fake_session):
    ob = new_mesh_object("Tri", TRI, [(0, 1, 2)])
    ob.location = (1, 2, 3)
    ob.rotation_euler = (0, 0, math.pi / 2)
    ob.scale = (2, 2, 2)
    g = export_scene(fake_session).geometry
    assert g.num_triangles == 1
    np.testing.assert_allclose(corners(g)[0], [(1, 2, 3), (1, 4, 3), (-1, 2, 3)], atol=1e-6)
    np.testing.assert_allclose(g.corner_normals()[0], [(0, 0, 1)] * 3, atol=1e-6)
    np.testing.assert_array_equal(g.uvs, np.zeros((1, 3, 2)))
    assert g.material_index.tolist() == [0]
    assert g.object_names == ["Tri"]


def _check_closed_cube(g, center):
    """Outward geometric normals that agree with the flat shading normals."""
    p = corners(g)
    ng = geometric_normals(g)
    outward = np.einsum("ti,ti->t", ng, p.mean(axis=1) - center)
    assert np.all(outward > 0), "some triangles face inwards"
    shading = g.corner_normals().astype(np.float64)
    for k in range(3):
        np.testing.assert_allclose(shading[:, k], ng, atol=1e-5)


@pytest.mark.parametrize("scale", [(1, 2, 3), (-1, 2, 3), (-1, -1, -1)])
def test_cube_positions_winding_and_normals(scene, fake_session, scale):
    ob = new_mesh_object("Cube", CUBE_VERTS, CUBE_FACES)
    ob.location = (0.5, -1, -5)
    ob.rotation_euler = (0.5, 0, 0.8)
    ob.scale = scale
    bpy.context.view_layer.update()
    m = np.array(ob.matrix_world)
    g = export_scene(fake_session).geometry
    assert g.num_triangles == 12
    expected = {tuple(np.round(m[:3, :3] @ v + m[:3, 3], 5)) for v in CUBE_VERTS}
    assert {tuple(np.round(v, 5)) for v in g.vertices.astype(np.float64)} == expected
    _check_closed_cube(g, m[:3, 3])
    # the faces keep their areas: 2x2 local squares spanned by the scaled axes
    a = np.linalg.norm(m[:3, :3], axis=0) * 2
    area = np.linalg.norm(np.cross(corners(g)[:, 1] - corners(g)[:, 0],
                                   corners(g)[:, 2] - corners(g)[:, 0]), axis=1).sum() / 2
    assert area == pytest.approx(2 * (a[0] * a[1] + a[1] * a[2] + a[0] * a[2]), rel=1e-5)


def test_normals_use_the_inverse_transpose(scene, fake_session):
    """A slanted face under non-uniform scale: the normal stays perpendicular to the face."""
    ob = new_mesh_object("Slant", [(0, 0, 0), (1, 0, 0), (0, 1, 1)], [(0, 1, 2)])
    ob.scale = (1, 1, 3)
    g = export_scene(fake_session).geometry
    np.testing.assert_allclose(g.corner_normals()[0, 0], geometric_normals(g)[0], atol=1e-6)
    np.testing.assert_allclose(g.corner_normals()[0, 0], np.array([0, -3, 1]) / math.sqrt(10), atol=1e-6)


def test_smooth_shading_normals(scene, fake_session):
    """A symmetric roof, shaded smooth: the ridge normal is straight up, the eaves keep the face normals."""
    verts = [(-1, -1, 0), (-1, 1, 0), (0, 1, 1), (0, -1, 1), (1, -1, 0), (1, 1, 0)]
    ob = new_mesh_object("Roof", verts, [(0, 3, 2, 1), (3, 4, 5, 2)])
    ob.data.shade_smooth()
    g = export_scene(fake_session).geometry
    p = corners(g)
    n = g.corner_normals().astype(np.float64)
    ridge = np.isclose(p[..., 2], 1)
    np.testing.assert_allclose(n[ridge], np.tile([0, 0, 1], (ridge.sum(), 1)), atol=1e-6)
    left = ~ridge & (p[..., 0] < 0)
    np.testing.assert_allclose(n[left], np.tile(np.array([-1, 0, 1]) / math.sqrt(2), (left.sum(), 1)),
                               atol=1e-6)


@pytest.mark.parametrize("shading", ["smooth", "flat"])
def test_normals_are_stored_once_per_vertex_or_face(scene, fake_session, shading):
    """Vertex normals take one row per exported vertex and the corners' rows are the triangles
    themselves (no index of their own); face normals one row per triangle.  A plain and a
    mirrored cube: each corner gets its own cube's outward normal (smooth: from the cube's
    centre through the vertex; flat: the face's)."""
    ob = new_mesh_object("Cube", CUBE_VERTS, CUBE_FACES)
    if shading == "smooth":
        ob.data.shade_smooth()
    twin = ob.copy()
    twin.location, twin.scale = (5, 0, 0), (-1, 2, 1)
    bpy.context.scene.collection.objects.link(twin)
    g = export_scene(fake_session).geometry
    n = g.corner_normals().astype(np.float64)
    if shading == "smooth":
        assert g.normal_index is g.triangles and len(g.normals) == len(g.vertices) == 16
    else:
        assert len(g.normals) == g.num_triangles == 24
        assert np.all(g.normal_index == g.normal_index[:, :1])
    for obj, center in enumerate([(0, 0, 0), (5, 0, 0)]):
        mine = g.object_index == obj
        if shading == "flat":
            _check_closed_cube(_subset(g, mine), np.array(center))
            continue
        outward = corners(g)[mine] - center
        scale = np.array([1, 1, 1]) if obj == 0 else np.array([1, 2, 1])
        expected = outward / scale ** 2            # the inverse transpose of the cube's scale
        expected /= np.linalg.norm(expected, axis=-1, keepdims=True)
        np.testing.assert_allclose(n[mine], expected, atol=1e-6)


@pytest.mark.parametrize("domain", ["CORNER", "MIXED"])
def test_normal_rows_give_the_corner_normals_computed_per_corner(scene, fake_session, addon,
                                                                 monkeypatch, domain):
    """Corner normals (sharp edges) and vertex normals beside flat faces, on a plain and a
    mirrored instance: the rows of each mesh's normal table, transformed once each and read
    through the corners' index, are the bits of normals transformed corner by corner (the
    layout of meshes with a zero-length normal), in fewer rows."""
    ob = new_mesh_object("Cube", CUBE_VERTS, CUBE_FACES)
    me = ob.data
    me.shade_smooth()
    if domain == "CORNER":
        for edge in me.edges:
            edge.use_edge_sharp = set(edge.vertices).issubset(me.polygons[0].vertices)
    else:
        me.polygons[0].use_smooth = False
    assert me.normals_domain == "CORNER"       # the export reads vertex and face normals for MIXED
    twin = ob.copy()
    twin.location, twin.rotation_euler, twin.scale = (5, 0, 0), (0.3, 0.2, 0.1), (-1, 2, 1)
    bpy.context.scene.collection.objects.link(twin)
    table = export_scene(fake_session).geometry
    mesh_module = importlib.import_module(f"{addon.__name__}.export.mesh")
    monkeypatch.setattr(mesh_module, "_per_corner_normals", lambda mesh, matrices: True)
    per_corner = export_scene(fake_session).geometry
    assert len(per_corner.normals) == 3 * per_corner.num_triangles > len(table.normals)
    corner = per_corner.corner_normals()
    assert len({tuple(c) for tri in corner for c in tri}) > 12     # corners of a face differ
    assert table.corner_normals().tobytes() == corner.tobytes()


def _subset(g, mine):
    """The triangles ``mine`` of a geometry, with their own corner normals (per corner)."""
    from mcengine.scene import Geometry
    return Geometry(vertices=g.vertices, triangles=g.triangles[mine],
                    normals=g.corner_normals()[mine])


@pytest.mark.parametrize("shading,domain", [("flat", "FACE"), ("smooth", "POINT"),
                                            ("sharp edges", "CORNER")])
def test_shading_normals_equal_blender_corner_normals(scene, fake_session, shading, domain):
    ob = new_mesh_object("Cube", CUBE_VERTS, CUBE_FACES)
    me = ob.data
    if shading != "flat":
        me.shade_smooth()
    if shading == "sharp edges":  # the edges around one face: its corners get the face normal
        for edge in me.edges:
            edge.use_edge_sharp = set(edge.vertices).issubset(me.polygons[0].vertices)
    assert me.normals_domain == domain
    loops = _blender_triangles(me)[0]
    corner = np.empty(len(me.loops) * 3, np.float32)
    me.corner_normals.foreach_get("vector", corner)
    g = export_scene(fake_session).geometry
    np.testing.assert_allclose(g.corner_normals().reshape(-1, 3), corner.reshape(-1, 3)[loops], atol=1e-6)


def _blender_triangles(me):
    """Blender's own triangles of ``me``: (T * 3,) corners and (T,) faces."""
    t = len(me.loop_triangles)
    loops, faces = np.empty(3 * t, np.int32), np.empty(t, np.int32)
    me.loop_triangles.foreach_get("loops", loops)
    me.loop_triangle_polygons.foreach_get("value", faces)
    return loops, faces


def _quad_mesh(kind, rng):
    """Vertex and face lists of 20,000 faces with fresh vertices each: quads of random
    corners (two thirds are cut along 1-3), nearly flat quads whose third corner lies on the
    first two's segment to within rounding (Blender's float32 test and a float64 one
    disagree on some), or triangles and quads mixed, on integer coordinates (degenerate
    quads, whose test is exactly 0: not cut along 1-3)."""
    n = 20_000
    if kind == "triangles and quads":
        sizes = rng.integers(3, 5, n)
    else:
        sizes = np.full(n, 4)
    verts = rng.normal(size=(sizes.sum(), 3)).astype(np.float32)
    if kind == "triangles and quads":       # small integers: many tests come out exactly 0
        verts = rng.integers(-2, 3, size=verts.shape).astype(np.float32)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    if kind == "nearly flat quads":
        q = verts.reshape(n, 4, 3)
        q[:] = q[:, :1] + np.float32(1e-3) * q
        t = rng.random((n, 1)).astype(np.float32)
        q[:, 2] = q[:, 0] + (q[:, 1] - q[:, 0]) * t + np.float32(1e-9) * rng.normal(size=(n, 3))
    return verts, [tuple(range(s, s + k)) for s, k in zip(starts, sizes)]


@pytest.mark.parametrize("kind", ["random quads", "nearly flat quads", "triangles and quads"])
def test_triangles_of_triangles_and_quads_are_blenders(kind):
    """``corner_triangles`` cuts every quad along the diagonal Blender cuts it along (its
    float32 test, to the bit) and numbers triangles and corners as ``loop_triangles``."""
    verts, faces = _quad_mesh(kind, np.random.default_rng(11))
    me = bpy.data.meshes.new(kind)
    me.from_pydata(verts.tolist(), [], faces)
    corner_verts = np.empty(len(me.loops), np.int32)
    me.attributes[".corner_vert"].data.foreach_get("value", corner_verts)
    positions = np.empty(3 * len(me.vertices), np.float32)
    me.vertices.foreach_get("co", positions)
    starts = np.empty(len(me.polygons), np.int32)
    me.polygons.foreach_get("loop_start", starts)
    loops, tri_faces = _blender_triangles(me)
    got = corner_triangles(starts, len(me.loops), corner_verts, positions.reshape(-1, 3))
    np.testing.assert_array_equal(got[0], loops)
    np.testing.assert_array_equal(got[1], tri_faces)
    quads = starts[np.diff(starts, append=len(me.loops)) == 4]
    cut_13 = loops.reshape(-1, 3)[quads - 2 * np.searchsorted(starts, quads), 2] == quads + 3
    assert 0.1 < cut_13.mean() < 0.9
    if kind == "nearly flat quads":
        p = positions.reshape(-1, 3).astype(np.float64)[corner_verts[quads[:, None] + np.arange(4)]]
        a = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        b = np.cross(p[:, 3] - p[:, 0], p[:, 2] - p[:, 0])
        assert np.sum(((a * b).sum(1) > 0) != cut_13) > 0


def test_meshes_with_ngons_get_blenders_triangles(scene, fake_session):
    """Faces of 5 or more corners need Blender's polygon fill: such a mesh is exported with
    Blender's triangles (a concave pentagon and quads), a mesh of quads with its own."""
    ngon = new_mesh_object("Ngon", [(0, 0, 0), (2, 0, 0), (2, 2, 0), (1, 0.5, 0), (0, 2, 0),
                                    (3, 0, 0), (3, 2, 1)], [(0, 1, 2, 3, 4), (1, 5, 6, 2)])
    quads = new_mesh_object("Quads", [(0, 0, 0), (2, 0, 0), (2, 2, 0), (1.5, 0.5, 0)], [(0, 1, 2, 3)])
    quads.location = (0, 0, 3)
    g = export_scene(fake_session).geometry
    expected = []
    for ob in (ngon, quads):
        me = ob.data
        corner_verts = np.array([loop.vertex_index for loop in me.loops], np.int32)
        expected.append(corner_verts[_blender_triangles(me)[0]].reshape(-1, 3))
    assert g.triangles.shape == (7, 3)
    np.testing.assert_array_equal(g.triangles[:5], expected[0])
    np.testing.assert_array_equal(g.triangles[5:] - len(ngon.data.vertices), expected[1])
    np.testing.assert_array_equal(expected[1], [[0, 1, 3], [1, 2, 3]])   # concave: cut along 1-3


def test_a_uv_map_every_mesh_renders_with_is_the_default_uvs_array(scene, fake_session):
    """Two meshes whose active render UV map is "UVMap" (and one with no UV map): the
    attribute "UVMap" is the geometry's default UVs, one array; a second map stays its own,
    as does "UVMap" once a mesh renders with another map."""
    a = new_mesh_object("A", TRI, [(0, 1, 2)])
    b = new_mesh_object("B", TRI, [(0, 1, 2)])
    b.location = (0, 3, 0)
    new_mesh_object("Bare", TRI, [(0, 1, 2)]).location = (0, 6, 0)
    for ob, value in ((a, 0.25), (b, 0.75)):
        ob.data.uv_layers.new(name="UVMap").uv.foreach_set("vector", [value] * 6)
    a.data.uv_layers.new(name="Second").uv.foreach_set("vector", [0.5] * 6)
    g = export_scene(fake_session).geometry
    assert g.attributes["UVMap"] is g.uvs and g.attributes["Second"] is not g.uvs
    np.testing.assert_array_equal(g.uvs[:, 0, 0], [0.25, 0.75, 0.0])
    np.testing.assert_array_equal(g.attributes["Second"][:, 0, 0], [0.5, 0.0, 0.0])
    a.data.uv_layers["Second"].active_render = True
    g = export_scene(fake_session).geometry
    assert g.attributes["UVMap"] is not g.uvs
    np.testing.assert_array_equal(g.uvs[:, 0, 0], [0.5, 0.75, 0.0])
    np.testing.assert_array_equal(g.attributes["UVMap"][:, 0, 0], [0.25, 0.75, 0.0])


def test_uvs_come_from_the_active_render_uv_map(scene, fake_session):
    ob = new_mesh_object("Tri", TRI, [(0, 1, 2)])
    first, second = ob.data.uv_layers.new(name="First"), ob.data.uv_layers.new(name="Second")
    first.uv.foreach_set("vector", [0.0] * 6)
    second.uv.foreach_set("vector", [0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    second.active_render = True
    g = export_scene(fake_session).geometry
    np.testing.assert_allclose(g.uvs[0], [(0.1, 0.2), (0.3, 0.4), (0.5, 0.6)], atol=1e-7)


def test_modifiers_are_applied(scene, fake_session):
    ob = new_mesh_object("Tri", TRI, [(0, 1, 2)])
    array = ob.modifiers.new("Array", "ARRAY")
    array.count = 3  # relative offset 1 along x: the triangle is 1 wide
    g = export_scene(fake_session).geometry
    assert g.num_triangles == 3
    assert sorted(corners(g)[:, :, 0].min(axis=1).round(6).tolist()) == [0, 1, 2]


def test_objects_hidden_from_render_are_skipped(scene, fake_session):
    new_mesh_object("Shown", TRI, [(0, 1, 2)])
    hidden = new_mesh_object("Hidden", CUBE_VERTS, CUBE_FACES)
    hidden.hide_render = True
    g = export_scene(fake_session).geometry
    assert g.object_names == ["Shown"] and g.num_triangles == 1


@pytest.fixture
def count_mesh_reads(addon, monkeypatch):
    calls = []
    real = addon.export.mesh.read_local_mesh

    def counting(ob, slots, wanted=(), tangents=()):
        calls.append(ob.name)
        return real(ob, slots, wanted, tangents)

    monkeypatch.setattr(addon.export.mesh, "read_local_mesh", counting)
    return calls


def test_collection_instances_are_expanded_and_read_once(scene, fake_session, count_mesh_reads):
    col = bpy.data.collections.new("Assets")  # not linked to the scene: only its instances render
    new_mesh_object("Tri", TRI, [(0, 1, 2)], collection=col)
    for i, x in enumerate((0, 10, 20)):
        empty = bpy.data.objects.new(f"Inst{i}", None)
        empty.instance_type, empty.instance_collection = "COLLECTION", col
        empty.location = (x, 0, 0)
        scene.collection.objects.link(empty)
    g = export_scene(fake_session).geometry
    assert g.num_triangles == 3
    assert sorted(corners(g)[:, 0, 0].round(6).tolist()) == [0, 10, 20]
    assert sorted(g.object_names) == ["Inst0/Tri", "Inst1/Tri", "Inst2/Tri"]
    assert count_mesh_reads == ["Tri"]


def test_vertex_instancing(scene, fake_session):
    parent = new_mesh_object("Dots", [(0, 0, 5), (3, 0, 5)], [])
    parent.instance_type = "VERTS"
    child = new_mesh_object("Tri", TRI, [(0, 1, 2)])
    child.parent = parent
    g = export_scene(fake_session).geometry
    assert g.num_triangles == 2
    assert sorted(map(tuple, corners(g)[:, 0].round(6))) == [(0, 0, 5), (3, 0, 5)]


def _instance_on_points_group(count):
    ng = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    ng.interface.new_socket(name="Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    ng.interface.new_socket(name="Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    ng.nodes.new("NodeGroupInput")
    out = ng.nodes.new("NodeGroupOutput")
    line = ng.nodes.new("GeometryNodeMeshLine")  # points at z = 0, 1, 2, ...
    line.inputs["Count"].default_value = count
    cube = ng.nodes.new("GeometryNodeMeshCube")  # 1 m cube centred on its point
    iop = ng.nodes.new("GeometryNodeInstanceOnPoints")
    ng.links.new(line.outputs["Mesh"], iop.inputs["Points"])
    ng.links.new(cube.outputs["Mesh"], iop.inputs["Instance"])
    ng.links.new(iop.outputs["Instances"], out.inputs["Geometry"])
    return ng


def test_geometry_nodes_instances_are_expanded_and_read_once(scene, fake_session, count_mesh_reads):
    ob = new_mesh_object("Scatter", [], [])
    ob.modifiers.new("GN", "NODES").node_group = _instance_on_points_group(3)
    ob.location = (1, 0, 0)
    g = export_scene(fake_session).geometry
    assert g.num_triangles == 3 * 12
    centers = [corners(g)[g.object_index == i].reshape(-1, 3).mean(axis=0) for i in range(3)]
    assert sorted(map(tuple, np.round(centers, 5))) == [(1, 0, 0), (1, 0, 1), (1, 0, 2)]
    assert len(count_mesh_reads) == 2  # the holder's own (empty) mesh, then the cube once


def test_multi_material_mesh_and_material_table(scene, fake_session):
    red, green = bpy.data.materials.new("Red"), bpy.data.materials.new("Green")
    verts = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (2, 0, 0), (3, 0, 0), (2, 1, 0), (4, 0, 0), (5, 0, 0), (4, 1, 0)]
    ob = new_mesh_object("Multi", verts, [(0, 1, 2), (3, 4, 5), (6, 7, 8)], materials=[red, green])
    ob.data.materials.append(None)  # an empty third slot
    ob.data.polygons.foreach_set("material_index", [1, 0, 7])   # 7: the last slot
    other = new_mesh_object("Other", TRI, [(0, 1, 2)], materials=[green])
    other.data.polygons.foreach_set("material_index", [4])   # out of range: the last slot
    other.location = (0, 5, 0)
    new_mesh_object("Bare", TRI, [(0, 1, 2)]).location = (0, 9, 0)
    desc = export_scene(fake_session)
    names = [m.name for m in desc.materials]
    assert sorted(names) == ["Green", "Red", "default surface"]  # de-duplicated
    g = desc.geometry
    per_tri = {}
    for t in range(g.num_triangles):
        key = (g.object_names[g.object_index[t]], round(float(corners(g)[t, 0, 0])))
        per_tri[key] = names[g.material_index[t]]
    assert per_tri == {("Multi", 0): "Green", ("Multi", 2): "Red", ("Multi", 4): "default surface",
                       ("Other", 0): "Green", ("Bare", 0): "default surface"}
    default = desc.materials[names.index("default surface")]     # a default Principled BSDF
    assert [(n.type, n.inputs) for n in default.nodes] == [("BsdfPrincipled", {})]


def test_material_override_replaces_every_slot(scene, fake_session):
    """View Layer > Material Override: every slot of every mesh, empty ones and objects
    without slots included, renders with that material (Cycles' find_used_shaders)."""
    red, green, clay = (bpy.data.materials.new(n) for n in ("Red", "Green", "Clay"))
    ob = new_mesh_object("Multi", TRI, [(0, 1, 2)], materials=[red, green])
    ob.data.materials.append(None)
    new_mesh_object("Bare", TRI, [(0, 1, 2)]).location = (0, 9, 0)
    bpy.context.view_layer.material_override = clay
    desc = export_scene(fake_session)
    names = [m.name for m in desc.materials]
    assert {names[i] for i in desc.geometry.material_index} == {"Clay"}
    assert "Red" not in names and "Green" not in names


def test_unit_scale_converts_positions_to_metres(scene, fake_session):
    scene.unit_settings.scale_length = 0.01
    ob = new_mesh_object("Tri", TRI, [(0, 1, 2)])
    ob.location = (100, 200, 300)
    scene.camera.data.clip_start, scene.camera.data.clip_end = 10, 5000
    desc = export_scene(fake_session)
    np.testing.assert_allclose(corners(desc.geometry)[0], [(1, 2, 3), (1.01, 2, 3), (1, 2.01, 3)], atol=1e-6)
    assert (desc.camera.clip_start, desc.camera.clip_end) == pytest.approx((0.1, 50))
    scene.unit_settings.system = "NONE"  # Blender ignores scale_length without a unit system
    np.testing.assert_allclose(corners(export_scene(fake_session).geometry)[0, 0], (100, 200, 300))


def test_curves_and_text_are_exported_once(scene, fake_session):
    curve = bpy.data.curves.new("Ring", "CURVE")
    curve.dimensions, curve.extrude = "3D", 0.2
    spline = curve.splines.new("POLY")
    spline.points.add(3)
    spline.points.foreach_set("co", [0, 0, 0, 1, 1, 0, 0, 1, 1, 1, 0, 1, 0, 1, 0, 1])
    spline.use_cyclic_u = True
    scene.collection.objects.link(bpy.data.objects.new("Ring", curve))
    g = export_scene(fake_session).geometry
    assert g.num_triangles == 8  # 4 extruded edges, 2 triangles each: not doubled


def test_one_failing_object_is_skipped_with_a_warning(scene, fake_session, addon, monkeypatch):
    new_mesh_object("Good", TRI, [(0, 1, 2)])
    new_mesh_object("Bad", TRI, [(0, 1, 2)]).location = (5, 0, 0)
    real = addon.export.mesh.read_local_mesh

    def failing(ob, slots, wanted=(), tangents=()):
        if ob.name == "Bad":
            raise ValueError("broken mesh")
        return real(ob, slots, wanted, tangents)

    monkeypatch.setattr(addon.export.mesh, "read_local_mesh", failing)
    desc = export_scene(fake_session)
    assert desc.geometry.object_names == ["Good"]
    assert "object 'Bad' skipped: ValueError: broken mesh" in desc.warnings


def test_ray_visibility_is_exported_per_object_and_instance(scene, fake_session):
    """Object > Visibility > Ray Visibility as VIS_* bits, an instance's ANDed with its
    instancer's (Cycles' blender/object.cpp); nothing is warned."""
    new_mesh_object("Plain", TRI, [(0, 1, 2)])
    ghost = new_mesh_object("Ghost", TRI, [(0, 1, 2)])
    ghost.visible_camera = False
    shy = new_mesh_object("Shy", TRI, [(0, 1, 2)])
    shy.visible_shadow, shy.visible_transmission = False, False
    assets = bpy.data.collections.new("Assets")          # instanced only
    new_mesh_object("Tri", TRI, [(0, 1, 2)], collection=assets).visible_glossy = False
    empty = bpy.data.objects.new("Inst", None)
    empty.instance_type, empty.instance_collection = "COLLECTION", assets
    empty.visible_diffuse = False
    scene.collection.objects.link(empty)
    desc = export_scene(fake_session)
    g = desc.geometry
    visibility = dict(zip(g.object_names, g.visibility().tolist()))
    assert visibility == {"Plain": VIS_ALL, "Ghost": VIS_ALL & ~VIS_CAMERA,
                          "Shy": VIS_ALL & ~(VIS_SHADOW | VIS_TRANSMISSION),
                          "Inst/Tri": VIS_ALL & ~(VIS_GLOSSY | VIS_DIFFUSE)}
    assert not [w for w in desc.warnings if "visib" in w.lower()]


def test_instances_of_one_object_keep_their_own_instancers_settings(scene, fake_session):
    """One object rendered as itself and instanced by two empties: what the instances share
    is read once per object and instancer (MeshCollector._source), so each entry keeps
    its instancer's Ray Visibility, and each instance its own random id."""
    assets = bpy.data.collections.new("Assets")
    scene.collection.children.link(assets)               # "Tri" renders as itself too
    new_mesh_object("Tri", TRI, [(0, 1, 2)], collection=assets).visible_glossy = False
    for name, switch in (("A", "visible_diffuse"), ("B", "visible_camera"), ("C", "visible_camera")):
        empty = bpy.data.objects.new(name, None)
        empty.instance_type, empty.instance_collection = "COLLECTION", assets
        setattr(empty, switch, False)
        scene.collection.objects.link(empty)
    g = export_scene(fake_session).geometry
    visibility = dict(zip(g.object_names, g.visibility().tolist()))
    assert visibility == {"Tri": VIS_ALL & ~VIS_GLOSSY,
                          "A/Tri": VIS_ALL & ~(VIS_GLOSSY | VIS_DIFFUSE),
                          "B/Tri": VIS_ALL & ~(VIS_GLOSSY | VIS_CAMERA),
                          "C/Tri": VIS_ALL & ~(VIS_GLOSSY | VIS_CAMERA)}
    assert len(set(g.object_info[:, 0].tolist())) == 4


def test_each_objects_shadow_terminator_offsets_are_exported(scene, fake_session):
    """Geometry and Shading Offset per object (what they render: test_bump_nodes.py)."""
    new_mesh_object("Default", TRI, [(0, 1, 2)])
    new_mesh_object("Geometry", TRI, [(0, 1, 2)]).shadow_terminator_geometry_offset = 0.3
    new_mesh_object("Shading", TRI, [(0, 1, 2)]).shadow_terminator_shading_offset = 0.2
    desc = export_scene(fake_session)
    g = desc.geometry
    offsets = dict(zip(g.object_names, g.terminator_offsets().tolist()))
    np.testing.assert_allclose([offsets["Default"], offsets["Geometry"], offsets["Shading"]],
                               [[0.1, 0.0], [0.3, 0.0], [0.1, 0.2]], rtol=1e-6)
    assert not [w for w in desc.warnings if "terminator" in w]


def test_particle_hair_is_named(scene, fake_session):
    """A particle system rendered as strands (Render As: Path, what Cycles draws as hair) is
    named in a warning; one rendered as objects is not (its instances are exported)."""
    furry = new_mesh_object("Furry", [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [(0, 1, 2, 3)])
    dotted = new_mesh_object("Dotted", [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [(0, 1, 2, 3)])
    for ob, render_type in ((furry, "PATH"), (dotted, "NONE")):
        ob.modifiers.new("Particles", "PARTICLE_SYSTEM")
        settings = ob.particle_systems[0].settings
        settings.type, settings.count, settings.render_type = "HAIR", 10, render_type
    desc = export_scene(fake_session)
    assert [w for w in desc.warnings if "particle" in w] == [
        "particle hair not supported yet ('Furry'); their strands are not rendered"]


def test_holdout_objects_and_collections_are_exported(scene, fake_session):
    """Object > Visibility > Holdout, a collection's Holdout in the view layer (for its own
    objects and for a collection instance of it: the instancer decides, as in Cycles); the
    shadow catcher is still named in a warning."""
    new_mesh_object("Plain", TRI, [(0, 1, 2)])
    new_mesh_object("Own", TRI, [(0, 1, 2)]).is_holdout = True
    col = bpy.data.collections.new("Masked")
    scene.collection.children.link(col)
    new_mesh_object("InMasked", TRI, [(0, 1, 2)], collection=col)
    bpy.context.view_layer.layer_collection.children["Masked"].holdout = True
    assets = bpy.data.collections.new("Assets")          # instanced only
    new_mesh_object("Tri", TRI, [(0, 1, 2)], collection=assets)
    for name, held in (("InstHeld", True), ("InstShown", False)):
        empty = bpy.data.objects.new(name, None)
        empty.instance_type, empty.instance_collection = "COLLECTION", assets
        empty.is_holdout = held
        scene.collection.objects.link(empty)
    new_mesh_object("Catcher", TRI, [(0, 1, 2)]).is_shadow_catcher = True
    desc = export_scene(fake_session)
    g = desc.geometry
    held = {name: info.holdout for name, info in zip(g.object_names, g.object_pass_info())}
    assert held == {"Plain": False, "Own": True, "InMasked": True, "InstHeld/Tri": True,
                    "InstShown/Tri": False, "Catcher": False}
    assert [w for w in desc.warnings if "holdout" in w] == []
    assert [w for w in desc.warnings if "shadow catcher" in w] == [
        "shadow catcher not supported yet ('Catcher'); these objects render as normal objects"]


def test_indirect_only_collections_are_hidden_from_the_camera(scene, fake_session):
    """A collection set Indirect Only in the view layer: its objects lose camera visibility
    (Cycles' blender/object.cpp); a holdout collection that is also Indirect Only is a
    holdout, as in Cycles, and keeps it."""
    for name, holdout in (("Bounce", False), ("Masked", True)):
        col = bpy.data.collections.new(name)
        scene.collection.children.link(col)
        new_mesh_object(f"In{name}", TRI, [(0, 1, 2)], collection=col)
        layer = bpy.context.view_layer.layer_collection.children[name]
        layer.indirect_only, layer.holdout = True, holdout
    new_mesh_object("Plain", TRI, [(0, 1, 2)])
    desc = export_scene(fake_session)
    g = desc.geometry
    visibility = dict(zip(g.object_names, g.visibility().tolist()))
    assert visibility == {"InBounce": VIS_ALL & ~VIS_CAMERA, "InMasked": VIS_ALL, "Plain": VIS_ALL}
    assert not [w for w in desc.warnings if "indirect" in w]


def _attribute_grid(n=6):
    """A smooth n x n grid with two UV maps (the second renders), a byte colour per corner,
    a float colour per point and a float per face read by its material's Attribute node;
    returns the mesh and those per-vertex colours and per-face values."""
    rng = np.random.default_rng(5)
    grid = bpy.data.meshes.new("Grid")
    verts = [(x, y, 0.1 * ((x * 7 + y * 3) % 5)) for y in range(n + 1) for x in range(n + 1)]
    quads = [(y * (n + 1) + x, y * (n + 1) + x + 1, (y + 1) * (n + 1) + x + 1, (y + 1) * (n + 1) + x)
             for y in range(n) for x in range(n)]
    grid.from_pydata(verts, [], quads)
    grid.shade_smooth()
    for name in ("UVMap", "Second"):
        grid.uv_layers.new(name=name).uv.foreach_set("vector", rng.random(len(grid.loops) * 2))
    grid.uv_layers["Second"].active_render = True
    grid.color_attributes.new("Col", "BYTE_COLOR", "CORNER").data.foreach_set(
        "color", rng.random(len(grid.loops) * 4))
    point_colors = rng.random((len(grid.vertices), 4)).astype(np.float32)
    grid.color_attributes.new("PCol", "FLOAT_COLOR", "POINT").data.foreach_set(
        "color", point_colors.reshape(-1))
    weights = rng.random(len(grid.polygons)).astype(np.float32)
    grid.attributes.new("weight", "FLOAT", "FACE").data.foreach_set("value", weights)
    mat = bpy.data.materials.new("ReadsWeight")
    tree = mat.node_tree
    attr = tree.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "weight"
    tree.links.new(attr.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    grid.materials.append(mat)
    return grid, point_colors, weights


def test_blocks_of_the_transform_do_not_change_the_export(scene, fake_session, addon, monkeypatch):
    """All instances are written block by block (one instance's range of triangles, or whole
    instances); any block size gives the same bytes as one block for everything, attributes
    and per-object data included, and the attributes follow the corners when mirrored
    instances swap them."""
    n = 6
    grid, point_colors, weights = _attribute_grid(n)
    col = bpy.data.collections.new("Assets")
    col.objects.link(bpy.data.objects.new("Grid", grid))
    for i, scale in enumerate([(1, 1, 1), (-1, 2, 1), (0.5, 0.5, 0.5), (1, -1, -1), (2, 1, 1)]):
        empty = bpy.data.objects.new(f"Inst{i}", None)
        empty.instance_type, empty.instance_collection = "COLLECTION", col
        empty.location, empty.rotation_euler, empty.scale = (3 * i, 0, 0), (0.3 * i, 0, 0.2), scale
        scene.collection.objects.link(empty)
    cube = new_mesh_object("Cube", CUBE_VERTS, CUBE_FACES)      # no attributes: zeros there
    cube.location, cube.pass_index = (0, 5, 0), 3
    fields = ("vertices", "triangles", "normals", "normal_index", "uvs", "material_index", "object_index",
              "object_matrix", "object_texspace", "object_info")
    exports = {}
    mesh_module = importlib.import_module(f"{addon.__name__}.export.mesh")
    for block in (1 << 20, 7, 72, 100):     # one block; ranges of one instance; whole instances
        monkeypatch.setattr(mesh_module, "_BLOCK", block)
        g = export_scene(fake_session).geometry
        exports[block] = ([getattr(g, f) for f in fields] + list(g.attributes.values()),
                          (g.object_names, list(g.attributes)))
    g = export_scene(fake_session).geometry
    grid_tris = 5 * 2 * n * n
    assert g.triangles.shape == (grid_tris + 12, 3)
    # The mesh's default colour attribute (the first made, "Col") also under the name a
    # Color Attribute node without one reads.
    assert set(g.attributes) == {"UVMap", "Second", "Col", "PCol", "weight", DEFAULT_COLOR_ATTRIBUTE}
    np.testing.assert_array_equal(g.attributes[DEFAULT_COLOR_ATTRIBUTE], g.attributes["Col"])
    for block, (arrays, names) in exports.items():
        assert names == exports[1 << 20][1]
        for name, a, b in zip(fields + tuple(names[1]), arrays, exports[1 << 20][0]):
            assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), f"{name} differs with blocks of {block}"
    # Attributes stay with their corners: a point colour is its vertex's, whatever the winding.
    local_vertex = g.triangles[:grid_tris] % len(grid.vertices)
    np.testing.assert_array_equal(g.attributes["PCol"][:grid_tris], point_colors[local_vertex])
    assert np.all(g.attributes["weight"][:grid_tris] == g.attributes["weight"][:grid_tris, :1])
    np.testing.assert_array_equal(g.attributes["weight"][:grid_tris, 0, 0],
                                  np.tile(np.repeat(weights, 2), 5))
    np.testing.assert_array_equal(g.uvs[:grid_tris], g.attributes["Second"][:grid_tris])
    assert not np.any(g.uvs[grid_tris:]) and not any(np.any(a[grid_tris:]) for a in g.attributes.values())
    np.testing.assert_array_equal(g.object_info[-1, 1], 3.0)


def test_zero_vertex_normals_become_the_triangles_normal_with_blocks_of_any_size(
        scene, fake_session, addon, monkeypatch):
    """A vertex Blender gives no normal (on a triangle whose corners lie on a line) makes its
    mesh keep a normal per corner, and such a corner takes its triangle's geometric normal,
    +z when it has none either; whole instances per block and ranges of triangles give the
    same bytes.  (``test_normal_rows_give_the_corner_normals_computed_per_corner`` checks
    the table layout against this per-corner one.)"""
    n = 4
    verts = [(x, y, 0.1 * ((x + 2 * y) % 3)) for y in range(n + 1) for x in range(n + 1)]
    quads = [(y * (n + 1) + x, y * (n + 1) + x + 1, (y + 1) * (n + 1) + x + 1, (y + 1) * (n + 1) + x)
             for y in range(n) for x in range(n)]
    v0 = len(verts)
    ob = new_mesh_object("Grid", verts + [(6, 0, 0), (7, 0, 0), (8, 0, 0)], quads + [(v0, v0 + 1, v0 + 2)])
    ob.data.shade_smooth()
    assert not any(ob.data.vertex_normals[v0].vector)              # Blender's zero normal
    ob.rotation_euler, ob.scale = (0.4, 0.2, 0.1), (1, -2, 1)
    mesh_module = importlib.import_module(f"{addon.__name__}.export.mesh")
    normals = {}
    for block in (1 << 20, 5):              # whole instances per block; ranges of triangles
        monkeypatch.setattr(mesh_module, "_BLOCK", block)
        normals[block] = export_scene(fake_session).geometry.corner_normals()
    assert normals[5].tobytes() == normals[1 << 20].tobytes()
    np.testing.assert_allclose(np.linalg.norm(normals[5], axis=-1), 1.0, rtol=1e-6)
    assert len(export_scene(fake_session).geometry.normals) == 3 * len(normals[5])
    line = normals[5][-1]                   # the collinear triangle, last
    assert any(np.array_equal(c, [0.0, 0.0, 1.0]) for c in line)


def _normal_map_material(uv_map=""):
    mat = bpy.data.materials.new("Bumpy")
    mat.use_nodes = True
    nt = mat.node_tree
    node = nt.nodes.new("ShaderNodeNormalMap")
    node.uv_map = uv_map
    nt.links.new(node.outputs["Normal"], nt.nodes["Principled BSDF"].inputs["Normal"])
    return mat


def test_normal_maps_get_the_tangents_of_their_uv_map(scene, fake_session):
    """Only UV maps a Normal Map reads get tangents: Blender's MikkTSpace ones, object space."""
    ob = new_mesh_object("Quad", [(0, 0, 0), (2, 0, 0), (2, 1, 0), (0, 1, 0)], [(0, 1, 2, 3)])
    ob.rotation_euler = (0, 0, 1.0)      # world space would turn the tangent
    plain = ob.data.uv_layers.new(name="Plain")
    plain.uv.foreach_set("vector", [0, 0, 1, 0, 1, 1, 0, 1])          # u along +x
    turned = ob.data.uv_layers.new(name="Turned")
    turned.uv.foreach_set("vector", [0, 0, 0, 1, 1, 1, 1, 0])        # u along +y
    ob.data.materials.append(_normal_map_material("Turned"))
    g = export_scene(fake_session).geometry
    assert "tangent:Turned" in g.attributes and "tangent:" not in g.attributes
    tangent = g.attributes["tangent:Turned"].reshape(-1, 4)
    np.testing.assert_allclose(tangent[:, :3], [(0, 1, 0)] * len(tangent), atol=1e-6)
    np.testing.assert_allclose(np.abs(tangent[:, 3]), 1.0)


def test_tangents_of_a_mesh_with_custom_normals_are_blenders_own(scene, fake_session):
    """On a mesh of triangles with custom normals (each corner its own) the exported
    tangents are those ``calc_tangents`` gives for the mesh itself, to float precision:
    the export's copy of the mesh keeps the corner normals exactly."""
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2)
    me = bpy.context.object.data
    rng = np.random.default_rng(3)
    me.shade_smooth()
    normals = np.empty(3 * len(me.loops), np.float32)
    me.corner_normals.foreach_get("vector", normals)
    normals = normals.reshape(-1, 3) + 0.2 * rng.normal(size=(len(me.loops), 3))
    me.normals_split_custom_set((normals / np.linalg.norm(normals, axis=1)[:, None]).tolist())
    me.uv_layers.active.uv.foreach_set("vector", rng.random(2 * len(me.loops)))
    me.materials.append(_normal_map_material())
    tangent = export_scene(fake_session).geometry.attributes["tangent:"].reshape(-1, 4)
    me.calc_tangents()
    me.calc_loop_triangles()
    loops = _blender_triangles(me)[0]
    expected = np.empty(3 * len(me.loops), np.float32)
    me.loops.foreach_get("tangent", expected)
    np.testing.assert_allclose(tangent[:, :3], expected.reshape(-1, 3)[loops], atol=1e-6)


def _blender_tangents_of_triangles(verts, tris, corner_normals, uvs):
    """``Mesh.calc_tangents`` of a mesh of these triangles (faces of 3 corners), with these
    corner normals (a float "custom_normal" attribute keeps them exactly) and UVs."""
    t = len(tris)
    me = bpy.data.meshes.new("triangles")
    try:
        me.vertices.add(len(verts))
        me.vertices.foreach_set("co", np.ascontiguousarray(verts, np.float32).ravel())
        me.loops.add(3 * t)
        me.loops.foreach_set("vertex_index", np.ascontiguousarray(tris, np.int32).ravel())
        me.polygons.add(t)
        me.polygons.foreach_set("loop_start", np.arange(0, 3 * t, 3, dtype=np.int32))
        me.update(calc_edges=True)
        normals = me.attributes.new("custom_normal", "FLOAT_VECTOR", "CORNER")
        normals.data.foreach_set("vector", np.ascontiguousarray(corner_normals, np.float32).ravel())
        me.uv_layers.new(name="UV").uv.foreach_set("vector", np.ascontiguousarray(uvs, np.float32).ravel())
        me.calc_tangents(uvmap="UV")
        out = np.empty((3 * t, 4), np.float32)
        values = np.empty(9 * t, np.float32)
        me.loops.foreach_get("tangent", values)
        out[:, :3] = values.reshape(-1, 3)
        me.loops.foreach_get("bitangent_sign", out[:, 3])
        return out
    finally:
        bpy.data.meshes.remove(me)


def _suzanne_triangles(levels, rng=None):
    """Positions, triangles, corner normals and UVs of a smooth Suzanne subdivided
    ``levels`` times (its own UV map; with ``rng``, a third of the UVs mirrored and two
    triangles made degenerate)."""
    bpy.ops.mesh.primitive_monkey_add()
    ob = bpy.context.object
    if levels:
        ob.modifiers.new("Subdivision", "SUBSURF").levels = levels
    bpy.ops.object.shade_smooth()
    me = ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    me.calc_loop_triangles()
    loops = _blender_triangles(me)[0]
    corners = np.empty(len(me.loops), np.int32)
    me.loops.foreach_get("vertex_index", corners)
    verts = np.empty(3 * len(me.vertices), np.float32)
    me.vertices.foreach_get("co", verts)
    normals = np.empty(3 * len(me.loops), np.float32)
    me.corner_normals.foreach_get("vector", normals)
    uvs = np.empty(2 * len(me.loops), np.float32)
    me.uv_layers.active.uv.foreach_get("vector", uvs)
    tris = corners[loops].reshape(-1, 3)
    uvs = uvs.reshape(-1, 2)[loops]
    if rng is not None:
        uvs[rng.random(len(uvs)) < 1 / 3, 0] *= -1.0
        tris[[5, 40]] = tris[[5, 40]][:, [0, 0, 2]]
    return verts.reshape(-1, 3), tris, normals.reshape(-1, 3)[loops], uvs


@pytest.mark.parametrize("levels, seed", [(0, None), (1, None), (1, 7)])
def test_mikktspace_gives_blenders_bits(scene, levels, seed):
    """kernels.tangents computes MikkTSpace as Blender's intern/mikktspace does on one
    thread (meshes of at most 10,000 faces): the same bits, mirrored UVs and degenerate
    triangles included."""
    from mcengine.kernels.tangents import mikktspace
    rng = None if seed is None else np.random.default_rng(seed)
    verts, tris, normals, uvs = _suzanne_triangles(levels, rng)
    assert len(tris) <= 10_000
    expected = _blender_tangents_of_triangles(verts, tris, normals, uvs)
    np.testing.assert_array_equal(mikktspace(verts, tris, normals, uvs), expected)


def test_tangents_of_a_large_mesh_are_the_same_bits_every_time(scene, fake_session):
    """Above 10,000 faces Blender's calc_tangents sums on threads in varying order (its
    results differ in the last bit on a few hundred corners from call to call, mostly in a
    process's first calls); the export's tangents are those of the serial order
    (kernels.tangents, which the test above checks against Blender), so they do not vary, and
    are Blender's to that last bit."""
    from mcengine.kernels.tangents import mikktspace
    verts, tris, normals, uvs = _suzanne_triangles(2)
    assert len(tris) > 10_000
    bpy.context.object.data.materials.append(_normal_map_material())
    first = export_scene(fake_session).geometry.attributes["tangent:"].reshape(-1, 4)
    assert first.tobytes() == mikktspace(verts, tris, normals, uvs).tobytes()
    again = export_scene(fake_session).geometry.attributes["tangent:"].reshape(-1, 4)
    assert again.tobytes() == first.tobytes()
    blender = _blender_tangents_of_triangles(verts, tris, normals, uvs)
    np.testing.assert_allclose(first, blender, rtol=0, atol=3e-7)


def test_tangent_nodes_along_a_uv_map_get_its_tangents(scene, fake_session):
    """A Tangent node along a UV map reads the same tangents; a radial one none."""
    ob = new_mesh_object("Quad", [(0, 0, 0), (2, 0, 0), (2, 1, 0), (0, 1, 0)], [(0, 1, 2, 3)])
    ob.data.uv_layers.new(name="Plain").uv.foreach_set("vector", [0, 0, 1, 0, 1, 1, 0, 1])
    mat = bpy.data.materials.new("Brushed")
    nt = mat.node_tree
    along, radial = nt.nodes.new("ShaderNodeTangent"), nt.nodes.new("ShaderNodeTangent")
    along.direction_type, along.uv_map = "UV_MAP", "Plain"
    nt.links.new(along.outputs["Tangent"], nt.nodes["Principled BSDF"].inputs["Tangent"])
    nt.links.new(radial.outputs["Tangent"], nt.nodes["Principled BSDF"].inputs["Normal"])
    ob.data.materials.append(mat)
    desc = export_scene(fake_session)
    assert set(k for k in desc.geometry.attributes if k.startswith("tangent:")) == {"tangent:Plain"}
    nodes = [n for m in desc.materials for n in m.nodes if n.type == "Tangent"]
    assert sorted(n.props["direction_type"] for n in nodes) == ["RADIAL", "UV_MAP"]
    assert not any("tangent" in w for w in desc.warnings)


def test_normal_maps_on_ngons_get_tangents(scene, fake_session):
    """Tangents come from the triangles, so n-gons (which calc_tangents refuses) have them."""
    ring = [(math.cos(a), math.sin(a), 0) for a in np.linspace(0, 2 * math.pi, 7)[:-1]]
    ob = new_mesh_object("Hexagon", ring, [tuple(range(6))])
    layer = ob.data.uv_layers.new(name="UV")
    layer.uv.foreach_set("vector", np.array(ring)[:, :2].ravel() * 0.5)   # u along +x
    ob.data.materials.append(_normal_map_material())
    desc = export_scene(fake_session)
    tangent = desc.geometry.attributes["tangent:"].reshape(-1, 4)
    np.testing.assert_allclose(tangent[:, :3], [(1, 0, 0)] * 12, atol=1e-6)
    assert not any("tangent" in w or "normal map" in w for w in desc.warnings)


def test_normal_maps_without_a_uv_map_get_the_tangents_of_the_sphere_mapping(scene, fake_session):
    """As in Cycles, MikkTSpace runs on the object-space positions mapped to a sphere: u =
    0.5 - atan2(x, y) / 2 pi grows along (-y, x, 0) (what it renders: test_normal_nodes.py)."""
    square = [(1, 1, 1), (2, 1, 1), (2, 2, 1), (1, 2, 1)]
    ob = new_mesh_object("Bare", square, [(0, 1, 2, 3)])
    ob.data.materials.append(_normal_map_material())
    desc = export_scene(fake_session)
    g = desc.geometry
    tangent = g.attributes["tangent:"].reshape(-1, 4)
    corners = g.vertices[g.triangles].reshape(-1, 3).astype(np.float64)
    around_z = np.stack([-corners[:, 1], corners[:, 0], np.zeros(len(corners))], axis=1)
    around_z /= np.linalg.norm(around_z, axis=1, keepdims=True)
    np.testing.assert_allclose(np.linalg.norm(tangent[:, :3], axis=1), 1.0, atol=1e-5)
    assert np.all(np.einsum("ij,ij->i", tangent[:, :3], around_z) > 0.9)
    assert not any("UV map" in w for w in desc.warnings)
    # Across the mapping's seam (x = 0, y < 0), where Cycles' tangents were seen to differ.
    across = new_mesh_object("Across", [(-1, -2, 1), (1, -2, 1), (1, -1, 1), (-1, -1, 1)],
                             [(0, 1, 2, 3)])
    across.data.materials.append(_normal_map_material())
    warnings = [w for w in export_scene(fake_session).warnings if "seam" in w]
    assert len(warnings) == 1 and "'Across'" in warnings[0] and "'Bare'" not in warnings[0]
