"""Bump, Displacement and displacement as bump against Cycles (harness.py).

The Bump node's Normal output is the emission colour.  Under the harness's orthographic
camera the ray differential is a pixel's width (Cycles' compact dP), so the offset points,
and with them the finite differences, are Cycles' own: heights from Noise, Wave, Gradient
textures and maths on Object, UV, Generated and Position coordinates, Strength, Distance,
Invert, Filter Width, a linked Normal input, a chain of two Bump nodes, turned, scaled and
back-facing planes; under a perspective camera, a fine noise whose bump depends on the
size of the offsets, so on the camera's ray differential.  Displacement as bump: the
Geometry node's Normal, read after the automatic bump has replaced the shading normal, is
the emission colour.  Lit spheres: near a smooth (or bumped) low-poly sphere's shadow
terminator, shadow rays start from the smooth surface as in Cycles (the one case here with
a light and shadow rays).
"""
import math

import numpy as np
import pytest

from .harness import assert_agree, black_world, pixel_centre_scene, render_cases


def _noise(nt, scale=4.0, coord=None):
    tex = nt.nodes.new("ShaderNodeTexNoise")
    tex.inputs["Scale"].default_value = scale
    tex.inputs["Detail"].default_value = 2.0
    if coord is not None:
        tc = nt.nodes.new("ShaderNodeTexCoord")
        nt.links.new(tc.outputs[coord], tex.inputs["Vector"])
    return tex.outputs["Fac"]


def _wave(nt):
    tex = nt.nodes.new("ShaderNodeTexWave")
    tex.inputs["Scale"].default_value = 3.0
    tex.inputs["Distortion"].default_value = 2.0
    return tex.outputs["Fac"]


def _gradient(nt):
    tex = nt.nodes.new("ShaderNodeTexGradient")
    tex.gradient_type = "QUADRATIC_SPHERE"
    return tex.outputs["Fac"]


def _object_math(nt):
    """sin(5 x) cos(3 y) on Object coordinates."""
    tc = nt.nodes.new("ShaderNodeTexCoord")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(tc.outputs["Object"], sep.inputs["Vector"])
    sx, cy, mul = (nt.nodes.new("ShaderNodeMath") for _ in range(3))
    sx.operation, cy.operation, mul.operation = "SINE", "COSINE", "MULTIPLY"
    m1, m2 = nt.nodes.new("ShaderNodeMath"), nt.nodes.new("ShaderNodeMath")
    m1.operation = m2.operation = "MULTIPLY"
    m1.inputs[1].default_value, m2.inputs[1].default_value = 5.0, 3.0
    nt.links.new(sep.outputs["X"], m1.inputs[0])
    nt.links.new(sep.outputs["Y"], m2.inputs[0])
    nt.links.new(m1.outputs[0], sx.inputs[0])
    nt.links.new(m2.outputs[0], cy.inputs[0])
    nt.links.new(sx.outputs[0], mul.inputs[0])
    nt.links.new(cy.outputs[0], mul.inputs[1])
    return mul.outputs[0]


def _position_length(nt):
    geo = nt.nodes.new("ShaderNodeNewGeometry")
    vm = nt.nodes.new("ShaderNodeVectorMath")
    vm.operation = "LENGTH"
    nt.links.new(geo.outputs["Position"], vm.inputs[0])
    return vm.outputs["Value"]


def _bump(height=_noise, strength=1.0, distance=0.1, invert=False, width=None, normal=None):
    def build(nt):
        node = nt.nodes.new("ShaderNodeBump")
        node.invert = invert
        node.inputs["Strength"].default_value = strength
        node.inputs["Distance"].default_value = distance
        if width is not None:
            node.inputs["Filter Width"].default_value = width
        nt.links.new(height(nt), node.inputs["Height"])
        if normal is not None:
            nt.links.new(normal(nt), node.inputs["Normal"])
        return node.outputs["Normal"]
    return build


