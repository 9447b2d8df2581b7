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

Computation: the columns scaled by ``1/sqrt(w)``; per fold their Gram matrix and per-run
sums (taken from the drift engine's cross-products of the folds: no pass over the readings);
a fit's Gram matrix is the sum over its folds, centred per run (the free zeros,
Frisch-Waugh), decomposed once (``eigh``); every lambda is then a diagonal solve, and a
fold's squared error for every lambda follows from its cross-products.  None of it depends
on the channel: it is shared (``cache``).
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


def _blocks(Zs, run, n_runs, fold, grams=None, keep=None, scale=None) -> list:
    """Per fold k: (Gram matrix, per-run sums (n_runs, p), per-run counts) of ``Zs`` over the
    fold's readings: every fit's cross-products are sums of these.  ``grams``: the folds'
    cross-products ``Z_k' Z_k`` of the whole design ``Z`` (run indicators first; the drift
    engine's, :class:`volerr.loop.drift.engine.Engine`), from which these follow by the
    columns ``keep`` and their ``scale`` without a pass over the readings."""
    out = []
    for k in range(int(fold.max()) + 1):
        if grams is not None:
            g = grams[k]
            out.append((g[np.ix_(keep, keep)] * np.outer(scale, scale),
                        g[:n_runs][:, keep] * scale, np.diag(g)[:n_runs].copy()))
            continue
        m = fold == k
        Zk, rk = Zs[m], run[m]
        sums = np.array([Zk[rk == r].sum(axis=0) for r in range(n_runs)])
        out.append((Zk.T @ Zk, sums, np.bincount(rk, minlength=n_runs).astype(float)))
    return out


def _decompose(blocks, leave):
    """Per-run means (n_runs, p) over the folds but ``leave`` (-1: none), their counts, and
    the eigen-decomposition (e, V) of the Gram matrix centred per run (the free zeros)."""
    parts = [b for k, b in enumerate(blocks) if k != leave]
    G = sum(b[0] for b in parts)
    sums, cnt = sum(b[1] for b in parts), sum(b[2] for b in parts)
    mu = sums / np.maximum(cnt, 1.0)[:, None]
    e, V = np.linalg.eigh(G - (sums.T * (1.0 / np.maximum(cnt, 1.0))) @ sums)
    return mu, cnt, np.clip(e, 0.0, None), V


def _centres(parts, block, anchored):
    """The held-out fold's Gram matrix of ``Zs - m[run]`` (m the fit's run means, or 0 where
    the fold is predicted from each run's first reading) and ``m``."""
    mu, cnt = parts[0], parts[1]
    G, S, n = block
    m = np.zeros_like(mu) if anchored else np.where(cnt[:, None] > 0, mu, 0.0)
    return G - S.T @ m - m.T @ S + (m.T * n) @ m, m


