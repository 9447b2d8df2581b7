"""The prediction interval of a drift channel's model: locally weighted (normalised) conformal
from the blocked cross-validation, widening where the model extrapolates, its level the
stated one for a held-out part that is one more draw of a fold.

The score of a training reading i is its blocked-CV residual over its scale,
``|r_i| / sigma_i``, with

    sigma_i^2 = 1 + c h_i,

``h_i`` the reading's leverage under the fit that predicts it (for a CV reading the fit
without its fold, for a held-out reading the fit on all training readings); the half-width
at a reading is ``q sigma_i`` (um): a band that widens where the inputs leave what the fit
has seen (Lei, G'Sell, Rinaldo, Tibshirani & Wasserman 2018, "Distribution-free predictive
inference for regression", JASA 113, section 5.2; Papadopoulos, Gammerman & Vovk 2008,
normalised nonconformity scores with the prediction's own variance as the scale).

``q``: the held-out part is one stretch never seen, like one more fold, and folds differ
tenfold in their error, so the quantile is judged fold by fold: ``q_k`` the ``LEVEL``
quantile of the scores of fold k, and ``q`` the one-sided ``LEVEL`` upper prediction bound
of one new draw of them, taken as log-normal (positive, spread over a decade):
``q = exp(mean ln q_k + t(0.95, K-1) sd(ln q_k) sqrt(1 + 1/K))`` (the Student prediction
interval of one future observation; Hahn & Meeker 1991, "Statistical Intervals", 4.4).  Why
not the largest ``q_k`` (the rule before): of K exchangeable draws the largest exceeds a new
one with probability K/(K+1) only, 86 % for six folds, below the stated 95 %.

The leverage (dimensionless, a prediction variance over the residual variance):
``h = h0 + (x - m)' (Xc' Xc + P)^-1 (x - m)``, ``x`` the reading's columns, ``Xc`` the
fitting readings' columns less their run's mean ``m`` (the free zero per run), ``P`` the
penalty of the regularised fit (:mod:`volerr.loop.drift.shrink`; 0 for least squares; the
Bayesian form of ridge, whose prior the penalty is, so that a shrunk direction still counts
as uncertain), and ``h0`` the zero's share: ``1 / n_r`` where the run's zero is fitted on
its ``n_r`` readings, 1 where the reading is predicted from its run's first reading (a fold
or a held-out run of whole runs: one reading's noise; then ``m`` = 0, the basis is zero at
the first reading).  The columns: the regularised fit's bank for the regularised fit *and*
for the lag model (its terms were chosen from that bank on the same folds: what it could
have chosen is uncertain where the bank is, and its own few columns would hide it), the
static regression's temperatures, none for the constant.

``c = (1 + rho) / (1 - rho)``, ``rho`` the lag-1 autocorrelation of the channel's CV
residuals within folds (pooled, clipped to [0, ``RHO_MAX``]): readings 15 s apart are not
independent, and for first-order autocorrelated errors and slowly varying inputs the least
squares covariance ``(X'X)^-1`` understates the coefficients' by about that factor (the
effective number of readings ``n (1 - rho) / (1 + rho)``); without it the leverage of
thousands of readings stays near 0 even where the inputs extrapolate.

Where the training runs hold the room and the held-out runs' room moves
(:func:`volerr.loop.drift.basis.room_undecided`), the folds cannot show what the sensors'
reading (absolute change or rise over the room) does there: every held-out reading's
half-width is widened by ``abs(prediction - alternative)``, the alternative being the chosen
family fitted on the sensors' other reading (:func:`widen_for_room`).

Calibration and prediction use the same definition of ``sigma``; the folds are still not
the held-out part (a held-out stretch is one draw of a level, and the lag model's terms were
chosen on all folds): the held-out coverage is reported beside the interval
(``coverage_test``).  Measured on FL_THERMAL's 30 channel-windows (docs/drift_loop.md):
95.9 % of all held-out readings pooled inside it (82 % by the rule before), 3 of 30
channel-windows within 90-98 % (24 above, 3 below: one held-out stretch is one draw).
"""

from __future__ import annotations

import numpy as np

from ...selection.linalg import pinv_sym
from ...selection.rules import t95

LEVEL = 0.95
#: the largest lag-1 autocorrelation taken (c at most 1999)
RHO_MAX = 0.999
METHOD = ("locally weighted conformal from the blocked CV: half-width q sigma(x) at each "
          "reading, sigma^2 = 1 + c h (h the reading's leverage in the fit that predicts it, "
          "c = (1 + rho)/(1 - rho), rho the lag-1 autocorrelation of the CV residuals); q the "
          "one-sided 95 % log-normal prediction bound of one more fold's 95 % quantile of "
          "|CV residual| / sigma from the K folds'")


