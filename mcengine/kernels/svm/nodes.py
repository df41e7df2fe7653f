"""The shader nodes the evaluator knows: their sockets, defaults and register layout.

This is the one vocabulary shared by the compiler (``mcengine.shaders``, which
lays a node's inputs out in consecutive registers) and the evaluator (which
reads them back by offset).  Names are Blender's: node types without the
``ShaderNode`` prefix, sockets by identifier (the Mix Shader's second shader
input is ``Shader_001``, the Math node's inputs ``Value``, ``Value_001``,
``Value_002``).  Defaults are Blender 5.0's.

Every socket has a type: ``float`` (1 register), ``color`` and ``vector``
(3), ``shader`` (none: closures travel by weight, not through registers).
A node's properties become inputs too, named ``prop:<name>``: enum properties
as the numeric codes of ``ENUMS``, flags as 0/1, numbers as they are; a
``table`` property (a ColorRamp's stops, a curve's samples) is a count
followed by its values and must be the node's last input; a ``matrix`` is an
affine transform's 3 x 4 rows (12 registers).  So every
parameter travels the same way, and a constant costs nothing at a hit: the
compiler stores constants in the registers once per render.

Node codes: closures 1-99 (``OP_CLOSURE``); other nodes are grouped in
families of a hundred (``family = code // 100``), each evaluated by one
module of this package (``FAMILY_*``).
"""
from __future__ import annotations

import math
from collections import namedtuple

from ...ies import FAILED_PROFILE
from ..closures.layout import SSS_BURLEY, SSS_RANDOM_WALK, SSS_RANDOM_WALK_SKIN

FLOAT = "float"
COLOR = "color"
VECTOR = "vector"
SHADER = "shader"
TABLE = "table"
MATRIX = "matrix"
SIZE = {FLOAT: 1, COLOR: 3, VECTOR: 3, SHADER: 0, TABLE: 0, MATRIX: 12}

Socket = namedtuple("Socket", ["name", "type", "default"])
NodeSpec = namedtuple("NodeSpec", [
    "code",       # OP_CLOSURE kind (closures) or OP_NODE code (family * 100 + n)
    "inputs",     # tuple of Socket, in register order
    "outputs",    # tuple of Socket (default unused), in register order
    "pure",       # output depends on the inputs only (no shading point, no image): the compiler
                  # evaluates it ahead of time when every input is constant
])

# Distributions of the microfacet nodes (the ``distribution`` property).
DIST_GGX = 0
DIST_MULTI_GGX = 1
DIST_BECKMANN = 2
DIST_ASHIKHMIN_SHIRLEY = 3
DIST_ASHIKHMIN = 4          # the Sheen BSDF's: Ashikhmin velvet
DIST_MICROFIBER = 5         # and microfibre
DISTRIBUTIONS = {"GGX": DIST_GGX, "MULTI_GGX": DIST_MULTI_GGX, "BECKMANN": DIST_BECKMANN,
                 "ASHIKHMIN_SHIRLEY": DIST_ASHIKHMIN_SHIRLEY, "ASHIKHMIN": DIST_ASHIKHMIN,
                 "MICROFIBER": DIST_MICROFIBER}

# The component of the Toon BSDF and of the Hair BSDF.
TOON_DIFFUSE = 0
TOON_GLOSSY = 1
HAIR_REFLECTION = 0
HAIR_TRANSMISSION = 1
COMPONENTS = {"DIFFUSE": TOON_DIFFUSE, "GLOSSY": TOON_GLOSSY,
              "Reflection": HAIR_REFLECTION, "Transmission": HAIR_TRANSMISSION}

# Texture settings (codes are Cycles' enum values where it has them).
DIMENSIONS = {"1D": 1, "2D": 2, "3D": 3, "4D": 4}
NOISE_MULTIFRACTAL = 0
NOISE_FBM = 1
NOISE_HYBRID_MULTIFRACTAL = 2
NOISE_RIDGED_MULTIFRACTAL = 3
NOISE_HETERO_TERRAIN = 4
NOISE_TYPES = {"MULTIFRACTAL": NOISE_MULTIFRACTAL, "FBM": NOISE_FBM,
               "HYBRID_MULTIFRACTAL": NOISE_HYBRID_MULTIFRACTAL,
               "RIDGED_MULTIFRACTAL": NOISE_RIDGED_MULTIFRACTAL,
               "HETERO_TERRAIN": NOISE_HETERO_TERRAIN}
VORONOI_F1 = 0
VORONOI_F2 = 1
VORONOI_SMOOTH_F1 = 2
VORONOI_DISTANCE_TO_EDGE = 3
VORONOI_N_SPHERE_RADIUS = 4
VORONOI_FEATURES = {"F1": VORONOI_F1, "F2": VORONOI_F2, "SMOOTH_F1": VORONOI_SMOOTH_F1,
                    "DISTANCE_TO_EDGE": VORONOI_DISTANCE_TO_EDGE,
                    "N_SPHERE_RADIUS": VORONOI_N_SPHERE_RADIUS}
EUCLIDEAN = 0
MANHATTAN = 1
CHEBYCHEV = 2
MINKOWSKI = 3
VORONOI_METRICS = {"EUCLIDEAN": EUCLIDEAN, "MANHATTAN": MANHATTAN, "CHEBYCHEV": CHEBYCHEV,
                   "MINKOWSKI": MINKOWSKI}
GRADIENT_TYPES = {"LINEAR": 0, "QUADRATIC": 1, "EASING": 2, "DIAGONAL": 3, "RADIAL": 4,
                  "QUADRATIC_SPHERE": 5, "SPHERICAL": 6}
