"""Shared helpers for the scene generator scripts in ``blend_scenes/``.

Each ``blend_scenes/<name>.py`` builds one test or demo scene from Blender's
factory settings with ``bpy`` and writes ``blend_scenes/<name>.blend`` next to
itself.  The scenes are the common ground on which Cycles and MC Engine are
compared, so every scene gets the same unbiased render settings
(:func:`apply_render_settings`): 128x128 pixels, 64 samples, seed 0, no
denoising, no adaptive sampling, no clamping, no Filter Glossy, Blackman-Harris
1.5 px pixel filter, exposure 1, view transform 'Standard', opaque film.

Conventions (Blender's): +Z is up, lengths in metres, colours linear in the
scene's working space (Linear Rec.709), angles in radians.  Cameras and lights
are aimed with :func:`look_at`, which points the object's local -Z axis (the
direction cameras look and area, spot and sun lights shine) at a target.

Materials of the light, camera and transform scenes are restricted to the
simplest closures, so that those scenes test lights and geometry only:

* :func:`diffuse_material`: Diffuse BSDF with roughness 0 (Lambert).
* :func:`lambert_principled_material`: Principled BSDF with 'Specular IOR
  Level' 0, which is exactly Lambert too (it exercises the Principled path).
* :func:`emission_material`: Emission shader, radiance = colour x strength.

The material scenes (``material_*.py``) build any shader node with
:func:`node_material` (one node into the Surface output) and
:func:`combine_material` (a Mix or Add Shader of two nodes); inputs are named
in snake case (``base_color=``, ``specular_ior_level=``) and anything that is
not an input is a node property (``distribution="GGX"``).

Determinism: the same script writes the same bytes.  :func:`save_blend` lets
Blender write the file uncompressed, rewrites the few fields Blender fills from
the clock or leftover memory (see ``_blendfile.py``) and compresses the result
with zstd itself (Blender reads plain zstd files).  Meshes drop their
edit-mode selection attributes, which Blender writes with uninitialised bytes.
"""
from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import _blendfile
import bpy
import zstandard
from mathutils import Euler, Vector

# Render settings shared by every scene (see the module docstring).
RESOLUTION = 128
SAMPLES = 64
FILTER_WIDTH_PX = 1.5  # Cycles' default Blackman-Harris width.

# UV sphere tessellation.  Smooth-shaded low-poly meshes are avoided on purpose:
# Cycles' shadow-terminator handling of interpolated normals differs from a
# plain renderer's, and 64x32 makes that difference invisible.
SPHERE_SEGMENTS = 64
SPHERE_RINGS = 32

# zstd level for the saved files: the files are tiny, so the slowest, densest
# level costs well under a second.
ZSTD_LEVEL = 19

# --------------------------------------------------------------------------
# Scene and render settings
# --------------------------------------------------------------------------

def new_scene():
    """Reset Blender to factory settings with an empty scene and return it.

    The scene gets the common render settings (with the default light-scene
    bounce limits; call :func:`set_bounces` to change them).
    """
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    apply_render_settings(scene)
    return scene


def apply_render_settings(scene):
    """Apply the unbiased render settings shared by all scenes (see module docstring)."""
    scene.render.engine = "CYCLES"
    scene.render.resolution_x = RESOLUTION
    scene.render.resolution_y = RESOLUTION
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = 1.0
    scene.render.pixel_aspect_y = 1.0
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0

    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = SAMPLES
    cycles.seed = 0
    cycles.use_animated_seed = False
    cycles.use_denoising = False
    cycles.use_adaptive_sampling = False
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.blur_glossy = 0.0
    cycles.caustics_reflective = True
    cycles.caustics_refractive = True
    cycles.pixel_filter_type = "BLACKMAN_HARRIS"
    cycles.filter_width = FILTER_WIDTH_PX
    cycles.film_exposure = 1.0
    set_bounces(scene, total=4, diffuse=4)


