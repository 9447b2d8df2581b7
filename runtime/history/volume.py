"""The volumetric error over the working volume from a history's parameters (``map=`` tolerances).

``M(p)`` = the largest length of the volumetric error vector (um) over the layout's travel
(tool point at the spindle reference, offset 0) for parameter values ``p``: the linear axes
at the corners of their travel (with the rotary axes fixed the error of the constant
parameters is affine in the linear axes, so its length is largest at a corner), the rotary
axes every :data:`ROTARY_STEP_DEG` (each angle once modulo 360).  The model is first order (linear in the parameters),
so ``E(pos) = sum_j A_j(pos) p_j`` with ``A_j`` the model's volumetric error for a unit value
of parameter j, computed once.  The parameters that enter: the layout's constants
(squareness, location and orientation of rotary axes: the ISO names of ``m.parameters``
that belong to no axis), in um or urad; every other name (a component error's polynomial
term) is listed as left out.

Forecast of ``M(t) <= T``: the parameters follow their trends (a parameter without a trend
keeps its last value), ``M`` is evaluated every :data:`STEP_DAYS` days from the last
entry over :data:`HORIZON_DAYS` (linear between); the date is the first day ``M >= T``.  Its 95 % interval: the 2.5 and
97.5 % quantiles of that day over :data:`SAMPLES` draws of every trend's (value, slope) from
its covariance (normal, a fixed seed: the same history gives the same interval); an end is
open (``None``) when more than 2.5 % of the draws never reach T within the horizon.
"""

from __future__ import annotations

import itertools

import numpy as np

#: angle step of the rotary axes' grid, deg
ROTARY_STEP_DEG = 30.0
#: days after the last entry the forecast looks ahead
HORIZON_DAYS = 3650
#: days between the evaluations of M (linear between them)
STEP_DAYS = 7.0
#: Monte Carlo draws of the trends
SAMPLES = 200
#: seed of the draws
SEED = 37
_SCALE = {"um": 1e-3, "urad": 1e-6}


def sensitivities(layout: str, units: dict) -> tuple[list, np.ndarray, list]:
    """(names used, A of shape (n_points, 3, n_used) in um per report unit, names left out);
    ``units``: {name: report unit} of the history's parameters."""
    from ..machine import load

    m = load(layout)
    grids = [_rotary_grid(*m.travel[a]) if a in m.rotary_axes else np.array(m.travel[a])
             for a in m.axes]
    pos = np.array(list(itertools.product(*grids)))
    used = [n for n in sorted(units) if n in m.parameters and m.parameter_axis.get(n) is None
            and units[n] in _SCALE]
    cols = [m.volumetric_error(pos, {n: _SCALE[units[n]]}) * 1e3 for n in used]
    A = np.stack(cols, axis=2) if cols else np.zeros((len(pos), 3, 0))
    return used, A, [n for n in sorted(units) if n not in used]


def _rotary_grid(lo: float, hi: float) -> np.ndarray:
    """Angles every :data:`ROTARY_STEP_DEG` over the travel, each angle once modulo 360."""
    n = int(np.floor((hi - lo) / ROTARY_STEP_DEG + 1e-9)) + 1
    a = lo + ROTARY_STEP_DEG * np.arange(n)
    _, first = np.unique(np.round(np.mod(a, 360.0), 9), return_index=True)
    return a[np.sort(first)]


def map_max(A: np.ndarray, p: np.ndarray) -> np.ndarray:
    """M for parameter vectors ``p`` of shape (n_t, n_used) -> (n_t,) um."""
    k, _, n = A.shape
    e = (A.reshape(k * 3, n) @ p.T).reshape(k, 3, len(p))
    return np.sqrt((e ** 2).sum(1)).max(0)


def _first(days: np.ndarray, m: np.ndarray, tol: float) -> float:
    """The first day ``m`` reaches ``tol`` (linear between the grid days), inf if never."""
    h = np.flatnonzero(m >= tol)
    if not len(h):
        return np.inf
    i = int(h[0])
    if i == 0:
        return float(days[0])
    return float(days[i - 1] + (tol - m[i - 1]) / (m[i] - m[i - 1]) * (days[i] - days[i - 1]))


def forecast(A: np.ndarray, lines: list, tol: float, t_last: float) -> dict:
    """``{"date_day", "interval_days": [lo, hi], "now_um"}`` (days since 1970, None: not
    reached / open) of ``M(t) >= tol``; ``lines``: one (a, b, cov(2x2), t0) per used
    parameter (b = 0 and a zero covariance for a parameter without trend).  M is evaluated
    every :data:`STEP_DAYS` days and interpolated linearly between."""
    days = t_last + np.arange(0.0, HORIZON_DAYS + STEP_DAYS, STEP_DAYS)
    a = np.array([ln[0] for ln in lines])
    b = np.array([ln[1] for ln in lines])
    t0 = np.array([ln[3] for ln in lines])
    dt = days[:, None] - t0[None, :]
    central = map_max(A, a[None, :] + b[None, :] * dt)
    day0 = _first(days, central, tol)
    rng = np.random.default_rng(SEED)
    draws = np.zeros((SAMPLES, len(lines), 2))
    for j, ln in enumerate(lines):
        cov = np.asarray(ln[2], float)
        w, v = np.linalg.eigh(cov)
        root = v * np.sqrt(np.clip(w, 0.0, None))
        draws[:, j, :] = np.array([ln[0], ln[1]]) + rng.standard_normal((SAMPLES, 2)) @ root.T
    first = np.array([_first(days, map_max(A, d[:, 0][None, :] + d[:, 1][None, :] * dt), tol)
                      for d in draws])
    lo = np.quantile(first, 0.025, method="lower")
    hi = np.quantile(first, 0.975, method="higher")
    return {"date_day": None if not np.isfinite(day0) else round(day0),
            "interval_days": [None if not np.isfinite(lo) else float(np.floor(lo)),
                              None if not np.isfinite(hi) else float(np.ceil(hi))],
            "now_um": float(central[0])}
