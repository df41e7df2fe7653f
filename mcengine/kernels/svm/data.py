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
    "dp",                      # the ray differential's footprint here (Cycles' compact sd->dP:
                               # dPdx, dPdy are dp times two unit tangents; 0: no differential)
    "rng",                     # key of the numbers ray-traced nodes (Bevel, AO) draw here
    "min_pdf",                 # smallest BSDF pdf on the path so far (Cycles' min_ray_pdf);
                               # 0 where nodes trace no rays (shadow rays, light samples,
                               # displacement, the world), as Cycles' shader evaluations there
])

TextureData = namedtuple("TextureData", [
    "attr",                    # (T, 3, S) f32  per-corner attributes (``ATTR_*`` layout, shaders.py)
    "normals",                 # (K, 3) f32     world shading normals (Geometry.normals)
    "normal_index",            # (T, 3) int32   the row of ``normals`` of each triangle corner
    "tri_object",              # (T,) int32     object of each triangle
    "objects",                 # (O, OBJ_STRIDE) f64  per-object data (OBJ_* columns)
    "camera",                  # (CAMERA_PARAMS,) f64  the camera (Camera and Window coordinates)
    "images",                  # (I, IMG_STRIDE) int64  the render's images (IMG_* columns)
    "pix8",                    # (N,) uint8    texels of the 8-bit images, row after row
    "pixf",                    # (N,) float32  texels of the float images
])

# What the shader evaluator reads of the scene, passed to it by reference (``jit.by_ref``,
# made once per kernel call: by value, every call would copy these 150 machine words).
ShaderScene = namedtuple("ShaderScene", [
    "ops",                     # (P, 4) int32   every material's program (``shaders.ShaderTable``)
    "tex",                     # TextureData
    "verts",                   # (V, 3) f64     the triangles, on which Bump nodes move the point,
    "tris",                    # (T, 3) int32
    "local",                   # subsurface.LocalBVH: what Bevel and AO nodes trace
])

# Per-object data (TextureData.objects columns).
OBJ_MATRIX = 0                # 3 x 4 object -> world (row major, world units)
OBJ_INVERSE = 12              # 3 x 4 world -> object
OBJ_TEXSPACE_LOC = 24         # generated texture space: centre and half-size (object space)
OBJ_TEXSPACE_SIZE = 27
OBJ_RANDOM = 30               # Object Info: Random, Pass Index, Color (RGBA)
OBJ_PASS_INDEX = 31
OBJ_COLOR = 32
OBJ_TERMINATOR_GEOMETRY = 36  # Shadow Terminator: Geometry Offset (a cosine; 0: off)
OBJ_TERMINATOR_SHADING = 37   # and Shading Offset s as Cycles keeps it: 1 / (1 - s / 2)
OBJ_HOLDOUT = 38              # 1: a holdout object (camera rays reaching it clear the film)
OBJ_VISIBILITY = 39           # its ray visibility (state.VIS_* bits)
OBJ_RECEIVER_SET = 40         # light linking: the light set it receives (0: the default set)
OBJ_LIGHT_SETS = 41           # 2: as an emitter, the light sets it lights (lights.light_set_columns)
OBJ_STRIDE = 43

# The default UV map's offset in TextureData.attr (always present, 2 components).
ATTR_DEFAULT_UV = 0

# Images (TextureData.images columns): where an image's texels start in its pool (pix8 or
# pixf), its size, channels (1 or 4), pool and flags.  Texels are stored bottom row first,
# alpha already associated (premultiplied) as Cycles loads them (``mcengine.images``).
IMG_OFFSET = 0
IMG_WIDTH = 1
IMG_HEIGHT = 2
IMG_CHANNELS = 3
IMG_FLOAT = 4                 # 1: texels in pixf, else in pix8 (divided by 255)
IMG_FLAGS = 5
IMG_STRIDE = 6
IMGF_SRGB = 1                 # stored sRGB-encoded: decoded after interpolation
IMGF_UNASSOCIATE = 2          # a linked Alpha output divides the colour by alpha