def _normal_map(nt):
    nm = nt.nodes.new("ShaderNodeNormalMap")
    nm.space = "OBJECT"
    nm.inputs["Color"].default_value = (0.7, 0.4, 0.9, 1.0)
    return nm.outputs["Normal"]


def _displacement(height=_noise, scale=0.1, midlevel=0.5, space="OBJECT", show="normal"):
    """Output's Displacement from a Displacement node; shows the Geometry Normal (after the
    automatic bump) or the node's own vector."""
    def build(nt):
        out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
        disp = nt.nodes.new("ShaderNodeDisplacement")
        disp.space = space
        disp.inputs["Scale"].default_value = scale
        disp.inputs["Midlevel"].default_value = midlevel
        nt.links.new(height(nt), disp.inputs["Height"])
        if show == "vector":
            return disp.outputs["Displacement"]
        nt.links.new(disp.outputs["Displacement"], out.inputs["Displacement"])
        return nt.nodes.new("ShaderNodeNewGeometry").outputs["Normal"]
    return build


def _rotated(ob):
    ob.rotation_euler = (0.3, -0.2, 0.5)
    ob.scale = (0.9, 1.3, 1.0)


def _back(ob):
    ob.rotation_euler = (math.pi, 0.0, 0.3)


def _chain(nt):
    first = _bump(_wave, distance=0.05)(nt)
    node = nt.nodes.new("ShaderNodeBump")
    node.inputs["Distance"].default_value = 0.1
    nt.links.new(_noise(nt, 6.0), node.inputs["Height"])
    nt.links.new(first, node.inputs["Normal"])
    return node.outputs["Normal"]


CASES = {
    "noise": _bump(),
    "noise default distance": _bump(distance=0.001),
    "noise distance 1": _bump(distance=1.0),
    "noise strength 0.5": _bump(strength=0.5),
    "noise strength 0": _bump(strength=0.0),
    "noise strength 2": _bump(strength=2.0),
    "noise invert": _bump(invert=True),
    "noise negative distance": _bump(distance=-0.3),
    "noise filter width 1": _bump(width=1.0),
    "noise filter width 0.01": _bump(width=0.01),
    "noise on uv": _bump(lambda nt: _noise(nt, 5.0, "UV")),
    "noise on object": _bump(lambda nt: _noise(nt, 3.0, "Object"), distance=0.3),
    "noise rotated": (_bump(distance=0.3), _rotated),
    # Back faces: Object coordinates move with P, UV maps the other way (as in Cycles).
    "object noise back face": (_bump(lambda nt: _noise(nt, 3.0, "Object"), distance=0.3), _back),
    "uv noise back face": (_bump(lambda nt: _noise(nt, 5.0, "UV"), distance=0.3), _back),
    "wave": _bump(_wave, distance=0.05),
    "gradient": _bump(_gradient, distance=0.5),
    "object maths": _bump(_object_math, distance=0.2),
    "object maths rotated": (_bump(_object_math, distance=0.2), _rotated),
    "position length": _bump(_position_length, distance=0.2),
    "constant height": _bump(lambda nt: nt.nodes.new("ShaderNodeValue").outputs[0]),
    "linked normal": _bump(normal=_normal_map, distance=0.2),
    "chained": _chain,
    "displacement as bump": _displacement(),
    "displacement as bump world": _displacement(space="WORLD", scale=0.3),
    "displacement as bump rotated": (_displacement(scale=0.2), _rotated),
    "displacement as bump wave": _displacement(_wave, scale=0.03),
    "displacement vector object": (_displacement(scale=0.7, show="vector"), _rotated),
    "displacement vector world": (_displacement(scale=0.7, space="WORLD", show="vector"), _rotated),
}


@pytest.fixture(scope="module")
def images():
    return render_cases(CASES)


@pytest.mark.parametrize("name", list(CASES))
def test_bump_agrees_with_cycles(images, name):
    ref, ours = images[name]
    assert np.abs(ref).max() > 0.1
    # Cycles differences its heights in float32: the worst case measured differs by 6.6e-5
    # (filter width 0.01, the smallest offsets), most by 1e-5.
    assert_agree(name, ref, ours, rel=1e-3, abs_tol=2e-4)


