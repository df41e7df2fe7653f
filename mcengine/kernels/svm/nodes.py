"""The shader nodes the evaluator knows: their inputs, defaults and parameter layout.

This is the one vocabulary shared by the compiler (``mcengine.shaders``, which
lays a node's inputs out in consecutive registers) and the evaluator (which
reads them back by offset).  Names are Blender's: node types without the
``ShaderNode`` prefix, input sockets by identifier (the Mix Shader's second
shader input is ``Shader_001``).  Defaults are Blender 5.0's.

A node's enum properties become numeric inputs too (``distribution`` as a
``DIST_*`` code), so that every parameter of a closure travels the same way
and can later come from a texture.
"""
from __future__ import annotations

# Distributions of the microfacet nodes (the ``distribution`` property).
DIST_GGX = 0
DIST_MULTI_GGX = 1
DIST_BECKMANN = 2
DIST_ASHIKHMIN_SHIRLEY = 3
DISTRIBUTIONS = {"GGX": DIST_GGX, "MULTI_GGX": DIST_MULTI_GGX, "BECKMANN": DIST_BECKMANN,
                 "ASHIKHMIN_SHIRLEY": DIST_ASHIKHMIN_SHIRLEY}

WHITE = (1.0, 1.0, 1.0)
GREY = (0.8, 0.8, 0.8)
UNLINKED = (0.0, 0.0, 0.0)   # a Normal or Tangent input nothing is linked to: the geometry's

# Closure nodes: kind code and inputs (identifier, components, default).  A property
# appears as ("prop:<name>", 1, default code).
NODES = {
    "BsdfPrincipled": (1, (
        ("Base Color", 3, GREY), ("Metallic", 1, 0.0), ("Roughness", 1, 0.5), ("IOR", 1, 1.5),
        ("Alpha", 1, 1.0), ("Normal", 3, UNLINKED), ("Diffuse Roughness", 1, 0.0),
        ("Subsurface Weight", 1, 0.0), ("Subsurface Radius", 3, (1.0, 0.2, 0.1)),
        ("Subsurface Scale", 1, 0.05), ("Specular IOR Level", 1, 0.5), ("Specular Tint", 3, WHITE),
        ("Anisotropic", 1, 0.0), ("Anisotropic Rotation", 1, 0.0), ("Tangent", 3, UNLINKED),
        ("Transmission Weight", 1, 0.0), ("Coat Weight", 1, 0.0), ("Coat Roughness", 1, 0.03),
        ("Coat IOR", 1, 1.5), ("Coat Tint", 3, WHITE), ("Coat Normal", 3, UNLINKED),
        ("Sheen Weight", 1, 0.0), ("Sheen Roughness", 1, 0.5), ("Sheen Tint", 3, WHITE),
        ("Emission Color", 3, WHITE), ("Emission Strength", 1, 0.0),
        ("Thin Film Thickness", 1, 0.0), ("Thin Film IOR", 1, 1.33),
        ("prop:distribution", 1, DIST_MULTI_GGX))),
    "BsdfDiffuse": (2, (("Color", 3, GREY), ("Roughness", 1, 0.0), ("Normal", 3, UNLINKED))),
    "BsdfGlossy": (3, (("Color", 3, GREY), ("Roughness", 1, 0.5), ("Anisotropy", 1, 0.0),
                       ("Rotation", 1, 0.0), ("Normal", 3, UNLINKED), ("Tangent", 3, UNLINKED),
                       ("prop:distribution", 1, DIST_MULTI_GGX))),
    "BsdfGlass": (4, (("Color", 3, WHITE), ("Roughness", 1, 0.0), ("IOR", 1, 1.5),
                      ("Normal", 3, UNLINKED), ("Thin Film Thickness", 1, 0.0),
                      ("Thin Film IOR", 1, 1.33), ("prop:distribution", 1, DIST_MULTI_GGX))),
    "BsdfRefraction": (5, (("Color", 3, WHITE), ("Roughness", 1, 0.0), ("IOR", 1, 1.45),
                           ("Normal", 3, UNLINKED), ("prop:distribution", 1, DIST_BECKMANN))),
    "BsdfTranslucent": (6, (("Color", 3, GREY), ("Normal", 3, UNLINKED))),
    "BsdfTransparent": (7, (("Color", 3, WHITE),)),
    "BsdfSheen": (8, (("Color", 3, GREY), ("Roughness", 1, 0.5), ("Normal", 3, UNLINKED))),
    "Emission": (9, (("Color", 3, WHITE), ("Strength", 1, 1.0))),
    "Holdout": (10, ()),
}
KIND = {name: kind for name, (kind, _inputs) in NODES.items()}
INPUTS = {name: inputs for name, (_kind, inputs) in NODES.items()}


