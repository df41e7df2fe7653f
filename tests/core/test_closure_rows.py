"""The shader evaluator's short cut for constant materials (``svm.eval_closure_rows``).

A material whose program is nothing but closure and mix-weight rows (every input a
constant register) is flagged ``MF_CLOSURES_ONLY``, and ``shading.shade_point`` runs its
rows with ``eval_closure_rows``, which does not take the texture data (a call copies it).
It must give exactly what ``eval_shader`` gives, and no material that reads anything at
the point may be flagged.
"""
from __future__ import annotations

import numpy as np
import pytest

from mcengine.kernels.closures.layout import CL_STRIDE, MAX_CLOSURES
from mcengine.kernels.state import MF_CLOSURES_ONLY
from mcengine.kernels.svm import ShaderScene, ShadingData, eval_closure_rows, eval_shader_by_value
from mcengine.scene import Link, Material, ShaderNode
from mcengine.shaders import NO_MESH, NO_TEXTURES, ShaderTable

CONSTANT = {
    "principled": Material(nodes=[ShaderNode("BsdfPrincipled", {"Base Color": (0.7, 0.3, 0.2)})],
                           surface=Link(0, "BSDF")),
    "layered principled": Material(nodes=[ShaderNode("BsdfPrincipled", {
        "Base Color": (0.2, 0.5, 0.9), "Metallic": 0.3, "Coat Weight": 0.5, "Sheen Weight": 0.4,
        "Transmission Weight": 0.2, "Alpha": 0.7, "Emission Color": (1.0, 0.5, 0.2),
        "Emission Strength": 2.0})], surface=Link(0, "BSDF")),
    "mix": Material(nodes=[ShaderNode("BsdfDiffuse", {"Color": (0.2, 0.5, 0.1)}),
                           ShaderNode("BsdfGlossy", {"Color": (0.9, 0.9, 0.9), "Roughness": 0.3}),
                           ShaderNode("MixShader", {"Fac": 0.3, "Shader": Link(0, "BSDF"),
                                                    "Shader_001": Link(1, "BSDF")})],
                    surface=Link(2, "Shader")),
    "add with holdout": Material(nodes=[
        ShaderNode("Emission", {"Color": (1.0, 0.2, 0.2), "Strength": 3.0}),
        ShaderNode("BsdfTransparent", {"Color": (0.5, 0.6, 0.7)}),
        ShaderNode("Holdout"),
        ShaderNode("AddShader", {"Shader": Link(0, "Emission"), "Shader_001": Link(1, "BSDF")}),
        ShaderNode("MixShader", {"Fac": 0.25, "Shader": Link(3, "Shader"),
                                 "Shader_001": Link(2, "Holdout")})],
        surface=Link(4, "Shader")),
    "shorthand": Material(base_color=(0.5, 0.5, 0.5), mirror_color=(0.3, 0.3, 0.3)),
    "metallic conductor over diffuse": Material(nodes=[
        ShaderNode("BsdfDiffuse", {"Color": (0.2, 0.5, 0.1)}),
        ShaderNode("BsdfMetallic", {"IOR": (0.18, 0.42, 1.37), "Extinction": (3.42, 2.35, 1.77),
                                    "Roughness": 0.2}, {"fresnel_type": "PHYSICAL_CONDUCTOR"}),
        ShaderNode("AddShader", {"Shader": Link(0, "BSDF"), "Shader_001": Link(1, "BSDF")})],
        surface=Link(2, "Shader")),
}
VARYING = {
    "checker": Material(nodes=[ShaderNode("TexChecker", {"Scale": 3.0}),
                               ShaderNode("BsdfDiffuse", {"Color": Link(0, "Color")})],
                        surface=Link(1, "BSDF")),
    "fresnel mix": Material(nodes=[ShaderNode("Fresnel", {"IOR": 1.45}),
                                   ShaderNode("BsdfDiffuse"), ShaderNode("BsdfGlossy"),
                                   ShaderNode("MixShader", {"Fac": Link(0, "Fac"),
                                                            "Shader": Link(1, "BSDF"),
                                                            "Shader_001": Link(2, "BSDF")})],
                        surface=Link(3, "Shader")),
}


@pytest.fixture(scope="module")
def table():
    return ShaderTable(list(CONSTANT.values()) + list(VARYING.values()))


def test_only_constant_materials_are_flagged(table):
    flagged = [bool(f & MF_CLOSURES_ONLY) for f in table.flags]
    assert flagged == [True] * len(CONSTANT) + [False] * len(VARYING)


def _points(count, seed=1):
    """Shading points with random normals, views and sides."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        wo = rng.normal(size=3)
        wo /= np.linalg.norm(wo)
        if wo @ n < 0.0:
            wo = -wo
        yield ShadingData(*rng.normal(size=3), *n, *n, *wo, bool(rng.integers(2)), True,
                          bool(rng.integers(2)), bool(rng.integers(2)), True, -1, 0.0, 0.0, -1,
                          0, 1.0, 1, 0, 0, 0, 0, 0.0, np.uint64(0), 0.0)


def test_closure_rows_give_what_the_shader_gives(table):
    for m, name in enumerate(CONSTANT):
        start, end = table.ranges[m]
        for sd in _points(25):
            regs_a, regs_b = table.registers.copy(), table.registers.copy()
            cl_a, cl_b = np.zeros((MAX_CLOSURES, CL_STRIDE)), np.zeros((MAX_CLOSURES, CL_STRIDE))
            a = eval_shader_by_value(start, end, regs_a, cl_a, sd,
                                     ShaderScene(table.ops, NO_TEXTURES, *NO_MESH))
            b = eval_closure_rows(table.ops, start, end, regs_b, cl_b, sd)
            assert tuple(a) == tuple(b), name
            assert a.n > 0 or name == "add with holdout", name
            np.testing.assert_array_equal(cl_a[:a.n], cl_b[:b.n], err_msg=name)
            np.testing.assert_array_equal(regs_a, regs_b, err_msg=name)
