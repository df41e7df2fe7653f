"""An image-textured asset: Suzanne with a colour map, a roughness map and a normal map.

What a user downloads and drops on the stage: Blender's monkey head, subdivided and
smooth, with the monkey's own UV unwrap (what Add > Mesh > Monkey makes), and a
Principled BSDF whose inputs come from three images on that UV map:

* Base Color: ``textures/suzanne_color.png`` (64 x 64, 8-bit sRGB), made here: a warm
  clay colour varying smoothly over the atlas, with darker painted stripes.
* Roughness: ``textures/suzanne_roughness.png`` (64 x 64, 8-bit grey, read as
  Non-Color), made here: a worn finish of roughness 0.7 with polished patches down to 0.25;
  its Red channel through a Separate Color node (RGB) into Roughness.
* Normal: ``textures/bumps.png`` (the egg-crate tangent-space normals of
  ``texture_normal_map.py``, Non-Color) on the UVs scaled 3 x by a Mapping node, through a
  Normal Map node (tangent space on UVMap, strength 0.8); the tangents are the UV map's
  (MikkTSpace).

``Suzanne``: subdivision level 2, smooth, scale 0.75, at (0, 0.2, 0.72), turned 20 deg, on
the stage floor (Diffuse 0.6).  ``Key``: square area light 2 m, 250 W, front left at 3 m;
world (0.12, 0.13, 0.16).  Bounces 4/4.

Run: .venv/bin/python blend_scenes/texture_suzanne_maps.py
"""
import math

import _common as c
import numpy as np

N = 64
NORMAL_TILING = 3.0  # the normal map repeats 3 x 3 times over the UV square


def _uv_grid():
    v, u = (np.mgrid[0:N, 0:N] + 0.5) / N
    return u, v


def color_pixels():
    """(N, N, 4) 8-bit sRGB values in [0, 1], bottom row first."""
    u, v = _uv_grid()
    rng = np.random.default_rng(11)
    blend = np.zeros_like(u)
    for _ in range(6):  # smooth variation: a few waves of random direction and phase
        k = rng.integers(1, 4, size=2)
        blend += np.sin(2 * math.pi * (k[0] * u + k[1] * v) + rng.uniform(0, 2 * math.pi))
    blend = 0.5 + blend / 12.0
    clay = np.array([0.85, 0.55, 0.35])
    ochre = np.array([0.95, 0.8, 0.45])
    rgb = (1 - blend)[..., None] * clay + blend[..., None] * ochre
    stripes = 0.5 + 0.5 * np.cos(2 * math.pi * 6 * (u + 0.3 * v))
    rgb *= (1.0 - 0.45 * (stripes > 0.8))[..., None]
    px = np.ones((N, N, 4))
    px[..., :3] = rgb
    return np.round(px * 255.0) / 255.0


def roughness_pixels():
    """(N, N, 4) grey 8-bit values in [0, 1], bottom row first: roughness 0.7 worn to 0.25
    in a few soft patches (wrapped around the UV square)."""
    u, v = _uv_grid()
    rng = np.random.default_rng(12)
    polish = np.zeros_like(u)
    for cu, cv, r in zip(rng.uniform(0, 1, 7), rng.uniform(0, 1, 7), rng.uniform(0.06, 0.14, 7)):
        du = (u - cu + 0.5) % 1.0 - 0.5
        dv = (v - cv + 0.5) % 1.0 - 0.5
        polish = np.maximum(polish, np.exp(-(du * du + dv * dv) / (2 * r * r)))
    rough = 0.7 - 0.45 * polish
    px = np.ones((N, N, 4))
    px[..., :3] = rough[..., None]
    return np.round(px * 255.0) / 255.0


def _mapped_material():
    material, tree, output = c._new_material("SuzanneMaps")
    bsdf = c.shader_node(tree, "ShaderNodeBsdfPrincipled")
    tree.links.new(bsdf.outputs[0], output.inputs["Surface"])
    color = c.image_texture(tree, c.save_texture("suzanne_color.png", color_pixels()),
                            location=(-700.0, 300.0))
    rough_image = c.save_texture("suzanne_roughness.png", roughness_pixels())
    rough_image.colorspace_settings.name = "Non-Color"
    rough = c.image_texture(tree, rough_image, location=(-700.0, 0.0))
    separate = c.shader_node(tree, "ShaderNodeSeparateColor", location=(-400.0, 0.0), mode="RGB")
    normal = c.image_texture(tree, c.load_texture("bumps.png", "Non-Color"), location=(-700.0, -300.0))
    coords = c.shader_node(tree, "ShaderNodeTexCoord", location=(-1200.0, -300.0))
    tiling = c.shader_node(tree, "ShaderNodeMapping", location=(-950.0, -300.0),
                           scale=(NORMAL_TILING, NORMAL_TILING, 1.0))
    tree.links.new(coords.outputs["UV"], tiling.inputs["Vector"])
    tree.links.new(tiling.outputs["Vector"], normal.inputs["Vector"])
    nmap = c.shader_node(tree, "ShaderNodeNormalMap", location=(-400.0, -300.0), space="TANGENT",
                         uv_map="UVMap", strength=0.8)
    tree.links.new(color.outputs["Color"], bsdf.inputs["Base Color"])
    tree.links.new(rough.outputs["Color"], separate.inputs["Color"])
    tree.links.new(separate.outputs["Red"], bsdf.inputs["Roughness"])
    tree.links.new(normal.outputs["Color"], nmap.inputs["Color"])
    tree.links.new(nmap.outputs["Normal"], bsdf.inputs["Normal"])
    material.diffuse_color = (0.85, 0.6, 0.4, 1.0)  # viewport colour only
    return material


def build(scene):
    c.set_world(scene, (0.12, 0.13, 0.16))
    c.add_floor(scene)
    c.add_suzanne(scene, "Suzanne", _mapped_material(), subdivision_levels=2, uv_map=True,
                  location=(0.0, 0.2, 0.72), rotation=(0.0, 0.0, math.radians(-20.0)),
                  scale=(0.75, 0.75, 0.75))
    c.add_light(scene, "Key", "AREA", 250.0, (-2.0, -2.2, 3.0), target=(0.0, 0.0, 0.5), size=2.0)
    c.add_camera(scene, (0.0, -2.9, 1.55), (0.0, 0.15, 0.68), lens_mm=50.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
