"""Scene model: everything a render needs, as plain data.

A :class:`SceneDescription` is what the Blender add-on exports and what the
renderer consumes.  It holds numpy arrays and small dataclasses only, so it can
be saved to one ``.npz`` file and rendered again without Blender
(``SceneDescription.load(path)``).

Conventions (the same as Blender and Cycles):

* World space is Blender's: right-handed, +Z up, metres (the exporter applies
  the scene unit scale).
* Colours are linear, in the scene's working colour space.
* Light colours are already multiplied by their strength (``color * energy *
  2**exposure``, times the temperature colour): ``Light.strength`` is in watts
  for point, spot and area lights and in W/m^2 for sun lights.
* Emission of materials is radiance ``color * strength`` (no factor pi).
* Images are stored top row first, as in EXR files.
"""
from __future__ import annotations

import dataclasses
import json
import math
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import integrators, memory, samplers
from .denoise import Denoising
from .ies import IESProfile
from .kernels.lights import LIGHT_SETS_ALL, MAX_LIGHT_SETS
from .kernels.state import VIS_ALL
from .passes import RenderPasses

__all__ = [
    "SceneError", "ObjectPassInfo", "Geometry", "Link", "ShaderNode", "Material", "Image", "Light",
    "Camera", "MotionBlur", "ObjectMotion", "World", "Film", "Integrator", "SceneDescription",
    "RenderPasses", "Denoising",
]

LIGHT_TYPES = ("POINT", "SPOT", "SUN", "AREA")
MAX_RESOLUTION = 65536          # pixels per side, Blender's own limit
MAX_SAMPLES = 1 << 24           # Cycles' limit
MAX_BOUNCES = 1024
MIN_FILTER_WIDTH = float(np.float32(0.01))   # pixels, Blender's own limit (stored as float32)
MAX_BLADES = 100000             # aperture blades; beyond, a polygon is a disk to float precision
PI_FLOAT32 = float(np.float32(np.pi))
AREA_SHAPES = ("SQUARE", "RECTANGLE", "DISK", "ELLIPSE")
FILTER_TYPES = ("BLACKMAN_HARRIS", "GAUSSIAN", "BOX")
IMAGE_COLORSPACES = ("sRGB", "linear", "data")
IMAGE_ALPHA_MODES = ("STRAIGHT", "PREMUL", "CHANNEL_PACKED", "NONE")
# An object's Shadow Terminator Geometry Offset and Shading Offset, Blender's defaults.
DEFAULT_TERMINATOR_OFFSETS = (0.1, 0.0)


class SceneError(ValueError):
    """The scene description is invalid; the message says what and where."""


@dataclass
class ObjectPassInfo:
    """What the film and render passes know of an object besides its Object Info
    (``Geometry.object_info``, which holds its pass index): its own name (the Cryptomatte
    object id; an instance's is the instanced object's), the name of its topmost parent (the
    Cryptomatte asset id; its own name without a parent), whether its mesh has a UV map (else
    the UV pass reads 0, as in Cycles), and whether it is a holdout (Object > Visibility >
    Holdout, or its collection's in the view layer: camera rays that reach it make the film
    transparent, as a Holdout shader would)."""

    name: str = ""
    asset: str = ""
    has_uv: bool = True
    holdout: bool = False


