"""What shader nodes see: the shading point and the scene's texture data.

``ShadingData`` is built for every shading point by the integrator
(``kernels.shading.shade_point``); ``TextureData`` is packed once per render
(``mcengine.packing``) from the scene's per-corner attributes and objects.
"""
from __future__ import annotations

from collections import namedtuple

ShadingData = namedtuple("ShadingData", [
    "px", "py", "pz",          # the point (world shaders: the ray direction)
    "nx", "ny", "nz",          # unit shading normal (interpolated), on the viewer's side
    "ngx", "ngy", "ngz",       # unit geometric normal, on the viewer's side
    "wox", "woy", "woz",       # unit direction to the viewer
    "backfacing",              # the ray arrived from the inside of the surface
    "allocate",                # closures are built (False on terminated and shadow paths:
                               # only emission, transparency and holdout are wanted)
    "reflective_caustics",     # glossy reflection closures are allowed at this vertex
    "refractive_caustics",     # refraction closures are allowed at this vertex
    "bump_correction",         # tilt glossy normals whose mirror direction points inside
    "prim",                    # triangle hit (-1: none, the world)
    "u", "v",                  # its barycentrics: P = (1 - u - v) p0 + u p1 + v p2
    "obj",                     # object of the triangle (index into TextureData.objects; -1: none)
    "path_flags",              # the path's PF_* bits (label of the ray that arrived here)
    "ray_length",              # length of the ray that arrived here
    "depth",                   # bounces so far, and per kind (Light Path node)
    "diffuse_depth", "glossy_depth", "transmission_depth", "transparent_depth",
])

TextureData = namedtuple("TextureData", [
    "attr",                    # (T, 3, S) f32  per-corner attributes (``ATTR_*`` layout, shaders.py)
    "normals",                 # (T, 3, 3) f32  world shading normals at the corners (SceneData.normals)
    "tri_object",              # (T,) int32     object of each triangle
    "objects",                 # (O, OBJ_STRIDE) f64  per-object data (OBJ_* columns)
    "camera",                  # (CAMERA_PARAMS,) f64  the camera (Camera and Window coordinates)
])

# Per-object data (TextureData.objects columns).
OBJ_MATRIX = 0                # 3 x 4 object -> world (row major, world units)
OBJ_INVERSE = 12              # 3 x 4 world -> object
OBJ_TEXSPACE_LOC = 24         # generated texture space: centre and half-size (object space)
OBJ_TEXSPACE_SIZE = 27
OBJ_RANDOM = 30               # Object Info: Random, Pass Index, Color (RGBA)
OBJ_PASS_INDEX = 31
OBJ_COLOR = 32
OBJ_STRIDE = 36

# The default UV map's offset in TextureData.attr (always present, 2 components).
ATTR_DEFAULT_UV = 0
