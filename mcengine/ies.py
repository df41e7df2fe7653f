"""IES light profiles (IESNA LM-63 files) read as Cycles 5.0 reads them (util/ies.cpp).

A lamp whose node tree routes an IES Texture's Factor into its emission shines with the
profile's intensity in each direction.  :func:`parse_ies` turns a file's text into an
:class:`IESProfile` the way Cycles' ``IESFile::load`` does:

* commas count as spaces; everything before the first line starting ``TILT=`` is ignored
  (keywords), and so is the tilt data (``TILT=INCLUDE`` blocks are skipped, ``TILT=<file>``
  is not read);
* the candela values are multiplied by the candela multiplier, the ballast factor, the
  ballast-lamp photometric factor and 4 pi / 177.83 (candela to watts per steradian at the
  D65 efficacy of 177.83 lm/W, times 4 pi: the unit of a lamp's power in Cycles); nothing
  else is used (lumens, dimensions, watts);
* photometric types A, B and C are brought to type C's frame (vertical angle 0 = the
  lamp's local -Z, horizontal angle 0 = its local -Y, 90 = -X), the symmetric halves and
  quadrants mirrored to the full circle, a missing 360 degree column added when the spacing
  shows it; angles become radians in float32, as Cycles stores them.

The kernel (``kernels/ies.py``) interpolates the table bicubically (Catmull-Rom) and gives 0
outside the angles the file covers.  A text Cycles cannot read makes every direction 100
(``FAILED_VALUE``): the exporter warns and renders that, as Cycles does.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

__all__ = ["CANDELA_TO_WATTS", "FAILED_PROFILE", "FAILED_VALUE", "IESError", "IESProfile", "parse_ies"]

CANDELA_TO_WATTS = 0.0706650768394     # 4 pi / 177.83
FAILED_VALUE = 100.0                   # what Cycles' lookup gives for a profile it could not load
TYPE_C, TYPE_B, TYPE_A = 1, 2, 3
_CLOSE = np.float32(1e-4)              # degrees: Cycles' angle_close
_DOUBLE = re.compile(rb"\s*([+-]?(?:inf(?:inity)?|nan|(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?))",
                     re.IGNORECASE)
_LONG = re.compile(rb"\s*([+-]?\d+)")


class IESError(ValueError):
    """A text that is not an IES file Cycles can read (the one-line reason)."""


@dataclass(frozen=True)
class IESProfile:
    """A profile in Cycles' type C frame: ``h_angles`` (H,) and ``v_angles`` (V,) in radians
    (float32, ascending as the file gives them), ``intensity`` (H, V) float32 in Cycles' lamp
    units (its product with a lamp's power is watts per steradian times 4 pi)."""

    h_angles: np.ndarray
    v_angles: np.ndarray
    intensity: np.ndarray

    def packed(self) -> np.ndarray:
        """The profile as the kernel reads it (float64): H, V, the three wrap flags of
        Cycles' lookup, the H and V angles, then the intensities row by row (h * V + v).

        The flags are computed in float32 as Cycles computes them: a table ending at exactly
        360 (or 180) degrees does not wrap there, since 2 pi - 1e-7 rounds to 2 pi in float32.
        """
        h, v = self.h_angles.astype(np.float32), self.v_angles.astype(np.float32)
        eps = np.float32(1e-7)
        wrap_h = bool(h[0] < eps and h[-1] > np.float32(2.0 * np.pi) - eps)
        wrap_vlow = bool(v[0] < eps)
        wrap_vhigh = bool(v[-1] > np.float32(np.pi) - eps)
        head = [len(h), len(v), float(wrap_h), float(wrap_vlow), float(wrap_vhigh)]
        return np.concatenate([np.array(head, np.float64), h.astype(np.float64),
                               v.astype(np.float64),
                               self.intensity.astype(np.float64).ravel()])

    @property
    def peak(self) -> float:
        return float(self.intensity.max()) if self.intensity.size else 0.0


# What Cycles gives for a profile it could not load: 100 everywhere (the lookup's range is
# [0, 2 pi) x [0, pi), and a constant table interpolates to its constant).
FAILED_PROFILE = IESProfile(h_angles=np.float32([0.0, 2.0 * np.pi]), v_angles=np.float32([0.0, np.pi]),
                            intensity=np.full((2, 2), FAILED_VALUE, np.float32))


class _Reader:
    """strtod / strtol over the text from a position, as Cycles' IESTextParser reads it."""

    def __init__(self, data: bytes, pos: int):
        self.data, self.pos = data, pos

    def _read(self, pattern, what):
        m = pattern.match(self.data, self.pos)
        if m is None:
            if self.data[self.pos:].strip():
                raise IESError(f"expected {what} at byte {self.pos}")
            raise IESError(f"the file ends before {what}")
        self.pos = m.end()
        return m.group(1)

    def double(self, what="a number") -> float:
        return float(self._read(_DOUBLE, what))

    def long(self, what="a whole number") -> int:
        return int(self._read(_LONG, what))


def parse_ies(text: str | bytes) -> IESProfile:
    """The profile of an IES file's text, processed as Cycles processes it; raises
    :class:`IESError` where Cycles' loader fails."""
    data = text.encode("latin-1", "replace") if isinstance(text, str) else bytes(text)
    data = data.replace(b",", b" ")
    pos = data.find(b"\nTILT=")
    if pos < 0:
        raise IESError("no TILT= line (on a line of its own, after the first)")
    if data.startswith(b"\nTILT=INCLUDE", pos):
        tilt = _Reader(data, pos + 13)
        tilt.double("the lamp-to-luminaire geometry")
        for _ in range(2 * tilt.long("the number of tilt angles")):
            tilt.double("a tilt angle or factor")
        pos = tilt.pos
    else:
        pos = data.find(b"\n", pos + 1)
    if pos < 0 or pos >= len(data):
        raise IESError("the file ends after its TILT line")
    r = _Reader(data, pos + 1)
    r.long("the number of lamps")
    r.double("the lumens per lamp")
    factor = r.double("the candela multiplier")
    n_v = r.long("the number of vertical angles")
    n_h = r.long("the number of horizontal angles")
    kind = r.long("the photometric type")
    if kind not in (TYPE_A, TYPE_B, TYPE_C):
        raise IESError(f"photometric type {kind} (1, 2 or 3: C, B or A)")
    r.long("the unit")
    for what in ("width", "length", "height"):
        r.double(f"the {what}")
    factor *= r.double("the ballast factor")
    factor *= r.double("the ballast-lamp photometric factor")
    r.double("the input watts")
    if n_v <= 0 or n_h <= 0:
        raise IESError(f"{n_v} vertical and {n_h} horizontal angles")
    if n_v * n_h > len(data):
        raise IESError(f"{n_v} x {n_h} values announced, more than the file holds")
    factor *= CANDELA_TO_WATTS
    v = [np.float32(r.double("a vertical angle")) for _ in range(n_v)]
    h = [np.float32(r.double("a horizontal angle")) for _ in range(n_h)]
    rows = [[np.float32(factor * r.double("a candela value")) for _ in range(n_v)] for _ in range(n_h)]
    values = np.array(rows, np.float32)
    if not (np.all(np.isfinite(values)) and np.all(np.isfinite(v)) and np.all(np.isfinite(h))):
        raise IESError("angles or candela values that are not finite numbers")
    if kind == TYPE_C:
        h, rows = _type_c(h, rows)
    elif kind == TYPE_B:
        h, v, rows = _type_b(h, v, rows)
    else:
        h, v, rows = _type_a(h, v, rows)
    to_rad = np.float32(np.float32(np.pi) / np.float32(180.0))
    return IESProfile(h_angles=np.array(h, np.float32) * to_rad,
                      v_angles=np.array(v, np.float32) * to_rad,
                      intensity=np.array(rows, np.float32).reshape(len(h), len(v)))


def _close(a, b) -> bool:
    return abs(np.float32(a) - np.float32(b)) < _CLOSE


def _f(x) -> np.float32:
    return np.float32(x)


def _type_c(h, rows):
    """Cycles' process_type_c: 90-270 files turned to 0-180, one angle made round, a quadrant
    or a half mirrored to the full circle, a missing 360 column added when the spacing
    shows it."""
    h, rows = list(h), list(rows)
    if _close(h[0], 90.0):
        h = [a - _f(90.0) for a in h]
    if len(h) == 1:
        h = [_f(0.0), _f(360.0)]
        rows = [rows[0], rows[0]]
    if _close(h[-1], 90.0):
        for i in range(len(h) - 2, -1, -1):
            h.append(_f(180.0) - h[i])
            rows.append(rows[i])
    if _close(h[-1], 180.0):
        for i in range(len(h) - 2, -1, -1):
            h.append(_f(360.0) - h[i])
            rows.append(rows[i])
    if _close(h[0], 0.0) and not _close(h[-1], 360.0):
        last, first, gap = h[-1] - h[-2], h[1] - h[0], _f(360.0) - h[-1]
        if _close(last, gap) or _close(first, gap):
            h.append(_f(360.0))
            rows.append(rows[0])
    return h, rows


def _mirror_about_90(angles):
    """0..x mirrored to 90-x..90+x (Cycles' types A/B), else shifted by 90; with the order
    of the source indices."""
    if _close(angles[0], 0.0):
        order = list(range(len(angles) - 1, 0, -1)) + list(range(len(angles)))
        new = [(_f(90.0) - angles[i]) if k < len(angles) - 1 else (_f(90.0) + angles[i])
               for k, i in enumerate(order)]
        return new, order
    return [a + _f(90.0) for a in angles], list(range(len(angles)))


def _type_b(h, v, rows):
    """Cycles' process_type_b: the table transposed (its polar axis made vertical), each
    axis mirrored about 90 degrees or shifted by 90; no 360 column."""
    rows = [[rows[j][i] for j in range(len(h))] for i in range(len(v))]
    h, v = v, h
    h, order = _mirror_about_90(h)
    rows = [rows[i] for i in order]
    v, order = _mirror_about_90(v)
    rows = [[row[j] for j in order] for row in rows]
    return h, v, rows


def _type_a(h, v, rows):
    """Cycles' process_type_a: vertical angles shifted by 90, horizontal -90..90 turned to
    270..90 (reversed), a 0..90 file mirrored to 90..270."""
    v = [a + _f(90.0) for a in v]
    new_h = [_f(180.0) - h[i] for i in range(len(h) - 1, -1, -1)]
    new_rows = [rows[i] for i in range(len(h) - 1, -1, -1)]
    if _close(h[0], 0.0):
        for i in range(1, len(h)):
            new_h.append(_f(180.0) + h[i])
            new_rows.append(rows[i])
    return new_h, v, new_rows
