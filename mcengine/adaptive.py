"""Adaptive sampling: which pixels keep sampling, by their estimated noise."""
from __future__ import annotations

import math

import numpy as np

from .film import BLOCK_PIXELS


class Adaptive:
    """Adaptive sampling: pixels stop once their estimated noise is below a threshold.

    A pixel's error is the standard error of its mean, summed over RGB in
    quadrature, relative to its brightness the way Cycles normalises it
    (kernel/film/adaptive_sampling.h): divided by sqrt(sum RGB) below 1,
    where the eye is more sensitive to noise, and by sum RGB above 1.  Every
    pixel takes at least ``min_samples``; convergence is checked every
    ``CHECK_EVERY`` samples after that, and the unconverged pixels' 3x3
    neighbours keep sampling too, as in Cycles, so a feature that the noise
    estimate missed in one pixel is not left half-sampled.
    """

    CHECK_EVERY = 16

    def __init__(self, threshold, min_samples):
        self.threshold = float(threshold)
        self.min_samples = int(min_samples)
        # (pixels left sampling, the samples each needs in all) from the last check.
        self._needed = None

    @staticmethod
    def from_settings(it):
        if not it.use_adaptive_sampling:
            return None
        threshold = it.adaptive_threshold if it.adaptive_threshold > 0 else max(0.001, 1.0 / it.samples)
        min_samples = it.adaptive_min_samples
        if min_samples <= 0:    # Cycles' automatic minimum
            min_samples = max(4, int(math.ceil(16.0 / threshold ** 0.3)))
        return Adaptive(threshold, min(min_samples, it.samples))

    def next_check(self, done):
        if done < self.min_samples:
            return self.min_samples
        return done + self.CHECK_EVERY

    def error(self, film):
        """(n,) relative error of every film pixel (inf below 2 samples)."""
        n = film.count.size
        err = np.empty(n)
        for a in range(0, n, BLOCK_PIXELS):
            b = min(n, a + BLOCK_PIXELS)
            samples = np.maximum(film.count[a:b], 1).astype(np.float64)
            var, total = film.mean_variance(a, b, 0), film.sum[a:b, 0] / samples
            for c in (1, 2):
                var += film.mean_variance(a, b, c)
                total += film.sum[a:b, c] / samples
            with np.errstate(divide="ignore", invalid="ignore"):
                scale = np.where(total < 1.0, np.sqrt(np.maximum(total, 0.0)), total)
                err[a:b] = np.sqrt(var) / (1e-4 + scale)
        return err

    def unconverged(self, film, done):
        """Indices of the pixels that keep sampling after ``done`` samples."""
        if done < self.min_samples:
            return np.arange(film.count.size, dtype=np.int32)
        err = self.error(film)
        open_ = (err >= self.threshold).reshape(film.height, film.width)
        grown = open_.copy()   # 3x3 dilation
        grown[1:, :] |= open_[:-1, :]
        grown[:-1, :] |= open_[1:, :]
        g2 = grown.copy()
        g2[:, 1:] |= grown[:, :-1]
        g2[:, :-1] |= grown[:, 1:]
        active = np.flatnonzero(g2.ravel()).astype(np.int32)
        self._needed = (active, self._samples_needed(film.count[active], err[active]))
        return active

    def remaining_samples(self, film, active, max_samples):
        """Estimated samples still to take by the pixels ``active``: as the error falls as
        1/sqrt(n), a pixel needs about n (error / threshold)^2 samples in all, at least the
        minimum and at most ``max_samples``.

        For the pixels the last check left sampling, that need is the check's (the error is
        not computed again after every pass: at 4K that took 1.5 s a pass); before the first
        check every pixel counts all its samples, as Cycles' progress does.
        """
        if active.size == 0:
            return 0
        if self._needed is not None and self._needed[0] is active:
            needed = self._needed[1]
        elif self._needed is None:
            needed = np.full(active.size, np.inf)
        else:
            needed = self._samples_needed(film.count[active], self.error(film)[active])
        needed = np.clip(np.maximum(needed, self.min_samples), 0, max_samples)
        return float(np.maximum(needed - film.count[active], 0).sum())

    def _samples_needed(self, n, err):
        """Samples in all that pixels of ``n`` samples and relative error ``err`` need (inf
        where the error is unknown)."""
        with np.errstate(invalid="ignore"):     # 0 x inf where the error is unknown
            return np.where(np.isfinite(err), n.astype(np.float64) * (err / self.threshold) ** 2,
                            np.inf)
