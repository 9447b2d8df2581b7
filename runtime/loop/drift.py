"""The loop on thermal drift runs: one machine position held while the machine heats and
cools, the displacement channels traced to the heat put in and to the sensors that see it.

Steps (:func:`run_drift`):

1. split (:mod:`volerr.loop.drift_split`): the held-out readings (``--holdout-time``,
   ``--holdout-files`` or, without them, the last ``DEFAULT_TEST`` of every run's time:
   whole contiguous stretches); nothing below sees them;
2. the declared model: at one position the geometric model predicts a constant per channel
   and run, the run's *zero* (its first displacement reading): the "before" prediction;
3. per channel, the basis (:mod:`volerr.loop.drift_basis`: sensors, the heat input
   ``lag((S/S_ref)^p, tau)``) and its blocked folds; the terms chosen by cross-validation
   (:mod:`volerr.loop.drift_select`) in two stages: first the heat input (its exponent, up
   to ``HEAT_TERMS`` terms: plain and one or two time constants), then the sensors;
4. every time constant refined between its grid neighbours by the cross-validated error
   (``REFINE`` values of ln tau), the model fitted on all training readings (a free zero per
   training run), the standard uncertainties of coefficients and time constants by the
   blocked jackknife over the folds (``u^2 = (K-1)/K sum (theta_k - mean)^2``: honest where
   the readings are autocorrelated, as a drift log is; the least-squares formula is not);
5. a term whose coefficient is not significant (``|value| < SIG_K u``) is dropped (the
   least significant first, refitted each time): no effect is presented with a term the
   data do not support;
6. the prediction of every reading: a training run with its fitted zero, a held-out run with
   its own zero (its first reading) and its own inputs; beside it the shop's usual model, a
   static multiple linear regression on all temperatures (their change since the run's
   start), fitted on the same training readings.

Units: displacements um, temperatures degC (changes in K), time s, speed rpm.
"""

from __future__ import annotations

import math

import numpy as np

from . import drift_basis as basis
from . import drift_select as sel
from .drift_cv import Engine

HEAT_TERMS = 3        # plain heat input and up to two time constants
REFINE = np.linspace(-1.0, 1.0, 9)   # ln-tau steps (in grid steps) tried around a grid value
RECENTRE = 3         # searches of a fold's time constant re-centred at an edge
SIG_K = 2.0           # coverage factor of the significance test of a term


def run_drift(s: basis.DriftSeries, differences: bool = False, progress=None) -> dict:
    """The loop on the drift runs ``s`` (its ``test`` mask set): per channel the chosen
    terms, predictions and figures (see :mod:`volerr.loop.drift_report` for the JSON)."""
    s.memo.clear()            # columns depend on the split (S_ref): computed afresh
    cols, X = basis.library(s)
    fold, rule = basis.folds(s)
    n_runs = len(s.runs)
    R = (s.run[:, None] == np.arange(n_runs)[None, :]).astype(float)
    Z = np.column_stack([R, X])
    cands = _candidates(s, cols, differences)
    out = {"fold_rule": rule, "n_folds": int(fold.max()) + 1, "channels": {}}
    cache: dict = {}
    for label, y in s.channels.items():
        if progress:
            progress(label)
        out["channels"][label] = _channel(s, cols, X, Z, R, y, fold, rule, cands, cache)
    return out


def _candidates(s, cols, differences: bool) -> tuple:
    """(heat candidates, sensor candidates) as (nc, 2) pairs: a sensor's lag is searched up
    to ``SENSOR_TAU_SPAN`` of the training span (a longer lag of a slowly moving sensor is a
    trend, not an effect: it cannot be told from one within the data)."""
    span = float(max(np.ptp(s.t_s[s.train & (s.run == r)]) if np.any(s.train & (s.run == r))
                     else 0.0 for r in range(len(s.runs))))
    c = sel.candidates(cols)
    keep = np.array([cols[a].p is not None or cols[a].tau_s <= basis.SENSOR_TAU_SPAN * span
                     for a, _ in c], bool)
    if not differences:
        keep &= c[:, 1] < 0
    c = c[keep]
    heat = np.array([cols[a].p is not None for a, _ in c], bool)
    return c[heat], c[~heat]


