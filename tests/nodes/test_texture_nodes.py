"""Procedural texture nodes against Cycles (harness.py): Noise, Voronoi, White Noise, Gradient,
Wave, Brick, Magic, Gabor, every dimension, type, metric, feature, output and option.

Patterns are compared at the pixel centres of flat emissive planes.  The
vector input is the plane's Generated coordinate (the default) or its Object
coordinate (centred on 0, so negative coordinates are covered); 1D and 4D
variants get a varying W from a coordinate linked to it (a vector into a
float input is its mean in both engines).  Signed outputs are shown twice,
with Emission Strength 1 and -1.
"""
import numpy as np
import pytest

from .harness import assert_agree, render_cases


def _tex(kind, output, props=None, inputs=None, w=True, vector=None, strength=1.0):
    """A texture node of type ``kind`` showing ``output``; ``w``: link a coordinate to W."""
    def build(nt):
        node = nt.nodes.new("ShaderNode" + kind)
        coords = nt.nodes.new("ShaderNodeTexCoord")
        props_ = dict(props or {})
        dims = {k: props_.pop(k) for k in list(props_) if k.endswith("_dimensions")}
        for name, value in props_.items():       # first: the type shows its inputs
            setattr(node, name, value)
        for name, value in (inputs or {}).items():
            if name in node.inputs:              # (Offset and Gain only where used)
                node.inputs[name].default_value = value
        if vector == "Position":                 # world space: z varies on a turned plane
            nt.links.new(nt.nodes.new("ShaderNodeNewGeometry").outputs["Position"],
                         node.inputs["Vector"])
        elif vector is not None:
            nt.links.new(coords.outputs[vector], node.inputs["Vector"])
        w_socket = next((s for s in node.inputs if s.identifier == "W"), None)
        if w and w_socket is not None:
            nt.links.new(coords.outputs["Object"], w_socket)
        for name, value in dims.items():         # last: they hide Vector or W
            setattr(node, name, value)
        if strength != 1.0:
            nt.nodes["Emission"].inputs["Strength"].default_value = strength
        return node.outputs[output]
    return build


def _huge(dim, point):
    """Noise of a constant point beyond 1e6 (Cycles' fmod 100000 and half-cell shift): an RGB
    node's exact float32 values (W 1.7e6), one value per plane; pixel coordinates that large
    would show float32 rounding of the coordinate, not the noise."""
    def build(nt):
        node = nt.nodes.new("ShaderNodeTexNoise")
        rgb = nt.nodes.new("ShaderNodeRGB")
        rgb.outputs["Color"].default_value = (*point, 1.0)
        nt.links.new(rgb.outputs["Color"], node.inputs["Vector"])
        node.noise_dimensions = "4D"
        node.inputs["W"].default_value = 1.7e6
        node.inputs["Scale"].default_value = 1.0
        node.inputs["Detail"].default_value = 1.5
        node.noise_dimensions = dim
        return node.outputs["Color"]
    return build


FRACTAL = {"Detail": 3.5, "Roughness": 0.6, "Lacunarity": 2.3, "Offset": 0.7, "Gain": 1.3}
NOISE_TYPES = ("FBM", "MULTIFRACTAL", "RIDGED_MULTIFRACTAL", "HYBRID_MULTIFRACTAL",
               "HETERO_TERRAIN")

NOISE = {
    **{f"noise {d} default": _tex("TexNoise", "Fac", {"noise_dimensions": d})
       for d in ("1D", "2D", "3D", "4D")},
    **{f"noise {d} {t}": _tex("TexNoise", "Fac", {"noise_dimensions": d, "noise_type": t},
                              FRACTAL)
       for t in NOISE_TYPES for d in ("1D", "2D", "3D", "4D")},
    **{f"noise {d} color distorted": _tex("TexNoise", "Color", {"noise_dimensions": d},
                                          {"Distortion": 0.4, "Detail": 1.3})
       for d in ("1D", "2D", "3D", "4D")},
    "noise fbm raw": _tex("TexNoise", "Fac", {"normalize": False}, vector="Object"),
    "noise fbm raw negative": _tex("TexNoise", "Fac", {"normalize": False}, vector="Object",
                                   strength=-1.0),
    "noise multifractal distorted": _tex("TexNoise", "Color", {"noise_type": "MULTIFRACTAL"},
                                         {"Distortion": -2.0, "Detail": 0.0}),
    "noise detail 15 rough 1": _tex("TexNoise", "Fac", {},
                                    {"Detail": 15.0, "Roughness": 1.0, "Lacunarity": 1.5}),
    "noise roughness 0": _tex("TexNoise", "Fac", {}, {"Roughness": -1.0, "Detail": 4.0}),
    # Through the Vector in 2D-4D too (an RGB node's value: it was lost at export, read as
    # the node's default grey, until the RGB and Value nodes' sockets were read).
    **{f"noise huge coordinates {d}": _huge(d, (1.3e6, -2.1e6, 0.9e6))
       for d in ("1D", "2D", "3D", "4D")},
    "noise ridged negative": _tex("TexNoise", "Fac", {"noise_type": "RIDGED_MULTIFRACTAL"},
                                  {"Offset": 0.2, "Gain": 3.0}, vector="Object", strength=-1.0),
    "noise hetero negative": _tex("TexNoise", "Fac", {"noise_type": "HETERO_TERRAIN"},
                                  {"Offset": -0.3}, vector="Object", strength=-1.0),
}


