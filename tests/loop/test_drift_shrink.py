"""The regularised fit over the lag bank, the drift loop's fourth candidate family (issue 44,
:mod:`volerr.loop.drift.shrink`), on small series built here (a few seconds in all):

* its blocked-CV residuals are those of the penalised least squares refitted without each
  fold, computed here by ``numpy.linalg.lstsq`` on the design augmented with the penalty's
  rows ``sqrt(lambda w_j)`` (the run zeros unpenalised), with the weights
  ``(1 + tau/T)^2`` and ``T`` (training time over the folds) computed here; its lambda is the
  grid's least CV mean square recomputed here; its prediction is the refit on all training
  readings; for folds of stretches (one run) and of whole runs (four runs, the last held
  out, each predicted from its first reading);
* the rule of :func:`volerr.loop.drift.family.choose` with the fourth candidate: a
  regularised fit significantly below everything is the model (the lag model's terms still
  named when the lag model beats both baselines), one far worse leaves the lag model, one
  equal to the constant is not a model; on a channel of noise it names no effect.
"""

from __future__ import annotations

import numpy as np
import pytest

from volerr.loop.drift import basis, family, shrink
from volerr.loop.drift import fit as core
from volerr.loop.drift.series import DriftSeries

DT = 120.0


def _lag(u, tau):
    """Implicit-Euler first-order lag at rest at the start (the tests' own)."""
    y = np.zeros_like(u)
    a = DT / (tau + DT)
    for i in range(1, len(u)):
        y[i] = y[i - 1] + a * (u[i] - y[i - 1])
    return y