def _layout(inputs) -> dict:
    offsets, k = {}, 0
    for name, size, _default in inputs:
        offsets[name] = k
        k += size
    return offsets


OFFSETS = {name: _layout(inputs) for name, inputs in INPUTS.items()}
SIZES = {name: sum(size for _n, size, _d in inputs) for name, inputs in INPUTS.items()}

# Register offsets the evaluator reads (numba freezes these module constants).
_P = OFFSETS["BsdfPrincipled"]
P_BASE_COLOR = _P["Base Color"]
P_METALLIC = _P["Metallic"]
P_ROUGHNESS = _P["Roughness"]
P_IOR = _P["IOR"]
P_ALPHA = _P["Alpha"]
P_NORMAL = _P["Normal"]
P_DIFFUSE_ROUGHNESS = _P["Diffuse Roughness"]
P_SUBSURFACE_WEIGHT = _P["Subsurface Weight"]
P_SPECULAR_LEVEL = _P["Specular IOR Level"]
P_SPECULAR_TINT = _P["Specular Tint"]
P_ANISOTROPIC = _P["Anisotropic"]
P_ANISOTROPIC_ROTATION = _P["Anisotropic Rotation"]
P_TANGENT = _P["Tangent"]
P_TRANSMISSION = _P["Transmission Weight"]
P_COAT_WEIGHT = _P["Coat Weight"]
P_COAT_ROUGHNESS = _P["Coat Roughness"]
P_COAT_IOR = _P["Coat IOR"]
P_COAT_TINT = _P["Coat Tint"]
P_COAT_NORMAL = _P["Coat Normal"]
P_SHEEN_WEIGHT = _P["Sheen Weight"]
P_SHEEN_ROUGHNESS = _P["Sheen Roughness"]
P_SHEEN_TINT = _P["Sheen Tint"]
P_EMISSION_COLOR = _P["Emission Color"]
P_EMISSION_STRENGTH = _P["Emission Strength"]
P_THIN_FILM = _P["Thin Film Thickness"]
P_DISTRIBUTION = _P["prop:distribution"]

# The other nodes share one layout idea: colour first, then their own inputs.
COLOR = 0                       # every BSDF node but the Principled: "Color" at offset 0
D_ROUGHNESS = OFFSETS["BsdfDiffuse"]["Roughness"]
D_NORMAL = OFFSETS["BsdfDiffuse"]["Normal"]
G_ROUGHNESS = OFFSETS["BsdfGlossy"]["Roughness"]
G_ANISOTROPY = OFFSETS["BsdfGlossy"]["Anisotropy"]
G_ROTATION = OFFSETS["BsdfGlossy"]["Rotation"]
G_NORMAL = OFFSETS["BsdfGlossy"]["Normal"]
G_TANGENT = OFFSETS["BsdfGlossy"]["Tangent"]
G_DISTRIBUTION = OFFSETS["BsdfGlossy"]["prop:distribution"]
GL_ROUGHNESS = OFFSETS["BsdfGlass"]["Roughness"]
GL_IOR = OFFSETS["BsdfGlass"]["IOR"]
GL_NORMAL = OFFSETS["BsdfGlass"]["Normal"]
GL_THIN_FILM = OFFSETS["BsdfGlass"]["Thin Film Thickness"]
GL_DISTRIBUTION = OFFSETS["BsdfGlass"]["prop:distribution"]
R_ROUGHNESS = OFFSETS["BsdfRefraction"]["Roughness"]
R_IOR = OFFSETS["BsdfRefraction"]["IOR"]
R_NORMAL = OFFSETS["BsdfRefraction"]["Normal"]
R_DISTRIBUTION = OFFSETS["BsdfRefraction"]["prop:distribution"]
TL_NORMAL = OFFSETS["BsdfTranslucent"]["Normal"]
S_ROUGHNESS = OFFSETS["BsdfSheen"]["Roughness"]
S_NORMAL = OFFSETS["BsdfSheen"]["Normal"]
E_STRENGTH = OFFSETS["Emission"]["Strength"]

K_PRINCIPLED = KIND["BsdfPrincipled"]
K_DIFFUSE = KIND["BsdfDiffuse"]
K_GLOSSY = KIND["BsdfGlossy"]
K_GLASS = KIND["BsdfGlass"]
K_REFRACTION = KIND["BsdfRefraction"]
K_TRANSLUCENT = KIND["BsdfTranslucent"]
K_TRANSPARENT = KIND["BsdfTransparent"]
K_SHEEN = KIND["BsdfSheen"]
K_EMISSION = KIND["Emission"]
K_HOLDOUT = KIND["Holdout"]

# Nodes that only route closures.
SHADER_ROUTING = ("MixShader", "AddShader")
