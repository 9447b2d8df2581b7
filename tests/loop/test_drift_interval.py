"""The drift loop's prediction interval (issue 44 item 4, :mod:`volerr.loop.drift.interval`)
on small synthetic data, every expected value computed here another way:

* the leverage of a reading is the hat value of the least-squares fit with an intercept per
  run (``A (A'A)^-1 A'`` of the augmented design, numpy's inverse), 1 + ``x'(Xc'Xc)^-1 x``
  where the reading is predicted from its run's first reading, and with a ridge penalty the
  Bayesian form ``a' (A'A + P)^-1 a`` (the zero unpenalised);
* the regularised fit's leverage from its eigen-decompositions per fold equals the direct
  formula with the penalty ``lambda W`` on the unscaled columns;
* the half-width at a reading is ``q sqrt(1 + c h)``, ``c`` from the lag-1 autocorrelation
  and ``q`` the Student prediction bound of the folds' log quantiles (scipy's t);
* where the folds' quantiles are log-normal, the bound exceeds one more fold's quantile in
  95 % of many draws (the largest of six in 6/7 of them).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from volerr.loop.drift import basis, shrink
from volerr.loop.drift import fit as core
from volerr.loop.drift import interval as band
from volerr.loop.drift.series import DriftSeries


def _runs(seed=1, n=60, p=3, n_runs=2):
    rng = np.random.default_rng(seed)
    run = np.repeat(np.arange(n_runs), n // n_runs)
    X = rng.normal(size=(len(run), p)) + run[:, None]
    return X, run, rng


def test_leverage_is_the_hat_value_with_a_zero_per_run():
    X, run, _ = _runs()
    fit = np.arange(len(run)) % 5 != 0              # every 5th reading not fitted
    A = np.column_stack([run == 0, run == 1, X]).astype(float)
    inv = np.linalg.inv(A[fit].T @ A[fit])
    want = np.einsum("ij,jk,ik->i", A, inv, A)      # hat values, fitted or not
    got = band.leverage(X, run, fit, np.ones(len(run), bool), anchored=False)
    np.testing.assert_allclose(got, want, rtol=1e-10)


def test_leverage_from_the_first_reading_and_of_an_unseen_run():
    X, run, _ = _runs()
    fit = run == 0
    Xf = X[fit]
    Xc = Xf - Xf.mean(0)
    inv = np.linalg.inv(Xc.T @ Xc)
    want = 1.0 + np.einsum("ij,jk,ik->i", X, inv, X)
    # anchored: every reading from its run's first reading; run 1 has no fitting reading
    np.testing.assert_allclose(band.leverage(X, run, fit, run >= 0, anchored=True), want,
                               rtol=1e-10)
    unseen = run == 1
    np.testing.assert_allclose(band.leverage(X, run, fit, unseen, anchored=False),
                               want[unseen], rtol=1e-10)


def test_leverage_with_a_ridge_penalty_is_the_bayesian_form():
    X, run, _ = _runs(n_runs=1)
    fit = np.ones(len(run), bool)
    P = np.diag([0.5, 2.0, 8.0])
    A = np.column_stack([np.ones(len(run)), X])
    Pa = np.zeros((4, 4))
    Pa[1:, 1:] = P                                  # the zero is not penalised
    inv = np.linalg.inv(A.T @ A + Pa)
    x0 = np.array([[1.0, 4.0, -3.0, 5.0]])          # far outside the readings
    X0 = np.vstack([X, x0[:, 1:]])
    run0 = np.zeros(len(X0), int)
    fit0 = np.append(fit, False)
    rows = np.zeros(len(X0), bool)
    rows[-1] = True
    got = band.leverage(X0, run0, fit0, rows, anchored=False, penalty=P)
    want = (x0 @ inv @ x0.T).item()
    assert got[0] == pytest.approx(want, rel=1e-9)
    assert got[0] > 10 * np.median(band.leverage(X, run, fit, fit, False, penalty=P))


def _series(seed=5):
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 12 * 3600.0, 60.0)
    S = 1500.0 * ((t // 5400.0) % 2)
    def lag(tau):                                   # implicit Euler, at rest at the start
        out = np.zeros_like(t)
        for i in range(1, len(t)):
            out[i] = out[i - 1] + 60.0 / (tau + 60.0) * (S[i] / 1500.0 - out[i - 1])
        return out

    T_a = 20.0 + 3.0 * lag(300.0) + rng.normal(0, 0.01, len(t))   # a fast sensor
    y = 8.0 * lag(2400.0) + rng.normal(0, 0.2, len(t))            # a slow heat lag
    s = DriftSeries(t_s=t, run=np.zeros(len(t), int), runs=[("sim.csv", "")],
                    inputs={"S_rpm": S, "T_a": T_a}, channels={"x": y},
                    directions={"x": "?"}, heights={"x": None})
    s.test = t >= 0.8 * t[-1]
    return s


def test_regularised_leverage_from_the_decompositions_is_the_direct_formula():
    s = _series()
    out = core.run_drift(s)["channels"]["x"]
    assert out["choice"]["family"] in ("lag", "regularised")   # the bank's leverage
    cols, X = basis.library(s)
    fold, rule = basis.folds(s)
    keep = out["shrink"]["keep"]
    n_runs = len(s.runs)
    Z = np.column_stack([s.indicators(), X])[:, keep]
    w = shrink.weights([cols[j - n_runs] for j in keep], shrink.fold_time(s, fold))
    lam = out["shrink"]["lambda_rel"] * float(s.train.sum())
    # shrink penalises lambda on the columns scaled by 1/sqrt(w): lambda w on these
    want = band.cv_leverage(Z, s.run, fold, s.train, basis.whole_runs(rule),
                            penalty=np.diag(lam * w))
    np.testing.assert_allclose(out["leverage"], want, rtol=1e-6, atol=1e-12)


def test_the_half_width_is_q_times_the_scale():
    rng = np.random.default_rng(7)
    K, n = 6, 200
    fold = np.repeat(np.arange(K), n)
    e = np.zeros(K * n)
    for k in range(K):                              # AR(1) residuals, levels per fold
        m = fold == k
        a = rng.normal(0, 1 + k, n)
        for i in range(1, n):
            a[i] += 0.8 * a[i - 1]
        e[m] = a
    fold = np.concatenate([fold, -np.ones(100, int)])
    cv = np.concatenate([e, np.full(100, np.nan)])
    lev = np.concatenate([rng.uniform(0.0, 0.05, K * n), np.linspace(0.0, 0.5, 100)])
    y = rng.normal(0, 3, len(fold))
    pred = np.zeros(len(fold))
    test = fold < 0
    iv = band.interval(cv, y, pred, fold, test, lev)
    # expected, computed here: rho pooled within folds, c, the scores, the bound
    num = sum(float(e[fold[:K * n] == k][:-1] @ e[fold[:K * n] == k][1:]) for k in range(K))
    rho = num / float(e @ e)
    c = (1 + rho) / (1 - rho)
    sig = np.sqrt(1 + c * lev)
    ln = np.log([np.quantile(np.abs(e[fold[:K * n] == k]) / sig[:K * n][fold[:K * n] == k],
                             0.95) for k in range(K)])
    q = np.exp(ln.mean() + stats.t.ppf(0.95, K - 1) * ln.std(ddof=1) * np.sqrt(1 + 1 / K))
    assert iv["rho"] == pytest.approx(rho, abs=1e-6)
    assert iv["q"] == pytest.approx(q, rel=1e-3)          # t95 is tabled to 3 decimals
    hw = iv["per_reading"]
    np.testing.assert_allclose(hw, iv["q"] * sig, rtol=1e-5)
    assert hw[test][-1] > hw[test][0] * 1.5                # wider where the leverage grows
    assert iv["half_width_um"] == pytest.approx(np.median(hw[test]))
    assert iv["coverage_test"] == pytest.approx(np.mean(np.abs(y[test]) <= hw[test]))


def test_the_bound_covers_one_more_fold_at_its_level():
    rng = np.random.default_rng(44)
    draws = np.exp(rng.normal(0.3, 0.8, size=(4000, 7)))  # 6 folds' quantiles + one more
    bound = np.array([band.one_more_fold(d[:6]) for d in draws])
    assert np.mean(draws[:, 6] <= bound) == pytest.approx(0.95, abs=0.012)
    # the rule before, the largest of six: 6/7 of them
    assert np.mean(draws[:, 6] <= draws[:, :6].max(1)) == pytest.approx(6 / 7, abs=0.015)


def test_one_fold_or_a_zero_quantile():
    assert band.one_more_fold([2.0]) == 2.0
    assert band.one_more_fold([0.0, 3.0]) == 3.0
    assert np.isnan(band.one_more_fold([]))


def test_thinned_readings_interpolated_within_each_run(monkeypatch):
    monkeypatch.setattr(band, "EVALUATED", 10)
    run = np.repeat([0, 1, 2], [17, 40, 23])
    rows = np.flatnonzero(run != 1)                  # a fit's readings: runs 0 and 2
    sub = band._thinned(rows, run)
    assert len(sub) < len(rows)
    for r in (0, 2):                                 # each run's first and last evaluated
        pos = np.flatnonzero(run[rows] == r)
        assert pos[0] in sub and pos[-1] in sub
    h = 0.5 + 0.01 * rows + 3.0 * (run[rows] == 2)   # linear within a run, a jump between
    np.testing.assert_allclose(band._filled(rows, sub, h[sub], run), h, rtol=1e-12)