def leverage(X, run, fit_mask, rows, anchored, penalty=None) -> np.ndarray:
    """The leverage (module docstring) of the readings ``rows`` (bool (N,)) under the fit of
    the term columns ``X`` (N, p) (a free zero per run ``run``) on the readings
    ``fit_mask``; ``anchored``: every reading predicted from its run's first reading; else a
    run without fitting readings is, the others from their fitted zero.  ``penalty``
    (p, p) is added to the centred cross-products before inversion."""
    n_runs = int(run.max()) + 1
    cnt = np.bincount(run[fit_mask], minlength=n_runs).astype(float)
    sums = np.zeros((n_runs, X.shape[1]))
    np.add.at(sums, run[fit_mask], X[fit_mask])
    mu = sums / np.maximum(cnt, 1.0)[:, None]
    Xc = X[fit_mask] - mu[run[fit_mask]]
    gram_inv = _inverse(Xc.T @ Xc + (0.0 if penalty is None else penalty))
    d, h0 = _from_zero(X[rows], run[rows], mu, cnt, not anchored)
    return h0 + np.einsum("ij,jk,ik->i", d, gram_inv, d)


def _from_zero(x, r, mu, cnt, fitted: bool) -> tuple[np.ndarray, np.ndarray]:
    """(the readings' columns ``x`` less their run's zero, the zero's share ``h0``): where
    the zero is fitted (``fitted`` and the run ``r`` has fitting readings) the run's mean
    ``mu`` of its ``cnt`` fitting readings and ``1 / cnt``; else 0 (the basis is zero at the
    run's first reading) and 1."""
    free = (cnt[r] > 0) & fitted
    return (x - np.where(free[:, None], mu[r], 0.0),
            np.where(free, 1.0 / np.maximum(cnt[r], 1.0), 1.0))


def _inverse(G) -> np.ndarray:
    """Pseudo-inverse of the symmetric ``G`` with its columns scaled to unit diagonal (nearly
    collinear temperatures), a zero column left 0."""
    d = np.sqrt(np.clip(np.diag(G), 0.0, None)) if G.size else np.zeros(0)
    on = d > 0
    out = np.zeros_like(G, dtype=float)
    if np.any(on):
        sub = pinv_sym(G[np.ix_(on, on)] / np.outer(d[on], d[on]))
        out[np.ix_(on, on)] = sub / np.outer(d[on], d[on])
    return out


def shrink_leverage(cache, Z, keep, run, fold, anchored, lam) -> np.ndarray:
    """(N,) leverage of every reading under the regularised fit at ``lam`` (absolute, in the
    scaled columns ``Z[:, keep] scale`` of :mod:`volerr.loop.drift.shrink`, whose
    decompositions per fold ``cache`` holds): ``h0 + sum_j (d' v_j)^2 / (e_j + lam)``; the
    projections ``(d' v_j)^2`` are the same for every channel and kept in ``cache``.  At
    most ``EVALUATED`` readings of a fit's are evaluated, evenly spaced in each run with its
    first and last, the others interpolated linearly (the columns are lags of smooth inputs;
    on FL_THERMAL every reading is evaluated)."""
    if "shrink_proj" not in cache:
        scale, eig = cache["shrink_scale"], cache["shrink_eig"]
        proj = []
        for k in range(-1, int(fold.max()) + 1):
            rows = np.flatnonzero(fold == k if k >= 0 else fold < 0)
            sub = _thinned(rows, run)
            mu, cnt, _, V = eig[k + 1]
            d, h0 = _from_zero(Z[rows[sub]][:, keep] * scale, run[rows[sub]], mu, cnt,
                               k < 0 or not anchored)
            proj.append((rows, sub, h0, (d @ V) ** 2))
        cache["shrink_proj"] = proj
    h = np.full(len(run), np.nan)
    for k, (rows, sub, h0, P) in enumerate(cache["shrink_proj"]):
        e = cache["shrink_eig"][k][2]
        h[rows] = _filled(rows, sub, h0 + P @ (1.0 / (e + lam)), run)
    return h


#: the most readings of one fit whose leverage is evaluated (the rest interpolated)
EVALUATED = 2500