def _channel(s, cols, X, Z, R, y, fold, rule, cands, cache) -> dict:
    n_runs = R.shape[1]
    eng = Engine(Z, y, fold, rule == "runs", s.run, n_runs, cache)
    heat_c, sensor_c = cands
    terms = []
    if len(heat_c):
        terms = sel.select_terms(eng, cols, n_runs, cands=heat_c, max_terms=HEAT_TERMS)
    if len(sensor_c):
        terms = terms + sel.select_terms(eng, cols, n_runs, cands=sensor_c, start=terms)
    specs = _backward(s, [_spec(cols, t) for t in terms], R, y, fold, rule)
    specs = _refine_all(s, specs, R, y, fold, rule)
    specs, fit = _significant(s, specs, R, y, fold, rule)
    return {"terms": specs, "fit": fit, "y": y,
            "static": _static(s, R, y), "before": y[s.firsts()][s.run]}


def _backward(s, specs, R, y, fold, rule) -> list:
    """Drop a term that, given all the others, no longer lowers the cross-validated mean
    square by ``drift_select.CV_GAIN`` (a later term made it redundant: the heat input
    taken first where a sensor tells the same story better), the least useful first."""
    while len(specs) > 1:
        cols = [column(s, sp) for sp in specs]
        full = _cv(np.column_stack([R] + cols), y, fold, rule, s.run, R.shape[1])
        without = [_cv(np.column_stack([R] + cols[:i] + cols[i + 1:]), y, fold, rule, s.run,
                       R.shape[1]) for i in range(len(specs))]
        i = int(np.argmin(without))
        if without[i] * (1 - sel.CV_GAIN) < full:
            specs = specs[:i] + specs[i + 1:]
            continue
        return specs
    return specs


def _spec(cols, term) -> dict:
    a, b = term["pair"]
    ca = cols[a]
    sp = {"source": ca.source, "p": ca.p, "tau_s": ca.tau_s,
          "minus": None if b < 0 else cols[b].source,
          "cv_rms_um": math.sqrt(term["cv_mse"]),
          "cv_rms_before_um": math.sqrt(term["cv_mse_before"]),
          "delta_bic": term["delta_bic"],
          "alternatives": [_alt(cols, x) for x in term["alternatives"]
                           if not _same_term(cols, x, ca, b)]}
    return sp


def _same_term(cols, x, ca, b) -> bool:
    """An alternative that is the chosen term at a neighbouring grid lag (the refinement
    searches there) is no other explanation."""
    c = cols[x[0]]
    same = (c.source, c.p, x[1] < 0 or cols[x[1]].source) == \
        (ca.source, ca.p, b < 0 or cols[b].source)
    return same and (c.tau_s > 0) == (ca.tau_s > 0) and (
        c.tau_s == 0 or abs(math.log(c.tau_s / ca.tau_s)) < 1.5 * _grid_step(cols))


def _grid_step(cols) -> float:
    taus = sorted({c.tau_s for c in cols if c.tau_s > 0})
    return math.log(taus[1] / taus[0]) if len(taus) > 1 else 1.0


def _alt(cols, x) -> dict:
    a, b, rms = x
    c = cols[a]
    src = basis.SPEED if c.source == "heat" else c.source
    return {"covariate": src if b < 0 else f"{src} - {cols[b].source}",
            "p": c.p, "lag_s": c.tau_s or None, "cv_rms_um": round(rms, 4)}


def column(s, sp, tau=None) -> np.ndarray:
    """The unscaled values (N,) of a term ``sp`` (its lag ``tau`` if given)."""
    tau = float(sp["tau_s"] if tau is None else tau)
    key = (sp["source"], sp["minus"], sp["p"], tau)
    if key not in s.memo:
        v = basis.series(s, sp["source"], tau, sp["p"])
        if sp["minus"]:
            v = v - basis.series(s, sp["minus"], tau)
        s.memo[key] = v
    return s.memo[key]