def fit(s, y, Z, keep, cols, fold, rule: str, cache: dict, grams=None) -> dict:
    """The regularised fit of one channel ``y`` (N,) um on the bank ``Z[:, keep]`` (unit-RMS
    columns ``cols``), judged on the blocked ``fold`` (rule ``rule``); ``grams`` the folds'
    ``Z_k' Z_k`` if known (:func:`_blocks`).  Returns {"pred" (N,) every reading by the fit
    on all training readings, "cv_resid" (N,) NaN off training, "lambda_rel", "edf"
    (effective number of coefficients, ``sum e/(e + lambda)``), "n_columns", "penalty"}."""
    n_runs, run, tr = len(s.runs), s.run, s.train
    K, anchored = int(fold.max()) + 1, basis.whole_runs(rule)
    if "shrink_eig" not in cache:
        cache["shrink_scale"] = scale = 1.0 / np.sqrt(weights(cols, fold_time(s, fold)))
        blocks = _blocks(None if grams is not None else Z[:, keep] * scale, run, n_runs,
                         fold, grams, keep, scale)
        cache["shrink_eig"] = eig = [_decompose(blocks, k) for k in range(-1, K)]
        cache["shrink_test"] = [(blocks[k],) + _centres(eig[k + 1], blocks[k], anchored)
                                for k in range(K)]
    scale, eig = cache["shrink_scale"], cache["shrink_eig"]
    idx = [np.flatnonzero(fold == k) for k in range(K)]
    zy = [(_rows(Z, i).T @ y[i])[keep] * scale for i in idx]       # Zs' y over each fold
    ys = [np.bincount(run[i], y[i], n_runs) for i in idx]
    lams = LAMBDAS * float(tr.sum())
    first = s.run_zeros(y)
    sse = np.zeros(len(lams))
    for k in range(K):           # the fold's SSE for every lambda from cross-products
        mu, cnt, e, V = eig[k + 1]
        (_, S, n), Gt, m = cache["shrink_test"][k]
        ysum = sum(ys[j] for j in range(K) if j != k)
        B = V @ ((V.T @ (sum(zy[j] for j in range(K) if j != k) - mu.T @ ysum))[:, None]
                 / (e[:, None] + lams[None, :]))
        c = first if anchored else np.where(cnt > 0, ysum / np.maximum(cnt, 1.0), first)
        h = zy[k] - S.T @ c - m.T @ ys[k] + m.T @ (n * c)
        yy = float(y[idx[k]] @ y[idx[k]]) - 2 * c @ ys[k] + n @ c ** 2
        sse += yy - 2 * B.T @ h + np.einsum("il,il->l", B, Gt @ B)
    i = len(lams) - 1                       # from the most shrunk: a tie keeps the larger
    for j in range(len(lams) - 2, -1, -1):
        if sse[j] < sse[i] * (1 - TIE_SCORE_REL):
            i = j
    bank = (Z, keep, scale)
    resid = np.full(len(y), np.nan)
    for k in range(K):
        pred = _predict(eig[k + 1], sum(zy[j] for j in range(K) if j != k),
                        sum(ys[j] for j in range(K) if j != k), bank, run, anchored, first,
                        lams[i], idx[k])
        resid[idx[k]] = y[idx[k]] - pred
    pred = _predict(eig[0], sum(zy), sum(ys), bank, run, False, first, lams[i],
                    np.arange(len(y)))
    e = eig[0][2]
    return {"pred": pred, "cv_resid": resid, "lambda_rel": float(LAMBDAS[i]),
            "edf": float(np.sum(e / (e + lams[i]))), "n_columns": len(keep),
            "penalty": "ridge, weights (1 + tau/T)^2, T = a fold's share of the training "
                       "time; lambda of least blocked-CV mean square"}


def _rows(Z, i):
    """``Z[i]`` for sorted row indices ``i``: a view where they are contiguous (a fold of
    stretches in one run), no copy of the design."""
    return Z[i[0]:i[-1] + 1] if len(i) and i[-1] - i[0] + 1 == len(i) else Z[i]


def _predict(parts, zy, ysum, bank, run, anchored, first, lam, rows):
    """Predictions of the readings ``rows`` (sorted indices) by the fit whose cross-products
    are ``parts`` (:func:`_decompose`), ``zy`` (``Zs' y`` over its readings) and ``ysum``
    (per-run sums of ``y`` there) at ``lam``; ``bank`` (Z, keep, scale): ``Zs = Z[:, keep]
    scale``; ``anchored``: from each run's first reading, else from the run's fitted zero (a
    run without fitting readings: its first reading)."""
    mu, cnt, e, V = parts
    Z, keep, scale = bank
    b = V @ ((V.T @ (zy - mu.T @ ysum)) / (e + lam))
    full = np.zeros(Z.shape[1])
    full[keep] = b * scale
    terms = _rows(Z, rows) @ full
    if anchored:
        return first[run[rows]] + terms
    zero = np.where(cnt > 0, ysum / np.maximum(cnt, 1.0) - mu @ b, first)
    return zero[run[rows]] + terms