@dataclass
class Geometry:
    """All triangles of the scene in world space.

    vertices        (V, 3) float32  vertex positions
    triangles       (T, 3) int32    vertex indices of each triangle
    normals         (K, 3) float32  shading normals (unit length; after true displacement of
                    a stretched object, the length its normal matrix gives them:
                    ``displacement``), one per vertex, face or corner as the mesh has them
    normal_index    (T, 3) int32    the row of ``normals`` of each triangle corner (for
                    vertex normals it is ``triangles`` itself: no copy).  Given per corner,
                    (T, 3, 3), ``normals`` become K = 3T rows and this index is made;
                    ``corner_normals`` gives them per corner
    uvs             (T, 3, 2) float32  UV at each corner (zeros if the mesh has none)
    material_index  (T,) int32      index into ``SceneDescription.materials``
    object_index    (T,) int32      index into ``object_names`` (for messages)
    attributes      name -> (T, 3, C) float32  per-corner attributes the shader nodes read by
                    name (UV maps, colour attributes, 1 <= C <= 4); ``uvs`` is the default UV map

    Per object (O = len(object_names)), optional: when absent, an object has the identity
    matrix, the bounding box of its triangles as texture space and zero Object Info.

    object_matrix   (O, 4, 4) float64  object -> world (world units)
    object_texspace (O, 2, 3) float64  generated texture space: centre and half-size
                    (object space; Blender's texspace_location and texspace_size)
    object_info     (O, 6) float64     Object Info: random, pass index, colour RGBA
    object_terminator (O, 2) float64   Shadow Terminator: Geometry Offset and Shading Offset,
                    each in [0, 1] (``DEFAULT_TERMINATOR_OFFSETS`` when absent)
    object_passes   per entry of ``object_names``, its :class:`ObjectPassInfo` (render passes, holdout;
                    empty: each object is named by its ``object_names`` entry)
    object_visibility (O,) uint8    Ray Visibility: the rays that see the object, ``VIS_*`` bits
                    (``kernels.state``: camera, diffuse, glossy, transmission, shadow, volume
                    scatter; absent: every ray)
    object_receiver_set (O,) uint8  light linking: the light set the object receives
                    (0..63, 0 the default set; absent: every object 0)
    object_light_sets (O,) uint64   light linking: as an emitter (emissive material), the
                    receivers' light sets it lights (bit s: set s; absent: all of them)
    """

    vertices: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.float32))
    triangles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.int32))
    normals: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.float32))
    uvs: np.ndarray = field(default_factory=lambda: np.zeros((0, 3, 2), np.float32))
    material_index: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))
    object_index: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))
    object_names: list = field(default_factory=list)
    attributes: dict = field(default_factory=dict)
    object_matrix: np.ndarray | None = None
    object_texspace: np.ndarray | None = None
    object_info: np.ndarray | None = None
    object_terminator: np.ndarray | None = None
    object_passes: list = field(default_factory=list)
    object_visibility: np.ndarray | None = None
    object_receiver_set: np.ndarray | None = None
    object_light_sets: np.ndarray | None = None
    normal_index: np.ndarray | None = None

    def __post_init__(self):
        if self.normal_index is None:
            normals = np.asarray(self.normals)
            t = len(self.triangles)
            self.normals = normals.reshape(-1, 3)
            self.normal_index = np.arange(3 * t, dtype=np.int32).reshape(t, 3)

    def corner_normals(self) -> np.ndarray:
        """(T, 3, 3) the shading normal at each triangle corner (a new array)."""
        return np.take(self.normals, self.normal_index, axis=0)

    @property
    def num_objects(self) -> int:
        return len(self.object_names)

    def object_arrays(self) -> tuple:
        """(object_matrix, object_texspace, object_info), the defaults filled in."""
        o = self.num_objects
        matrix = (np.broadcast_to(np.eye(4), (o, 4, 4)).copy() if self.object_matrix is None
                  else np.asarray(self.object_matrix, np.float64))
        info = np.zeros((o, 6)) if self.object_info is None else np.asarray(self.object_info, np.float64)
        if self.object_texspace is not None:
            return matrix, np.asarray(self.object_texspace, np.float64), info
        texspace = np.zeros((o, 2, 3))
        texspace[:, 1] = 1.0
        if self.num_triangles:
            corners = self.vertices[self.triangles].astype(np.float64)      # (T, 3, 3)
            inverse = np.linalg.inv(matrix)
            obj = np.clip(self.object_index, 0, max(o - 1, 0))
            local = np.einsum("tij,tkj->tki", inverse[obj, :3, :3], corners) + inverse[obj, None, :3, 3]
            lo = np.full((o, 3), np.inf)
            hi = np.full((o, 3), -np.inf)
            np.minimum.at(lo, obj, local.min(axis=1))
            np.maximum.at(hi, obj, local.max(axis=1))
            seen = np.isfinite(lo[:, 0])
            texspace[seen, 0] = 0.5 * (lo[seen] + hi[seen])
            texspace[seen, 1] = 0.5 * (hi[seen] - lo[seen])
        return matrix, auto_texspace_size(texspace), info

    def terminator_offsets(self) -> np.ndarray:
        """(O, 2) float64: each object's Shadow Terminator offsets, the defaults filled in."""
        if self.object_terminator is not None:
            return np.asarray(self.object_terminator, np.float64)
        return np.tile(DEFAULT_TERMINATOR_OFFSETS, (self.num_objects, 1))

    def visibility(self) -> np.ndarray:
        """(O,) uint8: each object's ray visibility, the default (every ray) filled in."""
        if self.object_visibility is not None:
            return np.asarray(self.object_visibility, np.uint8)
        return np.full(self.num_objects, VIS_ALL, np.uint8)

    def receiver_sets(self) -> np.ndarray:
        """(O,) uint8: each object's receiver light set, the default (0) filled in."""
        if self.object_receiver_set is not None:
            return np.asarray(self.object_receiver_set, np.uint8)
        return np.zeros(self.num_objects, np.uint8)

    def light_sets(self) -> np.ndarray:
        """(O,) uint64: the light sets each object lights as an emitter (all by default)."""
        if self.object_light_sets is not None:
            return np.asarray(self.object_light_sets, np.uint64)
        return np.full(self.num_objects, LIGHT_SETS_ALL, np.uint64)

    def triangle_visibility(self) -> np.ndarray | None:
        """(T,) uint8: the ray visibility of each triangle's object; None when every object
        is visible to every ray."""
        visibility = self.visibility()
        if np.all(visibility == VIS_ALL) or not self.num_triangles:
            return None
        return visibility[np.clip(self.object_index, 0, len(visibility) - 1)]

    def materials_used(self) -> list[int]:
        """The material indices some triangle has, ascending (a count per material, not a
        sort: ``np.unique`` of 4 million indices took 0.4 s)."""
        if not self.num_triangles:
            return []
        return np.flatnonzero(np.bincount(np.asarray(self.material_index).ravel())).tolist()

    def object_pass_info(self) -> list:
        """An :class:`ObjectPassInfo` per entry of ``object_names``."""
        if len(self.object_passes) == len(self.object_names):
            return list(self.object_passes)
        return [ObjectPassInfo(name, name) for name in self.object_names]

    @property
    def num_triangles(self) -> int:
        return int(self.triangles.shape[0])

    @staticmethod
    def from_triangles(positions, material_index=None, normals=None, uvs=None,
                       object_index=None, object_names=None) -> "Geometry":
        """Build from a (T, 3, 3) array of corner positions (flat shading by default)."""
        p = np.asarray(positions, np.float64).reshape(-1, 3, 3)
        t = p.shape[0]
        if normals is None:
            n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
            ln = np.linalg.norm(n, axis=1, keepdims=True)
            n = np.where(ln > 0, n / np.where(ln > 0, ln, 1), [0.0, 0.0, 1.0])
            normals = np.repeat(n[:, None, :], 3, axis=1)
        return Geometry(
            vertices=p.reshape(-1, 3).astype(np.float32),
            triangles=np.arange(3 * t, dtype=np.int32).reshape(-1, 3),
            normals=np.asarray(normals, np.float32).reshape(t, 3, 3),
            uvs=(np.zeros((t, 3, 2), np.float32) if uvs is None
                 else np.asarray(uvs, np.float32).reshape(t, 3, 2)),
            material_index=(np.zeros(t, np.int32) if material_index is None
                            else np.asarray(material_index, np.int32).reshape(t)),
            object_index=(np.zeros(t, np.int32) if object_index is None
                          else np.asarray(object_index, np.int32).reshape(t)),
            object_names=list(object_names or ["object"]),
        )

    @staticmethod
    def concatenate(parts) -> "Geometry":
        """Join several geometries (object indices, names, data and attributes are merged;
        an attribute some part lacks is zero there)."""
        parts = [g for g in parts if g.num_triangles]
        if not parts:
            return Geometry()
        sizes = {}
        for g in parts:
            for name, a in g.attributes.items():
                sizes[name] = max(sizes.get(name, 0), a.shape[2])
        attributes = {}
        for name, size in sizes.items():
            columns = []
            for g in parts:
                a = g.attributes.get(name)
                full = np.zeros((g.num_triangles, 3, size), np.float32)
                if a is not None:
                    full[:, :, :a.shape[2]] = a
                columns.append(full)
            attributes[name] = np.concatenate(columns)
        objects = [g.object_arrays() for g in parts]
        verts, tris, names, objs, infos = [], [], [], [], []
        v_off = 0
        for g in parts:
            verts.append(g.vertices)
            tris.append(g.triangles + v_off)
            objs.append(g.object_index + len(names))
            names.extend(g.object_names)
            infos.extend(g.object_pass_info())
            v_off += g.vertices.shape[0]
        return Geometry(
            vertices=np.concatenate(verts), triangles=np.concatenate(tris),
            normals=np.concatenate([g.normals for g in parts]),
            normal_index=np.concatenate([g.normal_index + k for g, k in
                                         zip(parts, np.cumsum([0] + [len(g.normals) for g in parts]))]),
            uvs=np.concatenate([g.uvs for g in parts]),
            material_index=np.concatenate([g.material_index for g in parts]),
            object_index=np.concatenate(objs), object_names=names, attributes=attributes,
            object_matrix=np.concatenate([o[0] for o in objects]),
            object_texspace=np.concatenate([o[1] for o in objects]),
            object_info=np.concatenate([o[2] for o in objects]),
            object_terminator=np.concatenate([g.terminator_offsets() for g in parts]),
            object_passes=infos,
            object_visibility=(None if all(g.object_visibility is None for g in parts)
                               else np.concatenate([g.visibility() for g in parts])),
            object_receiver_set=(None if all(g.object_receiver_set is None for g in parts)
                                 else np.concatenate([g.receiver_sets() for g in parts])),
            object_light_sets=(None if all(g.object_light_sets is None for g in parts)
                               else np.concatenate([g.light_sets() for g in parts])))


def auto_texspace_size(texspace: np.ndarray) -> np.ndarray:
    """Blender's rule for a texture space's half-size: 0 becomes 1, tiny ones +-1e-5."""
    out = np.array(texspace, np.float64)
    size = out[..., 1, :]
    size[size == 0.0] = 1.0
    tiny = np.abs(size) < 1e-5
    size[tiny] = np.where(size[tiny] < 0, -1e-5, 1e-5)
    return out


@dataclass(frozen=True)
class Link:
    """An input fed by another node: output socket ``socket`` of node number ``node``."""

    node: int
    socket: str = ""