WAVE_TYPES = {"BANDS": 0, "RINGS": 1}
WAVE_BANDS_DIRECTIONS = {"X": 0, "Y": 1, "Z": 2, "DIAGONAL": 3}
WAVE_RINGS_DIRECTIONS = {"X": 0, "Y": 1, "Z": 2, "SPHERICAL": 3}
WAVE_PROFILES = {"SIN": 0, "SAW": 1, "TRI": 2}
# Blend modes of the Mix node (colour) and of the legacy MixRGB (the ``blend_type`` property).
MIX_BLEND = 0
MIX_ADD = 1
MIX_MULTIPLY = 2
MIX_SUBTRACT = 3
MIX_SCREEN = 4
MIX_DIVIDE = 5
MIX_DIFFERENCE = 6
MIX_DARKEN = 7
MIX_LIGHTEN = 8
MIX_OVERLAY = 9
MIX_DODGE = 10
MIX_BURN = 11
MIX_HUE = 12
MIX_SATURATION = 13
MIX_VALUE = 14
MIX_COLOR = 15
MIX_SOFT_LIGHT = 16
MIX_LINEAR_LIGHT = 17
MIX_EXCLUSION = 18
BLEND_TYPES = {"MIX": MIX_BLEND, "ADD": MIX_ADD, "MULTIPLY": MIX_MULTIPLY, "SUBTRACT": MIX_SUBTRACT,
               "SCREEN": MIX_SCREEN, "DIVIDE": MIX_DIVIDE, "DIFFERENCE": MIX_DIFFERENCE,
               "DARKEN": MIX_DARKEN, "LIGHTEN": MIX_LIGHTEN, "OVERLAY": MIX_OVERLAY,
               "DODGE": MIX_DODGE, "BURN": MIX_BURN, "HUE": MIX_HUE, "SATURATION": MIX_SATURATION,
               "VALUE": MIX_VALUE, "COLOR": MIX_COLOR, "SOFT_LIGHT": MIX_SOFT_LIGHT,
               "LINEAR_LIGHT": MIX_LINEAR_LIGHT, "EXCLUSION": MIX_EXCLUSION}
FACTOR_UNIFORM = 0
FACTOR_NON_UNIFORM = 1
FACTOR_MODES = {"UNIFORM": FACTOR_UNIFORM, "NON_UNIFORM": FACTOR_NON_UNIFORM}

# Enum properties: property name -> {Blender's identifier: code}.  A node's enum inputs
# ("prop:<name>") are encoded with the table of that name.
# Image Texture and Environment Texture settings (Blender's identifiers; "Smart" renders as
# Cubic in Cycles).  The two nodes share the property name "projection".
INTERP_LINEAR = 0
INTERP_CLOSEST = 1
INTERP_CUBIC = 2
INTERPOLATIONS = {"Linear": INTERP_LINEAR, "Closest": INTERP_CLOSEST, "Cubic": INTERP_CUBIC,
                  "Smart": INTERP_CUBIC}
EXT_REPEAT = 0
EXT_EXTEND = 1
EXT_CLIP = 2
EXT_MIRROR = 3
EXTENSIONS = {"REPEAT": EXT_REPEAT, "EXTEND": EXT_EXTEND, "CLIP": EXT_CLIP, "MIRROR": EXT_MIRROR}
PROJ_FLAT = 0
PROJ_BOX = 1
PROJ_SPHERE = 2
PROJ_TUBE = 3
PROJ_EQUIRECTANGULAR = 4
PROJ_MIRROR_BALL = 5
PROJECTIONS = {"FLAT": PROJ_FLAT, "BOX": PROJ_BOX, "SPHERE": PROJ_SPHERE, "TUBE": PROJ_TUBE,
               "EQUIRECTANGULAR": PROJ_EQUIRECTANGULAR, "MIRROR_BALL": PROJ_MIRROR_BALL}

# Operations of the Math and Vector Math nodes (one ``operation`` property, one table: the
# identifiers both nodes share have one code).  Cycles' NodeMathType / NodeVectorMathType.
OPERATIONS = {name: k for k, name in enumerate((
    "ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "POWER", "LOGARITHM", "SQRT",
    "INVERSE_SQRT", "ABSOLUTE", "EXPONENT", "MINIMUM", "MAXIMUM", "LESS_THAN", "GREATER_THAN",
    "SIGN", "COMPARE", "SMOOTH_MIN", "SMOOTH_MAX", "ROUND", "FLOOR", "CEIL", "TRUNC", "FRACT",
    "MODULO", "FLOORED_MODULO", "WRAP", "SNAP", "PINGPONG", "SINE", "COSINE", "TANGENT",
    "ARCSINE", "ARCCOSINE", "ARCTANGENT", "ARCTAN2", "SINH", "COSH", "TANH", "RADIANS",
    "DEGREES",
    # Vector Math only
    "CROSS_PRODUCT", "PROJECT", "REFLECT", "REFRACT", "FACEFORWARD", "DOT_PRODUCT", "DISTANCE",
    "LENGTH", "SCALE", "NORMALIZE", "FRACTION"))}
# Map Range's interpolation.
MAP_RANGE_INTERPOLATIONS = {"LINEAR": 0, "STEPPED": 1, "SMOOTHSTEP": 2, "SMOOTHERSTEP": 3}
# ``data_type``: which sockets are in use (Map Range: FLOAT, FLOAT_VECTOR; Mix: FLOAT, VECTOR,
# RGBA).  Tables are per property name, so nodes sharing a property name share its table.
DATA_TYPES = {"FLOAT": 0, "FLOAT_VECTOR": 1, "VECTOR": 2, "RGBA": 3,
              "ROTATION": 0}       # Cycles mixes rotations as floats (MixFloatNode)
DATA_FLOAT = DATA_TYPES["FLOAT"]
DATA_VECTOR = DATA_TYPES["VECTOR"]
DATA_RGBA = DATA_TYPES["RGBA"]
CLAMP_TYPES = {"MINMAX": 0, "RANGE": 1}
# Separate / Combine Color: the colour model of the three channels.
COLOR_MODES = {"RGB": 0, "HSV": 1, "HSL": 2}
# ``vector_type``: Mapping (all four), Vector Transform (POINT, VECTOR, NORMAL).
VECTOR_TYPES = {"POINT": 0, "TEXTURE": 1, "VECTOR": 2, "NORMAL": 3}

# Vector Rotate's ``rotation_type``.
ROTATE_AXIS_ANGLE, ROTATE_X, ROTATE_Y, ROTATE_Z, ROTATE_EULER_XYZ = 0, 1, 2, 3, 4
ROTATE_TYPES = {"AXIS_ANGLE": ROTATE_AXIS_ANGLE, "X_AXIS": ROTATE_X, "Y_AXIS": ROTATE_Y,
                "Z_AXIS": ROTATE_Z, "EULER_XYZ": ROTATE_EULER_XYZ}

# Vector Transform's ``convert_from`` and ``convert_to``.
TRANSFORM_SPACES = {"WORLD": 0, "OBJECT": 1, "CAMERA": 2}

