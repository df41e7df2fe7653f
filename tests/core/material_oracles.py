"""Small material set-ups with Cycles' measured answers (the oracles), shared by the test
``test_material_oracles.py`` (MC Engine, no Blender) and the script
``tools/measure_material_oracles.py`` (which renders the same set-ups with Cycles
and writes ``material_oracles.json``).

The set-up is the reference's (cycles-conventions.md, experiment defaults): a
large plane at z = 0 with the material, an orthographic camera looking at the
origin from ``view`` degrees off the normal (in the x-z plane, from +x), a Box
pixel filter, and either a 1000 W point light of radius 0 at distance 2 m,
``light`` degrees off the normal (azimuth 0: the camera's side, 180: opposite)
with max_bounces 0, or (``light`` None) a white world of strength 1 with 64
bounces: a furnace.
"""
from __future__ import annotations

import math

# name: (nodes, view_deg, (light_theta_deg, light_azimuth_deg) or None)
# nodes: list of (type, inputs, props); the last node feeds the Surface socket,
# inputs of the form ("link", k) take node k's BSDF output, ("link", k, name) its output
# of that name.
ORACLES = {
    "principled_defaults": ([("BsdfPrincipled", {}, {})], 0.0, (0.0, 0.0)),
    "principled_white": ([("BsdfPrincipled", {"Base Color": (1, 1, 1)}, {})], 0.0, (0.0, 0.0)),
    "principled_metal": ([("BsdfPrincipled", {"Base Color": (1, 1, 1), "Metallic": 1.0}, {})],
                         0.0, (0.0, 0.0)),
    "principled_metal_ggx": ([("BsdfPrincipled", {"Base Color": (1, 1, 1), "Metallic": 1.0},
                               {"distribution": "GGX"})], 0.0, (0.0, 0.0)),
    "principled_gold_45": ([("BsdfPrincipled", {"Base Color": (1.0, 0.78, 0.34), "Metallic": 1.0,
                                                "Roughness": 0.3,
                                                "Specular Tint": (1.0, 0.8, 0.6)}, {})],
                           45.0, (30.0, 180.0)),
    "principled_plastic_45": ([("BsdfPrincipled", {"Base Color": (0.2, 0.4, 0.8), "Roughness": 0.2,
                                                   "Specular IOR Level": 0.8, "IOR": 1.6}, {})],
                              45.0, (45.0, 180.0)),
    "principled_coat": ([("BsdfPrincipled", {"Base Color": (1, 1, 1), "Specular IOR Level": 0.0,
                                             "Coat Weight": 1.0, "Coat Roughness": 0.5,
                                             "Coat Tint": (0.5, 0.5, 0.5)}, {})],
                        45.0, (0.0, 0.0)),
    "principled_sheen": ([("BsdfPrincipled", {"Base Color": (0.05, 0.05, 0.3), "Sheen Weight": 1.0,
                                              "Sheen Roughness": 0.3}, {})], 60.0, (50.0, 180.0)),
    "principled_transmission": ([("BsdfPrincipled", {"Transmission Weight": 1.0, "Roughness": 0.3,
                                                     "Base Color": (0.8, 1.0, 0.8)}, {})],
                                30.0, (20.0, 180.0)),
    "principled_alpha": ([("BsdfPrincipled", {"Alpha": 0.3, "Specular IOR Level": 0.0}, {})],
                         0.0, (0.0, 0.0)),
    "principled_rough_diffuse": ([("BsdfPrincipled", {"Diffuse Roughness": 1.0,
                                                      "Specular IOR Level": 0.0}, {})],
                                 45.0, (60.0, 0.0)),
    "principled_emission_coat": ([("BsdfPrincipled", {"Base Color": (0, 0, 0), "Coat Weight": 1.0,
                                                      "Specular IOR Level": 0.0,
                                                      "Emission Strength": 5.0}, {})],
                                 0.0, (30.0, 0.0)),
    "diffuse_rough_same_side": ([("BsdfDiffuse", {"Roughness": 1.0}, {})], 45.0, (60.0, 0.0)),
    "diffuse_rough_opposite": ([("BsdfDiffuse", {"Roughness": 0.5}, {})], 45.0, (60.0, 180.0)),
    "glossy_ggx_40": ([("BsdfGlossy", {"Color": (1, 1, 1)}, {"distribution": "GGX"})],
                      0.0, (40.0, 0.0)),
    "glossy_beckmann_40": ([("BsdfGlossy", {"Color": (1, 1, 1)}, {"distribution": "BECKMANN"})],
                           0.0, (40.0, 0.0)),
    "glossy_multi": ([("BsdfGlossy", {"Color": (1, 1, 1)}, {})], 0.0, (0.0, 0.0)),
    "metallic_conductor_45": ([("BsdfMetallic", {"IOR": (0.18, 0.42, 1.37), "Extinction": (3.42, 2.35, 1.77),
                                                 "Roughness": 0.3}, {"fresnel_type": "PHYSICAL_CONDUCTOR"})],
                              45.0, (30.0, 180.0)),
    "metallic_conductor_grazing": ([("BsdfMetallic", {"IOR": (1.37, 0.96, 0.61), "Extinction": (7.6, 6.4, 5.3),
                                                      "Roughness": 0.15},
                                     {"fresnel_type": "PHYSICAL_CONDUCTOR", "distribution": "GGX"})],
                                   75.0, (70.0, 180.0)),
    "metallic_f82_45": ([("BsdfMetallic", {"Base Color": (1.0, 0.78, 0.34), "Edge Tint": (1.0, 0.8, 0.6),
                                           "Roughness": 0.3}, {})], 45.0, (30.0, 180.0)),
    "metallic_beckmann": ([("BsdfMetallic", {"Roughness": 0.4}, {"distribution": "BECKMANN"})],
                          30.0, (20.0, 180.0)),
    "glass_rough_back_light": ([("BsdfGlass", {"Roughness": 0.4}, {})], 20.0, (150.0, 180.0)),
    "refraction_rough": ([("BsdfRefraction", {"Roughness": 0.3}, {"distribution": "GGX"})],
                         10.0, (160.0, 180.0)),
    "translucent": ([("BsdfTranslucent", {"Color": (0.9, 0.6, 0.3)}, {})], 0.0, (170.0, 0.0)),
    "sheen_node": ([("BsdfSheen", {"Roughness": 0.5, "Color": (1, 1, 1)}, {})], 0.0, (0.0, 0.0)),
    "sheen_ashikhmin_velvet": ([("BsdfSheen", {"Roughness": 0.5, "Color": (1, 1, 1)},
                                 {"distribution": "ASHIKHMIN"})], 75.0, (80.0, 0.0)),
    "sheen_ashikhmin_velvet_side": ([("BsdfSheen", {"Roughness": 1.0, "Color": (0.9, 0.5, 0.2)},
                                      {"distribution": "ASHIKHMIN"})], 45.0, (60.0, 90.0)),
    "glossy_ashikhmin_shirley_40": ([("BsdfGlossy", {"Color": (1, 1, 1), "Roughness": 0.4},
                                      {"distribution": "ASHIKHMIN_SHIRLEY"})], 0.0, (40.0, 0.0)),
    "glossy_ashikhmin_shirley_grazing": ([("BsdfGlossy", {"Color": (0.8, 0.6, 0.4), "Roughness": 0.7},
                                           {"distribution": "ASHIKHMIN_SHIRLEY"})], 70.0, (65.0, 180.0)),
    "holdout_mix": ([("Holdout", {}, {}), ("BsdfDiffuse", {"Color": (1, 1, 1)}, {}),
                     ("MixShader", {"Fac": 0.75, "Shader": ("link", 0), "Shader_001": ("link", 1)}, {})],
                    0.0, (0.0, 0.0)),
    "furnace_principled": ([("BsdfPrincipled", {"Base Color": (1, 1, 1)}, {})], 30.0, None),
    "furnace_principled_rough": ([("BsdfPrincipled", {"Base Color": (1, 1, 1), "Roughness": 1.0}, {})],
                                 30.0, None),
    "furnace_metal_rough": ([("BsdfPrincipled", {"Base Color": (1, 1, 1), "Metallic": 1.0,
                                                 "Roughness": 1.0}, {})], 0.0, None),
    "furnace_metal_rough_ggx": ([("BsdfPrincipled", {"Base Color": (1, 1, 1), "Metallic": 1.0,
                                                     "Roughness": 1.0}, {"distribution": "GGX"})],
                                0.0, None),
    "furnace_glass": ([("BsdfGlass", {"Roughness": 0.5}, {})], 30.0, None),
    "furnace_metallic_conductor": ([("BsdfMetallic", {"IOR": (0.18, 0.42, 1.37), "Extinction": (3.42, 2.35, 1.77),
                                                      "Roughness": 1.0}, {"fresnel_type": "PHYSICAL_CONDUCTOR"})],
                                   30.0, None),
}