def _voronoi(output, feature="F1", metric="EUCLIDEAN", dim="3D", normalize=False, **inputs):
    return _tex("TexVoronoi", output, {"feature": feature, "distance": metric,
                                       "voronoi_dimensions": dim, "normalize": normalize},
                inputs)


FRACTAL_V = {"Detail": 2.5, "Roughness": 0.7, "Lacunarity": 1.8}
VORONOI = {
    **{f"voronoi {f} {m}": _voronoi("Distance", f, m, Exponent=1.5)
       for f in ("F1", "F2", "SMOOTH_F1") for m in ("EUCLIDEAN", "MANHATTAN", "CHEBYCHEV",
                                                    "MINKOWSKI")},
    **{f"voronoi {d} {f}": _voronoi("Distance", f, dim=d, Smoothness=0.6)
       for d in ("1D", "2D", "4D") for f in ("F1", "F2", "SMOOTH_F1")},
    "voronoi 2D manhattan": _voronoi("Distance", "F2", "MANHATTAN", "2D"),
    "voronoi 4D minkowski": _voronoi("Distance", "F1", "MINKOWSKI", "4D", Exponent=3.0),
    "voronoi 3D color": _voronoi("Color"),
    "voronoi 3D position": _voronoi("Position"),
    "voronoi 4D position": _voronoi("Position", dim="4D"),
    "voronoi 4D W": _voronoi("W", dim="4D"),
    "voronoi 1D W": _voronoi("W", dim="1D"),
    "voronoi 1D color": _voronoi("Color", dim="1D"),
    "voronoi 2D smooth color": _voronoi("Color", "SMOOTH_F1", dim="2D"),
    "voronoi 3D smooth position": _voronoi("Position", "SMOOTH_F1", Smoothness=0.3),
    **{f"voronoi {d} edge": _voronoi("Distance", "DISTANCE_TO_EDGE", dim=d)
       for d in ("1D", "2D", "3D", "4D")},
    **{f"voronoi {d} radius": _voronoi("Radius", "N_SPHERE_RADIUS", dim=d)
       for d in ("1D", "2D", "3D", "4D")},
    "voronoi fractal F1": _voronoi("Distance", normalize=True, **FRACTAL_V),
    "voronoi fractal F1 color": _voronoi("Color", normalize=True, **FRACTAL_V),
    "voronoi fractal F1 position": _voronoi("Position", **FRACTAL_V),
    "voronoi fractal F2 2D": _voronoi("Distance", "F2", dim="2D", normalize=True, **FRACTAL_V),
    "voronoi fractal smooth 1D": _voronoi("Distance", "SMOOTH_F1", dim="1D", **FRACTAL_V),
    "voronoi fractal edge": _voronoi("Distance", "DISTANCE_TO_EDGE", normalize=True, **FRACTAL_V),
    "voronoi fractal edge 2D raw": _voronoi("Distance", "DISTANCE_TO_EDGE", dim="2D",
                                            Detail=1.0, Roughness=0.5),
    "voronoi randomness": _voronoi("Distance", "F2", Randomness=0.3, Scale=3.0),
    "voronoi normalize minkowski": _voronoi("Distance", "F1", "MINKOWSKI", normalize=True,
                                            Exponent=0.7, Randomness=1.4),
}


def _constant(kind, output, dim, vector, w):
    """A texture with constant inputs: folded by the compiler, one value per plane."""
    def build(nt):
        node = nt.nodes.new("ShaderNode" + kind)
        node.noise_dimensions = "4D"          # every input available
        node.inputs["Vector"].default_value = vector
        node.inputs["W"].default_value = w
        node.noise_dimensions = dim
        return node.outputs[output]
    return build


def _turned(ob):
    """A plane tilted about x and y, so that world z varies over it."""
    ob.rotation_euler = (0.6, -0.4, 0.2)