def set_bounces(scene, total, diffuse, glossy=4, transmission=12, caustics=True):
    """Set the bounce limits explicitly.

    Cycles stops a path at whichever limit is reached first, the total or the
    per-type one, so every limit is written rather than left to the defaults
    (whose glossy 4 / transmission 12 are the default arguments here).  With
    ``caustics`` False, Caustics Reflective and Refractive are turned off (a
    mirror's caustics of a small light would be fireflies that drown a comparison).
    """
    cycles = scene.cycles
    cycles.caustics_reflective = cycles.caustics_refractive = caustics
    cycles.max_bounces = total
    cycles.diffuse_bounces = diffuse
    cycles.glossy_bounces = glossy
    cycles.transmission_bounces = transmission
    cycles.volume_bounces = 0
    cycles.transparent_max_bounces = 8


def set_world(scene, color, strength=1.0):
    """Give the scene a constant world: Background node, radiance = color x strength."""
    world = bpy.data.worlds.new("World")
    tree = world.node_tree
    tree.nodes.clear()
    background = tree.nodes.new("ShaderNodeBackground")
    background.inputs["Color"].default_value = (*color, 1.0)
    background.inputs["Strength"].default_value = strength
    output = tree.nodes.new("ShaderNodeOutputWorld")
    output.location = (300, 0)
    tree.links.new(background.outputs["Background"], output.inputs["Surface"])
    scene.world = world
    return world


# --------------------------------------------------------------------------
# Materials
# --------------------------------------------------------------------------

def _new_material(name):
    """A material with an empty node tree plus a Material Output node."""
    material = bpy.data.materials.new(name)
    tree = material.node_tree
    tree.nodes.clear()
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    output.location = (300, 0)
    return material, tree, output


def diffuse_material(name, color):
    """Diffuse BSDF with roughness 0 (Lambert, albedo ``color``)."""
    material, tree, output = _new_material(name)
    node = tree.nodes.new("ShaderNodeBsdfDiffuse")
    node.inputs["Color"].default_value = (*color, 1.0)
    node.inputs["Roughness"].default_value = 0.0
    tree.links.new(node.outputs["BSDF"], output.inputs["Surface"])
    material.diffuse_color = (*color, 1.0)  # viewport colour only
    return material


def lambert_principled_material(name, color):
    """Principled BSDF reduced to exact Lambert: 'Specular IOR Level' 0, no other lobes."""
    material, tree, output = _new_material(name)
    node = tree.nodes.new("ShaderNodeBsdfPrincipled")
    node.inputs["Base Color"].default_value = (*color, 1.0)
    node.inputs["Specular IOR Level"].default_value = 0.0
    node.inputs["Diffuse Roughness"].default_value = 0.0
    node.inputs["Metallic"].default_value = 0.0
    node.inputs["Transmission Weight"].default_value = 0.0
    node.inputs["Coat Weight"].default_value = 0.0
    node.inputs["Sheen Weight"].default_value = 0.0
    node.inputs["Subsurface Weight"].default_value = 0.0
    node.inputs["Emission Strength"].default_value = 0.0
    tree.links.new(node.outputs["BSDF"], output.inputs["Surface"])
    material.diffuse_color = (*color, 1.0)
    return material


def emission_material(name, color, strength):
    """Emission shader: radiance color x strength on both sides (no factor pi)."""
    material, tree, output = _new_material(name)
    node = tree.nodes.new("ShaderNodeEmission")
    node.inputs["Color"].default_value = (*color, 1.0)
    node.inputs["Strength"].default_value = strength
    tree.links.new(node.outputs["Emission"], output.inputs["Surface"])
    material.diffuse_color = (*color, 1.0)
    return material


def _find_input(node, key):
    """The enabled input socket of ``node`` called ``key``: its identifier, its name, or
    either spelled in snake case ('base_color' for 'Base Color'); None if there is none."""
    spaced = key.replace("_", " ").lower()
    enabled = [socket for socket in node.inputs if socket.enabled]
    for socket in enabled:
        if key in (socket.identifier, socket.name):
            return socket
    for socket in enabled:
        if spaced in (socket.identifier.lower(), socket.name.lower()):
            return socket
    return None


def set_node_values(node, **values):
    """Set inputs of a shader node by name (see :func:`_find_input`); a key that names no
    input is a node property (``distribution="GGX"``).  RGB tuples get alpha 1."""
    for key, value in values.items():
        socket = _find_input(node, key)
        if socket is None:
            if not hasattr(node, key):
                raise KeyError(f"{node.bl_idname} has no input or property {key!r}")
            setattr(node, key, value)
        elif isinstance(value, (tuple, list)) and len(value) == 3 \
                and len(socket.default_value) == 4:
            socket.default_value = (*value, 1.0)
        else:
            socket.default_value = value
    return node


