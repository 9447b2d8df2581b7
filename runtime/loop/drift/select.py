"""Forward selection of the terms of one drift channel, judged by blocked cross-validation
(:mod:`volerr.loop.drift.engine`) on the training part only.

Steps (:func:`select_terms`):

1. the model starts as the run zeros (the declared model: a constant per run);
2. every candidate term is scored in the model's place plus it: each basis column (a sensor,
   the heat input, plain or through a lag on the grid) and each difference of two sensors at
   the same lag; the heat input keeps the exponent of its first term (one heat input);
3. the candidate with the least cross-validated SSE is taken when it lowers the
   cross-validated mean square by at least ``CV_GAIN`` (relative) *and* gains at least
   ``BIC_GAIN`` in BIC on all training readings (the rule of the 3-D loop; a
   difference costs one parameter more, for the choice of its second sensor); ties (equal
   to ``TIE_REL``) go to the candidate first in the library's order (sensors in file order,
   shorter lags first, the heat input last), a stated rule rather than rounding;
4. stop when no candidate passes or ``MAX_TERMS`` terms are in the model.

The candidates the cross-validation cannot tell from the chosen one in its place are its
*alternatives*, every one of them (issue 44): those within ``CV_SAME`` of its
cross-validated RMS (the sensor selection rule of :mod:`volerr.loop.lags`), and those the
chosen one is not significantly below by the paired t over the blocks of every fold (the
rule by which :mod:`volerr.loop.drift.family` judges the families).  A term is then a
*group* of equivalent sources (near-collinear sensors, their lags, the heat input at other
time constants), not the diagnosis of one sensor; :func:`tau_equivalent` the span of its
own source's time constants in the group.  ``CV_GAIN``, ``BIC_GAIN``, ``CV_SAME`` and the
tie tolerance ``TIE_REL`` (``TIE_SCORE_REL``) are the rules of
:mod:`volerr.selection.rules`.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ...selection import stepwise
from ...selection.rules import CV_GAIN, CV_SAME, bic_accepts, cv_gain, delta_bic, paired_t
from ...selection.rules import significantly_below
from ...selection.rules import TIE_SCORE_REL as TIE_REL
from .engine import Engine
from .family import SUB_BLOCKS

DIFF_GAIN = 0.10      # a difference of two sensors must beat the best single sensor by this
MAX_TERMS = 6         # terms per channel (the effects reported)


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
    """The chosen terms [{"pair": (a, b), "cv_mse", "alternatives": [(a, b, cv_rms, paired_t)]}] in
    the order taken (indices into ``cols``; Z's column of basis column j is n_runs + j)."""
    mz = n_runs + len(cols)
    if cands is None:
        cands = candidates(cols)
    st = {"W": np.eye(mz)[:, :n_runs], "taken": set(), "p": None}
    for term in start:
        a, b = term["pair"]
        st["W"] = np.column_stack([st["W"], _combo(mz, (a + n_runs, b + n_runs if b >= 0 else -1))])
        st["taken"].add((a, b))
        st["p"] = cols[a].p if cols[a].p is not None else st["p"]
    st["cur"] = eng.cv_sse(st["W"]) / eng.n
    st["rss0"] = eng.train_rss_many(st["W"], np.zeros((0, 2), int))[1]
    zc = cands + np.where(cands >= 0, n_runs, 0)

    def propose(chosen):
        ok = _allowed(cands, cols, st["p"], st["taken"])
        sse, _ = eng.cv_many(st["W"], zc[ok])
        mse = sse / eng.n
        if not np.isfinite(mse).any():
            return None
        k = _first_best(mse, cands[ok])
        rss, _ = eng.train_rss_many(st["W"], zc[ok][k:k + 1])
        extra = 1 + (cands[ok][k, 1] >= 0)
        dbic = delta_bic(eng.n, rss[0], st["rss0"], extra)
        return {"pair": tuple(int(x) for x in cands[ok][k]), "cv_mse": float(mse[k]),
                "cv_mse_before": float(st["cur"]), "delta_bic": float(dbic),
                "_z": zc[ok][k], "_rss": float(rss[0]), "_scored": (zc[ok], mse, k, cands[ok])}

    def take(term):
        # its alternatives in its place (the model before it): only for the terms taken
        term["alternatives"] = _alternatives(eng, st["W"], *term.pop("_scored"))
        pair = term["pair"]
        st["taken"].add(pair)
        if cols[pair[0]].p is not None:
            st["p"] = cols[pair[0]].p
        st["W"] = np.column_stack([st["W"], _combo(mz, term.pop("_z"))])
        st["cur"], st["rss0"] = term["cv_mse"], term.pop("_rss")

    def accept(term, chosen):
        return cv_gain(term["cv_mse"], st["cur"]) and bic_accepts(term["delta_bic"])

    return stepwise.forward(propose, accept, max_terms - len(start), take)


def _first_best(mse, cands) -> int:
    """The least score; among those tied to ``TIE_REL`` the first in candidate order.  A
    difference of two sensors is taken only where it beats the best single column by
    ``CV_GAIN`` as well (its second sensor is one choice more)."""
    single = cands[:, 1] < 0
    best = []
    for part in (single, ~single):
        part = part & np.isfinite(mse)
        if part.any():
            m = float(np.min(mse[part]))
            best.append(int(np.flatnonzero(part & (mse <= m * (1 + TIE_REL) + 1e-300))[0]))
    if len(best) == 2 and not mse[best[1]] < mse[best[0]] * (1 - DIFF_GAIN):
        return best[0]
    return min(best, key=lambda i: (mse[i], i)) if len(best) == 2 else best[0]


def _alternatives(eng, W, zc, mse, k, cands) -> list:
    """The candidates these data cannot tell from the chosen one ``k`` in its place, every
    one of them, the lowest CV RMS first: [(a, b, cv_rms, paired t)].  Two ways of not
    telling apart: the cross-validated RMS within ``CV_SAME`` (a difference too small to
    matter), or the chosen one not significantly below the candidate
    (:func:`volerr.selection.rules.significantly_below`: the paired t over the
    ``SUB_BLOCKS`` blocks of every fold of their CV mean squares, the rule
    :mod:`volerr.loop.drift.family` judges the families by: a difference that does not
    stand out of its block-to-block scatter).  The paired t is positive where the
    candidate is the worse."""
    fine = np.flatnonzero(np.isfinite(mse))
    fine = fine[fine != k]
    if not len(fine):
        return []
    blocks, _ = eng.cv_blocks(W, zc[np.r_[k, fine]], SUB_BLOCKS)
    rms = np.sqrt(mse)
    out = []
    for i, bm in zip(fine, blocks[1:]):
        if not np.all(np.isfinite(bm)):
            continue
        if rms[i] <= rms[k] * (1 + CV_SAME) or not significantly_below(blocks[0], bm):
            out.append((int(cands[i, 0]), int(cands[i, 1]), float(rms[i]),
                        paired_t(bm - blocks[0])))
    return sorted(out, key=lambda x: (x[2], x[0], x[1]))


def tau_equivalent(cols, term) -> list | None:
    """[lo, hi] s: the time constants of the chosen term's own source (the same sensor or
    difference, the heat input at the same exponent) among it and its CV-equivalent
    alternatives (:func:`_alternatives`): the lags these data cannot tell apart (lo 0: the
    plain source too); None for a term without a lag."""
    a, b = term["pair"]
    own = (cols[a].source, cols[a].p, b >= 0 and cols[b].source)
    taus = [cols[a].tau_s] + [cols[x[0]].tau_s for x in term["alternatives"]
                              if (cols[x[0]].source, cols[x[0]].p,
                                  x[1] >= 0 and cols[x[1]].source) == own]
    if not cols[a].tau_s > 0:
        return None
    return [float(min(taus)), float(max(taus))]


def _combo(mz, pair) -> np.ndarray:
    w = np.zeros(mz)
    w[pair[0]] = 1.0
    if pair[1] >= 0:
        w[pair[1]] = -1.0
    return w