@dataclass
class ShaderNode:
    """One node of a material's shader graph, as plain data.

    ``type`` is Blender's node type without its ``ShaderNode`` prefix
    ("BsdfPrincipled", "MixShader", ...).  ``inputs`` maps an input socket's
    identifier to a constant (a number, or a tuple for colours and vectors) or
    to a :class:`Link`; an input that is absent takes the node's default
    (``mcengine.kernels.svm.nodes``).  ``props`` holds enum and flag
    properties ("distribution": "MULTI_GGX", ...).
    """

    type: str
    inputs: dict = field(default_factory=dict)
    props: dict = field(default_factory=dict)
    name: str = ""


@dataclass
class Material:
    """A surface shader: a graph of shader nodes, as in Blender.

    ``nodes`` lists the graph's nodes and ``surface`` is what the material
    output's Surface socket receives (None: black, as in Cycles).
    ``use_transparent_shadow`` lets shadow rays through transparent closures;
    ``use_bump_map_correction`` tilts glossy normals whose mirror direction
    would point into the surface (Cycles' material setting of that name).
    ``displacement`` is what the output's Displacement socket receives: with
    ``displacement_method`` 'BUMP' it bumps the shading normal as Cycles' automatic bump
    does (``shaders``), with 'DISPLACEMENT' it moves the vertices of the material's triangles
    (true displacement, ``displacement``), and 'BOTH' does both.

    A material without ``nodes`` is described by the shorthand fields, a sum of
    closures convenient for tests and tools, equivalent to the graph
    :meth:`graph` builds: a Diffuse BSDF of ``base_color``, a Glossy BSDF (mirror,
    roughness 0, colour ``mirror_color``), a Glass BSDF (roughness 0,
    ``glass_color``, ``ior``), a Refraction BSDF (roughness 0,
    ``refraction_color``, ``ior``) and an Emission of radiance ``emission``
    (emitted on both sides like Cycles' mesh lights), added together.
    """

    name: str = "default"
    nodes: list = field(default_factory=list)
    surface: Link | None = None
    displacement: Link | None = None
    displacement_method: str = "BUMP"
    use_transparent_shadow: bool = True
    use_bump_map_correction: bool = True
    pass_index: int = 0
    base_color: tuple = (0.8, 0.8, 0.8)
    emission: tuple = (0.0, 0.0, 0.0)
    mirror_color: tuple = (0.0, 0.0, 0.0)
    glass_color: tuple = (0.0, 0.0, 0.0)
    refraction_color: tuple = (0.0, 0.0, 0.0)
    ior: float = 1.5

    def graph(self) -> tuple[list, Link | None]:
        """(nodes, surface link) of the material, built from the shorthand if it has no nodes."""
        if self.nodes:
            return self.nodes, self.surface
        nodes = []
        for color, node in ((self.base_color, ShaderNode("BsdfDiffuse")),
                            (self.mirror_color, ShaderNode("BsdfGlossy", {"Roughness": 0.0},
                                                           {"distribution": "GGX"})),
                            (self.glass_color, ShaderNode("BsdfGlass", {"IOR": self.ior},
                                                          {"distribution": "GGX"})),
                            (self.refraction_color, ShaderNode("BsdfRefraction",
                                                               {"IOR": self.ior},
                                                               {"distribution": "GGX"}))):
            if max(color) > 0.0:
                node.inputs["Color"] = tuple(color)
                nodes.append(node)
        if max(self.emission) > 0.0:
            nodes.append(ShaderNode("Emission", {"Color": tuple(self.emission), "Strength": 1.0}))
        if not nodes:
            return [], None
        out = Link(0, "BSDF")
        for k in range(1, len(nodes)):
            nodes.append(ShaderNode("AddShader", {"Shader": out, "Shader_001": Link(k, "BSDF")}))
            out = Link(len(nodes) - 1, "Shader")
        return nodes, out


@dataclass
class Image:
    """A texture image, read by the Image and Environment Texture nodes (``props["image"]``
    is its name in ``SceneDescription.images``).

    ``pixels`` is (H, W, C) uint8 (8-bit images) or float32 (float images), C = 1 to 4
    channels (grey, grey and alpha, RGB, RGBA), bottom row first as in Blender.
    ``colorspace`` says how texels become scene-linear colours: "sRGB" (decoded after
    interpolation, as Cycles does for images in an sRGB-equivalent space), "linear" (as
    stored) or "data" (Non-Color: as stored, and its alpha is never multiplied into the
    colour).  ``alpha`` is Blender's alpha mode: "STRAIGHT" (the colour is multiplied by
    alpha when the render loads it), "PREMUL" (already multiplied, as Blender's float
    buffers are), "CHANNEL_PACKED" (alpha independent of the colour), "NONE" (alpha read as
    1).
    """

    pixels: np.ndarray = field(default_factory=lambda: np.zeros((1, 1, 4), np.uint8))
    colorspace: str = "sRGB"
    alpha: str = "STRAIGHT"

    @property
    def nbytes(self) -> int:
        return int(np.asarray(self.pixels).nbytes)


@dataclass
class Light:
    """A Blender lamp, in Cycles' units (see module docstring).

    ``matrix_world`` is the object's 4x4 world matrix; lamps shine along local
    -Z.  Area-light extents are multiplied by the object scale, point radii are
    not (as in Cycles).
    """

    type: str = "POINT"
    matrix_world: np.ndarray = field(default_factory=lambda: np.eye(4))
    strength: tuple = (10.0, 10.0, 10.0)
    radius: float = 0.0              # point/spot: shadow_soft_size
    soft_falloff: bool = True        # point/spot: use_soft_falloff
    spot_size: float = np.pi / 4     # full cone angle, radians
    spot_blend: float = 0.15
    angle: float = 0.0               # sun: full angular diameter, radians
    shape: str = "SQUARE"            # area
    size_x: float = 1.0              # area: 'size' for SQUARE and DISK
    size_y: float = 1.0
    spread: float = np.pi            # area
    normalize: bool = True           # divide by the emitter area
    cast_shadow: bool = True
    use_mis: bool = True             # False: BSDF rays do not see the lamp
    visible_camera: bool = False     # Blender 5.0 default for lamps
    visible_diffuse: bool = True
    visible_glossy: bool = True
    visible_transmission: bool = True
    max_bounces: int = 1024
    light_sets: int = LIGHT_SETS_ALL  # light linking: the receivers' light sets it lights
    ies: IESProfile | None = None    # its IES Texture's profile (mcengine.ies) scales
                                     # the strength along each direction (None: none)
    name: str = "Light"


@dataclass
class Camera:
    """Blender camera data plus its world matrix (looks along local -Z, +Y up).

    Depth of field is described as Cycles' own camera describes it: a lens of
    radius ``aperture_size`` (metres; 0 is a pinhole camera) focused on the
    plane ``focal_distance`` metres in front of it, a disk or, with
    ``aperture_blades`` >= 3, a regular polygon turned by ``aperture_rotation``
    (radians), squeezed horizontally by ``aperture_ratio`` (anamorphic bokeh).
    The exporter derives them from Blender's f-stop, as Cycles does.
    """

    matrix_world: np.ndarray = field(default_factory=lambda: np.eye(4))
    type: str = "PERSP"              # 'PERSP' or 'ORTHO'
    lens: float = 50.0               # focal length, mm
    sensor_width: float = 36.0       # mm
    sensor_height: float = 24.0      # mm
    sensor_fit: str = "AUTO"         # 'AUTO', 'HORIZONTAL', 'VERTICAL'
    shift_x: float = 0.0
    shift_y: float = 0.0
    ortho_scale: float = 6.0
    clip_start: float = 0.1
    clip_end: float = 1000.0
    aperture_size: float = 0.0       # lens radius, m (0: no depth of field)
    focal_distance: float = 10.0     # distance of the plane in focus along the view axis, m
    aperture_blades: int = 0         # polygonal aperture with this many blades (< 3: a disk)
    aperture_rotation: float = 0.0   # rotation of the polygon, radians
    aperture_ratio: float = 1.0      # anamorphic squeeze: lens x is divided by it
    # Motion blur: the world matrices at the camera's motion steps, spread evenly over the
    # shutter (an odd number, the middle one the frame's; empty: the camera does not move),
    # and the view plane's size at shutter open and close relative to the frame's when
    # the focal length changes (perspective; Cycles' fov_pre and fov_post).
    motion: np.ndarray = field(default_factory=lambda: np.zeros((0, 4, 4)))
    view_scale_motion: tuple = (1.0, 1.0)