# Subsurface scattering: random walks are noisy even under a point light, so these are
# compared channel by channel within both renders' standard errors (test_subsurface.py);
# the plane is then the top of a half-space of the medium.
SUBSURFACE_ORACLES = {
    "subsurface_furnace": ([("BsdfPrincipled", {"Base Color": (0.8, 0.4, 0.1), "Subsurface Weight": 1.0,
                                                "Specular IOR Level": 0.0}, {})], 30.0, None),
    "subsurface_skin_furnace": ([("BsdfPrincipled", {"Base Color": (0.8, 0.4, 0.1),
                                                     "Subsurface Weight": 1.0,
                                                     "Specular IOR Level": 0.0},
                                  {"subsurface_method": "RANDOM_WALK_SKIN"})], 30.0, None),
    "subsurface_node_furnace": ([("SubsurfaceScattering", {"Color": (0.9, 0.6, 0.3), "Anisotropy": 0.6,
                                                           "Roughness": 0.5}, {})], 30.0, None),
    "subsurface_point": ([("BsdfPrincipled", {"Base Color": (0.8, 0.5, 0.3), "Subsurface Weight": 1.0,
                                              "Subsurface Scale": 0.2}, {})], 30.0, (20.0, 180.0)),
    "subsurface_half_point": ([("BsdfPrincipled", {"Base Color": (0.3, 0.6, 0.9),
                                                   "Subsurface Weight": 0.5, "Roughness": 0.3,
                                                   "Subsurface Anisotropy": 0.3}, {})],
                              45.0, (45.0, 0.0)),
    "subsurface_burley_furnace": ([("BsdfPrincipled", {"Base Color": (0.8, 0.4, 0.1),
                                                       "Subsurface Weight": 1.0,
                                                       "Specular IOR Level": 0.0},
                                    {"subsurface_method": "BURLEY"})], 30.0, None),
    "subsurface_burley_point": ([("SubsurfaceScattering", {"Color": (0.9, 0.6, 0.3), "Scale": 0.2},
                                  {"falloff": "BURLEY"})], 30.0, (20.0, 180.0)),
    # Light through a slab (the plane and a second one below it, facing down) from a point
    # light under it: what the camera sees left the slab's top after entering at its bottom,
    # so it depends on the radius against the thickness (a half-space does not).
    "subsurface_slab": ([("BsdfPrincipled", {"Base Color": (0.8, 0.5, 0.3), "Subsurface Weight": 1.0,
                                             "Subsurface Scale": 0.02}, {})], 20.0, (180.0, 0.0)),
    "subsurface_burley_slab": ([("SubsurfaceScattering", {"Color": (0.8, 0.5, 0.3), "Scale": 0.02},
                                 {"falloff": "BURLEY"})], 20.0, (180.0, 0.0)),
    # A linked Normal (an object-space Normal Map tilting it 30 degrees towards the camera,
    # away from the light) makes Cycles shade the walks' exits about the BSSRDF's normal
    # (SD_HAS_BSSRDF_BUMP): exits lit at 50 degrees off their normal instead of 20.
    "subsurface_bump_point": ([("NormalMap", {"Color": (0.75, 0.5, 0.933)}, {"space": "OBJECT"}),
                               ("BsdfPrincipled", {"Base Color": (0.8, 0.5, 0.3),
                                                   "Subsurface Weight": 1.0, "Subsurface Scale": 0.2,
                                                   "Normal": ("link", 0, "Normal")}, {})],
                              30.0, (20.0, 180.0)),
}
ALL_ORACLES = {**ORACLES, **SUBSURFACE_ORACLES}
SLAB_THICKNESS = {"subsurface_slab": 0.005, "subsurface_burley_slab": 0.005}   # metres

LIGHT_WATTS = 1000.0
LIGHT_DISTANCE = 2.0


def light_position(theta_deg, azimuth_deg):
    """Point-light position: theta off the +z normal, azimuth 0 on the camera's side (+x)."""
    t, a = math.radians(theta_deg), math.radians(azimuth_deg)
    return (LIGHT_DISTANCE * math.sin(t) * math.cos(a), LIGHT_DISTANCE * math.sin(t) * math.sin(a),
            LIGHT_DISTANCE * math.cos(t))


def camera_matrix(view_deg, distance=5.0):
    """4x4 world matrix of a camera looking at the origin from view_deg off +z, on the +x side."""
    t = math.radians(view_deg)
    back = (math.sin(t), 0.0, math.cos(t))            # camera local +Z (it looks along -Z)
    up = (-math.cos(t), 0.0, math.sin(t))             # camera local +Y
    right = (up[1] * back[2] - up[2] * back[1], up[2] * back[0] - up[0] * back[2],
             up[0] * back[1] - up[1] * back[0])
    return [[right[0], up[0], back[0], distance * back[0]],
            [right[1], up[1], back[1], distance * back[1]],
            [right[2], up[2], back[2], distance * back[2]],
            [0.0, 0.0, 0.0, 1.0]]
