"""The range of a fitted time constant: the profile-likelihood interval (issue 44), stated
beside the blocked jackknife's standard uncertainty (``lag_s.range_k2`` of the JSON).

For each term i with tau > 0 of the final lag model, trial values x over ln tau: the grid's
range at ``SUB`` points per grid step (``linspace(ln grid[0], ln grid[-1], SUB (n - 1) + 1)``)
united with ln of the term's tau.  At each x the RSS (um^2) over the training readings of the
lag model with term i at exp(x) s, the run zeros and every other coefficient refitted, and
every other lagged term's time constant re-optimised by one coordinate pass in the terms'
order over the same ``SUB`` grid (each taking the least RSS): the profile of Bates & Watts
(1988, *Nonlinear Regression Analysis and Its Applications*, Wiley, 6.1) with the other
parameters profiled out (Venzon & Moolgavkar 1988, *Appl. Statist.* 37, 87-94).  The range
is ``{x : RSS(x) <= RSS_min (1 + F(0.95; 1, nu) / nu)}``, its hull, ends interpolated
linearly in ln tau, an end at the grid's edge open (None); nu = max(n_eff - p, 1) with n_eff
= ``family.SUB_BLOCKS`` x the folds, the blocks the loop's paired test takes as independent
units (a drift model's misfit is smooth over hours: the readings are not), p = the design's
columns not all zero on the training readings + the lagged terms.  Measured in
``benchmarks/research/tau_uncertainty`` (variant P-block-prof: the planted time constants
inside in 39 of 48 and 39 of 48 pairs on fresh seeds, the jackknife's tau +- 2 u 21 and 25).

Cost: the cross-products (Gram) of [run zeros, the unlagged terms' columns, every lagged
term's column at its tau and at every trial tau, y] once per channel; every RSS from their
sub-blocks, the columns scaled to unit norm: per coordinate pass and trial value of term i,
one pseudo-inverse of the model without the other term's trial column, every trial column
then added by the bordered system (:func:`volerr.loop.drift.engine.rss_stack`; the same
RSS as a pseudo-inverse of every trial's whole system, to about 1e-11 relative on the
FL_THERMAL windows, every choice and printed range the same: benchmarks/speed_drift,
session 9).  Above ``THIN_ABOVE`` training readings the Gram
is taken on every k-th training reading of each run (k = ceil(n / ``THIN_ABOVE``)): the
threshold is a ratio of RSS, nearly unchanged by thinning columns smooth over many readings.

Units: time constants s, readings um.
"""

from __future__ import annotations

import math

import numpy as np

from ...machine.lags import lag
from ...selection.rules import f_quantile
from . import basis
from .engine import rss_stack
from .family import SUB_BLOCKS

__all__ = ["CONFIDENCE", "SUB", "THIN_ABOVE", "ranges"]

SUB = 4               # trial values of ln tau per grid step
CONFIDENCE = 0.95     # the F quantile of the threshold (two-sided 95 %: "k = 2")
THIN_ABOVE = 20000    # training readings above which the Gram is taken on thinned readings


def ranges(ch, specs, fit) -> list:
    """Per term of ``specs`` (the final fit ``fit`` of :func:`volerr.loop.drift.fit._jackknife`
    on the channel ``ch``): [lo, hi] s of its time constant (an end None: open, the grid's
    edge), or None for a term without a lag."""
    lagged = [i for i, sp in enumerate(specs) if sp["tau_s"] > 0]
    if not lagged:
        return [None] * len(specs)
    s, tr = ch.s, ch.s.train
    grid = basis.tau_grid(s)
    lg = np.log(grid)
    xs = np.linspace(lg[0], lg[-1], SUB * (len(grid) - 1) + 1)
    rows = _rows(s)
    cols = [ch.R[rows]] + [_values(s, sp, sp["tau_s"])[rows][:, None] for sp in specs]
    trial, seen = {}, {}
    at = ch.R.shape[1] + len(specs)
    for i in lagged:
        key = (specs[i]["source"], specs[i]["minus"], specs[i]["p"])
        if key not in seen:     # terms of one source (the heat input's) share their trials
            cols.append(_trial_columns(s, specs[i], xs, rows))
            seen[key] = np.arange(at, at + len(xs))
            at += len(xs)
        trial[i] = seen[key]
    A = np.column_stack(cols + [ch.y[rows]])
    scaled = _scaled(A.T @ A)
    n_runs = ch.R.shape[1]
    cur = {i: n_runs + i for i in range(len(specs))}
    D = fit["design"][tr]
    p = int(np.sum(np.any(D != 0, axis=0))) + len(lagged)
    nu = max(float(SUB_BLOCKS * (int(ch.fold.max()) + 1)) - p, 1.0)
    rise = 1.0 + f_quantile(CONFIDENCE, nu) / nu
    out = [None] * len(specs)
    for i in lagged:
        x, pos = _trials(xs, math.log(specs[i]["tau_s"]), trial[i], cur[i])
        rss = _profile(scaled, n_runs, cur, trial, lagged, i, pos)
        out[i] = _interval(x, rss, rss.min() * rise)
    return out


