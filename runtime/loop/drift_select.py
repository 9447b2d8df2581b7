"""Forward selection of the terms of one drift channel, judged by blocked cross-validation
(:mod:`volerr.loop.drift_cv`) on the training part only.

Steps (:func:`select_terms`):

1. the model starts as the run zeros (the declared model: a constant per run);
2. every candidate term is scored in the model's place plus it: each basis column (a sensor,
   the heat input, plain or through a lag on the grid) and each difference of two sensors at
   the same lag; the heat input keeps the exponent of its first term (one heat input);
3. the candidate with the least cross-validated SSE is taken when it lowers the
   cross-validated mean square by at least ``CV_GAIN`` (relative) *and* gains at least
   ``select.BIC_GAIN`` in BIC on all training readings (the rule of the 3-D loop; a
   difference costs one parameter more, for the choice of its second sensor); ties (equal
   to ``TIE_REL``) go to the candidate first in the library's order (sensors in file order,
   shorter lags first, the heat input last), a stated rule rather than rounding;
4. stop when no candidate passes or ``MAX_TERMS`` terms are in the model.

The candidates within ``ALT_REL`` of the chosen one's cross-validated RMS (in its place)
are its *alternatives*: explanations these data cannot tell apart (the sensor selection rule
of :mod:`volerr.loop.lags`, judged by cross-validation).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from .drift_cv import Engine
from .select import BIC_GAIN

CV_GAIN = 0.01        # relative drop of the cross-validated mean square a term must bring
DIFF_GAIN = 0.10      # a difference of two sensors must beat the best single sensor by this
MAX_TERMS = 6         # terms per channel (the effects reported)
TIE_REL = 1e-9        # relative difference of two scores below which they are tied
ALT_REL = 0.01        # cross-validated RMS within 1 %: not told apart (lags.CV_SAME)
N_ALT = 3


def candidates(cols) -> np.ndarray:
    """(nc, 2) index pairs into the basis columns (b = -1: one column): every column, then
    every difference of two sensors at the same lag."""
    single = [(j, -1) for j in range(len(cols))]
    by_tau = {}
    for j, c in enumerate(cols):
        if c.p is None:
            by_tau.setdefault(c.tau_s, []).append(j)
    pairs = [(i, j) for tau in sorted(by_tau) for i, j in itertools.combinations(by_tau[tau], 2)]
    return np.array(single + pairs, int).reshape(-1, 2)


def _allowed(cands, cols, chosen_p, taken) -> np.ndarray:
    ok = np.ones(len(cands), bool)
    for i, (a, b) in enumerate(cands):
        c = cols[a]
        if c.p is not None and chosen_p is not None and c.p != chosen_p:
            ok[i] = False
        if (a, b) in taken:
            ok[i] = False
    return ok


def select_terms(eng: Engine, cols, n_runs: int, cands=None, start=(), max_terms=MAX_TERMS) -> list:
    """The chosen terms [{"pair": (a, b), "cv_mse", "alternatives": [(a, b, cv_rms)]}] in
    the order taken (indices into ``cols``; Z's column of basis column j is n_runs + j)."""
    mz = n_runs + len(cols)
    if cands is None:
        cands = candidates(cols)
    W = np.eye(mz)[:, :n_runs]
    chosen, taken, chosen_p = [], set(), None
    for term in start:
        a, b = term["pair"]
        W = np.column_stack([W, _combo(mz, (a + n_runs, b + n_runs if b >= 0 else -1))])
        taken.add((a, b))
        chosen_p = cols[a].p if cols[a].p is not None else chosen_p
    cur = eng.cv_sse(W) / eng.n
    rss0 = eng.train_rss_many(W, np.zeros((0, 2), int))[1]
    zc = cands + np.where(cands >= 0, n_runs, 0)
    while len(chosen) + len(start) < max_terms:
        ok = _allowed(cands, cols, chosen_p, taken)
        sse, _ = eng.cv_many(W, zc[ok])
        mse = sse / eng.n
        if not np.isfinite(mse).any():
            break
        k = _first_best(mse, cands[ok])
        rss, _ = eng.train_rss_many(W, zc[ok][k:k + 1])
        extra = 1 + (cands[ok][k, 1] >= 0)
        dbic = eng.n * math.log(max(rss[0], 1e-300) / max(rss0, 1e-300)) + extra * math.log(eng.n)
        if not (mse[k] <= cur * (1 - CV_GAIN) and dbic <= -BIC_GAIN):
            break
        pair = tuple(int(x) for x in cands[ok][k])
        alts = _alternatives(mse, k, cands[ok])
        chosen.append({"pair": pair, "cv_mse": float(mse[k]), "cv_mse_before": float(cur),
                       "delta_bic": float(dbic), "alternatives": alts})
        taken.add(pair)
        if cols[pair[0]].p is not None:
            chosen_p = cols[pair[0]].p
        W = np.column_stack([W, _combo(mz, zc[ok][k])])
        cur, rss0 = float(mse[k]), float(rss[0])
    return chosen


def _first_best(mse, cands) -> int:
    """The least score; among those tied to ``TIE_REL`` the first in candidate order.  A
    difference of two sensors is taken only where it beats the best single column by
    ``CV_GAIN`` as well (its second sensor is one choice more)."""
    single = cands[:, 1] < 0
    best = []
    for part in (single, ~single):
        if np.isfinite(mse[part]).any():
            m = float(np.min(mse[part]))
            best.append(int(np.flatnonzero(part & (mse <= m * (1 + TIE_REL) + 1e-300))[0]))
    if len(best) == 2 and not mse[best[1]] < mse[best[0]] * (1 - DIFF_GAIN):
        return best[0]
    return min(best, key=lambda i: (mse[i], i)) if len(best) == 2 else best[0]


def _alternatives(mse, k, cands) -> list:
    rms = np.sqrt(mse)
    near = np.flatnonzero(np.isfinite(rms) & (rms <= rms[k] * (1 + ALT_REL)))
    near = [int(i) for i in near[np.argsort(rms[near], kind="stable")] if i != k][:N_ALT]
    return [(int(cands[i, 0]), int(cands[i, 1]), float(rms[i])) for i in near]


def _combo(mz, pair) -> np.ndarray:
    w = np.zeros(mz)
    w[pair[0]] = 1.0
    if pair[1] >= 0:
        w[pair[1]] = -1.0
    return w