def _thinned(rows, run) -> np.ndarray:
    """Positions in ``rows`` (sorted reading indices) evaluated: every reading where they
    are at most ``EVALUATED``, else evenly spaced ones of each run with its first and last."""
    step = -(-len(rows) // EVALUATED)
    if step <= 1:
        return np.arange(len(rows))
    out = []
    for r in np.unique(run[rows]):
        pos = np.flatnonzero(run[rows] == r)
        out.append(np.unique(np.append(pos[::step], pos[-1])))
    return np.concatenate(out)


def _filled(rows, sub, hs, run) -> np.ndarray:
    """The values ``hs`` at the positions ``sub`` of ``rows``, linearly interpolated (by
    reading index, within each run) at every position."""
    if len(sub) == len(rows):
        return hs
    out = np.empty(len(rows))
    for r in np.unique(run[rows]):
        pos = np.flatnonzero(run[rows] == r)
        at = np.isin(sub, pos)
        out[pos] = np.interp(rows[pos], rows[sub[at]], hs[at])
    return out


def cv_leverage(X, run, fold, train, anchored, penalty=None) -> np.ndarray:
    """(N,) leverage of every reading: a training reading of fold k under the fit without
    fold k, every other reading under the fit on all ``train`` readings (NaN: none)."""
    h = np.full(len(run), np.nan)
    for k in range(int(fold.max()) + 1):
        m = fold == k
        h[m] = leverage(X, run, train & ~m, m, anchored, penalty=penalty)
    rest = fold < 0
    h[rest] = leverage(X, run, train, rest, False, penalty=penalty)
    return h


def autocorrelation(r, fold) -> float:
    """Lag-1 autocorrelation of the CV residuals ``r`` within the folds (consecutive readings
    of one fold), pooled: ``sum r_t r_t+1 / sum r_t^2``, clipped to [0, ``RHO_MAX``]."""
    num = den = 0.0
    for k in range(int(fold.max()) + 1):
        e = r[fold == k]
        e = e[np.isfinite(e)]
        if len(e) > 1:
            num += float(e[:-1] @ e[1:])
            den += float(e @ e)
    return float(np.clip(num / den, 0.0, RHO_MAX)) if den > 0 else 0.0


def one_more_fold(qs) -> float:
    """The one-sided ``LEVEL`` upper prediction bound of one more draw of the folds'
    quantiles ``qs`` taken as log-normal (module docstring); fewer than two positive: their
    largest (NaN: none)."""
    qs = np.asarray(qs, float)
    pos = qs[qs > 0]
    if len(pos) < 2:
        return float(qs.max()) if len(qs) else float("nan")
    K, ln = len(pos), np.log(pos)
    return float(np.exp(ln.mean() + t95(K - 1) * ln.std(ddof=1) * np.sqrt(1.0 + 1.0 / K)))


def interval(cv_resid, y, pred, fold, test, lev=None) -> dict:
    """The ``LEVEL`` prediction interval (module docstring) from the CV residuals
    ``cv_resid`` (N,) um and the leverage ``lev`` (N,) (None: 0, the same half-width at
    every reading) of the model predicting ``pred`` (N,) um; ``fold`` (N,) the CV fold of a
    training reading (-1 held out), ``test`` the held-out mask.  Returns {"level",
    "half_width_um" (the median over the held-out readings, else over all), "half_width_um_range"
    [min, max] over the held-out readings, "q", "rho", "coverage_test", "method",
    "per_reading" (N,) um}."""
    lev = np.zeros(len(y)) if lev is None else np.asarray(lev, float)
    rho = autocorrelation(cv_resid, fold)
    c = (1.0 + rho) / (1.0 - rho)
    sigma = np.sqrt(1.0 + c * np.nan_to_num(lev, nan=0.0))
    qs = []
    for k in range(int(fold.max()) + 1):
        z = np.abs(cv_resid[fold == k]) / sigma[fold == k]
        z = z[np.isfinite(z)]
        if len(z):
            qs.append(float(np.quantile(z, LEVEL)))
    q = one_more_fold(qs)
    hw = q * sigma
    e = np.abs((y - pred)[test])
    at = hw[test] if np.any(test) else hw
    return {"level": LEVEL, "half_width_um": float(np.median(at)),
            "half_width_um_range": [float(np.min(at)), float(np.max(at))],
            "q": q, "rho": round(rho, 6),
            "coverage_test": float(np.mean(e <= hw[test])) if len(e) else None,
            "method": METHOD, "per_reading": hw}


def widen_for_room(iv: dict, y, pred, alternative, test, reading: str) -> None:
    """Widen the interval ``iv`` (:func:`interval`, in place) where the training runs hold
    the room (:func:`volerr.loop.drift.basis.room_undecided`): each held-out reading's
    half-width grows by ``abs(pred - alternative)`` (um), the difference of the chosen
    prediction ``pred`` and the chosen family's fit in the sensors' other reading
    ``alternative`` (``reading``: which; None: the same prediction, no widening).  Why
    added, not combined in quadrature: the two readings are two models these data cannot
    tell apart, not two random errors; the band must hold the alternative's too
    (``abs(y - alternative) <= hw`` gives ``abs(y - pred) <= hw + abs(d)``).  A confident
    wrong answer is worse than a wide one.  The prediction stays the chosen model's.  Adds
    ``iv["room_undecided"]`` {"alternative", "same_model" (no alternative: the family's two
    readings are one model), "difference_um" [median, max] over the held-out readings,
    "half_width_um_unwidened", "coverage_test_unwidened"}."""
    d = np.zeros(len(y)) if alternative is None else np.abs(np.asarray(pred) - alternative)
    d = np.where(test, d, 0.0)
    _widened(iv, "room_undecided", {"alternative": reading, "same_model": alternative is None},
             iv["per_reading"] + d, d, y, pred, test)
    if alternative is not None:
        iv["method"] = (METHOD + "; each held-out reading's half-width widened by abs(the "
                        "prediction - the same family in the sensors' other reading of the "
                        "room) (the training holds the room)")


def widen_for_kept_out(iv: dict, y, pred, test, terms: list) -> None:
    """Widen the interval ``iv`` (:func:`interval`, in place, after :func:`widen_for_room`)
    for the inputs kept out of the model (:func:`volerr.loop.drift.basis.kept_out`): their
    coefficients were never determined, what they do on the held-out readings is unmodelled.
    ``terms``: per input {"input", "coef_um_per_unit" b, "u" (its blocked jackknife standard
    uncertainty; b fitted to the chosen family's training residuals), "change" (N,) the
    input's change since its run's zero}.  The input's effect at a held-out reading is
    about ``N(b change, (u change)^2)``, not in the prediction: ``b change`` is an
    uncorrected bias, added to the half-width as it stands, and ``2 u abs(change)`` an
    uncertainty independent of the band's, combined with it in quadrature (the half-width
    ``hw`` becomes ``sum abs(b change) + sqrt(hw^2 + sum (2 u change)^2)``, um; the
    expanded uncertainty plus the magnitude of the uncorrected bias: Phillips, Eberhardt &
    Parry 1997, J. Res. NIST 102, 577-585; quadrature for independent contributions:
    JCGM 100:2008, 5.1.2).  The prediction stays the chosen model's.  Adds
    ``iv["kept_out_widening"]`` {"inputs": [{"input", "coef_um_per_unit", "u",
    "held_out_change_max" (max abs(change) over the held-out readings)}], "difference_um"
    [median, max] over the held-out readings, "half_width_um_unwidened",
    "coverage_test_unwidened"}."""
    bias, var = np.zeros(len(y)), np.zeros(len(y))
    items = []
    for e in terms:
        x = np.abs(np.asarray(e["change"], float))
        bias = bias + abs(e["coef_um_per_unit"]) * x
        var = var + (2.0 * e["u"] * x) ** 2
        items.append({"input": e["input"], "coef_um_per_unit": e["coef_um_per_unit"],
                      "u": e["u"],
                      "held_out_change_max": float(np.max(x[test])) if np.any(test) else 0.0})
    if not np.any(test):
        return
    h0 = iv["per_reading"]
    hw = np.where(test, bias + np.sqrt(h0 ** 2 + var), h0)
    _widened(iv, "kept_out_widening", {"inputs": items}, hw, hw - h0, y, pred, test)
    iv["method"] = iv["method"] + (
        "; for the inputs kept out, each held-out reading's half-width hw -> sum abs(b x) + "
        "sqrt(hw^2 + sum (2 u x)^2), x the input's change since its run's zero, b and u its "
        "coefficient on the training residuals and its blocked jackknife uncertainty")


def _widened(iv: dict, key: str, record: dict, hw, d, y, pred, test) -> None:
    """The interval ``iv`` with the half-widths ``hw`` (N,) um (wider by ``d`` (N,) um on the
    held-out readings ``test``, as they were elsewhere), in place: ``iv[key]`` = ``record``
    plus "difference_um" [median, max] of ``d`` over the held-out readings and the figures
    before it ("half_width_um_unwidened", "coverage_test_unwidened"); the median, range and
    held-out coverage of ``hw`` (``abs(y - pred) <= hw``)."""
    d = d[test]
    at, e = hw[test], np.abs((y - pred)[test])
    iv[key] = {**record, "difference_um": [float(np.median(d)), float(np.max(d))],
               "half_width_um_unwidened": iv["half_width_um"],
               "coverage_test_unwidened": iv["coverage_test"]}
    iv.update({"half_width_um": float(np.median(at)),
               "half_width_um_range": [float(np.min(at)), float(np.max(at))],
               "coverage_test": float(np.mean(e <= at)), "per_reading": hw})