@pytest.mark.parametrize("name", ["noise", "wave", "object maths", "displacement as bump"])
def test_bump_tilts_the_normal(images, name):
    """The cases see a bumped normal, not the plane's (0, 0, 1)."""
    ref, _ours = images[name]
    assert np.abs(ref[..., :2]).max() > 0.05


def _perspective(ob):
    """A perspective camera for the whole scene (every case of that render shares it)."""
    import bpy

    cam = bpy.context.scene.camera
    if cam.data.type != "PERSP":
        # The z = 0 plane fills the frame as the orthographic view did (same cells).
        cam.location.z = cam.data.ortho_scale * 50.0 / cam.data.sensor_width
        cam.data.type = "PERSP"
        cam.data.lens = 50.0


# Fine detail: the offsets are a fraction of the noise's wavelength, so the bumped normal
# depends on the ray differential's size (a perspective camera's spread times the distance).
PERSPECTIVE_CASES = {
    "perspective fine noise": (_bump(lambda nt: _noise(nt, 60.0), distance=0.02), _perspective),
    "perspective fine noise filter width 1": (_bump(lambda nt: _noise(nt, 60.0), distance=0.02, width=1.0),
                                              _perspective),
    "perspective fine noise rotated": (_bump(lambda nt: _noise(nt, 60.0), distance=0.02),
                                       lambda ob: (_perspective(ob), _rotated(ob))),
    "perspective object maths": (_bump(_object_math, distance=0.2), _perspective),
}


@pytest.fixture(scope="module")
def perspective_images():
    return render_cases(PERSPECTIVE_CASES)


@pytest.mark.parametrize("name", list(PERSPECTIVE_CASES))
def test_bump_under_a_perspective_camera_agrees_with_cycles(perspective_images, name):
    ref, ours = perspective_images[name]
    assert np.abs(ref).max() > 0.1
    # Cycles' float32 noise at scale 60 differs from ours by up to 4.6e-4 (measured; no bias:
    # the mean change along the tilt is 3e-5 of it); the smooth case agrees to 1.6e-5.  A
    # footprint 10 % off would move these normals by about 7e-3 on average.
    fine = name.startswith("perspective fine")
    assert_agree(name, ref, ours, rel=1e-3, abs_tol=1e-3 if fine else 2e-4)


def test_fine_bump_depends_on_the_filter_width(perspective_images):
    """The fine cases see the offsets' size: filter width 1 gives another normal than 0.1,
    so the agreement above checks the ray differential, not only the bump's arithmetic."""
    a = perspective_images["perspective fine noise"][0]
    b = perspective_images["perspective fine noise filter width 1"][0]
    assert np.abs(a - b).max() > 0.05


TERMINATOR_SPHERES = ("smooth", "bumped", "bump node",    # top to bottom in the image
                      "geometry offset 0", "shading offset 0.6", "shading offset 1")


