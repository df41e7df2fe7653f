"""The IES Texture node in materials against Cycles (harness.py): its Factor at pixel centres.

The profile (a Text data-block, an asymmetric full-circle type C table) is read along the
Vector: linked, as given (a direction that sweeps the profile across the plane, from its UV
coordinates); unlinked, Cycles' Incoming direction taken into the object's space as a normal
(constant over a plane seen by the orthographic camera, different for each turn of the
plane, so each case shows one value of the profile).  A file Cycles cannot read gives 100.
"""
import math

import numpy as np
import pytest

from .harness import assert_agree, render_cases


def _profile_text() -> str:
    v = list(range(0, 181, 15))
    h = list(range(0, 361, 30))
    rows = [[round(100.0 * (1.2 + math.cos(math.radians(a - 60))) * (1.0 + math.cos(math.radians(b))), 2)
             for b in v] for a in h]
    lines = ["IESNA:LM-63-2002", "[TEST] node", "TILT=NONE", f"1 -1 1 {len(v)} {len(h)} 1 2 0 0 0",
             "1 1 0", " ".join(map(str, v)), " ".join(map(str, h))]
    lines += [" ".join(map(str, row)) for row in rows]
    return "\n".join(lines) + "\n"


def _ies(vector=None, strength=1.0, missing=False, scale=0.05):
    """The node's Factor x ``scale`` as the Emission's colour; ``vector``: 'uv' links a
    direction built from the UV coordinates."""
    def build(nt):
        import bpy

        node = nt.nodes.new("ShaderNodeTexIES")
        if missing:
            node.mode, node.filepath = "EXTERNAL", "//no such profile.ies"
        else:
            text = bpy.data.texts.get("profile.ies") or bpy.data.texts.new("profile.ies")
            if not text.as_string():
                text.write(_profile_text())
            node.ies = text
        node.inputs["Strength"].default_value = strength
        if vector == "uv":
            uv = nt.nodes.new("ShaderNodeTexCoord").outputs["UV"]
            sub = nt.nodes.new("ShaderNodeVectorMath")
            sub.operation = "SUBTRACT"
            sub.inputs[1].default_value = (0.5, 0.5, 0.35)
            nt.links.new(uv, sub.inputs[0])
            nt.links.new(sub.outputs["Vector"], node.inputs["Vector"])
        times = nt.nodes.new("ShaderNodeMath")
        times.operation = "MULTIPLY"
        times.inputs[1].default_value = scale
        nt.links.new(node.outputs["Fac"], times.inputs[0])
        return times.outputs[0]
    return build


def _turned(rx, rz):
    def prepare(ob):
        ob.rotation_euler = (math.radians(rx), 0.0, math.radians(rz))
    return prepare


CASES = {
    "along a linked vector": _ies("uv"),
    "along a linked vector, strength 2.5": _ies("uv", strength=2.5),
    "incoming, plane turned 150 x": (_ies(), _turned(150, 0)),
    "incoming, plane turned 130 x 40 z": (_ies(), _turned(130, 40)),
    "incoming, plane turned 120 x -100 z": (_ies(), _turned(120, -100)),
    "incoming, plane turned 30 x 70 z": (_ies(), _turned(30, 70)),
    "a missing file gives 100": _ies(missing=True, scale=0.01),
}


@pytest.fixture(scope="module")
def images():
    return render_cases(CASES)


@pytest.mark.parametrize("name", list(CASES))
def test_ies_node_agrees_with_cycles(images, name):
    ref, ours = images[name]
    assert np.abs(ref).max() > 0, "Cycles shows nothing: the case tests nothing"
    assert_agree(name, ref, ours, rel=1e-4, abs_tol=2e-5)


def test_the_cases_show_different_values(images):
    """The turned planes read different directions of the profile (a transform that ignored
    the turn would give them one value)."""
    values = {round(float(images[name][0].mean()), 4) for name in CASES if name.startswith("incoming")}
    assert len(values) == 4