@dataclass
class ObjectMotion:
    """How one object of the geometry moves while the shutter is open.

    ``object`` is its index in ``Geometry.object_names``: its triangles are those
    of that ``object_index``, and their vertices are ``vertices`` = (first,
    count) of ``Geometry.vertices``, which hold the positions at the frame.
    Motion is given at S motion steps spread evenly over the shutter (S odd,
    the middle step is the frame):

    matrices   (S, 4, 4)  world matrices (metres) at the steps; empty when only
                          the mesh deforms
    positions  (S, count, 3) float32  the vertices at the steps, placed with the
                          frame's matrix (the deformation), or None
    normals    (S, T_o, 3, 3) float32  their corner shading normals likewise, for
                          the object's triangles in increasing order, or None

    At a time between two steps, the matrix is interpolated as Cycles does
    (``kernels.motion``) and applied to the positions, which are interpolated
    linearly; the result is ``M(t) M(frame)^-1 positions(t)``.
    """

    object: int
    vertices: tuple = (0, 0)
    matrices: np.ndarray = field(default_factory=lambda: np.zeros((0, 4, 4)))
    positions: np.ndarray | None = None
    normals: np.ndarray | None = None

    @property
    def steps(self) -> int:
        return len(self.matrices) if len(self.matrices) else len(self.positions)


@dataclass
class MotionBlur:
    """An open shutter: rays get times, and what moves is seen at those times.

    ``shutter_curve`` is Blender's shutter curve (``render.motion_blur_shutter_curve``)
    sampled at i / 256, i = 0..256, as Cycles samples it (None: flat); the ray
    times follow its inverted CDF over [0, 1], the whole shutter.  With
    ``rolling_shutter`` the rows are read out top to bottom, ``duration`` being
    the share of the shutter each row stays open (Cycles' rolling shutter).
    ``objects`` are the objects that move; the camera's motion is the camera's.
    Lamps do not move during the shutter, as in Cycles.
    """

    shutter_curve: np.ndarray | None = None
    rolling_shutter: bool = False
    rolling_shutter_duration: float = 0.1
    objects: list = field(default_factory=list)


@dataclass
class MotionVectors:
    """The scene at the previous and the next frame, for the Vector pass (motion blur off).

    ``objects`` are :class:`ObjectMotion` s of three steps (previous frame, frame, next
    frame) for the objects that move or deform; ``camera`` the camera's matrices (metres,
    without scale) at the previous and the next frame (None: it stays); ``view_scale`` a
    perspective camera's view plane there relative to the frame's, as
    ``Camera.view_scale_motion``.
    """

    objects: list = field(default_factory=list)
    camera: np.ndarray | None = None
    view_scale: tuple = (1.0, 1.0)


WORLD_SAMPLING = ("NONE", "AUTOMATIC", "MANUAL")


@dataclass
class World:
    """The background: light arriving from infinitely far along rays that escape.

    ``nodes`` and ``surface`` are the world's shader graph, as a material's
    (Background and Emission nodes emit their Color x Strength; Mix and Add
    Shader combine them; value nodes such as an Environment Texture feed them,
    the point being the ray's direction).  A world without ``nodes`` is the
    constant radiance ``color``.  ``visible_camera``, ``visible_diffuse``,
    ``visible_glossy`` and ``visible_transmission`` are its Ray Visibility (World >
    Settings: which rays that escape see it, and which lobes its light samples light, as
    Cycles' SHADER_EXCLUDE_* flags of the background); ``sampling`` and
    ``map_resolution`` are Cycles' world settings
    Sampling Method (None, Automatic, Manual) and Map Resolution: how next-event
    estimation samples the background.
    """

    color: tuple = (0.0509, 0.0509, 0.0509)
    visible_camera: bool = True
    visible_diffuse: bool = True
    visible_glossy: bool = True
    visible_transmission: bool = True
    nodes: list = field(default_factory=list)
    surface: Link | None = None
    sampling: str = "AUTOMATIC"
    map_resolution: int = 1024

    @property
    def name(self) -> str:
        return "world"

    def graph(self) -> tuple[list, Link | None]:
        """(nodes, surface link): the graph, or a Background node of ``color``."""
        if self.nodes:
            return self.nodes, self.surface
        return [ShaderNode("Background", {"Color": tuple(self.color), "Strength": 1.0})], Link(0, "Background")

    def material(self) -> "Material":
        """The graph as a material, for the shader compiler."""
        nodes, surface = self.graph()
        return Material(name="world", nodes=nodes, surface=surface)


@dataclass
class Film:
    """Output raster.

    ``width``/``height`` are the full frame in pixels (resolution percentage
    already applied).  ``region`` is the rendered window ``(x0, y0, x1, y1)`` in
    pixels, top-left origin, x1/y1 exclusive; ``None`` means the whole frame.
    """

    width: int = 128
    height: int = 128
    pixel_aspect_x: float = 1.0
    pixel_aspect_y: float = 1.0
    region: tuple | None = None
    filter_type: str = "BLACKMAN_HARRIS"
    filter_width: float = 1.5
    transparent: bool = False
    exposure: float = 1.0

    @property
    def window(self) -> tuple:
        return tuple(self.region) if self.region is not None else (0, 0, self.width, self.height)


@dataclass
class Integrator:
    """Sampling and path settings, named as Cycles names them.

    ``name`` chooses the algorithm, one of :data:`mcengine.integrators.NAMES`:
    "path" (path tracing, the default and the only one that matches Cycles),
    "raycast", "whitted" (mirror and refraction rays down to ``depth`` ray
    levels) or "distribution" (``branching`` rays at every hit, ``depth``
    levels).  ``sampler`` chooses the random numbers of the path tracer, one of
    :data:`mcengine.samplers.NAMES`: "sobol" (scrambled Sobol, as Cycles) or
    "independent" (the lecture's independent numbers).
    """

    name: str = integrators.DEFAULT
    depth: int = integrators.DEFAULT_DEPTH
    branching: int = integrators.DEFAULT_BRANCHING
    sampler: str = samplers.DEFAULT
    samples: int = 64
    seed: int = 0
    max_bounces: int = 12
    diffuse_bounces: int = 4
    glossy_bounces: int = 4
    transmission_bounces: int = 12
    transparent_max_bounces: int = 8
    min_light_bounces: int = 0
    clamp_direct: float = 0.0        # 0 = off
    clamp_indirect: float = 0.0      # 0 = off
    filter_glossy: float = 0.0       # Cycles' blur_glossy; 0 = off
    caustics_reflective: bool = True
    caustics_refractive: bool = True
    time_limit: float = 0.0          # seconds, 0 = none
    use_adaptive_sampling: bool = False
    adaptive_threshold: float = 0.01   # relative noise at which a pixel stops (0: automatic)
    adaptive_min_samples: int = 0      # samples before a pixel may stop (0: automatic)
    # Performance > Acceleration Structure: how Embree builds the BVH (kernels.embree.build).
    use_spatial_splits: bool = False
    use_compact_bvh: bool = False