def _series(n_runs: int, channel: str = "lag", seed: int = 5) -> DriftSeries:
    rng = np.random.default_rng(seed)
    t1 = np.arange(0.0, 12 * 3600.0 if n_runs == 1 else 6 * 3600.0, DT)
    t, run, S, Ta, Tw = [], [], [], [], []
    for r in range(n_runs):
        on = ((t1 // (3600.0 + 900 * r)) % 2 == 1) * (1.0 + (t1 // 7200.0) % 2)
        t.append(t1)
        run.append(np.full(len(t1), r))
        S.append(1500.0 * on)
        Ta.append(20.0 + 4.0 * _lag(on, 900.0) + rng.normal(0, 0.01, len(t1)))
        Tw.append(20.0 + np.cumsum(rng.normal(0, 0.02, len(t1))))
    cat = np.concatenate
    S = cat(S)
    noise = rng.normal(0, 0.2, len(S))
    heat = cat([_lag(s / S.max(), 2500.0) for s in np.split(S, n_runs)])
    y = {"lag": 8.0 * heat + noise, "noise": 1.0 + noise}[channel]
    s = DriftSeries(t_s=cat(t), run=cat(run), runs=[(f"r{r}.csv", "") for r in range(n_runs)],
                    inputs={"S_rpm": S, "T_a": cat(Ta), "T_w": cat(Tw)}, channels={"x": y},
                    directions={"x": "?"}, heights={"x": None})
    if n_runs == 1:
        s.test = s.t_s >= 0.8 * s.t_s[-1]
    else:
        s.test = s.run == n_runs - 1
    return s


def _bank(s):
    cols, X = basis.library(s)
    fold, rule = basis.folds(s)
    heat_c, sensor_c = core._candidates(s, cols, False)
    keep = sorted({int(a) for c in (heat_c, sensor_c) for a, _ in c})
    return [cols[j] for j in keep], X[:, keep], fold, rule


def _penalised(D, y, n_free, pen, lam):
    """Least squares of ``y`` on ``D`` plus the rows ``sqrt(lam pen_j)`` for the columns after
    the first ``n_free`` (unpenalised): the ridge solution by an independent route."""
    p = D.shape[1] - n_free
    A = np.vstack([D, np.column_stack([np.zeros((p, n_free)), np.diag(np.sqrt(lam * pen))])])
    b = np.linalg.lstsq(A, np.concatenate([y, np.zeros(p)]), rcond=None)[0]
    return b


def _independent(s, cols, X, fold, rule, lam_rel):
    """(CV residuals (N,), prediction (N,)) at ``lam_rel`` computed here."""
    y, tr = s.channels["x"], s.train
    K = int(fold.max()) + 1
    spans = [np.ptp(s.t_s[tr & (s.run == r)]) for r in range(len(s.runs))
             if np.any(tr & (s.run == r))]
    T = sum(spans) / K
    pen = np.array([(1 + c.tau_s / T) ** 2 for c in cols])
    R = s.indicators()
    D = np.column_stack([R, X])
    lam = lam_rel * tr.sum()
    n_runs = R.shape[1]
    first = y[s.firsts()]
    r = np.full(len(y), np.nan)
    for k in range(K):
        fit_, m = tr & (fold != k), fold == k
        keep = np.r_[R[fit_].any(axis=0), np.ones(X.shape[1], bool)]   # zeros of fitted runs
        b = np.zeros(D.shape[1])
        b[keep] = _penalised(D[fit_][:, keep], y[fit_], int(keep[:n_runs].sum()), pen, lam)
        if basis.whole_runs(rule):
            r[m] = y[m] - (first[s.run[m]] + X[m] @ b[n_runs:])
        else:
            r[m] = y[m] - D[m] @ b
    keep = np.r_[R[tr].any(axis=0), np.ones(X.shape[1], bool)]
    b = np.zeros(D.shape[1])
    b[keep] = _penalised(D[tr][:, keep], y[tr], int(keep[:n_runs].sum()), pen, lam)
    zeros = np.where(R[tr].any(axis=0), b[:n_runs], first)
    return r, zeros[s.run] + X @ b[n_runs:]


@pytest.mark.parametrize("n_runs,rule", [(1, "stretches"), (4, "runs")])
def test_the_regularised_fit_is_the_penalised_least_squares(n_runs, rule):
    s = _series(n_runs)
    cols, X, fold, got_rule = _bank(s)
    assert got_rule == rule
    res = shrink.fit(s, s.channels["x"], X, list(range(X.shape[1])), cols, fold, rule, {})
    tr = s.train
    # the lambda: the grid's least CV mean square, recomputed here for every grid value
    mse = [np.mean(_independent(s, cols, X, fold, rule, lr)[0][tr] ** 2)
           for lr in shrink.LAMBDAS]
    assert res["lambda_rel"] == shrink.LAMBDAS[int(np.argmin(mse))]
    r, pred = _independent(s, cols, X, fold, rule, res["lambda_rel"])
    scale = float(np.std(s.channels["x"]))
    np.testing.assert_allclose(res["cv_resid"][tr], r[tr], atol=1e-6 * scale)
    assert np.isnan(res["cv_resid"][s.test]).all()
    np.testing.assert_allclose(res["pred"], pred, atol=1e-6 * scale)
    assert 0 < res["edf"] < res["n_columns"] == X.shape[1]


def test_long_lags_are_shrunk_more():
    s = _series(1)
    cols, X, fold, rule = _bank(s)
    T = shrink.fold_time(s, fold)
    assert T == pytest.approx(np.ptp(s.t_s[s.train]) / 6)
    w = shrink.weights(cols, T)
    for c, v in zip(cols, w):
        assert v == pytest.approx((1 + c.tau_s / T) ** 2)
    assert w.min() == 1.0                      # a plain column: the plain ridge's weight


def _choice(channel, scale_of):
    """family.choose on a one-run series with the regularised CV residuals ``scale_of(r)``
    of the lag model's (``r``) or of the constant's."""
    s = _series(1, channel)
    cols, X, fold, rule = _bank(s)
    ch = core.Channel(s, s.channels["x"], s.indicators(), fold, rule)
    heat = [j for j, c in enumerate(cols) if c.p == 1.0 and 2000 < c.tau_s < 3500][0]
    D_lag = np.column_stack([ch.R, X[:, heat]])
    resid = {"lag": family.cv_residuals(ch, D_lag), "constant": family.cv_residuals(ch, ch.R)}
    designs = {"constant": ch.R, "static": core._static_design(ch), "lag": D_lag}
    return family.choose(ch, designs, True, regularised=scale_of(resid))


def test_the_rule_with_the_regularised_fit():
    half = _choice("lag", lambda r: 0.5 * r["lag"])    # far below everything
    assert half["family"] == "regularised" and half["named"]
    assert half["t"]["lag_vs_regularised"] < half["t_crit"]
    v = family.verdict("regularised", half["cv_rms_um"], half["t"], True, half["t_crit"],
                       named=True)
    assert "not the regularised fit" in v and "named" in v
    worse = _choice("lag", lambda r: 3.0 * r["lag"])   # far above the lag model
    assert worse["family"] == "lag" and worse["named"]
    same = _choice("lag", lambda r: r["constant"])     # no better than the constant
    assert same["family"] == "lag"
    noise = _choice("noise", lambda r: 0.5 * r["constant"])
    assert noise["family"] == "regularised" and not noise["named"]
    v = family.verdict("regularised", noise["cv_rms_um"], noise["t"], True, noise["t_crit"],
                       named=False)
    assert "names no effect" in v


def test_the_folds_cross_products_of_the_whole_design_give_the_same_fit():
    """The loop passes the drift engine's ``Z_k' Z_k`` of every fold (run indicators and the
    whole library); the fit from them equals the one from the columns themselves."""
    s = _series(1)
    cols, X, fold, rule = _bank(s)
    Z = np.column_stack([s.indicators(), X])
    keep = list(range(1, Z.shape[1]))
    grams = [Z[fold == k].T @ Z[fold == k] for k in range(int(fold.max()) + 1)]
    a = shrink.fit(s, s.channels["x"], Z, keep, cols, fold, rule, {})
    b = shrink.fit(s, s.channels["x"], Z, keep, cols, fold, rule, {}, grams)
    assert a["lambda_rel"] == b["lambda_rel"]
    np.testing.assert_allclose(a["pred"], b["pred"], atol=1e-8)
    np.testing.assert_allclose(a["cv_resid"], b["cv_resid"], atol=1e-8)
