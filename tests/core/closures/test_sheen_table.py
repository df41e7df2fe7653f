"""The measured Sheen LTC table (mcengine/kernels/closures/data/sheen_ltc.npy) against Cycles.

The table was measured by rendering with Cycles (tools/measure_sheen_ltc.py); these tests only
read the stored data (no Cycles at test time).  They check it against the oracles of
cycles-closures.md section 10 and against a few Cycles pixel values rendered for this test
(sun of strength S, black world, max_bounces 0: pixel / S = rho * eval(wo)).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

TABLE = Path(__file__).resolve().parents[3] / "mcengine" / "kernels" / "closures" / "data" / "sheen_ltc.npy"
N = 32

# The oracles are quoted to 5 decimals: the table must round to them (half a unit of the
# last decimal), plus float64 slack.
QUOTED_5_DECIMALS = 5e-6 + 1e-9


@pytest.fixture(scope="module")
def table() -> np.ndarray:
    return np.load(TABLE)


def lookup_1d(x: float) -> dict[int, float]:
    """Node weights of Cycles' lookup_table_read (kernel/util/lookup_table.h)."""
    x = min(max(x, 0.0), 1.0) * (N - 1)
    index = min(int(x), N - 1)
    following = min(index + 1, N - 1)
    t = x - index
    weights = {index: 1.0 - t}
    weights[following] = weights.get(following, 0.0) + t
    return weights


def lookup(table: np.ndarray, mu: float, roughness: float) -> np.ndarray:
    """(a, b, rho) as bsdf_sheen_setup reads them: x = cos theta_view, y = clamped roughness."""
    roughness = min(max(roughness, 1e-3), 1.0)
    out = np.zeros(3)
    for j, wj in lookup_1d(roughness).items():
        for i, wi in lookup_1d(mu).items():
            out += wj * wi * table[:, j, i]
    return out


def ltc_eval(a: float, b: float, wo) -> float:
    """bsdf_sheen_eval: f * cos for the local light direction wo (x towards the viewer's side)."""
    x, y, z = wo
    length_sq = (a * x + b * z) ** 2 + (a * y) ** 2 + z * z
    return max(z, 0.0) * (a / length_sq) ** 2 / math.pi


def pixel(table: np.ndarray, mu: float, roughness: float, wo) -> float:
    """rho * eval, or 0 where Cycles drops the closure (|a| < 1e-5 or rho < 1e-5)."""
    a, b, rho = lookup(table, mu, roughness)
    if abs(a) < 1e-5 or rho < 1e-5:
        return 0.0
    return rho * ltc_eval(a, b, wo)


def test_layout(table):
    """float64 (a, b, rho)[param, roughness index j, view-cosine index i], 5 decimals."""
    assert table.dtype == np.float64
    assert table.shape == (3, N, N)
    assert np.all(np.isfinite(table))
    steps = table * 1e5
    assert np.abs(steps - np.round(steps)).max() < 1e-6


@pytest.mark.parametrize("mu, roughness, expected", [
    (0.2, 0.5, (0.38549, -0.11081, 0.42570)),
    (1.0, 0.5, (0.56776, 0.00008, 0.01864)),
])
def test_table_oracles(table, mu, roughness, expected):
    """cycles-closures.md section 10: sheen (A, B, rho), interpolated."""
    assert lookup(table, mu, roughness) == pytest.approx(expected, abs=QUOTED_5_DECIMALS)


@pytest.mark.parametrize("roughness, cycles", [(0.5, 0.038060), (1.0, 1.67490)])
def test_render_oracles(table, roughness, cycles):
    """Sheen, normal view and light: a 1000 W point light (radius 0) 2 m above a white Sheen
    plane, orthographic camera on the normal (cycles-closures.md's reference set-up), so
    L = rho * eval(N) * P / (4 pi d^2).  Cycles' renders are float32, quoted to 5 digits."""
    radiance = pixel(table, 1.0, roughness, (0.0, 0.0, 1.0)) * 1000.0 / (4.0 * math.pi * 2.0 ** 2)
    assert radiance == pytest.approx(cycles, rel=1e-5)


