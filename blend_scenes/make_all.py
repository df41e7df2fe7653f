"""Regenerate every scene: run each ``blend_scenes/<name>.py`` in its own process.

Usage: .venv/bin/python blend_scenes/make_all.py [NAME ...]

Each generator resets Blender to factory settings, but a fresh interpreter per
scene also keeps add-on and module state from leaking between scenes.  Without
arguments all scenes in :data:`SCENES` are built; exits non-zero on the first
failure.
"""
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
SCENES = (
    "cornell_box",
    "light_point",
    "light_point_sphere",
    "light_spot",
    "light_sun",
    "light_area",
    "light_emissive_mesh",
    "world_color",
    "glass_mirror",
    "light_area_spread",
    "light_point_large",
    "light_spot_shapes",
    "light_sun_wide",
    "light_ies",
    "transforms",
    "instancing_modifiers",
    "camera_sensor_fit",
    "camera_portrait_wide",
    "camera_ortho",
    "camera_dof",
    "camera_dof_ortho",
    "motion_transform",
    "motion_camera",
    "motion_deform",
    "material_principled",
    "material_toon",
    "material_hair",
    "material_ray_portal",
    "material_nodes",
    "material_suzanne",
    "material_rough_glass",
    "material_anisotropic",
    "caustics",
    "caustics_point",
    "texture_procedural",
    "world_hdri_sun",
    "texture_image",
    "texture_normal_map",
    "texture_bump",
    "texture_checker_lights",
    "attribute_vertex_colors",
    "texture_suzanne_maps",
    "world_hdri_interior",
    "material_thin_film",
    "holdout_objects",
    "world_sky",
    "world_sky_preetham",
    "material_displacement",
    "material_subsurface",
    "ray_visibility",
    "light_linking",
    "material_nodes_extra",
    "material_bevel_ao",
)


def main(names):
    unknown = [n for n in names if n not in SCENES]
    if unknown:
        print(f"error: unknown scene(s) {', '.join(unknown)}; choose from {', '.join(SCENES)}",
              file=sys.stderr)
        return 2
    for name in names or SCENES:
        result = subprocess.run([sys.executable, str(HERE / f"{name}.py")],
                                capture_output=True, text=True)
        if result.returncode != 0:
            print(result.stdout + result.stderr, file=sys.stderr)
            print(f"error: {name}.py failed with exit code {result.returncode}", file=sys.stderr)
            return 1
        print(f"{name}.blend")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