# Normal Map's ``space`` (Displacement nodes use the same identifiers).
SPACE_TANGENT = 0
SPACE_OBJECT = 1
SPACE_WORLD = 2
SPACE_BLENDER_OBJECT = 3
SPACE_BLENDER_WORLD = 4
SPACES = {"TANGENT": SPACE_TANGENT, "OBJECT": SPACE_OBJECT, "WORLD": SPACE_WORLD,
          "BLENDER_OBJECT": SPACE_BLENDER_OBJECT, "BLENDER_WORLD": SPACE_BLENDER_WORLD}

# Tangent node: ``direction_type`` (radial about an object axis, or a UV map's tangent) and
# the ``axis`` of the radial one.
DIRECTION_RADIAL = 0
DIRECTION_UV_MAP = 1
DIRECTION_TYPES = {"RADIAL": DIRECTION_RADIAL, "UV_MAP": DIRECTION_UV_MAP}
AXIS_X, AXIS_Y, AXIS_Z = 0, 1, 2
AXES = {"X": AXIS_X, "Y": AXIS_Y, "Z": AXIS_Z}

# Metallic BSDF: the F82-tint model of Base Color and Edge Tint, or the conductor Fresnel of
# the complex IOR (IOR + i Extinction).
FRESNEL_F82 = 0
FRESNEL_PHYSICAL_CONDUCTOR = 1
FRESNEL_TYPES = {"F82": FRESNEL_F82, "PHYSICAL_CONDUCTOR": FRESNEL_PHYSICAL_CONDUCTOR}

# The Principled's subsurface_method and the Subsurface Scattering node's falloff.
SSS_METHODS = {"BURLEY": SSS_BURLEY, "RANDOM_WALK": SSS_RANDOM_WALK,
               "RANDOM_WALK_SKIN": SSS_RANDOM_WALK_SKIN}

ENUMS = {
    "distribution": DISTRIBUTIONS,
    "component": COMPONENTS,
    "subsurface_method": SSS_METHODS,
    "falloff": SSS_METHODS,
    "fresnel_type": FRESNEL_TYPES,
    "operation": OPERATIONS,
    "interpolation_type": MAP_RANGE_INTERPOLATIONS,
    "data_type": DATA_TYPES,
    "clamp_type": CLAMP_TYPES,
    "mode": COLOR_MODES,
    "vector_type": VECTOR_TYPES,
    "rotation_type": ROTATE_TYPES,
    "noise_dimensions": DIMENSIONS,
    "noise_type": NOISE_TYPES,
    "voronoi_dimensions": DIMENSIONS,
    "gabor_type": DIMENSIONS,
    "feature": VORONOI_FEATURES,
    "distance": VORONOI_METRICS,
    "gradient_type": GRADIENT_TYPES,
    "wave_type": WAVE_TYPES,
    "bands_direction": WAVE_BANDS_DIRECTIONS,
    "rings_direction": WAVE_RINGS_DIRECTIONS,
    "wave_profile": WAVE_PROFILES,
    "space": SPACES,
    "convert_from": TRANSFORM_SPACES,
    "direction_type": DIRECTION_TYPES,
    "axis": AXES,
    "convert_to": TRANSFORM_SPACES,
    "interpolation": INTERPOLATIONS,
    "extension": EXTENSIONS,
    "projection": PROJECTIONS,
    "blend_type": BLEND_TYPES,
    "factor_mode": FACTOR_MODES,
}

WHITE = (1.0, 1.0, 1.0)
GREY = (0.8, 0.8, 0.8)
UNLINKED = (0.0, 0.0, 0.0)   # a Normal input nothing is linked to: the shading normal's
IDENTITY = (1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0)   # a 3 x 4 matrix

# Defaults of texture coordinate inputs that Cycles fills from the shading point when
# nothing is linked (the compiler links a Texture Coordinate output there instead).
# IMPLICIT: default -> (node type, output) the compiler links there.
GENERATED = "generated"
UV = "uv"
POSITION = "position"          # the point (world shaders: the ray direction)
TANGENT = "tangent"            # the radial tangent about object Z (Geometry's Tangent)
INCOMING = "incoming"          # towards the viewer (Geometry's Incoming)
DPDV = "dpdv"                  # along the triangle's second edge (Cycles' sd->dPdv)
IMPLICIT = {GENERATED: ("TexCoord", "Generated"), UV: ("TexCoord", "UV"),
            POSITION: ("NewGeometry", "Position"), TANGENT: ("NewGeometry", "Tangent"),
            INCOMING: ("NewGeometry", "Incoming"), DPDV: ("dPdv", "dPdv")}

# Baked tables of the ColorRamp and curve nodes: Cycles samples them at RAMP_TABLE_SIZE + 1
# evenly spaced positions (blender/util.h: colorramp_to_array, curvemapping_*_to_array).
RAMP_TABLE_SIZE = 256
_RAMP_X = [i / RAMP_TABLE_SIZE for i in range(RAMP_TABLE_SIZE + 1)]
DEFAULT_RAMP = tuple(v for x in _RAMP_X for v in (x, x, x, 1.0))     # black to white, RGBA
# An IES Texture without a profile: 100 in every direction, as Cycles gives it (packed as
# kernels/ies.py reads profiles).
DEFAULT_IES = tuple(FAILED_PROFILE.packed().tolist())
IDENTITY_CURVE = tuple(_RAMP_X)
IDENTITY_CURVES = tuple(v for x in _RAMP_X for v in (x, x, x))


def _f(name, default):
    return Socket(name, FLOAT, float(default))


def _c(name, default):
    return Socket(name, COLOR, tuple(float(v) for v in default))


def _v(name, default=UNLINKED):
    return Socket(name, VECTOR, default if isinstance(default, str) else tuple(map(float, default)))


def _p(name, default):
    return Socket("prop:" + name, FLOAT, float(default))


def _table(default):
    return Socket("prop:table", TABLE, default)


def _curve(fac, value, out, default):
    """A curve node: factor, input, the curve's x range and extrapolation, its baked table."""
    return NodeSpec(0, (fac, value, _p("min_x", 0.0), _p("max_x", 1.0), _p("extrapolate", 0),
                        _table(default)), (out,), True)


_BSDF = (Socket("BSDF", SHADER, None),)