def _design(s, specs, R, taus=None) -> np.ndarray:
    cols = [column(s, sp, None if taus is None else taus[i]) for i, sp in enumerate(specs)]
    return np.column_stack([R] + cols) if cols else R


def _cv(D, y, fold, rule, run, n_runs) -> float:
    eng = Engine(D, y, fold, rule == "runs", run, n_runs)
    return eng.cv_sse(np.eye(D.shape[1])) / eng.n


def _refine_all(s, specs, R, y, fold, rule) -> list:
    """Every term's time constant refined in turn, the others as they stand."""
    specs = list(specs)
    for i in range(len(specs)):
        others = [column(s, o) for j, o in enumerate(specs) if j != i]
        specs[i] = _refine(s, specs[i], R, y, fold, rule, others)
    return specs


def _refine(s, sp, R, y, fold, rule, others=()) -> dict:
    """The term's time constant refined by the cross-validated error of the model with it
    beside the run zeros and the other terms (columns ``others``; grid step r: ln tau
    +- ``REFINE`` r)."""
    if not sp["tau_s"] > 0:
        return sp
    r = math.log(basis.tau_grid(s)[1] / basis.tau_grid(s)[0])
    best = None
    for d in REFINE:
        tau = sp["tau_s"] * math.exp(d * r)
        D = np.column_stack([R, *others, column(s, sp, tau)])
        e = _cv(D, y, fold, rule, s.run, R.shape[1])
        if best is None or e < best[0] * (1 - sel.TIE_REL):
            best = (e, tau)
    return {**sp, "tau_s": float(best[1])}


def _fit(D, y, mask) -> np.ndarray:
    """Least squares on the readings ``mask`` by the normal equations of the columns scaled
    to unit RMS (a column all zero there, a run without readings, gets 0)."""
    Dm = D[mask]
    return _solve_normal(Dm.T @ Dm, Dm.T @ y[mask])


def _solve_normal(G, h) -> np.ndarray:
    """The least-squares coefficients from the normal equations ``G b = h``, solved with the
    columns scaled to unit norm (pseudo-inverse, rcond 1e-12); a column all zero gets 0."""
    d = np.sqrt(np.diag(G))
    on = d > 0
    b = np.zeros(len(h))
    Gs = G[np.ix_(on, on)] / np.outer(d[on], d[on])
    b[on] = np.linalg.pinv(Gs, rcond=1e-12, hermitian=True) @ (h[on] / d[on])
    b[on] /= d[on]
    return b


def _significant(s, specs, R, y, fold, rule) -> tuple[list, dict]:
    """Fit, jackknife, and drop non-significant terms one at a time (module step 5)."""
    dropped = []
    while True:
        fit = _jackknife(s, specs, R, y, fold)
        fit["dropped"] = dropped
        t = [abs(c) / u if u > 0 else math.inf for c, u in zip(fit["coef"], fit["coef_std"])]
        weak = [i for i, v in enumerate(t) if v < SIG_K]
        if not weak:
            return specs, fit
        drop = min(weak, key=lambda i: (t[i], i))
        dropped.append(specs[drop])
        specs = specs[:drop] + specs[drop + 1:]


