"""mcengine: a Monte Carlo path tracer that renders Blender scenes like Cycles.

The core never imports Blender.  A render is described by a
:class:`mcengine.scene.SceneDescription` (plain numpy data, savable to .npz)
and produced by :class:`mcengine.session.RenderSession`.

Conventions used throughout the core:

* world space is Blender's (right-handed, +Z up, metres); colours are linear;
* light units are Cycles' (watts for point/spot/area, W/m^2 for sun);
* directions ``wo`` (towards the viewer) and ``wi`` (towards the light) point
  away from the surface; BSDF ``eval`` returns f * |cos(theta_i)|, BSDF
  ``sample`` returns (wi, weight = f * |cos| / pdf, pdf);
* images are top row first (as in EXR files).
"""
__version__ = "0.1.0"