def _lit_spheres():
    """Low-poly smooth spheres (12 x 6 faces, so the shading normals lean up to 15 deg off
    the facets) under a sun from +x (a little from above), seen from -y by an orthographic
    camera, so their shadow terminators run down the middle of the image: a plain white
    diffuse one; one whose displacement is rendered as bump (Wave bands on object
    coordinates), which tilts the normal towards the sun well past the facets' terminator;
    one whose Diffuse BSDF takes the same bump through its Normal input (a Bump node), which
    the offset ignores: Cycles measures the light against the shader's normal sd->N, not a
    closure's; then plain ones with the object's Shadow Terminator settings changed: Geometry
    Offset 0 (no shadow ray starts from the smooth surface; on a convex sphere any other
    value lights the same pixels: where the light is below a facet, every one offsets the
    ray in full) and Shading Offset 0.6 and 1 (the diffuse light falls off faster towards
    the terminator).  No bounces,
    black world, one sample at each pixel centre: every pixel is the sun's light through one
    shadow ray."""
    import bpy

    rows = len(TERMINATOR_SPHERES)
    scene = pixel_centre_scene(48, 48 * rows)
    cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 2.4 * rows
    cam.location = (0.0, -10.0, 2.4 - 1.2 * (rows - 1))
    cam.rotation_euler = (math.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    black_world(scene)
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy, sun.data.angle = 3.0, 0.0
    sun.rotation_euler = (0.0, math.pi / 2 - 0.05, 0.0)
    scene.collection.objects.link(sun)
    for k, kind in enumerate(TERMINATOR_SPHERES):
        bpy.ops.mesh.primitive_uv_sphere_add(segments=12, ring_count=6, radius=1.0,
                                             location=(0.0, 0.0, 2.4 - 2.4 * k))
        ob = bpy.context.active_object
        bpy.ops.object.shade_smooth()
        if kind.startswith("geometry offset"):
            ob.shadow_terminator_geometry_offset = float(kind.split()[-1])
        elif kind.startswith("shading offset"):
            ob.shadow_terminator_shading_offset = float(kind.split()[-1])
        mat = bpy.data.materials.new(f"m{k}")
        mat.use_nodes = True
        nt = mat.node_tree
        out = nt.nodes["Material Output"]
        diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
        diffuse.inputs["Color"].default_value = (0.8, 0.8, 0.8, 1.0)
        nt.links.new(diffuse.outputs["BSDF"], out.inputs["Surface"])
        if kind in ("bumped", "bump node"):
            wave = nt.nodes.new("ShaderNodeTexWave")
            wave.inputs["Scale"].default_value = 2.0
            tc = nt.nodes.new("ShaderNodeTexCoord")
            nt.links.new(tc.outputs["Object"], wave.inputs["Vector"])
        if kind == "bumped":
            mat.displacement_method = "BUMP"
            disp = nt.nodes.new("ShaderNodeDisplacement")
            disp.inputs["Scale"].default_value = 0.1
            nt.links.new(wave.outputs["Fac"], disp.inputs["Height"])
            nt.links.new(disp.outputs["Displacement"], out.inputs["Displacement"])
        elif kind == "bump node":
            bump = nt.nodes.new("ShaderNodeBump")
            bump.inputs["Distance"].default_value = 0.1
            nt.links.new(wave.outputs["Fac"], bump.inputs["Height"])
            nt.links.new(bump.outputs["Normal"], diffuse.inputs["Normal"])
        ob.data.materials.append(mat)
    return scene


@pytest.fixture(scope="module")
def lit_spheres():
    from .harness import render_both
    images = render_both(_lit_spheres())
    return images["CYCLES"], images["MCENGINE"]


@pytest.mark.parametrize("kind", TERMINATOR_SPHERES)
def test_shadow_terminator_offset_agrees_with_cycles(lit_spheres, kind):
    """Near the terminator, where the light is below a facet but above the shading normal,
    Cycles starts the shadow ray from the smooth surface the corner normals describe
    (Shadow Terminator Geometry Offset, 0.1 by default), so much of that band is lit; from
    the facet itself the ray is blocked by the sphere.  Before MC Engine did the same, its
    bumped sphere rendered 0.9 % darker than Cycles' (texture_bump at 100 %); before it read
    each object's offsets, the last three spheres rendered as the first."""
    k = TERMINATOR_SPHERES.index(kind)
    ref, ours = (img[48 * k:48 * (k + 1)] for img in lit_spheres)
    # The lit side is in view (Shading Offset 1 lights only within 45 deg of the sun).
    assert (ref.max(axis=2) > 0.05).mean() > (0.03 if kind == "shading offset 1" else 0.1)
    if "offset" in kind:               # Cycles renders the setting: not the default sphere
        assert np.abs(ref - lit_spheres[0][:48]).max() > 0.01
    assert_agree(kind, ref, ours, rel=1e-3, abs_tol=1e-4, edge_fraction=0.0)