# -- closure nodes (kernel/svm/closure.h) ---------------------------------------------------------
CLOSURES = {
    "BsdfPrincipled": NodeSpec(1, (
        _c("Base Color", GREY), _f("Metallic", 0.0), _f("Roughness", 0.5), _f("IOR", 1.5),
        _f("Alpha", 1.0), _v("Normal"), _f("Diffuse Roughness", 0.0),
        _f("Subsurface Weight", 0.0), _v("Subsurface Radius", (1.0, 0.2, 0.1)),
        _f("Subsurface Scale", 0.05), _f("Subsurface IOR", 1.4), _f("Subsurface Anisotropy", 0.0),
        _f("Specular IOR Level", 0.5), _c("Specular Tint", WHITE),
        _f("Anisotropic", 0.0), _f("Anisotropic Rotation", 0.0), _v("Tangent", TANGENT),
        _f("Transmission Weight", 0.0), _f("Coat Weight", 0.0), _f("Coat Roughness", 0.03),
        _f("Coat IOR", 1.5), _c("Coat Tint", WHITE), _v("Coat Normal"),
        _f("Sheen Weight", 0.0), _f("Sheen Roughness", 0.5), _c("Sheen Tint", WHITE),
        _c("Emission Color", WHITE), _f("Emission Strength", 0.0),
        _f("Thin Film Thickness", 0.0), _f("Thin Film IOR", 1.33),
        _p("distribution", DIST_MULTI_GGX), _p("subsurface_method", SSS_RANDOM_WALK)), _BSDF, False),
    "BsdfDiffuse": NodeSpec(2, (_c("Color", GREY), _f("Roughness", 0.0), _v("Normal")), _BSDF, False),
    "BsdfGlossy": NodeSpec(3, (_c("Color", GREY), _f("Roughness", 0.5), _f("Anisotropy", 0.0),
                               _f("Rotation", 0.0), _v("Normal"), _v("Tangent", TANGENT),
                               _p("distribution", DIST_MULTI_GGX)), _BSDF, False),
    "BsdfGlass": NodeSpec(4, (_c("Color", WHITE), _f("Roughness", 0.0), _f("IOR", 1.5),
                              _v("Normal"), _f("Thin Film Thickness", 0.0),
                              _f("Thin Film IOR", 1.33), _p("distribution", DIST_MULTI_GGX)),
                          _BSDF, False),
    "BsdfRefraction": NodeSpec(5, (_c("Color", WHITE), _f("Roughness", 0.0), _f("IOR", 1.45),
                                   _v("Normal"), _p("distribution", DIST_BECKMANN)), _BSDF, False),
    "BsdfTranslucent": NodeSpec(6, (_c("Color", GREY), _v("Normal")), _BSDF, False),
    "BsdfTransparent": NodeSpec(7, (_c("Color", WHITE),), _BSDF, False),
    "BsdfSheen": NodeSpec(8, (_c("Color", GREY), _f("Roughness", 0.5), _v("Normal"),
                              _p("distribution", DIST_MICROFIBER)), _BSDF, False),
    "BsdfMetallic": NodeSpec(12, (_c("Base Color", (0.617, 0.577, 0.540)),
                                  _c("Edge Tint", (0.695, 0.726, 0.770)),
                                  _v("IOR", (2.757, 2.513, 2.231)), _v("Extinction", (3.867, 3.404, 3.009)),
                                  _f("Roughness", 0.5), _f("Anisotropy", 0.0), _f("Rotation", 0.0),
                                  _v("Normal"), _v("Tangent", TANGENT), _f("Thin Film Thickness", 0.0),
                                  _f("Thin Film IOR", 1.33), _p("distribution", DIST_MULTI_GGX),
                                  _p("fresnel_type", FRESNEL_F82)), _BSDF, False),
    "SubsurfaceScattering": NodeSpec(13, (_c("Color", GREY), _f("Scale", 0.05),
                                          _v("Radius", (1.0, 0.2, 0.1)), _f("IOR", 1.4),
                                          _f("Roughness", 1.0), _f("Anisotropy", 0.0), _v("Normal"),
                                          _p("falloff", SSS_RANDOM_WALK)), _BSDF, False),
    "BsdfToon": NodeSpec(14, (_c("Color", GREY), _f("Size", 0.5), _f("Smooth", 0.0), _v("Normal"),
                              _p("component", TOON_DIFFUSE)), _BSDF, False),
    # Hair BSDF: "prop:implicit_tangent" is 1 when nothing is linked to Tangent (on a mesh
    # Cycles then takes dPdv, and no offset).
    "BsdfHair": NodeSpec(15, (_c("Color", GREY), _f("Offset", 0.0), _f("RoughnessU", 0.1),
                              _f("RoughnessV", 1.0), _v("Tangent", DPDV),
                              _p("component", HAIR_REFLECTION), _p("implicit_tangent", 1)),
                         _BSDF, False),
    "BsdfRayPortal": NodeSpec(16, (_c("Color", WHITE), _v("Position", POSITION), _v("Direction")),
                              _BSDF, False),
    "Emission": NodeSpec(9, (_c("Color", WHITE), _f("Strength", 1.0)),
                         (Socket("Emission", SHADER, None),), False),
    "Holdout": NodeSpec(10, (), (Socket("Holdout", SHADER, None),), False),
    # The world's light (an Emission by another name: Color x Strength).
    "Background": NodeSpec(11, (_c("Color", GREY), _f("Strength", 1.0)),
                           (Socket("Background", SHADER, None),), False),
}

# Nodes that only route closures.
SHADER_ROUTING = {
    "MixShader": NodeSpec(0, (_f("Fac", 0.5), Socket("Shader", SHADER, None),
                              Socket("Shader_001", SHADER, None)), (Socket("Shader", SHADER, None),),
                          False),
    "AddShader": NodeSpec(0, (Socket("Shader", SHADER, None), Socket("Shader_001", SHADER, None)),
                          (Socket("Shader", SHADER, None),), False),
}

# -- value nodes: families ------------------------------------------------------------------------
FAMILY_INPUT = 1       # svm/input_nodes.py: coordinates, attributes, geometry, constants;
                       # svm/wireframe.py: Wireframe; svm/ao.py: Ambient Occlusion
FAMILY_MATH = 2        # svm/math_nodes.py: Math, Vector Math, Map Range, converters
FAMILY_COLOR = 3       # svm/color_nodes.py: Mix, ColorRamp, curves, colour adjustments
FAMILY_TEXTURE = 4     # svm/texture_nodes.py: procedural textures (401-449);
                       # svm/image_nodes.py: image textures (450-469)
IMAGE_CODES = 450      # first code of the image nodes
FAMILY_VECTOR = 5      # svm/vector_nodes.py: Mapping, Vector Rotate, Vector Transform, Normal
FAMILY_NORMAL = 6      # svm/normal_nodes.py: Normal Map, Bump, Displacement, Vector Displacement;
                       # svm/bevel.py: Bevel

