"""An HDRI world with a small bright sun as the only light (Environment Texture, equirectangular).

The environment is ``textures/sky_small_sun.exr`` (128 x 64, float), made here: a
sky from blue at the zenith to pale at the horizon, a brown ground below the
horizon, and a sun of 2 x 2 texels (about 1.2e-3 of the sphere) 35 deg above the
horizon whose radiance, 900, gives about three quarters of the floor's light.
Tests the world's shader graph (Environment Texture into Background, strength
1.2), its importance sampling (World > Settings > Sampling Manual, a 1024 x 512 map)
combined with BSDF sampling by MIS, sharp sun shadows and the sky
seen directly above the horizon.

Run: .venv/bin/python blend_scenes/world_hdri_sun.py
"""
import math

import _common as c
import numpy as np

W, H = 128, 64
SUN_ELEVATION = math.radians(35.0)
SUN_AZIMUTH_U = 0.30          # image column of the sun, as a fraction of the width
SUN_RADIANCE = 900.0
STRENGTH = 1.2


def sky_pixels():
    """(H, W, 4) float32, bottom row first: v = 0 looks straight down, v = 1 straight up."""
    v = (np.arange(H) + 0.5) / H
    elevation = (v - 0.5) * math.pi                 # -90 .. 90 deg
    px = np.zeros((H, W, 4), np.float32)
    up = np.clip(np.sin(elevation), 0.0, 1.0)[:, None]
    sky = (1 - up) * np.array([0.75, 0.8, 0.85]) + up * np.array([0.2, 0.35, 0.7])
    ground = np.array([0.12, 0.09, 0.06])
    px[..., :3] = np.where((elevation > 0)[:, None, None], sky[:, None, :], ground)
    # A little variation along the horizon so that the map is not separable.
    u = (np.arange(W) + 0.5) / W
    px[..., :3] *= (0.85 + 0.15 * np.cos(2 * math.pi * u))[None, :, None]
    row = int((0.5 + SUN_ELEVATION / math.pi) * H)
    col = int(SUN_AZIMUTH_U * W)
    px[row:row + 2, col:col + 2, :3] = (SUN_RADIANCE, 0.92 * SUN_RADIANCE, 0.8 * SUN_RADIANCE)
    px[..., 3] = 1.0
    return px


def build(scene):
    env = c.environment_world(scene, strength=STRENGTH, map_resolution=1024)
    env.image = c.save_texture("sky_small_sun.exr", sky_pixels(), float_buffer=True)
    c.add_horizon_stage(scene)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