def _trials(xs, x0, trial, here) -> tuple:
    """The trial values of ln tau (``xs`` united with ``x0``, clipped to ``xs``' range) and
    their columns in the Gram (``trial`` for ``xs``, ``here`` for ``x0``)."""
    x = np.unique(np.r_[xs, x0])
    x = x[(x >= xs[0] - 1e-12) & (x <= xs[-1] + 1e-12)]
    pos = np.array([here if v == x0 else trial[int(np.searchsorted(xs, v))] for v in x])
    return x, pos


def _profile(scaled, n_runs, cur, trial, lagged, i, pos) -> np.ndarray:
    """RSS (um^2) at each trial column ``pos`` of term ``i``: the other lagged terms'
    columns chosen by one coordinate pass in their order, each the least RSS of its trials
    ``trial[j]`` with the others at their current columns (the fitted taus at the start);
    ``scaled`` the Gram of :func:`_scaled`."""
    X = len(pos)
    now = np.array([[cur[k] for k in sorted(cur)] for _ in range(X)])   # (X, terms)
    now[:, i] = pos
    runs = np.broadcast_to(np.arange(n_runs), (X, n_runs))
    best = None
    for j in [k for k in lagged if k != i]:
        T = trial[j]
        r = _rss(scaled, np.concatenate([runs, np.delete(now, j, axis=1)], axis=1), T)
        k = np.argmin(r, axis=1)
        now[:, j] = T[k]
        best = r[np.arange(X), k]
    if best is None:          # no other lagged term: the other columns the same at every x
        best = _rss(scaled, np.r_[np.arange(n_runs), np.delete(now[0], i)][None, :], pos)[0]
    return best


def _scaled(G) -> tuple:
    """The Gram's columns scaled to unit norm (a column all zero kept: its scale 1), as
    :func:`volerr.selection.linalg.solve_scaled` scales: (Z'Z, Z'y, y'y) of the scaled
    columns (the RSS is that of the unscaled ones)."""
    d = np.sqrt(np.diag(G)[:-1])
    d = np.where(d > 0, d, 1.0)
    return G[:-1, :-1] / np.outer(d, d), G[:-1, -1] / d, float(G[-1, -1])


def _rss(scaled, fixed, T) -> np.ndarray:
    """RSS (len(fixed), len(T)) of y on the columns ``fixed[x]`` of the Gram plus each trial
    column ``T[t]`` in turn, on the scaled columns (:func:`_scaled`): the bordered system of
    :func:`volerr.loop.drift.engine.rss_stack`, one pseudo-inverse per row of ``fixed``."""
    Gs, hs, yy = scaled
    return rss_stack(Gs, hs, yy, fixed, np.asarray(T))


def _interval(x, rss, thr) -> list:
    """Hull of ``{x : rss <= thr}`` (ln tau), ends interpolated linearly; [lo, hi] s, None
    for an end at the first or last trial value (open)."""
    inside = np.flatnonzero(rss <= thr)
    a, b = int(inside[0]), int(inside[-1])

    def cross(k, m):          # k inside, m outside
        return x[k] + (thr - rss[k]) / (rss[m] - rss[k]) * (x[m] - x[k])
    lo = None if a == 0 else math.exp(cross(a, a - 1))
    hi = None if b == len(x) - 1 else math.exp(cross(b, b + 1))
    return [lo, hi]


def _stride(s) -> int:
    """k of :func:`_rows`: 1, or ceil(n / ``THIN_ABOVE``) above ``THIN_ABOVE`` training
    readings."""
    n = int(s.train.sum())
    return 1 if n <= THIN_ABOVE else math.ceil(n / THIN_ABOVE)


def _rows(s) -> np.ndarray:
    """The training readings (indices) the Gram is taken on: all, or above ``THIN_ABOVE``
    every k-th of each run's (k = :func:`_stride`)."""
    idx = np.flatnonzero(s.train)
    k = _stride(s)
    if k == 1:
        return idx
    return np.concatenate([idx[s.run[idx] == r][::k] for r in range(len(s.runs))])


def _values(s, sp, tau) -> np.ndarray:
    """A term's column (N,) at the lag ``tau`` s (as :func:`volerr.loop.drift.fit.column`,
    from its memo when there, not stored: the trial columns are used once)."""
    key = (sp["source"], sp["minus"], sp["p"], float(tau))
    if key in s.memo:
        return s.memo[key]
    v = basis.series(s, sp["source"], float(tau), sp["p"])
    if sp["minus"]:
        v = v - basis.series(s, sp["minus"], float(tau))
    return v


def _trial_columns(s, sp, xs, rows) -> np.ndarray:
    """The term's columns at the lags exp(``xs``) s on the readings ``rows``
    (len(rows), len(xs)); kept in ``s.memo`` for the split (the runs' channels share them)."""
    key = ("_tau_trials", sp["source"], sp["minus"], sp["p"], s.test.tobytes(), len(xs),
           rows.tobytes())
    if key not in s.memo:
        u = basis.heat(s, sp["p"]) if sp["source"] == "heat" \
            else np.asarray(s.inputs[sp["source"]], float)
        if sp["minus"]:
            u = u - np.asarray(s.inputs[sp["minus"]], float)
        s.memo[key] = lag(u - s.zero(u), np.exp(xs), s.t_s, s.run, rows=rows,
                          step=_stride(s))
    return s.memo[key]
