"""Compute the BSDF tables of ``mcengine/kernels/closures/data/`` by integrating our own GGX closure.

    python -m tools.make_bsdf_tables [--log2-samples N] [--replicates R] [--only NAME ...]

Every table is the mean, over quasi-random samples, of a quantity returned by
``microfacet_sample`` (this package's sampler, so the tables describe exactly the
kernel's eval and pdf), at the nodes Cycles uses (intern/cycles/app/cycles_precompute.cpp):

* node i of n along an axis sits at i / (n - 1), clamped to [1e-4, 1] for the roughness r
  (alpha = r^2) and the view cosine mu, and to [1e-4, 0.99] for the IOR coordinate z,
  with ior = ior_from_F0(z^4) = (1 + z^2) / (1 - z^2);
* the view is wo = (sqrt(1 - mu^2), 0, mu);
* ``ggx_E``: E[f cos / pdf] of GGX reflection with F = 1 (a singular sample counts its
  weight, a failed one 0), ``ggx_glass_E``: the same for GGX glass with the dielectric
  Fresnel at ior (``_inv_``: at 1 / ior);
* ``*_Eavg``: mu is not a node but the 4th quasi-random coordinate, uniform on [0, 1],
  and the quantity is 2 mu f cos / pdf, so the table is the integral of 2 mu E(mu);
* ``ggx_gen_schlick_ior_s``: GGX reflection with the generalized Schlick Fresnel,
  F0 = (0, 1, 0), F90 = (1, 1, 0), exponent -1 (exact Fresnel of ior remapped); the
  quantity is the red/green ratio of the sample's value, i.e. the factor s at the sampled
  microfacet, for every successful sample, 0 for a failed one;
* ``ggx_gen_schlick_s``: the same with ior 1 and exponent e = 5 (1 - z) / z;
* each node's mean is clamped to [0, 1], as Cycles does.

Samples: for each table, R independent Owen-scrambled Sobol point sets (scipy) of
2^N / R points each, shared by all nodes of the table; the table is the mean of the R
replicate means, and the spread of the replicates estimates its error (standard error
= std / sqrt(R)), which the tool prints and stores next to the tables
(``data/bsdf_tables_error.json``).  Defaults: 2^22 points per node in 4 replicates for
the E and s tables, 2^24 for the averages over mu.  Runs on all cores (numba prange).
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
from numba import njit, prange
from scipy.stats import qmc

from mcengine.kernels.closures.fresnel import ior_from_F0
from mcengine.kernels.closures.layout import (
    CL_AX,
    CL_AY,
    CL_DIST,
    CL_ENERGY,
    CL_ETA,
    CL_EXPONENT,
    CL_F0,
    CL_F90,
    CL_FRESNEL,
    CL_RTINT,
    CL_STRIDE,
    CL_TTINT,
    CL_TYPE,
    CT_MICROFACET,
    CT_MICROFACET_GLASS,
    FR_DIELECTRIC,
    FR_NONE,
    FR_SCHLICK,
    LABEL_NONE,
    LABEL_SINGULAR,
    MD_GGX,
)
from mcengine.kernels.closures.microfacet import microfacet_sample
from mcengine.kernels.closures.tables import DATA_DIR, TABLE_SHAPES

# kinds of quantity
K_E = 0          # mean f cos / pdf
K_S = 1          # mean red/green ratio (generalized Schlick factor s)

# name: (closure type, Fresnel, kind, axis sizes (nx rough, ny mu, nz z), ior mapping, mu averaged)
TABLES = {
    "ggx_E": (CT_MICROFACET, FR_NONE, K_E, (32, 32, 1), "none", False),
    "ggx_Eavg": (CT_MICROFACET, FR_NONE, K_E, (32, 1, 1), "none", True),
    "ggx_glass_E": (CT_MICROFACET_GLASS, FR_DIELECTRIC, K_E, (16, 16, 16), "ior", False),
    "ggx_glass_Eavg": (CT_MICROFACET_GLASS, FR_DIELECTRIC, K_E, (16, 1, 16), "ior", True),
    "ggx_glass_inv_E": (CT_MICROFACET_GLASS, FR_DIELECTRIC, K_E, (16, 16, 16), "inv_ior", False),
    "ggx_glass_inv_Eavg": (CT_MICROFACET_GLASS, FR_DIELECTRIC, K_E, (16, 1, 16), "inv_ior", True),
    "ggx_gen_schlick_ior_s": (CT_MICROFACET, FR_SCHLICK, K_S, (16, 16, 16), "ior", False),
    "ggx_gen_schlick_s": (CT_MICROFACET, FR_SCHLICK, K_S, (16, 16, 16), "exponent", False),
}


def node_coordinate(i: int, n: int, lo: float, hi: float) -> float:
    return min(max(i / (n - 1), lo), hi)


def node_parameters(name: str) -> np.ndarray:
    """(n_nodes, 5): rough, mu (-1: averaged), eta, exponent, flat index in numpy order."""
    ctype, fresnel, kind, (nx, ny, nz), mapping, averaged = TABLES[name]
    rows = []
    for zi in range(nz):
        z = node_coordinate(zi, nz, 1e-4, 0.99) if nz > 1 else 0.0
        eta, exponent = 1.0, -1.0
        if mapping in ("ior", "inv_ior"):
            eta = ior_from_F0(z ** 4)
            if mapping == "inv_ior":
                eta = 1.0 / eta
        elif mapping == "exponent":
            exponent = 5.0 * (1.0 - z) / z
        for yi in range(ny):
            mu = -1.0 if averaged else node_coordinate(yi, ny, 1e-4, 1.0)
            for xi in range(nx):
                rough = node_coordinate(xi, nx, 1e-4, 1.0)
                rows.append((rough, mu, eta, exponent))
    return np.array(rows, dtype=np.float64)


@njit(parallel=True, cache=False)
def _integrate(ctype, fresnel, kind, params, points, out):
    n_nodes = params.shape[0]
    n = points.shape[0]
    for node in prange(n_nodes):
        cl = np.zeros((1, CL_STRIDE))
        rough, mu_node, eta, exponent = params[node, 0], params[node, 1], params[node, 2], params[node, 3]
        cl[0, CL_TYPE] = ctype
        cl[0, CL_AX] = rough * rough
        cl[0, CL_AY] = rough * rough
        cl[0, CL_ETA] = eta
        cl[0, CL_DIST] = MD_GGX
        cl[0, CL_FRESNEL] = fresnel
        cl[0, CL_ENERGY] = 1.0
        cl[0, CL_EXPONENT] = exponent
        cl[0, CL_F0 + 1] = 1.0             # F0 = (0, 1, 0), F90 = (1, 1, 0)
        cl[0, CL_F90] = 1.0
        cl[0, CL_F90 + 1] = 1.0
        for c in range(3):
            cl[0, CL_RTINT + c] = 1.0
            cl[0, CL_TTINT + c] = 1.0
        acc = 0.0
        for s in range(n):
            mu = mu_node if mu_node >= 0.0 else points[s, 3]
            wox = math.sqrt(max(0.0, 1.0 - mu * mu))
            x, y, z, r, g, b, pdf, label = microfacet_sample(cl, 0, wox, 0.0, mu,
                                                             points[s, 0], points[s, 1], points[s, 2])
            if label == LABEL_NONE:
                continue
            if kind == K_S:
                v = r / g
                v = min(max(v, 0.0), 1.0)
            elif label & LABEL_SINGULAR:
                v = (r + g + b) / 3.0
            elif pdf != 0.0:
                v = (r + g + b) / 3.0 / pdf
            else:
                v = 0.0
            if mu_node < 0.0:
                v *= 2.0 * mu
            if v == v:                     # NaN counts as 0, as in Cycles
                acc += v
        out[node] = acc / n


def compute(name: str, log2_samples: int, replicates: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    ctype, fresnel, kind, (nx, ny, nz), mapping, averaged = TABLES[name]
    params = node_parameters(name)
    per_rep = 2 ** log2_samples // replicates
    m = int(round(math.log2(per_rep)))
    reps = np.empty((replicates, params.shape[0]))
    for r in range(replicates):
        points = qmc.Sobol(d=4, scramble=True, seed=seed + 1000 * r + list(TABLES).index(name)).random_base2(m)
        np.clip(points, 0.0, np.nextafter(1.0, 0.0), out=points)
        out = np.empty(params.shape[0])
        _integrate(ctype, fresnel, kind, params, points, out)
        reps[r] = out
    mean = np.clip(reps.mean(axis=0), 0.0, 1.0)
    stderr = reps.std(axis=0, ddof=1) / math.sqrt(replicates)
    shape = TABLE_SHAPES[name]
    return mean.reshape(shape), stderr.reshape(shape)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--log2-samples", type=int, default=22, help="log2 of the points per node (E, s tables)")
    parser.add_argument("--log2-samples-avg", type=int, default=24, help="log2 of the points per node (averages)")
    parser.add_argument("--replicates", type=int, default=4)
    parser.add_argument("--seed", type=int, default=20250)
    parser.add_argument("--only", nargs="*", default=None, help="table names (default: all)")
    parser.add_argument("--out", type=Path, default=DATA_DIR)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    error_path = args.out / "bsdf_tables_error.json"
    errors = json.loads(error_path.read_text()) if error_path.exists() else {}
    for name in args.only or list(TABLES):
        averaged = TABLES[name][5]
        log2 = args.log2_samples_avg if averaged else args.log2_samples
        start = time.perf_counter()
        table, stderr = compute(name, log2, args.replicates, args.seed)
        elapsed = time.perf_counter() - start
        np.save(args.out / f"{name}.npy", table)
        errors[name] = {"samples_per_node": 2 ** log2, "replicates": args.replicates,
                        "max_stderr": float(stderr.max()), "rms_stderr": float(np.sqrt((stderr ** 2).mean())),
                        "seconds": round(elapsed, 1)}
        print(f"{name:24s} {str(table.shape):14s} 2^{log2} points/node  stderr max {stderr.max():.2e} "
              f"rms {np.sqrt((stderr ** 2).mean()):.2e}  {elapsed:.0f} s", flush=True)
    error_path.write_text(json.dumps(errors, indent=2, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