def _jackknife(s, specs, R, y, fold) -> dict:
    """Coefficients (unscaled units) fitted on all training readings, their blocked
    jackknife standard uncertainties, and the time constants' (re-estimated per fold)."""
    tr = s.train
    n_runs = R.shape[1]
    D = _design(s, specs, R)
    b = _fit(D, y, tr)
    K = int(fold.max()) + 1
    bk, tk, edge = [], [], []
    masks = [tr & (fold != k) for k in range(K)]
    got = [_tau_on(s, sp, i, specs, R, y, masks) for i, sp in enumerate(specs)]
    edge = [any(g[1] for g in gi) for gi in got]
    for k, m in enumerate(masks):
        taus = [gi[k][0] for gi in got]
        bk.append(_fit(_design(s, specs, R, taus), y, m)[n_runs:])
        tk.append(taus)
    bk, tk = np.array(bk).reshape(K, len(specs)), np.array(tk).reshape(K, len(specs))
    f = (K - 1) / K
    coef_std = np.sqrt(f * ((bk - bk.mean(0)) ** 2).sum(0))
    tau_std = np.sqrt(f * ((tk - tk.mean(0)) ** 2).sum(0))
    # a fold whose least RSS lies at the edge of the searched range: not determined there
    tau_std = [None if (e or not sp["tau_s"] > 0) else float(u)
               for e, sp, u in zip(edge, specs, tau_std)]
    return {"zeros": b[:n_runs], "coef": b[n_runs:], "coef_std": coef_std,
            "tau_std": tau_std, "design": D}


def _tau_on(s, sp, i, specs, R, y, masks) -> list:
    """Per mask of ``masks``: (the term's time constant re-estimated on those readings,
    whether it lies at the edge of the range searched): least RSS over ln tau within +- one
    grid step, the others fixed (a parabola through 7 values; the RSS of every trial from
    one set of cross-products per mask)."""
    if not sp["tau_s"] > 0:
        return [(0.0, False)] * len(masks)
    r = math.log(basis.tau_grid(s)[1] / basis.tau_grid(s)[0])
    xs = np.linspace(-r, r, 7)
    base = np.column_stack([R] + [column(s, o) for j, o in enumerate(specs) if j != i])
    out = []
    for m in masks:
        x0, res = 0.0, None
        for _ in range(RECENTRE):
            trial = np.column_stack([column(s, sp, sp["tau_s"] * math.exp(x0 + x)) for x in xs])
            rss = _trial_rss(base[m], trial[m], y[m])
            q, lin, _ = np.polyfit(xs, rss, 2)
            x = float(np.clip(-lin / (2 * q), -r, r)) if q > 0 else float(xs[int(np.argmin(rss))])
            if abs(x) < r * (1 - 1e-9):
                res = (sp["tau_s"] * math.exp(x0 + x), False)
                break
            x0 += x             # the least RSS at the edge: search again around it
        out.append(res or (sp["tau_s"] * math.exp(x0), True))
    return out


def _trial_rss(B, T, y) -> list:
    """RSS of the least-squares fit of ``y`` on the columns ``B`` plus each column of ``T``
    in turn, all from one set of cross-products (solved as :func:`_fit` solves)."""
    A = np.column_stack([B, T])
    G, hA, yy = A.T @ A, A.T @ y, float(y @ y)
    nb = B.shape[1]
    out = []
    for j in range(T.shape[1]):
        idx = list(range(nb)) + [nb + j]
        g, h = G[np.ix_(idx, idx)], hA[idx]
        b = _solve_normal(g, h)
        out.append(max(yy - 2 * b @ h + b @ g @ b, 0.0))
    return out


def _static(s, R, y) -> np.ndarray:
    """The static multiple linear regression on all temperatures (their change since the
    run's start; a zero per training run, a held-out run from its first reading), fitted
    on the training readings: its prediction of every reading (N,)."""
    temps = [k for k in basis.sensors(s) if k.startswith("T")]
    cols = [basis.series(s, k, 0.0) for k in temps]
    D = np.column_stack([R] + cols)
    b = _fit(D, y, s.train)
    return predict(s, R, D, b, y)


def predict(s, R, D, b, y) -> np.ndarray:
    """``D b`` where a run has training readings; a run without: its first reading plus the
    terms (the basis is zero at every run's first reading)."""
    n_runs = R.shape[1]
    zeros = b[:n_runs].copy()
    seen = np.array([np.any(s.train & (s.run == r)) for r in range(n_runs)])
    zeros[~seen] = y[s.firsts()][~seen]
    return zeros[s.run] + D[:, n_runs:] @ b[n_runs:]
