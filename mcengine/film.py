"""Film: per-pixel accumulation of path samples and the running image.

Each finished path adds its radiance (and alpha) to its pixel's sums; the
image is the per-pixel mean, so pixels may hold different sample counts (an
interrupted pass, adaptive sampling).  The sum of squares gives each pixel's
sample variance, from which ``variance()`` estimates the variance of the
pixel mean.  Memory is proportional to the film region, never to samples.
"""
from __future__ import annotations

import numpy as np


class Film:
    """Accumulators for a ``width`` x ``height`` region (row 0 at the top)."""

    def __init__(self, width: int, height: int):
        self.width, self.height = int(width), int(height)
        n = self.width * self.height
        self.sum = np.zeros((n, 4))          # radiance RGB and alpha
        self.sum_sq = np.zeros((n, 3))       # squared radiance
        self.count = np.zeros(n, np.int64)   # finished samples

    @property
    def arrays(self):
        return self.sum, self.sum_sq, self.count

    def image(self, exposure: float = 1.0) -> np.ndarray:
        """(h, w, 4) float32 mean RGBA; pixels without samples are 0."""
        n = np.maximum(self.count, 1)[:, None]
        img = self.sum / n
        img[:, :3] *= exposure
        return img.reshape(self.height, self.width, 4).astype(np.float32)

    def variance(self, exposure: float = 1.0) -> np.ndarray:
        """(h, w, 3) float32 estimated variance of each pixel's mean.

        Pixels with fewer than two samples get +inf (unknown).
        """
        n = self.count[:, None].astype(np.float64)
        with np.errstate(divide="ignore", invalid="ignore"):
            mean = self.sum[:, :3] / n
            s2 = (self.sum_sq - n * mean * mean) / (n - 1.0)
            var = np.where(n >= 2, np.maximum(s2, 0.0) / n, np.inf) * exposure * exposure
        return var.reshape(self.height, self.width, 3).astype(np.float32)

    def samples_min(self) -> int:
        return int(self.count.min()) if self.count.size else 0