# Texture Coordinate outputs, in register order (also the TC_* codes of "prop:output"
# of the single-output coordinate nodes the compiler inserts for implicit inputs).
TEX_COORD_OUTPUTS = ("Generated", "Normal", "UV", "Object", "Camera", "Window", "Reflection")
# Light Path outputs, in register order.
LIGHT_PATH_OUTPUTS = ("Is Camera Ray", "Is Shadow Ray", "Is Diffuse Ray", "Is Glossy Ray",
                      "Is Singular Ray", "Is Reflection Ray", "Is Transmission Ray",
                      "Is Volume Scatter Ray", "Ray Length", "Ray Depth", "Diffuse Depth",
                      "Glossy Depth", "Transparent Depth", "Transmission Depth", "Portal Depth")

VALUE_NODES = {
    # -- input family
    "Value": NodeSpec(101, (_f("prop:value", 0.0),), (_f("Value", 0.0),), True),
    "RGB": NodeSpec(102, (_c("prop:color", (0.5, 0.5, 0.5)),), (_c("Color", (0, 0, 0)),), True),
    "TexCoord": NodeSpec(103, (_p("use_object", 0), Socket("prop:object_inverse", MATRIX, IDENTITY),
                               _p("undisplaced", -1)),
                         tuple(_v(name, UNLINKED) for name in TEX_COORD_OUTPUTS), False),
    "UVMap": NodeSpec(104, (_p("attribute", -1),), (_v("UV", UNLINKED),), False),
    "Attribute": NodeSpec(105, (_p("attribute", -1), _p("attribute_size", 0)),
                          (_c("Color", (0, 0, 0)), _v("Vector", UNLINKED), _f("Fac", 0.0),
                           _f("Alpha", 0.0)), False),
    "NewGeometry": NodeSpec(106, (), (_v("Position"), _v("Normal"), _v("Tangent"),
                                      _v("True Normal"), _v("Incoming"), _v("Parametric"),
                                      _f("Backfacing", 0.0), _f("Pointiness", 0.0),
                                      _f("Random Per Island", 0.0)), False),
    "Fresnel": NodeSpec(107, (_f("IOR", 1.5), _v("Normal")), (_f("Fac", 0.0),), False),
    "LayerWeight": NodeSpec(108, (_f("Blend", 0.5), _v("Normal")),
                            (_f("Fresnel", 0.0), _f("Facing", 0.0)), False),
    "LightPath": NodeSpec(109, (), tuple(_f(name, 0.0) for name in LIGHT_PATH_OUTPUTS), False),
    "ObjectInfo": NodeSpec(110, (_p("material_index", 0),),
                           (_v("Location"), _c("Color", (0, 0, 0)), _f("Alpha", 0.0),
                            _f("Object Index", 0.0), _f("Material Index", 0.0),
                            _f("Random", 0.0)), False),
    "CameraData": NodeSpec(111, (), (_v("View Vector"), _f("View Z Depth", 0.0),
                                     _f("View Distance", 0.0)), False),
    "VertexColor": NodeSpec(112, (_p("attribute", -1), _p("attribute_size", 0)),
                            (_c("Color", (0, 0, 0)), _f("Alpha", 0.0)), False),
    # Tangent: "prop:attribute" is the UV map's tangent attribute (TANGENT_PREFIX)
    "Tangent": NodeSpec(113, (_p("direction_type", DIRECTION_RADIAL), _p("axis", AXIS_Z),
                              _p("attribute", -1)), (_v("Tangent", UNLINKED),), False),
    "LightFalloff": NodeSpec(114, (_f("Strength", 100.0), _f("Smooth", 0.0)),
                             (_f("Quadratic", 0.0), _f("Linear", 0.0), _f("Constant", 0.0)), False),
    # Wireframe reads the point's triangle (evaluated by ``svm.wireframe``, not by its family)
    "Wireframe": NodeSpec(115, (_f("Size", 0.01), _p("use_pixel_size", 0)), (_f("Fac", 0.0),),
                          False),
    # Ambient Occlusion traces rays (evaluated by ``svm.ao``); "prop:global_distance" is the
    # world's AO distance where a Distance of 0 is unlinked (Cycles' global radius), else -1
    "AmbientOcclusion": NodeSpec(116, (_c("Color", WHITE), _f("Distance", 1.0), _v("Normal"),
                                       _p("samples", 16), _p("inside", 0), _p("only_local", 0),
                                       _p("global_distance", -1)),
                                 (_c("Color", (0, 0, 0)), _f("AO", 0.0)), False),
    # Not a Blender node: the point's dPdv (a Hair BSDF's implicit Tangent; ``svm.bump``)
    "dPdv": NodeSpec(117, (), (_v("dPdv"),), False),
    # -- math family: converters (svm/math_nodes.py)
    "Math": NodeSpec(201, (_f("Value", 0.5), _f("Value_001", 0.5), _f("Value_002", 0.5),
                           _p("operation", OPERATIONS["ADD"]), _p("use_clamp", 0)),
                     (_f("Value", 0.0),), True),
    "VectorMath": NodeSpec(202, (_v("Vector"), _v("Vector_001"), _v("Vector_002"), _f("Scale", 1.0),
                                 _p("operation", OPERATIONS["ADD"])),
                           (_v("Vector"), _f("Value", 0.0)), True),
    "MapRange": NodeSpec(203, (
        _f("Value", 1.0), _f("From Min", 0.0), _f("From Max", 1.0), _f("To Min", 0.0),
        _f("To Max", 1.0), _f("Steps", 4.0), _v("Vector"), _v("From_Min_FLOAT3", (0, 0, 0)),
        _v("From_Max_FLOAT3", WHITE), _v("To_Min_FLOAT3", (0, 0, 0)), _v("To_Max_FLOAT3", WHITE),
        _v("Steps_FLOAT3", (4, 4, 4)), _p("clamp", 1), _p("interpolation_type", 0),
        _p("data_type", 0)), (_f("Result", 0.0), _v("Vector")), True),
    "Clamp": NodeSpec(204, (_f("Value", 1.0), _f("Min", 0.0), _f("Max", 1.0), _p("clamp_type", 0)),
                      (_f("Result", 0.0),), True),
    "SeparateXYZ": NodeSpec(205, (_v("Vector"),), (_f("X", 0.0), _f("Y", 0.0), _f("Z", 0.0)), True),
    "CombineXYZ": NodeSpec(206, (_f("X", 0.0), _f("Y", 0.0), _f("Z", 0.0)), (_v("Vector"),), True),
    "SeparateColor": NodeSpec(207, (_c("Color", GREY), _p("mode", 0)),
                              (_f("Red", 0.0), _f("Green", 0.0), _f("Blue", 0.0)), True),
    "CombineColor": NodeSpec(208, (_f("Red", 0.0), _f("Green", 0.0), _f("Blue", 0.0), _p("mode", 0)),
                             (_c("Color", (0, 0, 0)),), True),
    "RGBToBW": NodeSpec(209, (_c("Color", (0.5, 0.5, 0.5)),), (_f("Val", 0.0),), True),
    "Blackbody": NodeSpec(210, (_f("Temperature", 6500.0),), (_c("Color", (0, 0, 0)),), True),
    "Wavelength": NodeSpec(211, (_f("Wavelength", 500.0),), (_c("Color", (0, 0, 0)),), True),
    # -- colour family
    "Mix": NodeSpec(301, (_f("Factor_Float", 0.5), _v("Factor_Vector", (0.5, 0.5, 0.5)),
                          _f("A_Float", 0.0), _f("B_Float", 0.0), _v("A_Vector", (0, 0, 0)),
                          _v("B_Vector", (0, 0, 0)), _c("A_Color", (0.5, 0.5, 0.5)),
                          _c("B_Color", (0.5, 0.5, 0.5)), _p("data_type", DATA_FLOAT),
                          _p("factor_mode", FACTOR_UNIFORM), _p("blend_type", MIX_BLEND),
                          _p("clamp_factor", 1), _p("clamp_result", 0)),
                    (_f("Result_Float", 0.0), _v("Result_Vector", (0, 0, 0)),
                     _c("Result_Color", (0, 0, 0))), True),
    "MixRGB": NodeSpec(302, (_f("Fac", 0.5), _c("Color1", (0.5, 0.5, 0.5)),
                             _c("Color2", (0.5, 0.5, 0.5)), _p("blend_type", MIX_BLEND),
                             _p("use_clamp", 0)), (_c("Color", (0, 0, 0)),), True),
    "ValToRGB": NodeSpec(303, (_f("Fac", 0.5), _p("interpolate", 1), _table(DEFAULT_RAMP)),
                         (_c("Color", (0, 0, 0)), _f("Alpha", 0.0)), True),
    "RGBCurve": _curve(_f("Fac", 1.0), _c("Color", WHITE), _c("Color", (0, 0, 0)),
                       IDENTITY_CURVES)._replace(code=304),
    "VectorCurve": _curve(_f("Fac", 1.0), _v("Vector", (0, 0, 0)), _v("Vector", (0, 0, 0)),
                          IDENTITY_CURVES)._replace(code=305),
    "FloatCurve": _curve(_f("Factor", 1.0), _f("Value", 1.0), _f("Value", 0.0),
                         IDENTITY_CURVE)._replace(code=306),
    "HueSaturation": NodeSpec(307, (_f("Hue", 0.5), _f("Saturation", 1.0), _f("Value", 1.0),
                                    _f("Fac", 1.0), _c("Color", GREY)), (_c("Color", (0, 0, 0)),),
                              True),
    "Invert": NodeSpec(308, (_f("Fac", 1.0), _c("Color", (0, 0, 0))), (_c("Color", (0, 0, 0)),),
                       True),
    "BrightContrast": NodeSpec(309, (_c("Color", WHITE), _f("Bright", 0.0), _f("Contrast", 0.0)),
                               (_c("Color", (0, 0, 0)),), True),
    "Gamma": NodeSpec(310, (_c("Color", WHITE), _f("Gamma", 1.0)), (_c("Color", (0, 0, 0)),), True),
    # -- texture family
    "TexChecker": NodeSpec(401, (_v("Vector", GENERATED), _c("Color1", (0.8, 0.8, 0.8)),
                                 _c("Color2", (0.2, 0.2, 0.2)), _f("Scale", 5.0)),
                           (_c("Color", (0, 0, 0)), _f("Fac", 0.0)), True),
    "TexWhiteNoise": NodeSpec(402, (_v("Vector", (0, 0, 0)), _f("W", 0.0), _p("noise_dimensions", 3)),
                              (_f("Value", 0.0), _c("Color", (0, 0, 0))), True),
    "TexNoise": NodeSpec(403, (
        _v("Vector", GENERATED), _f("W", 0.0), _f("Scale", 5.0), _f("Detail", 2.0),
        _f("Roughness", 0.5), _f("Lacunarity", 2.0), _f("Offset", 0.0), _f("Gain", 1.0),
        _f("Distortion", 0.0), _p("noise_dimensions", 3), _p("noise_type", NOISE_FBM),
        _p("normalize", 1)), (_f("Fac", 0.0), _c("Color", (0, 0, 0))), True),
    "TexVoronoi": NodeSpec(404, (
        _v("Vector", GENERATED), _f("W", 0.0), _f("Scale", 5.0), _f("Detail", 0.0),
        _f("Roughness", 0.5), _f("Lacunarity", 2.0), _f("Smoothness", 1.0), _f("Exponent", 0.5),
        _f("Randomness", 1.0), _p("voronoi_dimensions", 3), _p("feature", VORONOI_F1),
        _p("distance", EUCLIDEAN), _p("normalize", 0)),
        (_f("Distance", 0.0), _c("Color", (0, 0, 0)), _v("Position"), _f("W", 0.0),
         _f("Radius", 0.0)), True),
    "TexGradient": NodeSpec(405, (_v("Vector", GENERATED), _p("gradient_type", 0)),
                            (_c("Color", (0, 0, 0)), _f("Fac", 0.0)), True),
    "TexWave": NodeSpec(406, (
        _v("Vector", GENERATED), _f("Scale", 5.0), _f("Distortion", 0.0), _f("Detail", 2.0),
        _f("Detail Scale", 1.0), _f("Detail Roughness", 0.5), _f("Phase Offset", 0.0),
        _p("wave_type", 0), _p("bands_direction", 0), _p("rings_direction", 0),
        _p("wave_profile", 0)), (_c("Color", (0, 0, 0)), _f("Fac", 0.0)), True),
    "TexBrick": NodeSpec(407, (
        _v("Vector", GENERATED), _c("Color1", (0.8, 0.8, 0.8)), _c("Color2", (0.2, 0.2, 0.2)),
        _c("Mortar", (0, 0, 0)), _f("Scale", 5.0), _f("Mortar Size", 0.02),
        _f("Mortar Smooth", 0.1), _f("Bias", 0.0), _f("Brick Width", 0.5), _f("Row Height", 0.25),
        _p("offset", 0.5), _p("offset_frequency", 2), _p("squash", 1.0),
        _p("squash_frequency", 2)), (_c("Color", (0, 0, 0)), _f("Fac", 0.0)), True),
    "TexMagic": NodeSpec(408, (_v("Vector", GENERATED), _f("Scale", 5.0), _f("Distortion", 1.0),
                               _p("turbulence_depth", 2)),
                         (_c("Color", (0, 0, 0)), _f("Fac", 0.0)), True),
    "TexGabor": NodeSpec(409, (_v("Vector", GENERATED), _f("Scale", 5.0), _f("Frequency", 2.0),
                               _f("Anisotropy", 1.0), _f("Orientation 2D", math.pi / 4.0),
                               _v("Orientation 3D", (math.sqrt(2.0), math.sqrt(2.0), 0.0)),
                               _p("gabor_type", 2)),
                         (_f("Value", 0.0), _f("Phase", 0.0), _f("Intensity", 0.0)), True),
    # IES Texture: "prop:implicit_vector" is 1 when nothing is linked to Vector (Cycles' default
    # there is Incoming taken into object space as a normal); the table is the packed profile.
    "TexIES": NodeSpec(410, (_v("Vector", INCOMING), _f("Strength", 1.0), _p("implicit_vector", 1),
                             _table(DEFAULT_IES)), (_f("Fac", 0.0),), False),
    # Images (svm/image_nodes.py, codes 450-469).  "prop:image" is the image's slot in the
    # render's image table (the compiler finds the node's image by name; -1: missing, magenta);
    # "prop:alpha_linked" is 1 when the Alpha output is used (Cycles then divides the colour
    # by alpha).
    "TexImage": NodeSpec(450, (_v("Vector", UV), _p("image", -1), _p("interpolation", INTERP_LINEAR),
                               _p("extension", EXT_REPEAT), _p("projection", PROJ_FLAT),
                               _p("projection_blend", 0.0), _p("alpha_linked", 0)),
                         (_c("Color", (0, 0, 0)), _f("Alpha", 0.0)), False),
    "TexEnvironment": NodeSpec(451, (_v("Vector", POSITION), _p("image", -1),
                                     _p("interpolation", INTERP_LINEAR),
                                     _p("projection", PROJ_EQUIRECTANGULAR), _p("alpha_linked", 0)),
                               (_c("Color", (0, 0, 0)), _f("Alpha", 0.0)), False),
    # Sky Texture (Multiple Scattering): the precomputed sky image ("prop:image", XYZ) and
    # the sun disc; its "sky_*" properties are what mcengine.sky.node_parameters derives from
    # the node's settings (the sun's wrapped elevation and rotation, its angular diameter or
    # -1 without a disc, the horizon's elevation, the disc's XYZ at its bottom and top).
    "TexSky": NodeSpec(452, (_v("Vector", GENERATED), _p("image", -1), _p("sky_elevation", 0.0),
                             _p("sky_rotation", 0.0), _p("sky_diameter", -1.0),
                             _p("sun_intensity", 1.0), _p("sky_horizon", 0.0),
                             _p("sky_bottom_x", 0.0), _p("sky_bottom_y", 0.0), _p("sky_bottom_z", 0.0),
                             _p("sky_top_x", 0.0), _p("sky_top_y", 0.0), _p("sky_top_z", 0.0)),
                       (_c("Color", (0, 0, 0)),), False),
    # -- vector family (svm/vector_nodes.py)
    "Mapping": NodeSpec(501, (_v("Vector"), _v("Location"), _v("Rotation"), _v("Scale", WHITE),
                              _p("vector_type", VECTOR_TYPES["POINT"])), (_v("Vector"),), True),
    "VectorRotate": NodeSpec(503, (_v("Vector", (0.0, 0.0, 0.0)), _v("Center", (0.0, 0.0, 0.0)),
                                   _v("Axis", (0.0, 0.0, 1.0)), _f("Angle", 0.0),
                                   _v("Rotation", (0.0, 0.0, 0.0)),
                                   _p("rotation_type", ROTATE_AXIS_ANGLE), _p("invert", 0)),
                             (_v("Vector"),), True),
    "VectorTransform": NodeSpec(502, (_v("Vector", (0.5, 0.5, 0.5)),
                                      _p("vector_type", VECTOR_TYPES["VECTOR"]),
                                      _p("convert_from", TRANSFORM_SPACES["WORLD"]),
                                      _p("convert_to", TRANSFORM_SPACES["OBJECT"])),
                                (_v("Vector"),), False),
    # Normal: "prop:direction" is the node's vector, which Blender keeps in its output socket
    "Normal": NodeSpec(504, (_v("Normal", (0.0, 0.0, 1.0)), Socket("prop:direction", VECTOR, (0.0, 0.0, 1.0))),
                       (_v("Normal"), _f("Dot", 0.0)), True),
    # -- normal family ("prop:attribute": the tangent attribute "tangent:<uv map>", see
    #    TANGENT_PREFIX; its 4 components are the MikkTSpace tangent and sign, object space)
    "NormalMap": NodeSpec(601, (_f("Strength", 1.0), _c("Color", (0.5, 0.5, 1.0)), _p("space", SPACE_TANGENT),
                                _p("attribute", -1)), (_v("Normal", UNLINKED),), False),
    # Bump: "Height" is the height at the point, "Height_dx" and "Height_dy" the compiler's
    # copies of its sub-graph at the offset points (BUMP_HEIGHTS; svm/bump.py)
    "Bump": NodeSpec(602, (_f("Strength", 1.0), _f("Distance", 0.001), _f("Filter Width", 0.1),
                           _f("Height", 1.0), _f("Height_dx", 1.0), _f("Height_dy", 1.0), _v("Normal"),
                           _p("invert", 0), _p("use_object_space", 0), _p("state", -1)),
                     (_v("Normal", UNLINKED),), False),
    "Displacement": NodeSpec(603, (_f("Height", 0.0), _f("Midlevel", 0.5), _f("Scale", 0.01), _v("Normal"),
                                   _p("space", SPACE_OBJECT)), (_v("Displacement", UNLINKED),), False),
    # Vector Displacement: "prop:attribute" is the default UV map's tangent attribute (tangent
    # space; TANGENT_PREFIX)
    "VectorDisplacement": NodeSpec(604, (_c("Vector", (0.8, 0.8, 0.8)), _f("Midlevel", 0.0), _f("Scale", 0.01),
                                         _p("space", SPACE_TANGENT), _p("attribute", -1)),
                                   (_v("Displacement", UNLINKED),), False),
    # Bevel traces rays against its object (evaluated by ``svm.bevel``, not by its family)
    "Bevel": NodeSpec(605, (_f("Radius", 0.05), _v("Normal"), _p("samples", 8)),
                      (_v("Normal", UNLINKED),), False),
}
# The Bump node's three heights: at the point, at the point moved along dPdx and along dPdy.
BUMP_HEIGHTS = ("Height", "Height_dx", "Height_dy")
IMAGE_NODES = ("TexImage", "TexEnvironment", "TexSky")     # nodes that read an image (``prop:image``)

