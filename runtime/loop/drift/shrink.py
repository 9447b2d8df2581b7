"""The regularised fit over the lag bank: a candidate family of the drift loop's selection
(:mod:`volerr.loop.drift.family`), beside the constant, the static regression and the sparse
lag model.

Every column the forward selection may take (:func:`volerr.loop.drift.fit._candidates`: each
sensor plain and through its lags, the heat input ``lag((S/S_ref)^p, tau)`` at every exponent
and lag; unit RMS over the training readings) enters at once, with a zero per run left
free, and the coefficients are shrunk (ridge regression, Hoerl & Kennard 1970; ESL 2nd ed.
3.4.1) by the penalty ``lambda sum_j w_j b_j^2`` with

    w_j = (1 + tau_j / T)^2,

``tau_j`` the column's time constant (0 for a plain column) and ``T`` a fold's share of the
training time (the training time of every run summed, over the number of blocked folds).
Why the weight: a term whose lag is longer than the stretch a fold holds out carries a
*level* across that stretch, and a level is what the sparse lag model got wrong where it lost
to the baselines on FL_THERMAL (issue 44: 40-60 % ch5, 80-100 % ch2, the held-out error
almost all bias); the longer a term's lag against the stretch, the less the blocked folds
can tell its level from the run's zero, so the more it is shrunk (a prior standard deviation
of its coefficient ``1 / (1 + tau/T)`` of a plain column's).

``lambda`` (relative to the training readings' count, on the grid ``LAMBDAS``) is the one
of least cross-validated mean square over the SAME blocked folds as the other families
(:func:`volerr.loop.drift.basis.folds`: a fold of stretches predicted from the run's zero
fitted on the other stretches, a fold of whole runs from the run's first reading); a tie
(``TIE_SCORE_REL``) goes to the larger lambda (the more shrunk).  One number is chosen on the
folds, where the sparse model chooses its terms, exponent and time constants on them: its
CV residuals are nearly those of a model fitted without the fold, the sparse model's are
optimistic.  The fit names no effect (hundreds of shrunk coefficients): where it is the
channel's model the report says so and lists no term.

Computation: per fold the columns (scaled by ``1/sqrt(w)``) are centred per run over the
fitting readings (the free zeros, Frisch-Waugh) and the Gram matrix decomposed once
(``eigh``); every lambda is then a diagonal solve.  The decompositions do not depend on the
channel and are shared (``cache``).
"""

from __future__ import annotations

import numpy as np

from ...selection.rules import TIE_SCORE_REL
from . import basis

#: lambda / (training readings) tried, quarter decades
LAMBDAS = np.geomspace(1e-7, 1e1, 33)
NAME = "the regularised fit over the lag bank"


def weights(cols, T: float) -> np.ndarray:
    """The penalty weights ``(1 + tau / T)^2`` of the columns ``cols`` (module docstring)."""
    return np.array([(1.0 + c.tau_s / T) ** 2 for c in cols])


def fold_time(s, fold) -> float:
    """``T`` (s): the training time of every run summed, over the number of folds."""
    tr = s.train
    span = sum(float(np.ptp(s.t_s[tr & (s.run == r)])) for r in range(len(s.runs))
               if np.any(tr & (s.run == r)))
    return max(span, 1.0) / (int(fold.max()) + 1)


def _decompose(Zs, run, n_runs, fit):
    """Per-run means (n_runs, p) of ``Zs`` over the readings ``fit``, their counts, and the
    eigen-decomposition (e, V) of the centred Gram matrix."""
    mu, cnt = np.zeros((n_runs, Zs.shape[1])), np.zeros(n_runs)
    for r in range(n_runs):
        m = fit & (run == r)
        cnt[r] = m.sum()
        if cnt[r]:
            mu[r] = Zs[m].mean(axis=0)
    Zc = Zs[fit] - mu[run[fit]]
    e, V = np.linalg.eigh(Zc.T @ Zc)
    return mu, cnt, np.clip(e, 0.0, None), V


def _path(parts, Zs, y, run, fit, rows, anchored, first, lams):
    """Predictions (len(rows), L) of the readings ``rows`` by the fits on ``fit`` for every
    lambda of ``lams`` (absolute); ``anchored``: from each run's first reading, else from
    the run's zero fitted on ``fit`` (a run without fitting readings: its first reading)."""
    mu, cnt, e, V = parts
    ybar = np.array([y[fit & (run == r)].mean() if c else 0.0 for r, c in enumerate(cnt)])
    g = V.T @ (Zs[fit].T @ y[fit] - mu.T @ (cnt * ybar))
    B = V @ (g[:, None] / (e[:, None] + lams[None, :]))          # (p, L) coefficients
    rr = run[rows]
    if anchored:
        return first[rr][:, None] + Zs[rows] @ B, B
    zero = ybar[:, None] - mu @ B
    zero[cnt == 0] = first[cnt == 0][:, None]
    return zero[rr] + Zs[rows] @ B, B


def fit(s, y, X, cols, fold, rule: str, cache: dict) -> dict:
    """The regularised fit of one channel ``y`` (N,) um on the bank ``X`` (N, p) (unit-RMS
    columns ``cols``), judged on the blocked ``fold`` (rule ``rule``).  Returns {"pred" (N,)
    every reading by the fit on all training readings, "cv_resid" (N,) NaN off training,
    "lambda_rel", "edf" (effective number of coefficients, ``sum e/(e + lambda)``),
    "n_columns", "penalty"}."""
    n_runs, run, tr = len(s.runs), s.run, s.train
    if "shrink_Z" not in cache:
        cache["shrink_Z"] = X / np.sqrt(weights(cols, fold_time(s, fold)))
    Zs = cache["shrink_Z"]
    lams = LAMBDAS * float(tr.sum())
    first = y[s.firsts()]
    anchored = basis.whole_runs(rule)
    resid = np.full((len(y), len(lams)), np.nan)
    for k in range(int(fold.max()) + 1):
        rows, fit_ = fold == k, tr & (fold != k) & (fold >= 0)
        if ("shrink", k) not in cache:
            cache[("shrink", k)] = _decompose(Zs, run, n_runs, fit_)
        pred, _ = _path(cache[("shrink", k)], Zs, y, run, fit_, rows, anchored, first, lams)
        resid[rows] = y[rows][:, None] - pred
    mse = np.mean(resid[tr] ** 2, axis=0)
    i = len(lams) - 1                       # from the most shrunk: a tie keeps the larger
    for j in range(len(lams) - 2, -1, -1):
        if mse[j] < mse[i] * (1 - TIE_SCORE_REL):
            i = j
    if "shrink_all" not in cache:
        cache["shrink_all"] = _decompose(Zs, run, n_runs, tr)
    parts = cache["shrink_all"]
    everything = np.ones(len(y), bool)
    pred, _ = _path(parts, Zs, y, run, tr, everything, False, first, lams[i:i + 1])
    e = parts[2]
    return {"pred": pred[:, 0], "cv_resid": resid[:, i], "lambda_rel": float(LAMBDAS[i]),
            "edf": float(np.sum(e / (e + lams[i]))), "n_columns": int(X.shape[1]),
            "penalty": "ridge, weights (1 + tau/T)^2, T = a fold's share of the training "
                       "time; lambda of least blocked-CV mean square"}