@dataclass
class SceneDescription:
    geometry: Geometry = field(default_factory=Geometry)
    materials: list = field(default_factory=lambda: [Material()])
    lights: list = field(default_factory=list)
    camera: Camera = field(default_factory=Camera)
    world: World = field(default_factory=World)
    film: Film = field(default_factory=Film)
    integrator: Integrator = field(default_factory=Integrator)
    passes: RenderPasses = field(default_factory=RenderPasses)
    denoising: Denoising = field(default_factory=Denoising)
    motion_blur: MotionBlur | None = None     # None: the shutter is closed, every ray at time 0.5
    motion_vectors: MotionVectors | None = None   # Vector pass: None when nothing moves
    warnings: list = field(default_factory=list)
    images: dict = field(default_factory=dict)       # name -> Image

    # -- validation --------------------------------------------------------
    def validate(self) -> "SceneDescription":
        """Raise :class:`SceneError` with a one-line message if anything is unusable."""
        g = self.geometry
        t = g.num_triangles
        if g.vertices.ndim != 2 or g.vertices.shape[1] != 3:
            raise SceneError(f"geometry.vertices must be (V, 3), got {g.vertices.shape}")
        for name, arr, shape in (("triangles", g.triangles, (t, 3)),
                                 ("normal_index", g.normal_index, (t, 3)),
                                 ("uvs", g.uvs, (t, 3, 2)),
                                 ("material_index", g.material_index, (t,)),
                                 ("object_index", g.object_index, (t,))):
            if arr.shape != shape:
                raise SceneError(f"geometry.{name} has shape {arr.shape}, expected {shape}")
        if t and (g.triangles.min() < 0 or g.triangles.max() >= g.vertices.shape[0]):
            raise SceneError("geometry.triangles refers to vertices that do not exist")
        if g.normals.ndim != 2 or g.normals.shape[1] != 3:
            raise SceneError(f"geometry.normals must be (K, 3), got {g.normals.shape}")
        if t and (g.normal_index.min() < 0 or g.normal_index.max() >= g.normals.shape[0]):
            raise SceneError("geometry.normal_index refers to normals that do not exist")
        for name in ("vertices", "normals", "uvs"):
            if not np.all(np.isfinite(getattr(g, name))):
                raise SceneError(f"geometry.{name} contains NaN or infinite values")
        for name, a in g.attributes.items():
            a = np.asarray(a)
            if not isinstance(name, str) or a.ndim != 3 or a.shape[:2] != (t, 3) or not 1 <= a.shape[2] <= 4:
                raise SceneError(f"geometry attribute {name!r} has shape {a.shape}, expected ({t}, 3, 1..4)")
            if not np.all(np.isfinite(a)):
                raise SceneError(f"geometry attribute {name!r} contains NaN or infinite values")
        o = g.num_objects
        if t and (g.object_index.min() < 0 or g.object_index.max() >= max(o, 1)):
            raise SceneError("geometry.object_index refers to an object that does not exist")
        for name, shape in (("object_matrix", (o, 4, 4)), ("object_texspace", (o, 2, 3)),
                            ("object_info", (o, 6)), ("object_terminator", (o, 2))):
            a = getattr(g, name)
            if a is None:
                continue
            if np.shape(a) != shape or not np.all(np.isfinite(a)):
                raise SceneError(f"geometry.{name} must be finite with shape {shape}")
        if g.object_visibility is not None and (
                np.shape(g.object_visibility) != (o,)
                or np.any((np.asarray(g.object_visibility, np.int64) & ~VIS_ALL) != 0)):
            raise SceneError(f"geometry.object_visibility must hold ({o},) masks of VIS_* bits "
                             f"(0..{VIS_ALL})")
        if g.object_receiver_set is not None and (
                np.shape(g.object_receiver_set) != (o,)
                or np.any(np.asarray(g.object_receiver_set, np.int64) >= MAX_LIGHT_SETS)
                or np.any(np.asarray(g.object_receiver_set, np.int64) < 0)):
            raise SceneError(f"geometry.object_receiver_set must hold ({o},) light sets "
                             f"(0..{MAX_LIGHT_SETS - 1})")
        if g.object_light_sets is not None and (
                np.shape(g.object_light_sets) != (o,)
                or np.asarray(g.object_light_sets).dtype.kind not in "iu"
                or np.any(np.asarray(g.object_light_sets) < 0)):
            raise SceneError(f"geometry.object_light_sets must hold ({o},) masks of light sets "
                             f"(unsigned 64-bit integers)")
        if g.object_terminator is not None and not np.all(
                (np.asarray(g.object_terminator) >= 0.0) & (np.asarray(g.object_terminator) <= 1.0)):
            raise SceneError("geometry.object_terminator: the Shadow Terminator offsets must lie "
                             "in [0, 1]")
        if g.object_matrix is not None and o and np.any(
                np.abs(np.linalg.det(np.asarray(g.object_matrix)[:, :3, :3])) < 1e-300):
            raise SceneError("geometry.object_matrix has a singular matrix (an object scaled to 0)")
        if t and (g.material_index.min() < 0 or g.material_index.max() >= len(self.materials)):
            raise SceneError("geometry.material_index refers to a material that does not exist")
        if not self.materials:
            raise SceneError("the scene needs at least one material")
        for m in self.materials:
            where = f"material '{m.name}'"
            _check_number(where, "ior", m.ior, lo=1e-6)
            for attr in ("base_color", "emission", "mirror_color", "glass_color", "refraction_color"):
                v = np.asarray(getattr(m, attr), float)
                if v.shape != (3,) or not np.all(np.isfinite(v)) or np.any(v < 0):
                    raise SceneError(f"{where}: {attr} must be 3 finite non-negative values")
            _check_graph(where, m)
        for li in self.lights:
            where = f"light '{li.name}'"
            if li.type not in LIGHT_TYPES:
                raise SceneError(f"{where}: unknown type {li.type!r}")
            if li.type == "AREA" and li.shape not in AREA_SHAPES:
                raise SceneError(f"{where}: unknown area shape {li.shape!r}")
            _check_matrix(where, li.matrix_world)
            _check_vector(where, "strength", li.strength, 3)
            for attr in ("radius", "angle", "size_x", "size_y", "spot_blend"):
                _check_number(where, attr, getattr(li, attr), lo=0.0)
            # Blender stores angles as float32: pi arrives slightly above math.pi.
            _check_number(where, "spot_size", li.spot_size, lo=0.0, hi=PI_FLOAT32)
            _check_number(where, "spread", li.spread, lo=0.0, hi=PI_FLOAT32)
            _check_number(where, "max_bounces", li.max_bounces, lo=0)
            if not (isinstance(li.light_sets, (int, np.integer)) and 0 <= li.light_sets <= LIGHT_SETS_ALL):
                raise SceneError(f"{where}: light_sets must be a mask of light sets "
                                 f"(an integer in 0..2^{MAX_LIGHT_SETS} - 1), got {li.light_sets!r}")
        _check_vector("world", "color", self.world.color, 3)
        _check_graph("world", self.world)
        if self.world.sampling not in WORLD_SAMPLING:
            raise SceneError(f"world: unknown sampling {self.world.sampling!r} ({', '.join(WORLD_SAMPLING)})")
        _check_number("world", "map_resolution", self.world.map_resolution, lo=4, hi=MAX_RESOLUTION)
        for name, im in self.images.items():
            _check_image(name, im)
        f = self.film
        for attr in ("width", "height"):
            _check_number("film", attr, getattr(f, attr), lo=1, hi=MAX_RESOLUTION)
        x0, y0, x1, y1 = f.window
        if not (0 <= x0 < x1 <= f.width and 0 <= y0 < y1 <= f.height):
            raise SceneError(f"film region {f.window} is empty or outside the {f.width}x{f.height} frame")
        if f.filter_type not in FILTER_TYPES:
            raise SceneError(f"unknown pixel filter {f.filter_type!r}")
        _check_number("film", "filter_width", f.filter_width, lo=MIN_FILTER_WIDTH)
        _check_number("film", "exposure", f.exposure)
        for attr in ("pixel_aspect_x", "pixel_aspect_y"):
            _check_number("film", attr, getattr(f, attr), lo=1e-6)
        c = self.camera
        if c.type not in ("PERSP", "ORTHO"):
            raise SceneError(f"camera type {c.type!r} is not supported (PERSP, ORTHO)")
        _check_matrix("camera", c.matrix_world, axes=True)
        for attr in ("lens", "sensor_width", "sensor_height", "ortho_scale"):
            _check_number("camera", attr, getattr(c, attr), lo=1e-9)
        for attr in ("shift_x", "shift_y"):
            _check_number("camera", attr, getattr(c, attr))
        _check_number("camera", "clip_start", c.clip_start, lo=0.0)
        _check_number("camera", "clip_end", c.clip_end, lo=c.clip_start + 1e-12)
        motion = np.asarray(c.motion, float)
        if motion.size and (motion.ndim != 3 or motion.shape[1:] != (4, 4) or len(motion) % 2 == 0):
            raise SceneError(f"camera: motion must be an odd number of 4x4 matrices, got {motion.shape}")
        for m in motion:
            _check_matrix("camera motion", m, axes=True)
        _check_vector("camera", "view_scale_motion", c.view_scale_motion, 2)
        if min(c.view_scale_motion) <= 0.0:
            raise SceneError(f"camera: view_scale_motion must be positive, got {c.view_scale_motion}")
        if self.motion_blur is not None:
            mb = self.motion_blur
            if mb.shutter_curve is not None:
                curve = np.asarray(mb.shutter_curve, float)
                if curve.shape != (257,) or not np.all(np.isfinite(curve)) or not np.any(curve):
                    raise SceneError("motion blur: shutter_curve must be 257 finite values, not all 0")
            _check_number("motion blur", "rolling_shutter_duration", mb.rolling_shutter_duration,
                          lo=0.0, hi=1.0)
            for om in mb.objects:
                _check_object_motion(om, self.geometry)
        if self.motion_vectors is not None:
            mv = self.motion_vectors
            for om in mv.objects:
                _check_object_motion(om, self.geometry)
                if om.steps != 3:
                    raise SceneError(f"motion vectors: an object's motion needs 3 steps (previous "
                                     f"frame, frame, next frame), got {om.steps}")
            if mv.camera is not None:
                if np.shape(mv.camera) != (2, 4, 4):
                    raise SceneError(f"motion vectors: camera must be 2 4x4 matrices, got "
                                     f"{np.shape(mv.camera)}")
                for m in mv.camera:
                    _check_matrix("motion vectors camera", m, axes=True)
            _check_vector("motion vectors", "view_scale", mv.view_scale, 2)
            if min(mv.view_scale) <= 0.0:
                raise SceneError(f"motion vectors: view_scale must be positive, got {mv.view_scale}")
        if c.sensor_fit not in ("AUTO", "HORIZONTAL", "VERTICAL"):
            raise SceneError(f"camera: unknown sensor_fit {c.sensor_fit!r} (AUTO, HORIZONTAL, VERTICAL)")
        _check_number("camera", "aperture_size", c.aperture_size, lo=0.0)
        _check_number("camera", "focal_distance", c.focal_distance, lo=0.0)
        _check_number("camera", "aperture_blades", c.aperture_blades, lo=0, hi=MAX_BLADES)
        _check_number("camera", "aperture_rotation", c.aperture_rotation)
        _check_number("camera", "aperture_ratio", c.aperture_ratio, lo=1e-6)
        i = self.integrator
        try:
            integrators.get(i.name)
            integrators.check_parameters(i.depth, i.branching)
            samplers.get(i.sampler)
        except ValueError as exc:
            raise SceneError(str(exc)) from None
        _check_number("integrator", "samples", i.samples, lo=1, hi=MAX_SAMPLES)
        for attr in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
                     "transparent_max_bounces", "min_light_bounces", "adaptive_min_samples"):
            _check_number("integrator", attr, getattr(i, attr), lo=0, hi=MAX_BOUNCES)
        for attr in ("clamp_direct", "clamp_indirect", "filter_glossy", "time_limit",
                     "adaptive_threshold"):
            _check_number("integrator", attr, getattr(i, attr), lo=0.0)
        for problem in self.passes.check() + self.denoising.check():
            raise SceneError(problem)
        return self

    # -- persistence -------------------------------------------------------
    def save(self, path) -> None:
        """Write the whole description to one ``.npz`` file."""
        g = self.geometry
        meta = {
            "object_names": g.object_names,
            "object_passes": [dataclasses.asdict(o) for o in g.object_passes],
            "materials": [dataclasses.asdict(m) for m in self.materials],
            "lights": [_light_meta(li) for li in self.lights],
            "camera": _plain(dataclasses.asdict(self.camera)),
            "world": dataclasses.asdict(self.world),
            "film": dataclasses.asdict(self.film),
            "integrator": dataclasses.asdict(self.integrator),
            "passes": dataclasses.asdict(self.passes),
            "denoising": dataclasses.asdict(self.denoising),
            "motion_blur": _motion_meta(self.motion_blur),
            "motion_vectors": _motion_meta(self.motion_vectors),
            "warnings": list(self.warnings),
        }
        matrix, texspace, info = g.object_arrays()
        meta["attributes"] = list(g.attributes)
        attributes = {f"attribute{k}": a for k, a in enumerate(g.attributes.values())}
        meta["images"] = [{"name": name, "colorspace": im.colorspace, "alpha": im.alpha}
                          for name, im in self.images.items()]
        images = {f"image{k}": im.pixels for k, im in enumerate(self.images.values())}
        np.savez_compressed(
            path, vertices=g.vertices, triangles=g.triangles, normals=g.normals,
            normal_index=g.normal_index,
            uvs=g.uvs, material_index=g.material_index, object_index=g.object_index,
            object_matrix=matrix, object_texspace=texspace, object_info=info,
            object_terminator=g.terminator_offsets(), object_visibility=g.visibility(),
            object_receiver_set=g.receiver_sets(), object_light_sets=g.light_sets(),
            **attributes,
            **images, meta=np.frombuffer(json.dumps(meta).encode(), np.uint8))

    @staticmethod
    def load(path) -> "SceneDescription":
        """Read a scene written by :meth:`save`, validated.

        Any damaged, foreign or crafted file gives a :class:`SceneError`.  The
        arrays' sizes are read from their headers first: a file that would not
        fit in memory once decompressed is refused before it is decompressed.
        """
        path = Path(path)
        try:
            with zipfile.ZipFile(path) as archive:
                arrays = _read_arrays(archive, path)
            meta = json.loads(bytes(arrays.pop("meta")).decode())
            scene = _from_saved(arrays, meta)
        except SceneError:
            raise
        except (OSError, EOFError, KeyError, IndexError, TypeError, ValueError, AttributeError,
                zipfile.BadZipFile) as exc:
            raise SceneError(f"{path}: not a saved mcengine scene ({type(exc).__name__}: {exc})"
                             ) from None
        try:
            return scene.validate()
        except SceneError as exc:
            raise SceneError(f"{path}: {exc}") from None