# Name of the per-corner tangent attribute of a UV map ("" is the default UV map).
TANGENT_PREFIX = "tangent:"

NODES = {**CLOSURES, **VALUE_NODES}
KIND = {name: spec.code for name, spec in CLOSURES.items()}
INPUTS = {name: spec.inputs for name, spec in NODES.items()}
OUTPUTS = {name: spec.outputs for name, spec in NODES.items()}


def _layout(sockets) -> dict:
    offsets, k = {}, 0
    for socket in sockets:
        offsets[socket.name] = k
        k += SIZE[socket.type]
    return offsets


OFFSETS = {name: _layout(spec.inputs) for name, spec in NODES.items()}
OUTPUT_OFFSETS = {name: _layout(spec.outputs) for name, spec in NODES.items()}
SIZES = {name: sum(SIZE[s.type] for s in spec.inputs) for name, spec in NODES.items()}
OUTPUT_SIZES = {name: sum(SIZE[s.type] for s in spec.outputs) for name, spec in NODES.items()}

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
P_SUBSURFACE_RADIUS = _P["Subsurface Radius"]
P_SUBSURFACE_SCALE = _P["Subsurface Scale"]
P_SUBSURFACE_IOR = _P["Subsurface IOR"]
P_SUBSURFACE_ANISOTROPY = _P["Subsurface Anisotropy"]
P_SUBSURFACE_METHOD = _P["prop:subsurface_method"]
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
P_THIN_FILM_IOR = _P["Thin Film IOR"]
P_DISTRIBUTION = _P["prop:distribution"]

