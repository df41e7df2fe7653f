"""Compute ``mcengine/kernels/closures/data/thin_film_cmf.npy``: the Fourier transform of the CIE 1931 CMFs.

    pip install --target /tmp/colour colour-science     # the CIE data (development only)
    PYTHONPATH=/tmp/colour .venv/bin/python -m tools.make_thin_film_table

Thin-film interference (Belcour and Barla 2017, "A Practical Extension to Microfacet Theory
for the Modeling of Varying Iridescence") integrates a film's reflectance, which oscillates
as cos(2 pi OPD / lambda) with the optical path difference OPD, against the colour matching
functions.  Written over the wavenumber f = 1 / lambda, that integral is the Fourier
transform of the CMFs at the "time" OPD, so a table of the transform replaces the spectral
integral by a lookup per term of the Airy series.  Cycles 5.0 tabulates it with these
choices (intern/cycles/doc/precompute/thin_film_table.py, kernel/closure/bsdf_util.h), which
the table here follows so that the lookups land on the same values:

* the CIE 1931 2-degree XYZ CMFs at 1 nm, 360 to 830 nm, with a zero added at 359 and
  831 nm, interpolated by a cubic spline (scipy's default, not-a-knot) and zero outside;
* sampled at N = 1022 wavenumbers f_n = n pi / 60 per micrometre (n = 0 ... 1021), as
  CMF(1000 / f_n) / f_n^2 (the Jacobian of lambda = 1000 / f nm; f_0 is a tiny positive
  number, where the value is 0);
* the real FFT of those samples (numpy's sign convention, exp(-2 pi i j n / N)): 512
  complex values; entry j belongs to OPD = j 60000 / (2 pi 511) nm, so the kernel's
  coordinate x = 2 pi OPD / 60000 nm spans the table from 0 to 1 (OPD 0 to about 9.5 um).

The file holds shape (2, 3, 512): real and imaginary parts of X, Y and Z.  The kernels turn
it into the working space's RGB with its XYZ -> RGB matrix and divide each channel by its
value at OPD 0 (``closures.tables``), as Cycles does at scene load.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

OUT = Path(__file__).resolve().parents[1] / "mcengine/kernels/closures/data/thin_film_cmf.npy"
TABLE_SIZE = 512                  # complex entries (Cycles' THIN_FILM_TABLE_SIZE)
SAMPLES = 2 * (TABLE_SIZE - 1)    # real samples whose rfft has TABLE_SIZE entries
END_UM = 60.0                     # the table spans OPD 0 .. SAMPLES / (2 * END_UM / pi) um


def cie_1931_cmfs() -> tuple[np.ndarray, np.ndarray]:
    """(wavelengths nm, (n, 3) XYZ CMFs): 1 nm from 360 to 830 nm, zero at 359 and 831 nm."""
    try:
        import colour
    except ImportError:
        raise SystemExit("make_thin_film_table needs the CIE data of colour-science: "
                         "pip install --target /tmp/colour colour-science, then "
                         "PYTHONPATH=/tmp/colour") from None
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    wl = np.asarray(cmfs.wavelengths, np.float64)
    values = np.asarray(cmfs.values, np.float64)
    if wl[0] != 360 or wl[-1] != 830 or not np.all(np.diff(wl) == 1):
        raise SystemExit(f"unexpected CIE 1931 sampling: {wl[0]} .. {wl[-1]} nm")
    wl = np.concatenate([[359.0], wl, [831.0]])
    values = np.concatenate([np.zeros((1, 3)), values, np.zeros((1, 3))])
    return wl, values


def thin_film_cmf_table(wl: np.ndarray, cmf: np.ndarray) -> np.ndarray:
    """(2, 3, TABLE_SIZE) real and imaginary parts of the rfft of the CMFs over wavenumber."""
    f = np.maximum(np.linspace(0.0, np.pi * (SAMPLES - 1) / END_UM, SAMPLES), 1e-40)
    out = np.empty((2, 3, TABLE_SIZE))
    for c in range(3):
        spline = CubicSpline(wl, cmf[:, c], extrapolate=False)
        samples = np.nan_to_num(spline(1000.0 / f) / (f * f))
        spectrum = np.fft.rfft(samples)
        out[0, c], out[1, c] = spectrum.real, spectrum.imag
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args(argv)
    table = thin_film_cmf_table(*cie_1931_cmfs())
    tmp = args.out.with_suffix(".tmp.npy")
    np.save(tmp, table)
    tmp.replace(args.out)
    print(f"{args.out}: shape {table.shape}, DC X Y Z = {table[0, :, 0]}")


if __name__ == "__main__":
    main()