def shader_node(tree, bl_idname, location=(0.0, 0.0), **values):
    """Add a node of type ``bl_idname`` to ``tree`` with the given input values."""
    node = tree.nodes.new(bl_idname)
    node.location = location
    return set_node_values(node, **values)


def _viewport_color(material, values):
    color = values.get("base_color", values.get("color"))
    if isinstance(color, (tuple, list)) and len(color) == 3:
        material.diffuse_color = (*color, 1.0)  # viewport colour only


def node_material(name, bl_idname, **values):
    """One shader node (e.g. 'ShaderNodeBsdfGlass') into the Surface output.

    ``values`` are its inputs in snake case and its properties, e.g.
    ``node_material("Metal", "ShaderNodeBsdfPrincipled", base_color=(1, .78, .34),
    metallic=1.0, roughness=0.3, distribution="GGX")``.  Inputs not given keep
    Blender's defaults.
    """
    material, tree, output = _new_material(name)
    node = shader_node(tree, bl_idname, **values)
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    _viewport_color(material, values)
    return material


def combine_material(name, first, second, fac=None):
    """A Mix Shader (``fac`` given: 0 is ``first``, 1 is ``second``) or an Add Shader
    (``fac`` None) of two shader nodes, each given as ``(bl_idname, {input: value})``."""
    material, tree, output = _new_material(name)
    nodes = [shader_node(tree, kind, location=(-300.0, 150.0 - 300.0 * i), **values)
             for i, (kind, values) in enumerate((first, second))]
    if fac is None:
        combine = shader_node(tree, "ShaderNodeAddShader")
    else:
        combine = shader_node(tree, "ShaderNodeMixShader", fac=fac)
    tree.links.new(nodes[0].outputs[0], combine.inputs["Shader"])
    tree.links.new(nodes[1].outputs[0], combine.inputs["Shader_001"])
    tree.links.new(combine.outputs[0], output.inputs["Surface"])
    _viewport_color(material, first[1])
    return material


def diffuse_between(tree, output, factor, color_a, color_b, location=(-300.0, 0.0)):
    """A Diffuse BSDF (roughness 0) into ``output``'s Surface, its colour a Mix (RGBA, factor
    clamped, at ``location``) from ``color_a`` to ``color_b`` by the output socket
    ``factor``."""
    mix = shader_node(tree, "ShaderNodeMix", location=location, data_type="RGBA",
                      clamp_factor=True)
    sockets = {s.identifier: s for s in (*mix.inputs, *mix.outputs)}
    sockets["A_Color"].default_value = (*color_a, 1.0)
    sockets["B_Color"].default_value = (*color_b, 1.0)
    tree.links.new(factor, sockets["Factor_Float"])
    bsdf = shader_node(tree, "ShaderNodeBsdfDiffuse", roughness=0.0)
    tree.links.new(sockets["Result_Color"], bsdf.inputs["Color"])
    tree.links.new(bsdf.outputs["BSDF"], output.inputs["Surface"])


# --------------------------------------------------------------------------
# Textures (written next to the scenes, in textures/, and read by relative path)
# --------------------------------------------------------------------------

TEXTURES_DIR = Path(__file__).resolve().parent / "textures"


def save_texture(name, pixels, float_buffer=False):
    """Write ``pixels`` ((H, W, 4), bottom row first, as Blender stores them) to
    ``textures/<name>`` and load it as an image that the .blend refers to by its relative
    path: 8-bit sRGB PNG through Blender, or a linear 32-bit float OpenEXR written with
    mcengine's writer (Blender's own EXR save encodes the values with the image's colour
    space)."""
    h, w = pixels.shape[:2]
    TEXTURES_DIR.mkdir(exist_ok=True)
    path = TEXTURES_DIR / name
    if float_buffer:
        from mcengine.imageio import write_exr
        write_exr(path, pixels[::-1])
    else:
        image = bpy.data.images.new(name + " (writer)", w, h, alpha=True)
        image.pixels.foreach_set([float(v) for v in pixels.ravel()])
        image.filepath_raw = str(path)
        image.file_format = "PNG"
        image.save()
        bpy.data.images.remove(image)
    return load_texture(name, "Linear Rec.709" if float_buffer else "sRGB")