# Arrays of a saved scene: name -> (dtype kind, trailing shape); optional ones (files saved
# before 0.3 lack them), and attributes "attribute<k>" of trailing shape (3, C).
_SAVED_ARRAYS = {
    "vertices": ("f", (3,)), "triangles": ("iu", (3,)), "normals": ("f", (3, 3)),
    "uvs": ("f", (3, 2)), "material_index": ("iu", ()), "object_index": ("iu", ()),
    "meta": ("u", ()),
}
_OPTIONAL_ARRAYS = {"object_matrix": ("f", (4, 4)), "object_texspace": ("f", (2, 3)),
                    "object_info": ("f", (6,)), "object_terminator": ("f", (2,)),
                    "object_visibility": ("iu", ()), "object_receiver_set": ("iu", ()),
                    "object_light_sets": ("iu", ()), "normal_index": ("iu", (3,))}
MAX_META_BYTES = 64 << 20


def _read_arrays(archive: zipfile.ZipFile, path: Path) -> dict:
    """The saved arrays, after checking every header (dtype, shape, total size)."""
    headers = {}
    present = {name[:-4] for name in archive.namelist() if name.endswith(".npy")}
    expected = dict(_SAVED_ARRAYS)
    expected.update({n: spec for n, spec in _OPTIONAL_ARRAYS.items() if n in present})
    if "normal_index" in present:            # normals a table (K, 3); older files: per corner
        expected["normals"] = ("f", (3,))
    for name in present:
        if name.startswith("attribute"):
            expected[name] = ("f", None)
        elif name.startswith("image"):
            expected[name] = ("fu", "image")
    for name, (kinds, trailing) in expected.items():
        with archive.open(f"{name}.npy") as f:
            version = np.lib.format.read_magic(f)
            read_header = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                           else np.lib.format.read_array_header_2_0)
            shape, _fortran, dtype = read_header(f)
        if trailing is None and len(shape) == 3 and shape[1] == 3:   # an attribute: (T, 3, C)
            trailing = tuple(shape[1:])
        if trailing == "image" and len(shape) == 3 and dtype in (np.uint8, np.float32):
            trailing = tuple(shape[1:])                               # an image: (H, W, C)
        if dtype.kind not in kinds or dtype.hasobject or tuple(shape[1:]) != trailing \
                or len(shape) != 1 + len(trailing):
            raise SceneError(f"{path}: array {name!r} has dtype {dtype} and shape {shape}")
        headers[name] = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
    if headers["meta"] > MAX_META_BYTES:
        raise SceneError(f"{path}: its description block is {headers['meta']} bytes")
    total = sum(headers.values())
    free = memory.available()
    if free is not None and total > free // 2:
        raise SceneError(f"{path}: its arrays need {total / memory.GIB:.2f} GiB once decompressed, "
                         f"more than half the {free / memory.GIB:.2f} GiB of memory available")
    with np.load(path, allow_pickle=False) as z:
        return {name: z[name] for name in expected}


