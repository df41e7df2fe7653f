"""Film: per-pixel accumulation of path samples and the running image.

Each finished path adds its radiance (and alpha) to its pixel's sums; the
image is the per-pixel mean, so pixels may hold different sample counts (an
interrupted pass, adaptive sampling).  Light tracing (``kernels.light_tracing``)
adds light to whichever pixels a light path reaches: ``splat`` sums it and
``light_paths`` counts the light paths traced, each an estimate of the whole
image, so the image adds ``splat / light_paths`` (which ``variance`` does not
see).  The sum of squares gives each pixel's
sample variance, from which ``variance()`` estimates the variance of the
pixel mean.  Memory is proportional to the film region, never to samples:
``memory.FILM_BYTES_PER_PIXEL`` for the sums, and read-out works through
blocks of rows, so it needs no full-frame float64 temporaries, only the
float32 image it returns.

Render passes other than Combined accumulate in ``passes``, one row of
``pass_stride`` float64 sums per pixel (``mcengine.passes`` lays them out and
reads them); a render without passes has none.  Light tracing's ``splat`` is
Combined's only: ``pass_image`` does not add it (the add-on writes passes for
the path tracer alone).
"""
from __future__ import annotations

import numpy as np

BLOCK_PIXELS = 1 << 16     # pixels per read-out block (temporaries of a few MB)


class Film:
    """Accumulators for a ``width`` x ``height`` region (row 0 at the top)."""

    def __init__(self, width: int, height: int, pass_stride: int = 0):
        self.width, self.height = int(width), int(height)
        n = self.width * self.height
        self.sum = np.zeros((n, 4))          # radiance RGB and alpha
        self.sum_sq = np.zeros((n, 3))       # squared radiance
        self.count = np.zeros(n, np.int32)   # finished samples
        # Render passes' sums (kernels.passes); one column when there are none, so the
        # kernels see the same array type either way.
        self.passes = np.zeros((n if pass_stride else 1, max(int(pass_stride), 1)))
        self.splat = None                    # (n, 3) light-tracing sums, once a light path ran
        self.light_paths = 0                 # light paths traced into ``splat``

    def add_splats(self, splat, light_paths: int) -> None:
        """Add a worker's light-tracing sums (then zeroed) over ``light_paths`` light paths."""
        if self.splat is None:
            self.splat = np.zeros((self.count.size, 3))
        self.splat += splat
        splat[:] = 0.0
        self.light_paths += int(light_paths)

    @property
    def arrays(self):
        return self.sum, self.sum_sq, self.count

    def _row_blocks(self):
        """(first row, end row) of consecutive row blocks covering the film."""
        rows = max(1, BLOCK_PIXELS // max(self.width, 1))
        for r0 in range(0, self.height, rows):
            yield r0, min(self.height, r0 + rows)

    def image(self, exposure: float = 1.0, bottom_up: bool = False) -> np.ndarray:
        """(h, w, 4) float32 mean RGBA; pixels without samples are 0.

        ``bottom_up`` returns the rows in Blender's order (row 0 at the bottom),
        still contiguous.  The blocks are computed in two buffers reused from block to
        block (the same arithmetic in fresh temporaries took four times as long at 4K).
        """
        w, h = self.width, self.height
        out = np.empty((h, w, 4), np.float32)
        rows_per_block = max(1, BLOCK_PIXELS // max(w, 1))
        counts = np.empty((rows_per_block * w, 1))
        means = np.empty((rows_per_block * w, 4))
        for r0, r1 in self._row_blocks():
            a, b = r0 * w, r1 * w
            count, block = counts[:b - a], means[:b - a]
            np.maximum(self.count[a:b, None], 1, out=count)
            np.divide(self.sum[a:b], count, out=block)
            if self.splat is not None and self.light_paths:
                block[:, :3] += self.splat[a:b] / self.light_paths
            if exposure != 1.0:
                block[:, :3] *= exposure
            rows = block.reshape(r1 - r0, w, 4)
            if bottom_up:
                out[h - r1:h - r0] = rows[::-1]
            else:
                out[r0:r1] = rows
        return out

    def pass_image(self, name: str, layout, exposure: float = 1.0, bottom_up: bool = False
                   ) -> np.ndarray:
        """(h, w, C) float32 image of render pass ``name`` (``mcengine.passes.read``)."""
        from .passes import read
        w, h = self.width, self.height
        out = None
        for r0, r1 in self._row_blocks():
            a, b = r0 * w, r1 * w
            block = read(name, self.passes[a:b], self.count[a:b], layout, exposure)
            if out is None:
                out = np.empty((h, w, block.shape[1]), np.float32)
            rows = block.reshape(r1 - r0, w, -1)
            if bottom_up:
                out[h - r1:h - r0] = rows[::-1]
            else:
                out[r0:r1] = rows
        return out

    def variance(self, exposure: float = 1.0) -> np.ndarray:
        """(h, w, 3) float32 estimated variance of each pixel's mean.

        Pixels with fewer than two samples get +inf (unknown).
        """
        w = self.width
        out = np.empty((self.height, w, 3), np.float32)
        for r0, r1 in self._row_blocks():
            block = out[r0:r1].reshape(-1, 3)
            for c in range(3):
                block[:, c] = self.mean_variance(r0 * w, r1 * w, c) * exposure ** 2
        return out

    def mean_variance(self, a: int, b: int, channel: int) -> np.ndarray:
        """(b - a,) float64 variance of the means of pixels a..b-1 in RGB channel ``channel``
        (inf below 2 samples).  One channel at a time: the same arithmetic on the (b - a, 3)
        columns at once, through broadcast and strided loops, took five times as long."""
        n = self.count[a:b].astype(np.float64)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            mean = self.sum[a:b, channel] / n
            s2 = n * mean
            s2 *= mean
            np.subtract(self.sum_sq[a:b, channel], s2, out=s2)
            s2 /= n - 1.0
            np.maximum(s2, 0.0, out=s2)
            s2 /= n
        s2[n < 2] = np.inf
        return s2

    def samples_min(self) -> int:
        return int(self.count.min()) if self.count.size else 0
