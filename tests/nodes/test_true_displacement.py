"""True displacement ('Displacement Only', 'Displacement and Bump') against Cycles (harness.py).

Each case's plane is subdivided (Simple, 16 x 16 quads) and moved by its material's
Displacement before the BVH is built, as Cycles moves it (scene/mesh_displace.cpp); the
emission shows what a camera ray meets there: the Geometry node's Position (where the
displaced surface is), its Normal (the normals recomputed after displacement: smooth faces
the normalised sum of their vertices' face normals, flat faces their own), the Texture
Coordinate's Generated output (the point before displacement, Cycles' generated attribute)
or a texture on the UV map.  Heights from Noise on Generated and UV coordinates, a vector
fed straight to the output, Object and World space, a turned and stretched object, the
Vector Displacement node in tangent, object and world space (also as bump),
'Displacement and Bump' (moved, and bumped), and Bump nodes on a displaced surface: their
heights are evaluated at the undisplaced point and normal with the undisplaced triangle's
ray differential, as Cycles' bump evaluation does there.

The camera looks straight down, so a pixel's ray meets the surface where both engines put
the same triangles; the emission then agrees to float rounding at every pixel (measured:
2.1e-5 at worst).  The planes are turned a little (``_subdivided``): square to the pixels,
triangle edges ran through rows of pixel centres, where the engines met different triangles.
"""
import numpy as np
import pytest

from .harness import assert_agree, render_cases


def _subdivided(ob, smooth=False, turned=False):
    import bpy

    mod = ob.modifiers.new("subdivide", "SUBSURF")
    mod.subdivision_type = "SIMPLE"
    mod.levels = mod.render_levels = 4
    if smooth:
        for poly in ob.data.polygons:
            poly.use_smooth = True
    if turned:
        ob.rotation_euler = (0.25, -0.2, 0.5)
        ob.scale = (0.9, 1.2, 1.5)
    else:
        # Turned a little, so that the triangles' edges do not run through rows of pixel
        # centres (where either engine may meet either triangle).
        ob.rotation_euler = (0.0, 0.0, 0.07)
    bpy.context.view_layer.update()


def _prepare(**kw):
    return lambda ob: _subdivided(ob, **kw)


def _material(nt):
    import bpy

    return next(m for m in bpy.data.materials if m.node_tree == nt)


def _noise(nt, coord="Generated", scale=3.0):
    tc = nt.nodes.new("ShaderNodeTexCoord")
    tex = nt.nodes.new("ShaderNodeTexNoise")
    tex.inputs["Scale"].default_value = scale
    tex.inputs["Detail"].default_value = 2.0
    nt.links.new(tc.outputs[coord], tex.inputs["Vector"])
    return tex.outputs["Fac"]


def _noise_vector(nt, coord):
    """Three noises' Fac (scales 3, 5 and 2) as a vector.  Not the Noise's Color: its green
    and blue are noise at the point plus an offset of 100-200, rounded to float32 in both
    engines (1.5e-5 apart there), and a bump's finite differences over a few hundredths
    turn the roundings where the engines' points differ by a float32 ulp into normals
    7e-4 apart (measured at 5-8 % of the pixels)."""
    combine = nt.nodes.new("ShaderNodeCombineXYZ")
    for k, scale in enumerate((3.0, 5.0, 2.0)):
        nt.links.new(_noise(nt, coord, scale), combine.inputs[k])
    return combine.outputs["Vector"]


def _show(nt, what):
    if what in ("Position", "Normal"):
        return nt.nodes.new("ShaderNodeNewGeometry").outputs[what]
    if what == "Generated":
        return nt.nodes.new("ShaderNodeTexCoord").outputs["Generated"]
    checker = nt.nodes.new("ShaderNodeTexChecker")           # on the UV map
    checker.inputs["Scale"].default_value = 4.0
    nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["UV"], checker.inputs["Vector"])
    return checker.outputs["Color"]


