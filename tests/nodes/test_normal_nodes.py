"""Normal Map against Cycles (harness.py): the perturbed normal as the emission colour.

Tangent space reads the MikkTSpace tangents of a UV map (Blender's calc_tangents) and
the interpolated vertex normals in object space; the cases turn, scale and mirror the
plane, curve it (smooth shading over a bumpy grid), show its back face, use a second UV
map, vary the colour across the plane with a checker, and cover every space and strength.
Without a UV map, the tangents come from the object-space positions mapped to a sphere,
as in Cycles (away from that mapping's seam, x = 0, y < 0: across it they were seen to
differ, and the export warns).
"""
import math

import numpy as np
import pytest

from .harness import assert_agree, render_cases

COLOR = (0.7, 0.35, 0.9, 1.0)


def _normal_map(space="TANGENT", strength=1.0, uv_map="", color=COLOR, checker=False):
    def build(nt):
        node = nt.nodes.new("ShaderNodeNormalMap")
        node.space = space
        node.uv_map = uv_map
        node.inputs["Strength"].default_value = strength
        if checker:
            tex = nt.nodes.new("ShaderNodeTexChecker")
            tex.inputs["Color1"].default_value = (0.8, 0.3, 0.75, 1.0)
            tex.inputs["Color2"].default_value = (0.25, 0.6, 0.95, 1.0)
            tex.inputs["Scale"].default_value = 2.0
            nt.links.new(tex.outputs["Color"], node.inputs["Color"])
        else:
            node.inputs["Color"].default_value = color
        return node.outputs["Normal"]
    return build


def _rotated(ob):
    ob.rotation_euler = (0.3, -0.2, 0.5)
    ob.scale = (0.9, 1.3, 1.0)


def _mirrored(ob):
    ob.scale = (-1.0, 1.0, 1.0)
    ob.rotation_euler = (0.0, 0.0, 0.4)


def _back(ob):
    ob.rotation_euler = (math.pi, 0.0, 0.3)


def _second_uv(ob):
    layer = ob.data.uv_layers.new(name="Turned")
    uv = np.array([d.uv[:] for d in ob.data.uv_layers[0].data])
    for d, (u, v) in zip(layer.data, uv):
        d.uv = (v, 1.0 - 0.5 * u)     # turned by 90 degrees and squeezed: other tangents


def _flipped_uv(ob):
    layer = ob.data.uv_layers.new(name="Flipped")
    uv = np.array([d.uv[:] for d in ob.data.uv_layers[0].data])
    for d, (u, v) in zip(layer.data, uv):
        d.uv = (1.0 - u, v)           # mirrored: the tangent sign is -1


def _bumpy(ob):
    """A 6 x 6 grid with smooth shading and a wavy height: interpolated normals vary."""
    import bmesh
    import bpy

    me = bpy.data.meshes.new("bumpy")
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_grid(bm, x_segments=6, y_segments=6, size=0.5, calc_uvs=True)
    for v in bm.verts:
        v.co.z = 0.08 * math.sin(5.0 * v.co.x) * math.cos(4.0 * v.co.y)
    for f in bm.faces:
        f.smooth = True
    bm.to_mesh(me)
    bm.free()
    ob.data = me
    ob.rotation_euler = (0.2, 0.1, 0.0)


def _without_uv(ob):
    """No UV map, and the plane off its object's origin (its object moved back, so it is seen
    where it was): the sphere mapping of the positions varies over it, and its seam stays
    clear of it."""
    from mathutils import Matrix

    me = ob.data
    while me.uv_layers:
        me.uv_layers.remove(me.uv_layers[0])
    me.transform(Matrix.Translation((0.2, 0.9, 0.4)))
    ob.location = (ob.location.x - 0.2, ob.location.y - 0.9, ob.location.z - 0.4)


def _bumpy_without_uv(ob):
    _bumpy(ob)
    _without_uv(ob)


CASES = {
    "tangent": _normal_map(),
    "tangent strength 0.5": _normal_map(strength=0.5),
    "tangent strength 2": _normal_map(strength=2.0),
    "tangent strength 0": _normal_map(strength=0.0),
    "tangent rotated": (_normal_map(), _rotated),
    "tangent mirrored": (_normal_map(), _mirrored),
    "tangent back face": (_normal_map(), _back),
    "tangent second uv map": (_normal_map(uv_map="Turned"), _second_uv),
    "tangent mirrored uv map": (_normal_map(uv_map="Flipped"), _flipped_uv),
    "tangent checker": _normal_map(checker=True),
    "tangent bumpy smooth": (_normal_map(), _bumpy),
    "tangent bumpy checker": (_normal_map(checker=True, strength=1.5), _bumpy),
    "tangent missing uv map": _normal_map(uv_map="Nothing"),
    "tangent without uv maps": (_normal_map(), _without_uv),
    "tangent bumpy without uv maps": (_normal_map(checker=True, strength=1.5), _bumpy_without_uv),
    **{f"{space.lower()} {label}": (_normal_map(space=space, strength=s), prep)
       for space in ("OBJECT", "WORLD", "BLENDER_OBJECT", "BLENDER_WORLD")
       for label, s, prep in (("rotated", 1.0, _rotated), ("strength 0.5", 0.5, _rotated),
                              ("back face", 1.0, _back))},
}


@pytest.fixture(scope="module")
def images():
    return render_cases(CASES)


@pytest.mark.parametrize("name", list(CASES))
def test_normal_map_agrees_with_cycles(images, name):
    ref, ours = images[name]
    assert np.abs(ref).max() > 0.1
    # The tangents are float32 in both engines; the checker's edges cross pixel centres.
    assert_agree(name, ref, ours, rel=1e-3, abs_tol=2e-4, edge_fraction=0.04)


def test_normal_map_changes_the_normal(images):
    """The cases see a perturbed normal, not the plane's (0, 0, 1)."""
    ref, _ours = images["tangent"]
    assert np.abs(ref[..., 2].mean() - 1.0) > 0.05