_POINTS = [((0.3, -1.7, 2.5), 0.8), ((-123.25, 0.0, 1e-3), -7.5), ((0.0, -0.0, 3e7), 1e-39)]
OTHERS = {
    **{f"white noise {d} {o} {k}": _constant("TexWhiteNoise", o, d, v, w)
       for d in ("1D", "2D", "3D", "4D") for o in ("Value", "Color")
       for k, (v, w) in enumerate(_POINTS[:2])},
    **{f"white noise {d} tiny": _constant("TexWhiteNoise", "Color", d, *_POINTS[2])
       for d in ("2D", "4D")},
    **{f"gradient {t}": _tex("TexGradient", "Color", {"gradient_type": t}, vector="Object")
       for t in ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "SPHERICAL", "QUADRATIC_SPHERE",
                 "RADIAL")},
    "gradient generated": _tex("TexGradient", "Fac", {"gradient_type": "EASING"}),
    **{f"wave bands {d}": (_tex("TexWave", "Fac", {"bands_direction": d}, {"Scale": 0.7},
                                vector="Position"), _turned)
       for d in ("X", "Y", "Z", "DIAGONAL")},
    **{f"wave rings {d}": (_tex("TexWave", "Color", {"wave_type": "RINGS", "rings_direction": d},
                                {"Scale": 0.7}, vector="Position"), _turned)
       for d in ("X", "Y", "Z", "SPHERICAL")},
    **{f"wave profile {p}": _tex("TexWave", "Fac", {"wave_profile": p, "bands_direction": "DIAGONAL"},
                                 {"Phase Offset": 1.3, "Scale": 0.6})
       for p in ("SIN", "SAW", "TRI")},
    "wave distorted": _tex("TexWave", "Fac", {"wave_type": "RINGS"},
                           {"Distortion": 4.0, "Detail": 3.5, "Detail Scale": 2.0,
                            "Detail Roughness": 0.7}),
    "brick default": _tex("TexBrick", "Color"),
    "brick fac": _tex("TexBrick", "Fac", inputs={"Mortar Size": 0.1, "Mortar Smooth": 0.6}),
    "brick squash offset": _tex("TexBrick", "Color", {"offset": 0.3, "offset_frequency": 3,
                                                      "squash": 0.6, "squash_frequency": 2},
                                {"Mortar": (0.1, 0.5, 0.9, 1.0), "Bias": -0.3},
                                vector="Object"),
    "brick sharp mortar": _tex("TexBrick", "Color", {}, {"Mortar Smooth": 0.0, "Bias": 0.4,
                                                        "Brick Width": 0.9, "Row Height": 0.4,
                                                        "Color1": (1.0, 0.2, 0.0, 1.0)}),
    **{f"magic depth {n}": _tex("TexMagic", "Color", {"turbulence_depth": n},
                                {"Distortion": 1.7, "Scale": 1.0}, vector="Object")
       for n in (0, 1, 2, 3, 5, 8, 10)},
    "magic fac": _tex("TexMagic", "Fac", {"turbulence_depth": 4}),
    "magic no distortion": _tex("TexMagic", "Color", {}, {"Distortion": 0.0, "Scale": 2.0}),
    **{f"gabor {t} {o}": _tex("TexGabor", o, {"gabor_type": t}, vector="Object")
       for t in ("2D", "3D") for o in ("Value", "Phase", "Intensity")},
    "gabor 2D anisotropic": _tex("TexGabor", "Value", {"gabor_type": "2D"},
                                 {"Anisotropy": 0.8, "Orientation 2D": -0.6, "Frequency": 3.5,
                                  "Scale": 3.0}),
    "gabor 2D isotropic": _tex("TexGabor", "Intensity", {"gabor_type": "2D"},
                               {"Anisotropy": 0.0, "Frequency": 0.5, "Scale": 8.0}),
    "gabor 3D anisotropic": (_tex("TexGabor", "Value", {"gabor_type": "3D"},
                                  {"Anisotropy": 0.7, "Orientation 3D": (0.2, -1.0, 0.6),
                                   "Frequency": 3.0, "Scale": 2.5}, vector="Position"), _turned),
    "gabor 3D along z": _tex("TexGabor", "Value", {"gabor_type": "3D"},
                             {"Anisotropy": 0.0, "Orientation 3D": (0.3, 0.0, 2.0)}),
}

CASES = {**NOISE, **VORONOI, **OTHERS}

# Bounds (relative, absolute, fraction of pixels allowed beyond them), from the measured
# differences (float32 in Cycles, float64 here; both at the same pixel centres).  Most
# patterns agree to a few 1e-6; amplifying patterns need more: Magic nests sines whose
# arguments grow by the distortion at each level, Brick's smooth mortar divides by its
# width and smoothness.  Discontinuities (cell edges, brick joints) may cross a pixel centre.
DEFAULT = (1e-4, 2e-5, 0.0)
BOUNDS = {
    "noise detail 15": (3e-4, 2e-5, 0.0),
    "voronoi": (1e-4, 2e-5, 0.01),
    "wave": (1e-4, 2e-5, 0.01),
    "brick": (1e-4, 1e-4, 0.02),
    "magic depth": (1e-4, 5e-4, 0.0),
}


@pytest.fixture(scope="module")
def images():
    return render_cases(CASES)


@pytest.mark.parametrize("name", list(CASES))
def test_texture_node_agrees_with_cycles(images, name):
    ref, ours = images[name]
    assert np.abs(ref).max() > 0, "Cycles shows nothing: the case tests nothing"
    rel, abs_tol, edge = next((v for k, v in BOUNDS.items() if name.startswith(k)), DEFAULT)
    assert_agree(name, ref, ours, rel=rel, abs_tol=abs_tol, edge_fraction=edge)