def load_texture(name, colorspace="sRGB"):
    """Load ``textures/<name>`` (written by a generator) as an image that the .blend refers
    to by its relative path, read in ``colorspace`` ('sRGB', 'Non-Color', 'Linear Rec.709')."""
    loaded = bpy.data.images.load(str(TEXTURES_DIR / name))
    loaded.colorspace_settings.name = colorspace
    loaded.filepath = "//textures/" + name
    return loaded


def environment_world(scene, strength=1.0, map_resolution=1024):
    """An HDRI world: an Environment Texture (equirectangular) into the Background's
    Color, times ``strength``, sampled with a ``map_resolution`` importance map (World >
    Settings > Sampling Manual).  Returns the Environment Texture node: set its ``image``.

    A map finer than the image: an image-sized map (Automatic) is baked at texel centres
    and misses the part of a small sun's bilinear footprint that lies between them.
    """
    world = set_world(scene, (0.0, 0.0, 0.0))
    tree = world.node_tree
    background = tree.nodes["Background"]
    background.inputs["Strength"].default_value = strength
    env = shader_node(tree, "ShaderNodeTexEnvironment", location=(-300.0, 0.0))
    tree.links.new(env.outputs["Color"], background.inputs["Color"])
    world.cycles.sampling_method = "MANUAL"
    world.cycles.sample_map_resolution = map_resolution
    return env


def image_texture(tree, image, location=(-300.0, 0.0), **values):
    """An Image Texture node reading ``image`` (inputs and properties as shader_node)."""
    node = shader_node(tree, "ShaderNodeTexImage", location=location, **values)
    node.image = image
    return node


def set_planar_uvs(obj, scale=1.0):
    """A UV map projecting the object's local X and Y (times ``scale``) onto U and V."""
    mesh = obj.data
    layer = mesh.uv_layers.new(name="UVMap")
    for loop in mesh.loops:
        co = mesh.vertices[loop.vertex_index].co
        layer.data[loop.index].uv = (co.x * scale, co.y * scale)


# --------------------------------------------------------------------------
# Objects
# --------------------------------------------------------------------------

def _link(scene, obj, location=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0),
          scale=(1.0, 1.0, 1.0)):
    obj.location = location
    obj.rotation_euler = Euler(rotation, "XYZ")
    obj.scale = scale
    scene.collection.objects.link(obj)
    return obj


def add_mesh(scene, name, vertices, faces, material, smooth=False, **transform):
    """Add a mesh object from vertex and face lists.

    Parameters
    ----------
    vertices : sequence of (3,) float
        Vertex positions in object space.
    faces : sequence of sequence of int
        Polygons as vertex indices, counter-clockwise seen from the front.
    material : bpy.types.Material
    smooth : bool
        Smooth (vertex-normal) shading; flat otherwise.
    transform : location, rotation (XYZ Euler, radians), scale
    """
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in vertices], [], [tuple(f) for f in faces])
    mesh.validate()
    _finish_mesh(mesh, material, smooth)
    return _link(scene, bpy.data.objects.new(name, mesh), **transform)


def _finish_mesh(mesh, material, smooth):
    # Edit-mode selection is meaningless here and is saved with garbage bytes.
    for name in [a.name for a in mesh.attributes if a.name.startswith(".select_")]:
        mesh.attributes.remove(mesh.attributes[name])
    if smooth:
        mesh.shade_smooth()
    else:
        mesh.shade_flat()
    mesh.materials.append(material)
    mesh.update()


def add_quad(scene, name, corners, material, **transform):
    """Add one flat quad; ``corners`` (4, 3) counter-clockwise seen from the front."""
    return add_mesh(scene, name, corners, [(0, 1, 2, 3)], material, **transform)


