"""The loop on thermal drift runs: one machine position held while the machine heats and
cools, the displacement channels traced to the heat put in and to the sensors that see it.

Steps (:func:`run_drift`):

1. split (:mod:`volerr.loop.drift.split`): the held-out readings (``--holdout-time``,
   ``--holdout-files`` or, without them, the last ``DEFAULT_TEST`` of every run's time:
   whole contiguous stretches); nothing below sees them;
2. the declared model: at one position the geometric model predicts a constant per channel
   and run, the run's *zero* (its first displacement reading): the "before" prediction;
3. per channel, the basis (:mod:`volerr.loop.drift.basis`: sensors, the heat input
   ``lag((S/S_ref)^p, tau)``) and its blocked folds; the terms chosen by cross-validation
   (:mod:`volerr.loop.drift.select`) in two stages: first the heat input (its exponent, up
   to ``HEAT_TERMS`` terms: plain and one or two time constants), then the sensors;
4. every time constant refined between its grid neighbours by the cross-validated error
   (``REFINE`` values of ln tau), the model fitted on all training readings (a free zero per
   training run), the standard uncertainties of coefficients and time constants by the
   blocked jackknife over the folds (``u^2 = (K-1)/K sum (theta_k - mean)^2``: honest where
   the readings are autocorrelated, as a drift log is; the least-squares formula is not);
5. a term whose coefficient is not significant (``|value| < SIG_K u``,
   :mod:`volerr.selection.rules`) is dropped (the
   least significant first, refitted each time): no effect is presented with a term the
   data do not support; every term kept is then scored against its absence
   (:func:`volerr.loop.drift.family.without_each`) and one the cross-validation cannot tell
   from it is named as not decided (``cv_decided`` false), not dropped: the model is judged
   as a whole by the families' rule, and pairwise tests are not transitive;
6. the prediction of every reading: a training run with its fitted zero, a held-out run with
   its own zero (its first reading) and its own inputs; beside it the shop's usual model, a
   static multiple linear regression on all temperatures (their change since the run's
   start), fitted on the same training readings, and the regularised fit over every column
   the selection may take (:mod:`volerr.loop.drift.shrink`); the channel's model is chosen
   among them and the constant by :func:`volerr.loop.drift.family.choose`.

Units: displacements um, temperatures degC (changes in K), time s, speed rpm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...selection import stepwise
from ...selection.linalg import solve_scaled as _solve_normal
from ...selection.profile import profile_vertex
from ...selection.rules import CV_GAIN, SIG_K, TIE_SCORE_REL
from . import basis
from . import family
from . import interval as band
from . import select as sel
from . import shrink
from . import tau_range
from .engine import Engine

__all__ = ["HEAT_TERMS", "REFINE", "RECENTRE", "SIG_K", "Channel", "column", "predict",
           "run_drift"]

HEAT_TERMS = 3        # plain heat input and up to two time constants
REFINE = np.linspace(-1.0, 1.0, 9)   # ln-tau steps (in grid steps) tried around a grid value
RECENTRE = 3         # searches of a fold's time constant re-centred at an edge


@dataclass
class Channel:
    """What the steps of one channel share: the series ``s`` (its ``test`` mask set), the
    channel's readings ``y`` (N,) um, the run indicators ``R`` (N, n_runs), the blocked
    ``fold`` of every training reading (-1 held out) and its ``rule`` (``"environments"``,
    ``"runs"`` or ``"stretches"``)."""

    s: basis.DriftSeries
    y: np.ndarray
    R: np.ndarray
    fold: np.ndarray
    rule: str

    @property
    def n_runs(self) -> int:
        return self.R.shape[1]

    def cv(self, D) -> float:
        """Cross-validated mean square (um^2) of the model with the columns ``D``."""
        eng = Engine(D, self.y, self.fold, basis.whole_runs(self.rule), self.s.run,
                     self.n_runs, zero=self.s.zero(self.y))
        return eng.cv_sse(np.eye(D.shape[1])) / eng.n

    def design(self, specs, taus=None) -> np.ndarray:
        """The run indicators and the columns of the terms ``specs`` (their lags ``taus``)."""
        cols = [column(self.s, sp, None if taus is None else taus[i])
                for i, sp in enumerate(specs)]
        return np.column_stack([self.R] + cols) if cols else self.R


def run_drift(s: basis.DriftSeries, differences: bool = False, progress=None) -> dict:
    """The loop on the drift runs ``s`` (its ``test`` mask set): per channel the chosen
    terms, predictions and figures (see :mod:`volerr.loop.drift.report` for the JSON)."""
    s.memo.clear()            # columns depend on the split (S_ref): computed afresh
    cols, X = basis.library(s)
    fold, rule = basis.folds(s)
    R = s.indicators()
    Z = np.column_stack([R, X])
    cands = _candidates(s, cols, differences, basis.many_runs(s))
    out = {"fold_rule": rule, "n_folds": int(fold.max()) + 1, "channels": {},
           "room_undecided": basis.room_undecided(s)}
    cache: dict = {}
    alt = _Alternative(s, differences) if out["room_undecided"] else None
    for label, y in s.channels.items():
        if progress:
            progress(label)
        ch = Channel(s, y, R, fold, rule)
        out["channels"][label] = r = _channel(ch, cols, Z, cands, cache)
        if alt is not None:
            r["alternative"] = alt.predict(ch, r)
    return out


class _Alternative:
    """The chosen family fitted on the sensors' other reading (plain instead of their rise
    over the room, or the reverse: :func:`volerr.loop.drift.basis.alternative_reference`),
    on the same training readings, where the training cannot decide between the two
    (:func:`volerr.loop.drift.basis.room_undecided`); its prediction widens the interval
    (:func:`volerr.loop.drift.interval.widen_for_room`).  Per family: the constant has no
    sensor (no alternative); the static regression takes every temperature as its rise
    over the room, except where the room is itself one of its columns (then the two
    readings span the same columns: the same prediction, none computed); the lag model
    keeps its terms and time constants, each sensor term in its other reading (a
    difference of two sensors, the room's own terms and the heat input as they are), its
    coefficients refitted by least squares; the regularised fit is refitted on the bank in
    the other reading, its lambda chosen by the same blocked CV (shared by the channels:
    ``cache``)."""

    def __init__(self, s, differences: bool):
        self.s, self.differences, self.cache = s, differences, {}
        self.ref, self.other = basis.reference(s), basis.alternative_reference(s)
        self.bank = None

    def predict(self, ch: Channel, r: dict) -> np.ndarray | None:
        """(N,) um: the alternative's prediction of every reading (None: the same as the
        chosen family's)."""
        fam, s, tr = r["choice"]["family"], ch.s, ch.s.train
        if fam == "static":
            room = basis.room(s)
            temps = _temperatures(s)
            if room in temps:
                return None
            D = np.column_stack([ch.R] + [basis.series(s, k, 0.0) - basis.series(s, room, 0.0)
                                          for k in temps])
            return predict(s, D, _fit(D, ch.y, tr), ch.y)
        if fam == "lag":
            D = ch.design([self._other(sp) for sp in r["terms"]])
            return predict(s, D, _fit(D, ch.y, tr), ch.y)
        if fam == "regularised":
            if self.bank is None:
                cols, X = basis.library(s, alternative=True)
                cands = _candidates(s, cols, self.differences, basis.many_runs(s))
                self.bank = (cols, np.column_stack([ch.R, X]),
                             sorted({int(a) for c in cands for a, b in c if b < 0}))
            cols, Z, keep = self.bank
            return shrink.fit(s, ch.y, Z, [ch.n_runs + j for j in keep],
                              [cols[j] for j in keep], ch.fold, ch.rule, self.cache)["pred"]
        return None

    def _other(self, sp: dict) -> dict:
        """The term ``sp`` in the sensors' other reading (the class docstring)."""
        if sp["source"] == "heat" or basis.is_room(sp["source"]):
            return sp
        if self.ref and sp["minus"] == self.ref:
            return {**sp, "minus": None}
        if not self.ref and sp["minus"] is None:
            return {**sp, "minus": self.other}
        return sp


def _candidates(s, cols, differences: bool, many: bool = False) -> tuple:
    """(heat candidates, sensor candidates) as (nc, 2) pairs: a sensor's lag is searched up
    to ``SENSOR_TAU_SPAN`` of the training span (a longer lag of a slowly moving sensor is a
    trend, not an effect: within one run's stretches it cannot be told from one); with
    ``many`` runs (:func:`volerr.loop.drift.basis.many_runs`) every lag of the grid (each fold
    a run predicted from its own start and inputs: a trend that is no effect does not carry
    over to several of them, and the room reaches the structure through hours)."""
    span = float(max(np.ptp(s.t_s[s.train & (s.run == r)]) if np.any(s.train & (s.run == r))
                     else 0.0 for r in range(len(s.runs))))
    cap = np.inf if many else basis.SENSOR_TAU_SPAN * span
    c = sel.candidates(cols)
    keep = np.array([cols[a].p is not None or cols[a].tau_s <= cap for a, _ in c], bool)
    if not differences:
        keep &= c[:, 1] < 0
    c = c[keep]
    heat = np.array([cols[a].p is not None for a, _ in c], bool)
    return c[heat], c[~heat]


def _channel(ch: Channel, cols, Z, cands, cache) -> dict:
    eng = Engine(Z, ch.y, ch.fold, basis.whole_runs(ch.rule), ch.s.run, ch.n_runs, cache,
                 ch.s.zero(ch.y))
    heat_c, sensor_c = cands
    terms = []
    if len(heat_c):
        terms = sel.select_terms(eng, cols, ch.n_runs, cands=heat_c, max_terms=HEAT_TERMS)
    if len(sensor_c):
        terms = terms + sel.select_terms(eng, cols, ch.n_runs, cands=sensor_c, start=terms)
    specs = _backward(ch, [_spec(cols, t) for t in terms])
    specs = _refine_all(ch, specs)
    specs, fit = _significant(ch, specs)
    fit["tau_range"] = tau_range.ranges(ch, specs, fit)    # profile ranges, s (issue 44)
    for sp, w in zip(specs, family.without_each(ch, fit["design"])):
        sp.update(w)          # is the model without it CV-equivalent? (issue 44)
    Ds = _static_design(ch)
    tr = ch.s.train
    reg = _regularised(ch, cols, Z, cands, cache)
    out = {"terms": specs, "fit": fit, "y": ch.y,
           "static": predict(ch.s, Ds, _fit(Ds, ch.y, tr), ch.y),
           "constant": predict(ch.s, ch.R, _fit(ch.R, ch.y, tr), ch.y),
           "regularised": reg["pred"], "shrink": reg,
           "before": ch.s.zero(ch.y)}
    designs = {"constant": ch.R, "static": Ds, "lag": fit["design"]}
    out["choice"] = family.choose(ch, designs, bool(specs), _nested_in_static(specs),
                                  regularised=reg["cv_resid"])
    out["leverage"] = _leverage(ch, out["choice"]["family"], designs, reg, Z, cache)
    return out


def _leverage(ch: Channel, fam: str, designs: dict, reg: dict, Z, cache) -> np.ndarray:
    """(N,) leverage of every reading in the chosen family's fit that predicts it (its CV
    fold's for a training reading), the scale of the prediction interval
    (:mod:`volerr.loop.drift.interval`: the lag model's is the bank's it was chosen from)."""
    anchored = basis.whole_runs(ch.rule)
    if fam in ("regularised", "lag"):
        lam = reg["lambda_rel"] * float(ch.s.train.sum())
        return band.shrink_leverage(cache, Z, reg["keep"], ch.s.run, ch.fold, anchored, lam)
    return band.cv_leverage(designs[fam][:, ch.n_runs:], ch.s.run, ch.fold, ch.s.train,
                            anchored)


def _regularised(ch: Channel, cols, Z, cands, cache) -> dict:
    """The regularised fit over the columns the selection may take (every single column of
    ``cands``; :mod:`volerr.loop.drift.shrink`)."""
    keep = sorted({int(a) for c in cands for a, b in c if b < 0})
    grams = [cache[("fit", k)] for k in range(int(ch.fold.max()) + 1)] \
        if ("fit", 0) in cache else None         # the engine's cross-products of the folds
    out = shrink.fit(ch.s, ch.y, Z, [ch.n_runs + j for j in keep], [cols[j] for j in keep],
                     ch.fold, ch.rule, cache, grams)
    out["keep"] = [ch.n_runs + j for j in keep]
    return out


def _backward(ch: Channel, specs) -> list:
    """Drop a term that, given all the others, no longer lowers the cross-validated mean
    square by ``CV_GAIN`` (a later term made it redundant: the heat input taken first where
    a sensor tells the same story better), the least useful first."""
    def without(items, i):
        cols = [column(ch.s, sp) for sp in items]
        return ch.cv(np.column_stack([ch.R] + cols[:i] + cols[i + 1:])), None

    def drop(res, items):
        full = ch.cv(np.column_stack([ch.R] + [column(ch.s, sp) for sp in items]))
        return res[0] * (1 - CV_GAIN) < full

    return stepwise.backward(specs, without, drop, keep=1)[0]


def _spec(cols, term) -> dict:
    a, b = term["pair"]
    ca = cols[a]
    sp = {"source": ca.source, "p": ca.p, "tau_s": ca.tau_s,
          "minus": ca.minus if b < 0 else cols[b].source,
          "cv_rms_um": math.sqrt(term["cv_mse"]),
          "cv_rms_before_um": math.sqrt(term["cv_mse_before"]),
          "delta_bic": term["delta_bic"],
          "alternatives": [_alt(cols, x) for x in term["alternatives"]
                           if not _same_term(cols, x, ca, b)],
          "tau_equivalent_s": sel.tau_equivalent(cols, term)}
    return sp


def _same_term(cols, x, ca, b) -> bool:
    """An alternative that is the chosen term at a neighbouring grid lag (the refinement
    searches there) is no other explanation."""
    c = cols[x[0]]
    same = (c.source, c.p, c.minus if x[1] < 0 else cols[x[1]].source) == \
        (ca.source, ca.p, ca.minus if b < 0 else cols[b].source)
    return same and (c.tau_s > 0) == (ca.tau_s > 0) and (
        c.tau_s == 0 or abs(math.log(c.tau_s / ca.tau_s)) < 1.5 * _grid_step(cols))


def _grid_step(cols) -> float:
    taus = sorted({c.tau_s for c in cols if c.tau_s > 0})
    return math.log(taus[1] / taus[0]) if len(taus) > 1 else 1.0


def _alt(cols, x) -> dict:
    a, b, rms, t = x
    c = cols[a]
    src = basis.SPEED if c.source == "heat" else c.source
    minus = c.minus if b < 0 else cols[b].source
    return {"covariate": f"{src} - {minus}" if minus else src,
            "p": c.p, "lag_s": c.tau_s or None, "cv_rms_um": round(rms, 4),
            "paired_t": round(t, 3)}


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


def _refine_all(ch: Channel, specs) -> list:
    """Every term's time constant refined in turn, the others as they stand."""
    specs = list(specs)
    for i in range(len(specs)):
        others = [column(ch.s, o) for j, o in enumerate(specs) if j != i]
        specs[i] = _refine(ch, specs[i], others)
    return specs


def _refine(ch: Channel, sp, others=()) -> dict:
    """The term's time constant refined by the cross-validated error of the model with it
    beside the run zeros and the other terms (columns ``others``; grid step r: ln tau
    +- ``REFINE`` r, clipped to the grid's range); ties (``TIE_SCORE_REL``) go to the first
    value tried."""
    if not sp["tau_s"] > 0:
        return sp
    r = _grid_step_of(ch.s)
    grid = basis.tau_grid(ch.s)
    best = None
    for d in REFINE:
        # within the grid's range: a lag shorter than its shortest (TAU_MIN_STEPS readings)
        # is not resolved by the readings, one longer than its longest not by the runs
        tau = min(max(sp["tau_s"] * math.exp(d * r), float(grid[0])), float(grid[-1]))
        e = ch.cv(np.column_stack([ch.R, *others, column(ch.s, sp, tau)]))
        if best is None or e < best[0] * (1 - TIE_SCORE_REL):
            best = (e, tau)
    return {**sp, "tau_s": float(best[1])}


def _grid_step_of(s) -> float:
    """ln of the ratio of two neighbouring time constants of the grid."""
    return math.log(basis.tau_grid(s)[1] / basis.tau_grid(s)[0])


def _fit(D, y, mask) -> np.ndarray:
    """Least squares on the readings ``mask`` by the normal equations of the columns scaled
    to unit RMS (a column all zero there, a run without readings, gets 0)."""
    Dm = D[mask]
    return _solve_normal(Dm.T @ Dm, Dm.T @ y[mask])


def _significant(ch: Channel, specs) -> tuple[list, dict]:
    """Fit, jackknife, and drop non-significant terms one at a time (module step 5)."""
    dropped = []
    while True:
        fit = _jackknife(ch, specs)
        fit["dropped"] = dropped
        t = [abs(c) / u if u > 0 else math.inf for c, u in zip(fit["coef"], fit["coef_std"])]
        weak = [i for i, v in enumerate(t) if v < SIG_K]
        if not weak:
            return specs, fit
        drop = min(weak, key=lambda i: (t[i], i))
        dropped.append(specs[drop])
        specs = specs[:drop] + specs[drop + 1:]


def _jackknife(ch: Channel, specs) -> dict:
    """Coefficients (unscaled units) fitted on all training readings, their blocked
    jackknife standard uncertainties, and the time constants' (re-estimated per fold)."""
    tr, n_runs = ch.s.train, ch.n_runs
    D = ch.design(specs)
    b = _fit(D, ch.y, tr)
    K = int(ch.fold.max()) + 1
    bk, tk = [], []
    masks = [tr & (ch.fold != k) for k in range(K)]
    got = [_tau_on(ch, sp, i, specs, masks) for i, sp in enumerate(specs)]
    edge = [any(g[1] for g in gi) for gi in got]
    for k, m in enumerate(masks):
        taus = [gi[k][0] for gi in got]
        bk.append(_fit(ch.design(specs, taus), ch.y, m)[n_runs:])
        tk.append(taus)
    bk, tk = np.array(bk).reshape(K, len(specs)), np.array(tk).reshape(K, len(specs))
    f = (K - 1) / K
    coef_std = np.sqrt(f * ((bk - bk.mean(0)) ** 2).sum(0))
    tau_std = np.sqrt(f * ((tk - tk.mean(0)) ** 2).sum(0))
    # a fold whose least RSS lies at the edge of the searched range: not determined there
    tau_std = [None if (e or not sp["tau_s"] > 0) else float(u)
               for e, sp, u in zip(edge, specs, tau_std)]
    return {"zeros": b[:n_runs], "coef": b[n_runs:], "coef_std": coef_std,
            "tau_std": tau_std, "design": D, "coef_dev": bk - bk.mean(0),
            "tau_dev": tk - tk.mean(0)}


def kept_out_coef(s, resid, x, fold) -> tuple[float, float]:
    """What the training readings say of a kept-out input's coefficient
    (:func:`volerr.loop.drift.basis.kept_out`): ``resid`` (N,) um the chosen family's
    residuals, ``x`` (N,) the input's change since its run's zero (units of the input),
    regressed on a free zero per training run and ``x`` over the training readings.  Returns
    (b um per unit, u its blocked jackknife standard uncertainty over the folds ``fold``:
    each fit without one fold, ``sqrt((K - 1) / K sum (b_k - mean b_k)^2)``, as
    :func:`_jackknife`)."""
    tr = s.train
    D = np.column_stack([s.indicators(), x])
    b = float(_fit(D, resid, tr)[-1])
    K = int(fold.max()) + 1
    bk = np.array([_fit(D, resid, tr & (fold != k))[-1] for k in range(K)])
    return b, float(np.sqrt((K - 1) / K * ((bk - bk.mean()) ** 2).sum()))


def _tau_on(ch: Channel, sp, i, specs, masks) -> list:
    """Per mask of ``masks``: (the term's time constant re-estimated on those readings,
    whether it lies at the edge of the range searched): least RSS over ln tau within +- one
    grid step, the others fixed (:func:`volerr.selection.profile.profile_vertex`: a parabola
    through 7 values; the RSS of every trial from one set of cross-products per mask)."""
    if not sp["tau_s"] > 0:
        return [(0.0, False)] * len(masks)
    s, y = ch.s, ch.y
    base = np.column_stack([ch.R] + [column(s, o) for j, o in enumerate(specs) if j != i])
    out, step = [], _grid_step_of(s)
    for m in masks:
        bm, ym = base[m], y[m]

        def rss_at(x0, xs):
            trial = np.column_stack([column(s, sp, sp["tau_s"] * math.exp(x0 + x)) for x in xs])
            return _trial_rss(bm, trial[m], ym)

        x, edge = profile_vertex(rss_at, step, 7, RECENTRE)
        out.append((sp["tau_s"] * math.exp(x), edge))
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


def _nested_in_static(specs) -> bool:
    """Whether every term is a plain temperature (or a difference of two): the model is then
    a sub-model of the static regression (:func:`_static_design`)."""
    def temp(k):
        return k is None or (k != "heat" and k.startswith("T"))
    return all(sp["tau_s"] == 0 and temp(sp["source"]) and temp(sp["minus"]) for sp in specs)


def _static_design(ch: Channel) -> np.ndarray:
    """The design of the static multiple linear regression on all temperatures (their change
    since the run's start) and a zero per run; fitted on the training readings (a held-out
    run predicted from its first reading, :func:`predict`) it is the shop's usual model."""
    s = ch.s
    temps = _temperatures(s)
    return np.column_stack([ch.R] + [basis.series(s, k, 0.0) for k in temps])


def _temperatures(s) -> list:
    """The logged temperatures (the sensors named ``T...``): the static regression's inputs."""
    return [k for k in basis.sensors(s) if k.startswith("T")]


def predict(s, D, b, y) -> np.ndarray:
    """``D b`` where a run has training readings; a run without: its first reading plus the
    terms (the basis is zero at every run's first reading)."""
    n_runs = len(s.runs)
    zeros = b[:n_runs].copy()
    seen = basis.trained_runs(s)
    zeros[~seen] = s.run_zeros(y)[~seen]
    return zeros[s.run] + D[:, n_runs:] @ b[n_runs:]