# The other nodes share one layout idea: colour first, then their own inputs.
COLOR_IN = 0                    # every BSDF node but the Principled: "Color" at offset 0
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
GL_THIN_FILM_IOR = OFFSETS["BsdfGlass"]["Thin Film IOR"]
GL_DISTRIBUTION = OFFSETS["BsdfGlass"]["prop:distribution"]
R_ROUGHNESS = OFFSETS["BsdfRefraction"]["Roughness"]
R_IOR = OFFSETS["BsdfRefraction"]["IOR"]
R_NORMAL = OFFSETS["BsdfRefraction"]["Normal"]
R_DISTRIBUTION = OFFSETS["BsdfRefraction"]["prop:distribution"]
TL_NORMAL = OFFSETS["BsdfTranslucent"]["Normal"]
_M = OFFSETS["BsdfMetallic"]
M_BASE_COLOR = _M["Base Color"]
M_EDGE_TINT = _M["Edge Tint"]
M_IOR = _M["IOR"]
M_EXTINCTION = _M["Extinction"]
M_ROUGHNESS = _M["Roughness"]
M_ANISOTROPY = _M["Anisotropy"]
M_ROTATION = _M["Rotation"]
M_NORMAL = _M["Normal"]
M_TANGENT = _M["Tangent"]
M_THIN_FILM = _M["Thin Film Thickness"]
M_THIN_FILM_IOR = _M["Thin Film IOR"]
M_DISTRIBUTION = _M["prop:distribution"]
M_FRESNEL = _M["prop:fresnel_type"]
S_ROUGHNESS = OFFSETS["BsdfSheen"]["Roughness"]
S_NORMAL = OFFSETS["BsdfSheen"]["Normal"]
S_DISTRIBUTION = OFFSETS["BsdfSheen"]["prop:distribution"]
_SS = OFFSETS["SubsurfaceScattering"]
SS_SCALE = _SS["Scale"]
SS_RADIUS = _SS["Radius"]
SS_IOR = _SS["IOR"]
SS_ROUGHNESS = _SS["Roughness"]
SS_ANISOTROPY = _SS["Anisotropy"]
SS_NORMAL = _SS["Normal"]
SS_FALLOFF = _SS["prop:falloff"]
_TN = OFFSETS["BsdfToon"]
T_SIZE, T_SMOOTH, T_NORMAL, T_COMPONENT = _TN["Size"], _TN["Smooth"], _TN["Normal"], _TN["prop:component"]
_HB = OFFSETS["BsdfHair"]
H_OFFSET, H_ROUGHNESS_U, H_ROUGHNESS_V, H_TANGENT = _HB["Offset"], _HB["RoughnessU"], _HB["RoughnessV"], _HB["Tangent"]
H_COMPONENT, H_IMPLICIT_TANGENT = _HB["prop:component"], _HB["prop:implicit_tangent"]
RP_POSITION = OFFSETS["BsdfRayPortal"]["Position"]
RP_DIRECTION = OFFSETS["BsdfRayPortal"]["Direction"]
E_STRENGTH = OFFSETS["Emission"]["Strength"]
assert OFFSETS["Background"]["Strength"] == E_STRENGTH

K_PRINCIPLED = KIND["BsdfPrincipled"]
K_SUBSURFACE = KIND["SubsurfaceScattering"]
K_DIFFUSE = KIND["BsdfDiffuse"]
K_GLOSSY = KIND["BsdfGlossy"]
K_GLASS = KIND["BsdfGlass"]
K_REFRACTION = KIND["BsdfRefraction"]
K_TRANSLUCENT = KIND["BsdfTranslucent"]
K_TRANSPARENT = KIND["BsdfTransparent"]
K_SHEEN = KIND["BsdfSheen"]
K_TOON = KIND["BsdfToon"]
K_HAIR = KIND["BsdfHair"]
K_RAY_PORTAL = KIND["BsdfRayPortal"]
K_METALLIC = KIND["BsdfMetallic"]
K_EMISSION = KIND["Emission"]
K_HOLDOUT = KIND["Holdout"]
K_BACKGROUND = KIND["Background"]