def _from_saved(z: dict, meta: dict) -> "SceneDescription":
    """Build the description from the arrays and the JSON metadata of a saved file."""
    names = list(meta.get("attributes", []))
    geom = Geometry(vertices=z["vertices"], triangles=z["triangles"], normals=z["normals"],
                    normal_index=z.get("normal_index"),
                    uvs=z["uvs"], material_index=z["material_index"],
                    object_index=z["object_index"], object_names=list(meta["object_names"]),
                    attributes={str(name): z[f"attribute{k}"] for k, name in enumerate(names)},
                    object_matrix=z.get("object_matrix"), object_texspace=z.get("object_texspace"),
                    object_info=z.get("object_info"), object_terminator=z.get("object_terminator"),
                    object_visibility=z.get("object_visibility"),
                    object_receiver_set=z.get("object_receiver_set"),
                    object_light_sets=z.get("object_light_sets"),
                    object_passes=[ObjectPassInfo(**o) for o in meta.get("object_passes", [])])
    lights = []
    for d in meta["lights"]:
        d = dict(d)
        d["matrix_world"] = np.array(d["matrix_world"], float)
        if d.get("ies") is not None:
            d["ies"] = IESProfile(**{k: _array_from_json(v) for k, v in d["ies"].items()})
        lights.append(Light(**{k: (tuple(v) if isinstance(v, list) and k != "matrix_world" else v)
                               for k, v in d.items()}))
    cam = dict(meta["camera"])
    cam["matrix_world"] = np.array(cam["matrix_world"], float)
    cam["motion"] = np.array(cam.get("motion", []), float).reshape(-1, 4, 4)
    cam["view_scale_motion"] = tuple(cam.get("view_scale_motion", (1.0, 1.0)))
    motion_blur = _motion_from_meta(MotionBlur, meta.get("motion_blur"))
    motion_vectors = _motion_from_meta(MotionVectors, meta.get("motion_vectors"))
    film = dict(meta["film"])
    if film.get("region") is not None:
        film["region"] = tuple(film["region"])
    images = {str(d["name"]): Image(pixels=z[f"image{k}"], colorspace=str(d["colorspace"]),
                                    alpha=str(d["alpha"]))
              for k, d in enumerate(meta.get("images", []))}
    return SceneDescription(
        geometry=geom, images=images,
        materials=[_material_from_saved(d) for d in meta["materials"]],
        lights=lights, camera=Camera(**cam),
        world=_world_from_saved(meta["world"]),
        film=Film(**film), integrator=Integrator(**_integrator_meta(meta["integrator"])),
        passes=RenderPasses(**{k: (tuple(v) if isinstance(v, list) else v)
                               for k, v in meta.get("passes", {}).items()}),
        denoising=Denoising(**meta.get("denoising", {})),
        motion_blur=motion_blur, motion_vectors=motion_vectors,
        warnings=list(meta.get("warnings", [])))


def _json_array(a) -> dict:
    a = np.asarray(a)
    return {"dtype": a.dtype.str, "shape": list(a.shape), "values": a.ravel().tolist()}


def _array_from_json(d: dict) -> np.ndarray:
    return np.array(d["values"], np.dtype(d["dtype"])).reshape(d["shape"])


def _motion_meta(motion) -> dict | None:
    """A MotionBlur or MotionVectors as JSON: its arrays and its objects' arrays with their
    dtypes and shapes, so that a loaded scene renders the same bits."""
    if motion is None:
        return None
    d = {f.name: getattr(motion, f.name) for f in dataclasses.fields(motion)}
    d["objects"] = [{f.name: (_json_array(v) if isinstance(v := getattr(om, f.name), np.ndarray)
                              else v) for f in dataclasses.fields(om)} for om in motion.objects]
    return {k: (_json_array(v) if isinstance(v, np.ndarray) else v) for k, v in d.items()}


