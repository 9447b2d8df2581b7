"""The history's statistics against independent computations: the ISO 7870-6 EWMA limits,
weighted least squares by the normal equations, the false-event rate of the change-point
rule on clean series, the size of a planted step, the forecast against the line's exact
crossing and the confidence band scanned day by day."""

import math

import numpy as np
import pytest

from volerr.history import analysis as an


def series(y, s, step_days=7.0):
    n = len(y)
    t = 20000.0 + step_days * np.arange(n)
    return an.Series("P", "um", [an.date_of(x) for x in t], t, np.asarray(y, float),
                     np.asarray(s, float))


def test_ewma_limits_are_the_standards_with_one_sigma():
    rng = np.random.default_rng(3)
    sig = 0.5
    y = rng.normal(0, sig, 15)
    s = series(y, np.full(15, sig))
    c = an.control(s)
    x0 = y[0]
    lam, L = an.EWMA_LAMBDA, an.EWMA_L
    z = x0
    for i, p in enumerate(c["ewma"]):
        # ISO 7870-6: sigma_z^2 = sigma^2 lam/(2-lam) [1-(1-lam)^(2i)]; point 0 is the
        # reference itself (sigma s0), points after it carry sqrt(s^2 + s0^2)
        z = lam * y[i] + (1 - lam) * z
        g2 = [sig ** 2] + [2 * sig ** 2] * i
        var = sum(lam ** 2 * (1 - lam) ** (2 * (i - k)) * g2[k] for k in range(i + 1))
        assert p["z"] == pytest.approx(z, rel=1e-12)
        assert p["ucl"] - x0 == pytest.approx(L * math.sqrt(var), rel=1e-12)
    # far from the start with one sigma (2 sig^2) the limit tends to the steady state
    assert c["ewma"][-1]["ucl"] - x0 == pytest.approx(
        L * math.sqrt(2 * sig ** 2 * lam / (2 - lam)), rel=2e-3)
    assert all(p["ucl"] - x0 == pytest.approx(3 * math.sqrt(2) * sig)
               for p in c["shewhart"][1:])


def test_trend_is_weighted_least_squares():
    rng = np.random.default_rng(4)
    s_i = rng.uniform(0.1, 0.5, 12)
    t = 7.0 * np.arange(12)
    y = 1.0 + 0.05 * t + rng.normal(0, s_i)
    s = series(y, s_i)
    tr = an.trend(s)
    W = np.diag(1 / s_i ** 2)
    X = np.column_stack([np.ones(12), t - t[-1]])
    N = X.T @ W @ X
    beta = np.linalg.solve(N, X.T @ W @ y)
    r = y - X @ beta
    phi = max(1.0, float(r @ W @ r) / 10)
    assert tr.b == pytest.approx(beta[1], rel=1e-9)
    assert tr.a == pytest.approx(beta[0], rel=1e-9)
    assert math.sqrt(tr.cov[1, 1]) == pytest.approx(math.sqrt(np.linalg.inv(N)[1, 1] * phi),
                                                   rel=1e-9)


@pytest.mark.slow
def test_clean_series_rarely_show_an_event():
    """ALPHA = 1 % per series: 400 clean series of 20 entries (with a trend) give at most
    2 % series with an event (binomial: P(> 8 | 400, 0.01) < 2 %)."""
    rng = np.random.default_rng(5)
    hits = 0
    for _ in range(400):
        s_i = rng.uniform(0.5, 1.5, 20)
        y = 0.02 * 7 * np.arange(20) + rng.normal(0, s_i)
        hits += bool(an.steps(series(y, s_i)))
    assert hits <= 8


@pytest.mark.parametrize("at,size", [(11, 3.0), (5, -2.0), (19, 6.0)])
def test_a_planted_step_is_found_with_its_size(at, size):
    rng = np.random.default_rng(at)
    s_i = np.full(20, 0.3)
    y = 0.01 * 7 * np.arange(20) + np.where(np.arange(20) >= at, size, 0) + rng.normal(0, s_i)
    st = an.steps(series(y, s_i))
    assert [e["index"] for e in st] == [at]
    assert abs(st[0]["change"] - size) < 3 * st[0]["std"]


def test_forecast_date_and_band():
    rng = np.random.default_rng(6)
    s_i = np.full(10, 0.2)
    t = 7.0 * np.arange(10)
    y = 2.0 + 0.1 * t + rng.normal(0, s_i)
    s = series(y, s_i)
    tr = an.trend(s)
    f = an.forecast(tr, 20.0)
    exact = tr.t0 + (20.0 - tr.a) / tr.b
    assert f["date"] == an.date_of(exact)
    # the interval: the days whose 95 % band holds the limit (scanned by brute force)
    tau = np.arange(0.0, 400.0, 0.01)
    value = tr.a + tr.b * tau
    u = np.sqrt(tr.cov[0, 0] + 2 * tau * tr.cov[0, 1] + tau ** 2 * tr.cov[1, 1])
    inside = tr.t0 + tau[np.abs(value - 20.0) <= an._quantile(tr) * u]
    assert f["interval"] == [an.date_of(inside.min()), an.date_of(inside.max())]
    # moving away from the tolerance: no date
    away = an.forecast(an.trend(series(-y, s_i)), 1e3)
    assert away["date"] is not None      # -y falls towards -1e3: it is reached, far out
    flat = an.forecast(an.trend(series(1.0 + 0.2 * (-1.0) ** np.arange(10), s_i)), 50.0)
    assert None in flat["interval"]     # a slope not significant: one end open


def test_a_drift_that_starts_later_is_no_event():
    """Flat for 8 weeks, then 0.5 per week: a change of slope (no step, no event), and the
    trend from where the drift starts."""
    hits, slopes = 0, []
    rng = np.random.default_rng(8)
    for _ in range(40):
        w = np.arange(20)
        y = np.where(w >= 8, 0.5 * (w - 8), 0.0) + rng.normal(0, 0.2, 20)
        s = series(y, np.full(20, 0.2))
        ch = an.changes(s)
        hits += bool(an.steps(s))
        tr = an.trend(s, ch[-1]["index"] if ch else 0)
        slopes.append(tr.b * 7)
        if ch and ch[-1]["kind"] == an.SLOPE:
            assert abs(ch[-1]["index"] - 8) <= 1
    assert hits <= 1
    assert abs(np.mean(slopes) - 0.5) < 0.02