def _displaced(show="Position", method="DISPLACEMENT", coord="Generated", scale=0.3,
               space="OBJECT", vector=False, bump=None, vector_node=False):
    """A displaced plane showing ``show``; with ``bump`` (a texture coordinate), the Normal
    output of a Bump node (Distance 0.1) of a noise on that coordinate; with
    ``vector_node`` a Vector Displacement node of three noises (midlevel 0.5) in
    ``space``."""
    def build(nt):
        _material(nt).displacement_method = method
        out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
        if vector_node:
            disp = nt.nodes.new("ShaderNodeVectorDisplacement")
            disp.space = space
            disp.inputs["Midlevel"].default_value = 0.5
            disp.inputs["Scale"].default_value = scale
            nt.links.new(_noise_vector(nt, coord), disp.inputs["Vector"])
            nt.links.new(disp.outputs["Displacement"], out.inputs["Displacement"])
        elif vector:
            # A vector straight to the output: moved sideways by noise.
            combine = nt.nodes.new("ShaderNodeCombineXYZ")
            nt.links.new(_noise(nt, coord), combine.inputs["X"])
            combine.inputs["Z"].default_value = 0.1
            nt.links.new(combine.outputs["Vector"], out.inputs["Displacement"])
        else:
            disp = nt.nodes.new("ShaderNodeDisplacement")
            disp.space = space
            disp.inputs["Scale"].default_value = scale
            nt.links.new(_noise(nt, coord), disp.inputs["Height"])
            nt.links.new(disp.outputs["Displacement"], out.inputs["Displacement"])
        if bump is not None:
            node = nt.nodes.new("ShaderNodeBump")
            node.inputs["Distance"].default_value = 0.1
            nt.links.new(_noise(nt, bump, scale=6.0), node.inputs["Height"])
            return node.outputs["Normal"]
        return _show(nt, show)
    return build


CASES = {
    "position": (_displaced(), _prepare()),
    "normal flat": (_displaced("Normal"), _prepare()),
    "normal smooth": (_displaced("Normal"), _prepare(smooth=True)),
    "generated": (_displaced("Generated"), _prepare()),
    "uv noise, uv checker": (_displaced("UV", coord="UV"), _prepare(smooth=True)),
    "world space": (_displaced(space="WORLD", scale=0.2), _prepare()),
    "turned position": (_displaced(), _prepare(turned=True)),
    "turned normal smooth": (_displaced("Normal"), _prepare(smooth=True, turned=True)),
    "vector sideways": (_displaced(vector=True), _prepare()),
    "displacement and bump position": (_displaced(method="BOTH"), _prepare(smooth=True)),
    "displacement and bump normal": (_displaced("Normal", method="BOTH"), _prepare(smooth=True)),
    "displacement and bump turned": (_displaced("Normal", method="BOTH"), _prepare(smooth=True, turned=True)),
    # Heights from Object coordinates: the bump must read them at the undisplaced point.
    "displacement and bump on object": (_displaced("Normal", method="BOTH", coord="Object"),
                                        _prepare(smooth=True)),
    "displacement and bump on object turned": (_displaced("Normal", method="BOTH", coord="Object"),
                                               _prepare(smooth=True, turned=True)),
    "bump node on object": (_displaced(bump="Object"), _prepare(smooth=True)),
    "bump node on uv, flat": (_displaced(bump="UV"), _prepare()),
    # Vector Displacement: tangent space along the UV map's tangents, object and world space
    **{f"vector displacement {space.lower()}{' turned' if turned else ''}": (
        _displaced(space=space, vector_node=True), _prepare(smooth=True, turned=turned))
       for space in ("TANGENT", "OBJECT", "WORLD") for turned in (False, True)},
    "vector displacement tangent normal": (_displaced("Normal", space="TANGENT", vector_node=True),
                                           _prepare(smooth=True, turned=True)),
    "vector displacement tangent as bump": (_displaced("Normal", method="BUMP", space="TANGENT",
                                                      vector_node=True), _prepare(smooth=True)),
}


@pytest.fixture(scope="module")
def images():
    return render_cases(CASES)


@pytest.mark.parametrize("name", list(CASES))
def test_true_displacement_agrees_with_cycles(images, name):
    ref, ours = images[name]
    assert np.abs(ref).max() > 0.1
    assert_agree(name, ref, ours, rel=1e-3, abs_tol=2e-4)


def test_the_surface_moved(images):
    """The cases show a displaced surface: heights vary across the plane (a flat plane's
    Position z would be 0 everywhere), and smooth normals vary where flat ones step."""
    ref, _ours = images["position"]
    z = ref[..., 2]
    assert z.max() - z.min() > 0.1
    smooth, _ = images["normal smooth"]
    assert np.abs(smooth[..., :2]).max() > 0.1
