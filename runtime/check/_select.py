"""Which parameters changed: the smallest set that explains the check's readings, by the
loop's rule (:mod:`volerr.loop.select`): forward selection, a parameter accepted when it
lowers the BIC by more than ``BIC_GAIN`` and the cross-validated residual significantly
(paired t on the held-out points' squared residuals above :func:`cv_limit`); then a backward
pass that drops a parameter no longer earning its place given the others.

1. ``chi2(S)`` of the generalised least-squares fit of :mod:`volerr.check._system` with the
   set ``S`` free to change; the BIC of ``S`` is ``chi2(S) + |S| ln n`` (``n`` readings), so
   a parameter enters when it lowers ``chi2`` by more than :func:`threshold`;
2. the threshold is at least the chi-square (1 dof) quantile of ``1 - ALPHA / p`` (Bonferroni
   over the ``p`` candidates), so that a machine that did not change is called "changed"
   with a probability below ``ALPHA`` whatever ``n``;
3. cross-validation: :data:`volerr.check._system.FOLDS` folds of the points (point ``i`` in
   fold ``i mod FOLDS``; every set-up keeps points in the training part), the held-out points' squared weighted
   residual with and without the candidate; the paired t must exceed the loop's ``CV_T``
   (3, for campaigns of thousands of points) or, for a check of few points, the one-sided
   5 % quantile of Student's t on ``n - 1`` degrees of freedom, whichever is smaller (a
   check of 15 points would otherwise refuse a change of 8 standard uncertainties that the
   held-out points confirm at t = 2.8);
4. ties (candidates whose ``chi2`` reductions agree to ``TIE`` relative) are broken by the
   reference's order; two parameters whose columns in this check correlate by more than
   ``INDISTINCT`` (set-ups eliminated) cannot be told apart by it and are named; among
   such parameters whose ``chi2`` lies within ``SAME_CHI2`` of the best (a statistical tie)
   the simpler explanation enters: a constant (squareness, location error) before a series
   term, then the reference's order;
5. alternatives (the loop's rule, :mod:`volerr.loop.lags`): for every parameter named
   changed, each other parameter that in its place (the other named ones kept) explains the
   readings within the loop's ``BIC_TIE`` (``chi2`` higher by less than 10: the sets are of
   one size, so the BIC difference is the ``chi2`` difference) *and* whose cross-validated
   squared residuals do not differ significantly (|paired t| below :func:`cv_limit`, or the
   held-out RMS within the loop's ``CV_SAME``) is an *alternative*: this check cannot tell
   the two apart, whatever their correlation; the result names them and what would separate
   them (a second placement, :func:`separate_by`).

References: Schwarz (1978) for the BIC; the blocked cross-validation of the loop
(:mod:`volerr.loop.select`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..selection import stepwise
from ..selection.rules import BIC_GAIN, BIC_TIE, CV_SAME, CV_T, TIE_SCORE_REL

#: false-alarm probability the threshold holds at least (a clean machine called "changed")
ALPHA = 0.05
#: relative agreement of two chi2 reductions that counts as a tie (the rule of
#: :mod:`volerr.selection.rules`)
TIE = TIE_SCORE_REL
#: correlation of two parameters' columns above which this check cannot tell them apart
INDISTINCT = 0.98
#: chi2 difference within which two indistinguishable candidates are a statistical tie
SAME_CHI2 = 1.0
#: most parameters a check names as changed
MAX_CHANGED = 8
#: most alternatives named per changed parameter
MAX_ALTERNATIVES = 3


def threshold(n_readings: int, p: int) -> float:
    """chi2 reduction a parameter must bring to enter (module docstring, steps 1-2)."""
    from scipy.stats import chi2

    bic = math.log(max(n_readings, 2)) + BIC_GAIN
    return max(bic, float(chi2.isf(ALPHA / max(p, 1), 1)))


@dataclass
class Selection:
    """``changed`` indices (order of entry), the final :class:`volerr.check._system.Fit`,
    ``steps`` [{"parameter" index, "dchi2", "cv_t", "accepted"}], ``threshold``."""

    changed: list
    fit: object
    threshold: float
    steps: list = field(default_factory=list)
    alternatives: dict = field(default_factory=dict)


def select(system, candidates=None, series=()) -> Selection:
    """Forward selection over ``candidates`` (indices; default every parameter the check
    sees), then the backward pass (module docstring); ``series``: the indices that are
    series terms (step 4)."""
    cands = list(range(system.p)) if candidates is None else list(candidates)
    c = threshold(system.n_readings, max(len(cands), 1))
    corr = _correlation(system)
    steps, state = [], {"fit": system.solve([])}

    def propose(chosen):
        S = [t[0] for t in chosen]
        trial = [(j, system.solve(S + [j])) for j in cands if j not in S]
        if not trial:
            return None
        best = min(f.chi2 for _, f in trial)
        fit = state["fit"]
        j, f = next((j, f) for j, f in trial if f.chi2 <= best + TIE * max(fit.chi2, 1.0))
        tied = [(j2 in series, j2, f2) for j2, f2 in trial
                if f2.chi2 <= best + SAME_CHI2 and abs(corr[j, j2]) > INDISTINCT]
        _, j, f = min(tied + [(j in series, j, f)], key=lambda t: (t[0], t[1]))
        return j, f

    def accept(term, chosen):
        S, (j, f) = [t[0] for t in chosen], term
        gain = state["fit"].chi2 - f.chi2
        t = cv_t(system, S, S + [j]) if gain > c else float("nan")
        ok = gain > c and t > cv_limit(len(np.unique(system.point)))
        steps.append({"parameter": j, "dchi2": gain, "cv_t": t, "accepted": bool(ok)})
        return ok

    chosen = stepwise.forward(propose, accept, MAX_CHANGED,
                              take=lambda term: state.update(fit=term[1]))
    S, fit = _backward(system, [j for j, _ in chosen], state["fit"], c)
    return Selection(S, fit, c, steps, alternatives(system, S, fit, cands))


def cv_limit(n_points: int) -> float:
    """The paired t the cross-validation must exceed (module docstring, step 3)."""
    from scipy.stats import t

    return min(CV_T, float(t.ppf(0.95, max(n_points - 1, 1))))


def _backward(system, S, fit, c):
    """Drop, one at a time, the parameter whose removal raises ``chi2`` least while that
    rise stays below the threshold."""
    state = {"fit": fit}

    def without(S, i):
        f = system.solve([k for k in S if k != S[i]])
        return f.chi2, f

    def drop(res, S):
        if res[1].chi2 - state["fit"].chi2 > c:
            return False
        state["fit"] = res[1]
        return True

    S, _ = stepwise.backward(S, without, drop)
    return S, state["fit"]


def alternatives(system, S, fit, candidates) -> dict:
    """``{j: [{"parameter" k, "delta_bic", "cv_paired_t", "change", "std"}]}``: for every
    changed ``j`` the candidates that explain the readings in its place about as well (module
    docstring, step 5), best BIC first (ties: the reference's order); ``change`` and ``std``
    of ``k`` in that place."""
    out = {}
    limit = cv_limit(len(np.unique(system.point)))
    for pos, j in enumerate(S):
        others = S[:pos] + S[pos + 1:]
        found = []
        for k in candidates:
            if k in S:
                continue
            f = system.solve(others + [k])
            d_bic = f.chi2 - fit.chi2
            if d_bic >= BIC_TIE:
                continue
            t = cv_t(system, others + [k], S)
            if not (abs(t) < limit or abs(_cv_rms_ratio(system, others + [k], S) - 1) < CV_SAME):
                continue
            delta, std = f.change()
            found.append({"parameter": k, "delta_bic": d_bic, "cv_paired_t": t,
                          "change": float(delta[-1]), "std": float(std[-1])})
        found.sort(key=lambda a: (round(a["delta_bic"], 6), a["parameter"]))
        out[j] = found[:MAX_ALTERNATIVES]
    return out


def freed(system, S) -> dict:
    """``{j: (change, std)}`` for every parameter ``j`` not in ``S``: its change estimated
    with it free beside ``S`` (report units): the check's measurement of a parameter it calls
    unchanged (below the threshold), ``std`` its uncertainty of "no change"; ``std`` inf
    where the check does not see the parameter."""
    out = {}
    for j in range(system.p):
        if j in S:
            continue
        delta, std = system.solve(list(S) + [j]).change()
        s = float(std[-1])
        out[j] = (float(delta[-1]), s) if s > 0 and math.isfinite(s) else (0.0, math.inf)
    return out


def _cv_rms_ratio(system, a, b) -> float:
    """Held-out RMS of the fit with ``a`` free over that with ``b`` free."""
    ea = eb = 0.0
    for k in range(system.folds):
        test = system.fold_of_row == k
        if not test.any() or test.all():
            continue
        ea += float(_heldout(system, system.solve(a, k), test).sum())
        eb += float(_heldout(system, system.solve(b, k), test).sum())
    return math.sqrt(ea / eb) if eb > 0 else float("inf")


def cv_t(system, without, with_) -> float:
    """Paired t of the held-out points' squared residuals without minus with the candidate
    (positive: the candidate predicts held-out points better)."""
    d = []
    for k in range(system.folds):
        test = system.fold_of_row == k
        if not test.any() or test.all():
            continue
        e0 = _heldout(system, system.solve(without, k), test)
        e1 = _heldout(system, system.solve(with_, k), test)
        d.append(e0 - e1)
    d = np.concatenate(d) if d else np.zeros(0)
    if len(d) < 2:
        return float("inf")
    sd = float(np.std(d, ddof=1))
    return float("inf") if sd == 0 else float(np.mean(d) / (sd / math.sqrt(len(d))))


def _heldout(system, fit, test) -> np.ndarray:
    """Per held-out point: the squared weighted residual (rows of a point summed)."""
    pred = system.A[test] @ fit.z[:system.ns + system.p]
    e = (system.r[test] - pred) ** 2
    pts = system.point[test]
    uniq, inv = np.unique(pts, return_inverse=True)
    return np.bincount(inv, weights=e, minlength=len(uniq))


def _correlation(system) -> np.ndarray:
    """(p, p) correlation of the parameters' columns in this check, set-ups eliminated."""
    G = system.data_information()
    d = np.sqrt(np.maximum(np.diag(G), 0.0))
    d[d == 0] = np.inf
    return G / np.outer(d, d)


def indistinguishable(system, names) -> tuple[list, list]:
    """(pairs [[a, b]] of parameters this check cannot tell apart, names it does not see):
    correlation of the columns above ``INDISTINCT`` with the set-ups eliminated; not seen:
    the check's information on a parameter below 1e-6 of the reference's."""
    G = system.data_information()
    ref_info = np.diag(system.Sinv)
    d = np.diag(G)
    seen = d > 1e-6 * np.maximum(ref_info, 1e-300)
    pairs = []
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            if seen[i] and seen[j] and abs(G[i, j]) > INDISTINCT * math.sqrt(d[i] * d[j]):
                pairs.append([names[i], names[j]])
    return pairs, [n for n, s in zip(names, seen) if not s]