def _motion_from_meta(kind, d: dict | None):
    if d is None:
        return None
    arrays = {k: (_array_from_json(v) if isinstance(v, dict) else v) for k, v in d.items()}
    arrays["objects"] = [ObjectMotion(**{k: (_array_from_json(v) if isinstance(v, dict)
                                             else tuple(v) if isinstance(v, list) else v)
                                         for k, v in om.items()}) for om in d["objects"]]
    if "view_scale" in arrays:
        arrays["view_scale"] = tuple(arrays["view_scale"])
    return kind(**arrays)


def _plain(d: dict) -> dict:
    return {k: (np.asarray(v).tolist() if isinstance(v, np.ndarray) else v) for k, v in d.items()}


def _light_meta(li: Light) -> dict:
    d = _plain(dataclasses.asdict(dataclasses.replace(li, ies=None)))
    if li.ies is not None:
        d["ies"] = {name: _json_array(getattr(li.ies, name))
                    for name in ("h_angles", "v_angles", "intensity")}
    d["strength"] = [float(x) for x in d["strength"]]
    d["light_sets"] = int(d["light_sets"])
    return {k: (float(v) if isinstance(v, np.floating) else v) for k, v in d.items()}


def _integrator_meta(d: dict) -> dict:
    """Integrator settings of a saved scene; files saved before 0.2 call the name "method"."""
    d = dict(d)
    if "method" in d:
        d["name"] = d.pop("method")
    return d


def _check_number(where: str, name: str, value, lo=None, hi=None) -> None:
    """SceneError unless ``value`` is a finite number within [lo, hi]."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SceneError(f"{where}: {name} must be a number, got {value!r}") from None
    if not math.isfinite(x):
        raise SceneError(f"{where}: {name} must be finite, got {value!r}")
    if (lo is not None and x < lo) or (hi is not None and x > hi):
        bounds = f"at least {lo}" if hi is None else f"between {lo} and {hi}" if lo is not None \
            else f"at most {hi}"
        raise SceneError(f"{where}: {name} must be {bounds}, got {value!r}")


def _check_vector(where: str, name: str, value, size: int) -> None:
    v = np.asarray(value, float) if np.ndim(value) == 1 else None
    if v is None or v.shape != (size,) or not np.all(np.isfinite(v)):
        raise SceneError(f"{where}: {name} must be {size} finite values, got {value!r}")


def _check_matrix(where: str, value, axes: bool = False) -> None:
    """A finite 4x4 matrix; with ``axes``, its three axes must have a length (they are normalised)."""
    m = np.asarray(value, float)
    if m.shape != (4, 4) or not np.all(np.isfinite(m)):
        raise SceneError(f"{where}: matrix_world must be a finite 4x4 matrix")
    if axes and np.any(np.linalg.norm(m[:3, :3], axis=0) <= 0.0):
        raise SceneError(f"{where}: matrix_world has a zero-length axis (scale 0)")


def _check_image(name, im) -> None:
    where = f"image {name!r}"
    if not isinstance(name, str) or not isinstance(im, Image):
        raise SceneError(f"{where}: images must map names to Image")
    p = np.asarray(im.pixels)
    if p.ndim != 3 or not 1 <= p.shape[2] <= 4 or p.shape[0] < 1 or p.shape[1] < 1 \
            or p.dtype not in (np.uint8, np.float32):
        raise SceneError(f"{where}: pixels must be (H, W, 1..4) uint8 or float32, got "
                         f"{p.dtype} {p.shape}")
    if im.colorspace not in IMAGE_COLORSPACES:
        raise SceneError(f"{where}: unknown colour space {im.colorspace!r} ({', '.join(IMAGE_COLORSPACES)})")
    if im.alpha not in IMAGE_ALPHA_MODES:
        raise SceneError(f"{where}: unknown alpha mode {im.alpha!r} ({', '.join(IMAGE_ALPHA_MODES)})")


def _check_object_motion(om: ObjectMotion, g: Geometry) -> None:
    """An ObjectMotion names an existing object, its own vertices and consistent steps."""
    if not 0 <= om.object < max(len(g.object_names), 1):
        raise SceneError(f"motion blur: object {om.object} does not exist")
    where = f"motion of object '{g.object_names[om.object]}'" if g.object_names else "motion"
    first, count = (int(v) for v in om.vertices)
    if first < 0 or count < 0 or first + count > g.vertices.shape[0]:
        raise SceneError(f"{where}: vertices {om.vertices} are outside the geometry")
    mats = np.asarray(om.matrices, float)
    if mats.size:
        if mats.ndim != 3 or mats.shape[1:] != (4, 4) or len(mats) % 2 == 0:
            raise SceneError(f"{where}: matrices must be an odd number of 4x4 matrices")
        for m in mats:
            _check_matrix(where, m)
    tris = g.triangles[g.object_index == om.object]
    if len(tris) and (tris.min() < first or tris.max() >= first + count):
        raise SceneError(f"{where}: its triangles use vertices outside {om.vertices}")
    if om.positions is None:
        if not mats.size:
            raise SceneError(f"{where}: neither matrices nor positions")
        return
    steps = len(mats) if mats.size else len(om.positions)
    pos = np.asarray(om.positions)
    if pos.shape != (steps, count, 3) or steps % 2 == 0 or steps < 3:
        raise SceneError(f"{where}: positions have shape {pos.shape}, expected ({steps}, {count}, 3)")
    if om.normals is None or np.asarray(om.normals).shape != (steps, len(tris), 3, 3):
        raise SceneError(f"{where}: normals must have shape ({steps}, {len(tris)}, 3, 3)")
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(om.normals))):
        raise SceneError(f"{where}: positions or normals are not finite")


def _check_graph(where: str, material: Material) -> None:
    """Links point at existing nodes and every constant input is finite."""
    nodes = material.nodes
    links = [link for link in (material.surface, getattr(material, "displacement", None))
             if link is not None]
    for k, node in enumerate(nodes):
        if not isinstance(node, ShaderNode) or not isinstance(node.type, str):
            raise SceneError(f"{where}: node {k} is not a ShaderNode")
        for socket, value in node.inputs.items():
            if isinstance(value, Link):
                links.append(value)
            elif not np.all(np.isfinite(np.asarray(value, float))):
                raise SceneError(f"{where}: node {k} ({node.type}) input '{socket}' is not finite")
    for link in links:
        if not isinstance(link, Link) or not 0 <= link.node < len(nodes):
            raise SceneError(f"{where}: a link refers to node {getattr(link, 'node', link)!r}, "
                             f"which does not exist")


def _saved_value(v):
    """A saved input or setting: links are dicts, colours lists."""
    if isinstance(v, dict):
        return Link(int(v["node"]), str(v["socket"]))
    return tuple(v) if isinstance(v, list) else v


def _graph_from_saved(d: dict) -> dict:
    """A saved material's or world's fields, its graph as nodes and links again."""
    d = dict(d)
    d["nodes"] = [ShaderNode(type=n["type"], inputs={k: _saved_value(v) for k, v in n["inputs"].items()},
                             props=dict(n.get("props", {})), name=n.get("name", ""))
                  for n in d.get("nodes", [])]
    if d.get("surface") is not None:
        d["surface"] = _saved_value(d["surface"])
    return {k: (_saved_value(v) if k not in ("nodes", "surface") else v) for k, v in d.items()}


def _material_from_saved(d: dict) -> Material:
    return Material(**_graph_from_saved(d))


def _world_from_saved(d: dict) -> World:
    return World(**_graph_from_saved(d))
