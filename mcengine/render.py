"""Render session: the one entry point the add-on, the CLI and the tests use.

Typical use::

    session = RenderSession(scene)          # validates, builds the BVH, loads kernels
    session.run(on_pass=show, should_stop=esc_pressed)
    rgba = session.image()                  # (h, w, 4) float32, top row first

``run`` renders progressive passes until ``scene.integrator.samples`` samples
per pixel are done, the time limit is reached or ``should_stop()`` returns
True (polled at least every 0.2 s).  After a stop the image holds what was
rendered so far.
"""
from __future__ import annotations

# Implementation in progress: see the signatures below.


class RenderSession:  # pragma: no cover - placeholder replaced by the implementation
    def __init__(self, scene, *, threads=None, batch_size=None):
        raise NotImplementedError

    def run(self, on_pass=None, should_stop=None):
        """on_pass(session) is called after each pass; returns self."""
        raise NotImplementedError

    def image(self):
        """(h, w, 4) float32 linear RGBA of the film region, top row first."""
        raise NotImplementedError

    def variance(self):
        """(h, w, 3) float32 variance of each pixel's mean (per channel)."""
        raise NotImplementedError