def add_box(scene, name, size, material, **transform):
    """Add a flat-shaded box with its base centred on the object origin.

    ``size`` is (x, y, z) in metres; the box spans z = 0 .. size_z in object
    space, so ``location`` is the centre of its bottom face.
    """
    sx, sy, sz = (0.5 * size[0], 0.5 * size[1], float(size[2]))
    vertices = [(-sx, -sy, 0.0), (sx, -sy, 0.0), (sx, sy, 0.0), (-sx, sy, 0.0),
                (-sx, -sy, sz), (sx, -sy, sz), (sx, sy, sz), (-sx, sy, sz)]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4),
             (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    return add_mesh(scene, name, vertices, faces, material, **transform)


def add_uv_sphere(scene, name, radius, material, smooth=True,
                  segments=SPHERE_SEGMENTS, rings=SPHERE_RINGS, **transform):
    """Add a UV sphere centred on the object origin (64x32, smooth by default).

    Same layout as Blender's UV sphere: poles on the Z axis, ``rings`` bands
    of ``segments`` faces, triangle fans at the poles and quads between.
    Built vertex by vertex (bmesh's primitive merges seam vertices in an
    order that varies between runs).
    """
    vertices = [(0.0, 0.0, radius)]
    for ring in range(1, rings):
        theta = math.pi * ring / rings
        for segment in range(segments):
            phi = 2.0 * math.pi * segment / segments
            vertices.append((radius * math.sin(theta) * math.cos(phi),
                             radius * math.sin(theta) * math.sin(phi),
                             radius * math.cos(theta)))
    bottom = len(vertices)
    vertices.append((0.0, 0.0, -radius))

    def ring_vertex(ring, segment):
        return 1 + (ring - 1) * segments + segment % segments

    faces = []  # counter-clockwise seen from outside
    for segment in range(segments):
        faces.append((0, ring_vertex(1, segment), ring_vertex(1, segment + 1)))
        for ring in range(1, rings - 1):
            faces.append((ring_vertex(ring, segment), ring_vertex(ring + 1, segment),
                          ring_vertex(ring + 1, segment + 1), ring_vertex(ring, segment + 1)))
        faces.append((ring_vertex(rings - 1, segment), bottom,
                      ring_vertex(rings - 1, segment + 1)))
    return add_mesh(scene, name, vertices, faces, material, smooth=smooth, **transform)


def sphere_grid(count, radius, spacing, columns=3):
    """Locations of ``count`` spheres of ``radius`` resting on the floor (z = 0), in rows of
    ``columns`` ``spacing`` apart, centred on the origin: the first row at the back (largest
    y), each row from left to right."""
    rows = (count + columns - 1) // columns
    return [((column - (columns - 1) / 2) * spacing, ((rows - 1) / 2 - row) * spacing, radius)
            for row, column in (divmod(i, columns) for i in range(count))]


def add_cylinder(scene, name, radius, height, material, segments=SPHERE_SEGMENTS, **transform):
    """Add a closed cylinder standing on the object origin (z = 0 .. height).

    The side is smooth-shaded and the two caps are flat; the caps have their
    own vertices, so the side's vertex normals stay horizontal (no averaging
    with the caps) while the surface stays closed (the caps' rims lie exactly
    on the side's).
    """
    ring = [(radius * math.cos(2.0 * math.pi * k / segments),
             radius * math.sin(2.0 * math.pi * k / segments)) for k in range(segments)]
    vertices = [(x, y, z) for z in (0.0, float(height)) for x, y in ring]  # side: 0..2n-1
    vertices += [(x, y, z) for z in (0.0, float(height)) for x, y in ring]  # caps: 2n..4n-1
    n = segments
    side = [(k, (k + 1) % n, n + (k + 1) % n, n + k) for k in range(n)]
    bottom = tuple(2 * n + k for k in reversed(range(n)))
    top = tuple(3 * n + k for k in range(n))
    obj = add_mesh(scene, name, vertices, side + [bottom, top], material, smooth=True, **transform)
    mesh = obj.data
    for face in mesh.polygons[n:]:
        face.use_smooth = False
    mesh.update()
    return obj


def add_suzanne(scene, name, material, subdivision_levels=2, uv_map=False, **transform):
    """Add Blender's monkey head (the data of ``bmesh.ops.create_monkey``, 2 m wide,
    facing -Y) with a Subdivision Surface modifier and smooth shading; with ``uv_map``,
    also the monkey's own UV unwrap (what Add > Mesh > Monkey makes) as ``UVMap``."""
    import bmesh

    bm = bmesh.new()
    layer = bm.loops.layers.uv.new("UVMap") if uv_map else None
    bmesh.ops.create_monkey(bm, calc_uvs=uv_map)
    vertices = [tuple(v.co) for v in bm.verts]
    faces = [tuple(v.index for v in f.verts) for f in bm.faces]
    uvs = [tuple(loop[layer].uv) for f in bm.faces for loop in f.loops] if uv_map else []
    bm.free()
    obj = add_mesh(scene, name, vertices, faces, material, smooth=True, **transform)
    if uv_map:  # from_pydata keeps the faces' order and each face's loop order
        layer = obj.data.uv_layers.new(name="UVMap")
        layer.data.foreach_set("uv", [x for uv in uvs for x in uv])
    if subdivision_levels:
        modifier = obj.modifiers.new("Subdivision", "SUBSURF")
        modifier.levels = subdivision_levels
        modifier.render_levels = subdivision_levels
    return obj


def add_empty(scene, name, parent=None, **transform):
    """Add an empty (a transform only), optionally parented; returns it.

    With ``parent``, the transform is relative to the parent (the parent
    inverse matrix stays identity, so world = parent world @ local).
    """
    obj = _link(scene, bpy.data.objects.new(name, None), **transform)
    obj.parent = parent
    return obj


def animate(obj, data_path, keys):
    """Keyframe ``obj.<data_path>`` at each ``(frame, value)`` with linear interpolation
    (``data_path`` may go through sub-structures, e.g. ``"data.lens"``)."""
    *owners, attribute = data_path.split(".")
    target = obj
    for name in owners:
        target = getattr(target, name)
    for frame, value in keys:
        setattr(target, attribute, value)
        target.keyframe_insert(attribute, frame=frame)
    make_linear(target.id_data)


def make_linear(id_data):
    """Every keyframe of ``id_data``'s action interpolates linearly (keyframe_insert makes
    Bezier keys whatever the preferences say when Blender runs in the background)."""
    for layer in id_data.animation_data.action.layers:
        for strip in layer.strips:
            for bag in strip.channelbags:
                for fcurve in bag.fcurves:
                    for point in fcurve.keyframe_points:
                        point.interpolation = "LINEAR"


def look_at(obj, target):
    """Rotate ``obj`` so that its local -Z axis points at ``target`` (+Y stays up)."""
    direction = Vector(target) - Vector(obj.location)
    obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler("XYZ")


def add_camera(scene, location, target, lens_mm=50.0):
    """Add a perspective camera aimed at ``target`` and make it the scene camera."""
    data = bpy.data.cameras.new("Camera")
    data.lens = lens_mm
    data.sensor_width = 36.0
    data.sensor_fit = "AUTO"
    data.clip_start = 0.1
    data.clip_end = 100.0
    obj = _link(scene, bpy.data.objects.new("Camera", data), location=location)
    look_at(obj, target)
    scene.camera = obj
    return obj


def add_light(scene, name, light_type, energy, location, target=None,
              color=(1.0, 1.0, 1.0), visible_camera=False, rotation=None,
              scale=(1.0, 1.0, 1.0), **settings):
    """Add a lamp.

    Parameters
    ----------
    light_type : {'POINT', 'SPOT', 'SUN', 'AREA'}
    energy : float
        Watts (point, spot, area) or W/m^2 irradiance (sun).
    target : (3,) float, optional
        Aim the light's local -Z axis at this point.
    rotation : (3,) float, optional
        XYZ Euler angles in radians; used when ``target`` is None.
    visible_camera : bool
        Camera-ray visibility (Blender 5.0 creates lights invisible to the camera).
    settings
        Further ``bpy.types.Light`` attributes, e.g. ``shadow_soft_size``,
        ``spot_size``, ``shape``, ``size``.
    """
    data = bpy.data.lights.new(name, light_type)
    data.energy = energy
    data.color = color
    for key, value in settings.items():
        setattr(data, key, value)
    obj = _link(scene, bpy.data.objects.new(name, data), location=location,
                rotation=rotation or (0.0, 0.0, 0.0), scale=scale)
    if target is not None:
        look_at(obj, target)
    obj.visible_camera = visible_camera
    return obj


# --------------------------------------------------------------------------
# The stage shared by the light scenes
# --------------------------------------------------------------------------

# Floor half-size: large enough that the camera of add_stage sees floor only.
STAGE_FLOOR_HALF_SIZE = 12.0
STAGE_CAMERA_LOCATION = (0.0, -5.2, 4.4)
STAGE_CAMERA_TARGET = (0.0, 0.2, 0.35)


def add_floor(scene, material=None):
    """The stage floor: a 24 m square quad at z = 0, grey Diffuse BSDF 0.6 by default."""
    h = STAGE_FLOOR_HALF_SIZE
    if material is None:
        material = diffuse_material("Floor", (0.6, 0.6, 0.6))
    return add_quad(scene, "Floor", [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], material)


def add_stage(scene):
    """Floor, a rotated cube, a smooth sphere, a small box and the camera.

    The floor is a 24 m square of grey Diffuse BSDF at z = 0, large enough to
    fill the frame.  The cube uses the Lambert Principled material, the sphere
    and the small box use Diffuse BSDF.  Returns a dict of the objects.
    """
    floor = add_floor(scene)
    cube = add_box(scene, "Cube", (1.0, 1.0, 1.0),
                   lambert_principled_material("Cube", (0.2, 0.35, 0.7)),
                   location=(-1.0, 0.4, 0.0), rotation=(0.0, 0.0, math.radians(30.0)))
    sphere = add_uv_sphere(scene, "Sphere", 0.6, diffuse_material("Sphere", (0.8, 0.8, 0.8)),
                           location=(0.9, 0.0, 0.6))
    block = add_box(scene, "Block", (0.5, 0.5, 0.3), diffuse_material("Block", (0.7, 0.3, 0.15)),
                    location=(0.1, -1.3, 0.0), rotation=(0.0, 0.0, math.radians(-20.0)))
    camera = add_camera(scene, STAGE_CAMERA_LOCATION, STAGE_CAMERA_TARGET)
    return {"floor": floor, "cube": cube, "sphere": sphere, "block": block, "camera": camera}


def add_material_lights(scene, fill=True):
    """The lamps of the single-node material scenes: ``Key``, a warm square area lamp 1.2 m,
    150 W, at (-2.0, -2.2, 3.2) aimed at the stage's objects, and (``fill``) ``Fill``, a bluish
    point lamp 120 W, radius 0.2, at (2.5, -1.0, 2.0)."""
    add_light(scene, "Key", "AREA", 150.0, (-2.0, -2.2, 3.2), target=(0.0, 0.0, 0.4),
              color=(1.0, 0.9, 0.8), size=1.2)
    if fill:
        add_light(scene, "Fill", "POINT", 120.0, (2.5, -1.0, 2.0), color=(0.7, 0.8, 1.0),
                  shadow_soft_size=0.2)


def add_horizon_stage(scene):
    """The stage (:func:`add_stage`) seen from a camera lowered to z = 1.8, so that the world
    above the horizon fills the top of the frame (the world scenes)."""
    stage = add_stage(scene)
    camera = stage["camera"]
    camera.location = (0.0, -6.0, 1.8)
    look_at(camera, (0.0, 0.0, 0.7))
    return stage


# --------------------------------------------------------------------------
# Saving
# --------------------------------------------------------------------------

def output_path(script_file):
    """The .blend path next to a generator script: ``<dir>/<name>.blend``."""
    return Path(script_file).resolve().with_suffix(".blend")


def save_blend(path):
    """Save the current file byte-for-byte reproducibly, zstd-compressed.

    Blender writes the file uncompressed to a temporary path, which is
    normalised by :func:`_blendfile.normalize` and compressed into ``path``.
    """
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp), compress=False, relative_remap=False,
                                copy=True)
    try:
        raw = bytearray(tmp.read_bytes())
    finally:
        os.remove(tmp)
    _blendfile.normalize(raw, bpy.data.colorspace.working_space, mark_compressed=True)
    # The frame carries its uncompressed size; single-threaded compression
    # (the default) keeps the output identical across machines.
    compressed = zstandard.ZstdCompressor(level=ZSTD_LEVEL).compress(bytes(raw))
    path.write_bytes(compressed)
    print(f"wrote {path} ({len(compressed)} bytes)")


def run(build, script_file):
    """Build a scene with ``build(scene)`` and save it next to ``script_file``."""
    scene = new_scene()
    build(scene)
    bpy.context.view_layer.update()
    save_blend(output_path(script_file))
    return 0


if __name__ == "__main__":
    sys.exit("_common.py is a helper module; run one of the scene scripts instead")