# Cycles 5.0.1 renders made for this test (delta sun at 35 and 80 degrees, white Sheen facets
# seen by an orthographic camera): view cosine, roughness, local light direction (x towards
# the viewer's side), pixel / sun strength.  Off-node points, some in the low-roughness corner
# where rho is tiny or the closure is dropped (0.0).
RENDERED = [
    (0.6687980844620305, 0.24932057715157963,
     (0.4690075030988255, 0.5340217011703214, 0.7034577348470634), 0.00010394060482985078),
    (0.4665144314324694, 0.95732864379454,
     (0.8063239506244451, -0.5461366196189381, 0.22710455601019347), 0.04926079468207828),
    (0.8205411496917959, 0.3743584979376803,
     (0.2722634548523646, -0.5214974798646315, 0.808648866719476), 0.000772338018184554),
    (0.4285738803686801, 0.23779471952583042,
     (0.4944186844871024, -0.01859161136219089, 0.8690250378539163), 0.0002544065743512722),
    (0.5855120122456027, 0.18614680983389864,
     (0.7717593007705162, -0.5432806744953171, 0.3305052047912668), 9.915370091581565e-05),
    (0.2090788701641996, 0.7485876883600753,
     (0.7786707289828428, 0.5635026025972927, 0.27592881816041936), 0.1122621180768174),
    (0.38818506028904176, 0.77756522151156,
     (0.7700853804387852, 0.5722435920719591, 0.2819676899345616), 0.07435909792675868),
    (0.560294776993563, 0.23967894219457475,
     (-0.34593034456526595, 0.4536182116783769, 0.8213176698103285), 0.00010354214007211887),
    (0.7087186543233577, 0.6036246844606636,
     (-0.5610959107057545, -0.19866068063025943, 0.8035579089031493), 0.01907093522118899),
    (0.9478328359628271, 0.647031856401938,
     (-0.7823414867225235, -0.43444597880610886, 0.4463165800774081), 0.01665344668270606),
    (0.2392165469655079, 0.07220122888907314,
     (0.7497998911973619, -0.54101971584861, 0.3809170385051233), 2.8894882540250383e-06),
    (0.9261851040260011, 0.09483751214071282,
     (0.06451197826776969, 0.5092918686230818, 0.8581724752136882), 0.0),
    (0.6548387096774194, 0.1064516129032258,
     (0.4627846731470252, 0.5215515815831125, 0.7168084081875401), 4.1106952945795045e-07),
    (0.7689804647841069, 0.05607689121649304,
     (-0.2787902913975683, -0.8443312610599238, 0.45758135344375395), 0.0),
    (0.1929831636925014, 0.12747497410357816,
     (0.023961264540370536, 0.6278298068332272, 0.7779817423650629), 2.6518750472332982e-05),
    (0.19089949611615575, 0.11542202647502557,
     (0.0847899665945579, -0.8766276888495632, 0.4736396908063841), 7.311801901875357e-05),
]


@pytest.mark.parametrize("mu, roughness, wo, rendered", RENDERED)
def test_reproduces_cycles_renders(table, mu, roughness, wo, rendered):
    """The table reproduces Cycles' pixels to float32 precision (largest error seen: 2.1e-6)."""
    predicted = pixel(table, mu, roughness, wo)
    if rendered == 0.0:
        assert predicted == 0.0
    else:
        assert predicted == pytest.approx(rendered, rel=1e-5)


def test_dropped_region(table):
    """rho is 0 only at low roughness (j <= 3, the more so the more the view faces the normal);
    elsewhere the closure is kept with a > 0 and 0 < rho < 1."""
    a, _, rho = table
    dropped = (np.abs(a) < 1e-5) | (rho < 1e-5)
    assert not dropped[4:].any()
    assert dropped[:4].any()
    for j in range(4):                                 # a kept run from mu = 0, then dropped
        kept = ~dropped[j]
        assert kept[0] and not kept[-1]
        first_dropped = int(np.argmin(kept))
        assert not kept[first_dropped:].any()
    assert np.all(rho[dropped] == 0.0)
    assert np.all(a[~dropped] > 0.0) and np.all((rho[~dropped] > 0.0) & (rho[~dropped] < 1.0))
