"""A machine's history, parameter by parameter: control charts, change points, trends, forecasts.

Every parameter's entries form a series ``(t_i, y_i, s_i)``: the entry's date (days), value
and stated standard uncertainty (k = 1) in the parameter's report unit.  A check's value is
its reference's value plus the stated change (:mod:`volerr.history.results`); an entry with
no number for the parameter is left out.  The steps, in order:

1. **Control charts** (phase 2, standard values given).  Centre line ``X0`` = the value of
   the first calibration of the machine (its reference), ``sigma_i`` = the stated
   uncertainty of entry i combined with the reference's, ``sqrt(s_i^2 + s_0^2)``.
   *Shewhart individuals chart* (ISO 7870-2:2023, 5.3 and 6.5): limits ``X0 +- 3 sigma_i``;
   the moving-range estimate ``MR / d2`` (d2 = 1.128) is reported beside the stated
   sigma, as a check of the stated uncertainties.  *EWMA chart* (ISO 7870-6:2016; Roberts
   1959): ``z_i = lambda y_i + (1 - lambda) z_(i-1)``, ``z_0 = X0``, limits ``X0 +- L
   sqrt(Var z_i)`` with ``Var z_i = sum_k lambda^2 (1 - lambda)^(2(i-k)) sigma_k^2`` (with
   one sigma this is the standard's ``sigma^2 lambda/(2-lambda) [1 - (1-lambda)^(2i)]``),
   ``lambda`` = :data:`EWMA_LAMBDA`, ``L`` = :data:`EWMA_L`.
2. **Change points** (steps in the level).  The model ``y = a + b t + sum_k d_k H(t - tau_k)
   + sum_j g_j (t - tau_j)+`` (a step ``d_k`` at each change point, and where a drift starts,
   stops or turns a change of slope ``g_j``, tried beside the steps so that it is not taken
   for a series of jumps; only steps are events) fitted by weighted
   least squares with weights ``1 / s_i^2``; steps are added one at a time (forward
   selection, the best position first) while the likelihood-ratio statistic ``chi2(without)
   - chi2(with)`` (scaled by the Birge ratio ``max(1, chi2/dof)`` of the larger model, when
   the scatter exceeds the stated uncertainties) exceeds the chi-square(1) quantile at
   ``1 - ALPHA / m`` (Bonferroni over the ``m`` positions a step could take;
   :data:`ALPHA`): a false event in a series without one has a probability of at most
   ``ALPHA``.  A step sits between two dates; its ``date`` is the first entry after it (a
   step at the newest entry cannot be told from an outlier until the next one).  BIC's
   penalty ``ln n`` (3.0 for 20 entries) lies far below this threshold (12.0 for 19
   positions): the best of 19 positions passes BIC in most clean series (19 P(chi2_1 > 3.0)
   = 1.6 expected passes), so BIC alone would draw events from noise.
3. **Trend**: a generalised least-squares line on the stretch after the parameter's last change
   (a step, or a change of slope: then from the entry where the new slope starts)
   (at least :data:`MIN_TREND_POINTS` entries), slope in unit per day with its standard
   uncertainty (stated uncertainties, scaled by the Birge ratio when larger than 1).  The
   checks on one reference calibration all carry that reference's error: the part of a
   check's stated uncertainty the reference's covariance gives (its budget's source
   ``reference ... (its covariance)``, ``c_i``) is correlated among them (covariance
   ``c_i c_j``, :func:`entry_covariance`), the rest independent.  A fit that took every
   entry as independent averaged the shared part away: on the demo's 20 weekly checks the
   line's value at the last check was stated to 0.065 um where the reference alone
   contributes 0.067 um.
4. **Forecast** of a tolerance ``|value| <= T``: the date the trend line reaches ``+T`` or
   ``-T`` (the side it moves towards), with a 95 % interval: the dates where the line's
   95 % confidence band reaches the limit (the inverse of the band, Fieller's solution;
   ``z`` = 1.96 with stated uncertainties, Student's t with the Birge ratio).  An open end
   (``None``) where the band never reaches the limit (a slope not significantly towards it).
"""

from __future__ import annotations

import datetime as _dt
import math
from dataclasses import dataclass, field

import numpy as np

#: EWMA smoothing constant (ISO 7870-6 suggests 0.05 ... 0.3; 0.2 with L = 3 is the common
#: choice for shifts of about one sigma)
EWMA_LAMBDA = 0.2
#: EWMA limit width in sigma of z_i
EWMA_L = 3.0
#: Shewhart limit width (ISO 7870-2 action limits)
SHEWHART_K = 3.0
#: d2 for moving ranges of two successive values (ISO 7870-2 Table 2, n = 2)
D2_N2 = 1.128
#: the false-event probability per parameter series of the change-point rule
ALPHA = 0.01
#: the kinds of change point
STEP, SLOPE = "step", "slope"
#: the fewest entries a trend (and a change point) is fitted from
MIN_TREND_POINTS = 3
#: two-sided 95 % normal quantile of the forecast interval
Z95 = 1.959963984540054


@dataclass
class Series:
    """One parameter's numeric entries in date order: ``dates`` (ISO), ``t`` days since the
    machine's first entry, values ``y`` and standard uncertainties ``s`` in ``unit``."""
    name: str
    unit: str
    dates: list
    t: np.ndarray
    y: np.ndarray
    s: np.ndarray
    kinds: list = field(default_factory=list)
    #: per entry the part of ``s`` its reference shares with the other checks on it (0 for
    #: a calibration), and that reference (its SHA-256; None for a calibration)
    common: np.ndarray | None = None
    groups: list = field(default_factory=list)


def day(date: str) -> int:
    """Days since 1970-01-01 of an ISO date."""
    return _dt.date.fromisoformat(date).toordinal() - _dt.date(1970, 1, 1).toordinal()


def date_of(d: float) -> str | None:
    """ISO date of day ``d`` since 1970-01-01 (rounded to the nearest day); None beyond the
    calendar (years 1 to 9999: a forecast that far is "not foreseen")."""
    try:
        return (_dt.date(1970, 1, 1) + _dt.timedelta(days=int(round(d)))).isoformat()
    except (OverflowError, ValueError):
        return None


def series_of(entries) -> dict:
    """``{name: Series}`` of every parameter with at least one number (module docstring);
    entries with a std <= 0 are left out (no weight can be given to them)."""
    out: dict = {}
    for e in entries:
        for name, v in e.values.items():
            if v.value is None or v.std is None or not v.std > 0:
                continue
            shared = e.reference_sha256 if v.common else None
            out.setdefault(name, {"unit": v.unit, "rows": []})["rows"].append(
                (e.date, v.value, v.std, e.kind, v.common or 0.0, shared))
    series = {}
    for name in sorted(out):
        rows = out[name]["rows"]
        series[name] = Series(name, out[name]["unit"], [r[0] for r in rows],
                              np.array([day(r[0]) for r in rows], float),
                              np.array([r[1] for r in rows]), np.array([r[2] for r in rows]),
                              [r[3] for r in rows], np.array([r[4] for r in rows]),
                              [r[5] for r in rows])
    return series


# -- 1. control charts ----------------------------------------------------------------------
def control(s: Series) -> dict:
    """Shewhart individuals and EWMA charts of ``s`` against its first entry (step 1)."""
    x0, s0 = float(s.y[0]), float(s.s[0])
    sig = np.sqrt(s.s ** 2 + s0 ** 2)
    sig[0] = s0
    shew = [{"date": d, "value": float(y), "lcl": x0 - SHEWHART_K * g,
             "ucl": x0 + SHEWHART_K * g, "out": bool(abs(y - x0) > SHEWHART_K * g)}
            for d, y, g in zip(s.dates, s.y, sig)]
    lam = EWMA_LAMBDA
    z, var, ewma = x0, 0.0, []
    for d, y, g in zip(s.dates, s.y, sig):
        z = lam * y + (1 - lam) * z
        var = (1 - lam) ** 2 * var + lam ** 2 * g ** 2
        h = EWMA_L * math.sqrt(var)
        ewma.append({"date": d, "z": float(z), "lcl": x0 - h, "ucl": x0 + h,
                     "out": bool(abs(z - x0) > h)})
    mr = np.abs(np.diff(s.y))
    return {"centre": x0, "unit": s.unit,
            "sigma_moving_range": float(mr.mean() / D2_N2) if len(mr) else None,
            "shewhart": shew, "ewma": ewma, "ewma_lambda": lam, "ewma_L": EWMA_L}


# -- 2. change points -----------------------------------------------------------------------
def _wls(X: np.ndarray, y: np.ndarray, s: np.ndarray):
    """Weighted least squares: (coefficients, covariance (stated), chi2) or None when X is
    rank-deficient."""
    w = 1.0 / s
    A = X * w[:, None]
    b = y * w
    if np.linalg.matrix_rank(A) < X.shape[1]:
        return None
    q, r = np.linalg.qr(A)
    coef = np.linalg.solve(r, q.T @ b)
    rinv = np.linalg.inv(r)
    chi2 = float(np.sum((A @ coef - b) ** 2))
    return coef, rinv @ rinv.T, chi2


def entry_covariance(s: Series, rows: slice) -> np.ndarray:
    """The covariance of the entries ``rows`` of ``s`` (step 3): ``s_i^2`` on the diagonal,
    ``c_i c_j`` between two checks on the same reference (``c`` = :attr:`Series.common`,
    the reference's error every check on it carries); diagonal without ``common``."""
    u = s.s[rows]
    if s.common is None or not np.any(s.common[rows] > 0):
        return np.diag(u ** 2)
    c, g = s.common[rows], s.groups[rows]
    same = np.array([[a is not None and a == b for b in g] for a in g])
    V = np.where(same, np.outer(c, c), 0.0)
    V[np.diag_indices_from(V)] = u ** 2
    return V


def _gls(X: np.ndarray, y: np.ndarray, V: np.ndarray):
    """Generalised least squares with the covariance ``V``: :func:`_wls` of the rows whitened
    by the Cholesky factor ``V = L L^T`` (coefficients, covariance, chi2 of the whitened
    residual)."""
    L = np.linalg.cholesky(V)
    return _wls(np.linalg.solve(L, X), np.linalg.solve(L, y), np.ones(len(y)))


def wls_budget(X: np.ndarray, s: Series, rows: slice, j: int, phi: float,
               f: float = 1.0, correlated: bool = False) -> dict:
    """The GUM budget (:mod:`volerr.report.budget`, quantity named by the caller) of
    coefficient ``j`` (times ``f``) of the WLS fit of the entries ``rows`` of ``s`` on the
    columns ``X``: coef = C A^T (y / u) with A = X / u, C = (A^T A)^-1, so each entry i is a
    source, its stated u_i with the sensitivity f (C A^T)_ji / u_i; the scatter beyond the
    stated u (``phi`` = chi2 / dof above 1 widens the covariance by phi) one more source,
    f sqrt((phi - 1) C_jj).  The combined u is f sqrt(max(phi, 1) C_jj), the std stated.
    ``correlated``: the fit of :func:`trend` (generalised least squares over
    :func:`entry_covariance`), coef = C X^T V^-1 y with C = (X^T V^-1 X)^-1: each entry's own
    part sqrt(s_i^2 - c_i^2) one source, and the reference a group of checks shares one more,
    sensitivity f sum_i gain_i c_i."""
    from ..report.budget import budget, source

    u, dates = s.s[rows], s.dates[rows]
    V = entry_covariance(s, rows) if correlated else np.diag(u ** 2)
    Vi = np.linalg.inv(V)
    C = np.linalg.inv(X.T @ Vi @ X)
    gain = (C @ X.T @ Vi)[j]
    c = s.common[rows] if correlated and s.common is not None else np.zeros_like(u)
    own = np.sqrt(np.maximum(u ** 2 - c ** 2, 0.0))
    srcs = [source(f"entry of {d} (its stated u" + (", its reference's part apart)" if ci else
                                                     ")"), ui, s.unit, f * g)
            for d, ui, g, ci in zip(dates, own, gain, c)]
    groups = s.groups[rows] if correlated and s.groups else [None] * len(u)
    for ref in dict.fromkeys(x for x, ci in zip(groups, c) if x is not None and ci > 0):
        at = [i for i, x in enumerate(groups) if x == ref]
        srcs.append(source(f"the reference of the checks from {dates[at[0]]} (its covariance, "
                           f"common to its {len(at)} checks)", 1.0, s.unit,
                           f * float(sum(gain[i] * c[i] for i in at))))
    srcs.append(source(f"scatter beyond the stated u (chi2/dof = {phi:.3g}"
                       + (")" if phi > 1 else " <= 1: not widened)"),
                       abs(f) * math.sqrt(max(phi - 1.0, 0.0) * C[j, j]), s.unit))
    return budget("", s.unit, srcs, 2.0)


def _chi2_isf(p: float, dof: int) -> float:
    from scipy.stats import chi2

    return float(chi2.isf(p, dof))


def _base(s: Series) -> np.ndarray:
    t = (s.t - s.t[0]) / 365.25          # years: a well-scaled column
    return np.column_stack([np.ones_like(t), t]) if np.ptp(s.t) > 0 else \
        np.ones((len(t), 1))


def _column(s: Series, cand: tuple) -> np.ndarray:
    """The design column of a change ``(k, kind)``: a step ``H`` from entry k on, or a
    change of slope ``(t - t_(k-1))+`` (years) from entry k - 1 on."""
    k, kind = cand
    if kind == STEP:
        return (np.arange(len(s.t)) >= k).astype(float)
    return np.clip(s.t - s.t[k - 1], 0.0, None) / 365.25


def _select(s: Series, base: np.ndarray, cands: list, threshold: float) -> list:
    """Forward selection of changes (step 2): the best candidate while its likelihood ratio
    exceeds ``threshold``; of candidates whose statistics agree to 1e-12 (relative) the
    first in ``cands`` (earlier entry, step before slope) is taken."""
    n = len(s.y)
    chosen: list = []
    cur = _wls(base, s.y, s.s)
    while cur is not None:
        best = None
        for c in cands:
            if c in chosen:
                continue
            X = np.column_stack([base] + [_column(s, x) for x in chosen + [c]])
            if X.shape[1] >= n:
                continue
            fit = _wls(X, s.y, s.s)
            if fit is None:
                continue
            phi = max(1.0, fit[2] / (n - X.shape[1]))
            stat = (cur[2] - fit[2]) / phi
            if best is None or stat > best[0] + 1e-12 * max(1.0, abs(best[0])):
                best = (stat, c, fit)
        if best is None or best[0] <= threshold:
            break
        chosen.append(best[1])
        cur = best[2]
    return chosen


def changes(s: Series) -> list:
    """``[{"kind", "index", "date", "previous_date", "change", "std"}]``: the change points
    of ``s`` (step 2), in entry order.  ``kind`` ``step``: a jump of the level by ``change``
    (unit), dated by the first entry after it (``index``); ``slope``: a change of the slope by
    ``change`` (unit per day) from entry ``index`` on (a drift that starts, stops or turns;
    tried beside the steps so that it is not mistaken for a series of jumps, and not an
    event)."""
    n = len(s.y)
    if n < MIN_TREND_POINTS:
        return []
    base = _base(s)
    pos = [k for k in range(1, n) if s.t[k] > s.t[k - 1]]
    cands = [(k, kind) for k in pos for kind in (STEP, SLOPE)
             if kind == STEP or 1 < k < n - 1]
    if not cands:
        return []
    chosen = _select(s, base, cands, _chi2_isf(ALPHA / len(cands), 1))
    if not chosen:
        return []
    X = np.column_stack([base] + [_column(s, c) for c in chosen])
    coef, cov, chi2 = _wls(X, s.y, s.s)
    phi = max(1.0, chi2 / (n - X.shape[1]))
    nb = base.shape[1]
    out = []
    for i, (k, kind) in enumerate(chosen):
        f = 1.0 if kind == STEP else 1.0 / 365.25
        at = k if kind == STEP else k - 1
        out.append({"kind": kind, "index": at, "date": s.dates[at],
                    "previous_date": s.dates[at - 1] if at > 0 else None,
                    "change": float(coef[nb + i]) * f,
                    "std": float(math.sqrt(cov[nb + i, nb + i] * phi)) * f,
                    "budget": wls_budget(X, s, slice(None), nb + i, phi, f)})
    return sorted(out, key=lambda e: (e["index"], e["kind"]))


def steps(s: Series) -> list:
    """The steps (events) among :func:`changes`."""
    return [c for c in changes(s) if c["kind"] == STEP]


# -- 3. trend -------------------------------------------------------------------------------
@dataclass
class Trend:
    """``value(t) = a + b (t - t0)`` (t in days) with the covariance ``cov`` of (a, b)."""
    a: float
    b: float
    cov: np.ndarray
    t0: float
    n: int
    since: str
    scaled: bool
    dof: int
    budget: dict | None = None      # of the slope b (:func:`wls_budget`)

    def at(self, t: float) -> tuple[float, float]:
        """(value, standard uncertainty) of the line at day ``t``."""
        g = np.array([1.0, t - self.t0])
        return float(self.a + self.b * (t - self.t0)), float(math.sqrt(g @ self.cov @ g))


def trend(s: Series, start: int = 0) -> Trend | None:
    """The line of ``s`` from entry ``start`` on (step 3; generalised least squares over
    :func:`entry_covariance`); None with too few entries or a single date."""
    t, y = s.t[start:], s.y[start:]
    if len(t) < MIN_TREND_POINTS or np.ptp(t) <= 0:
        return None
    t0 = float(t[-1])
    X = np.column_stack([np.ones_like(t), t - t0])
    coef, cov, chi2 = _gls(X, y, entry_covariance(s, slice(start, None)))
    dof = len(t) - 2
    phi = chi2 / dof
    scaled = phi > 1.0
    cov = cov * max(1.0, phi)
    return Trend(float(coef[0]), float(coef[1]), cov, t0, len(t), s.dates[start], scaled,
                 dof, wls_budget(X, s, slice(start, None), 1, phi, correlated=True))


# -- 4. forecast ----------------------------------------------------------------------------
def _quantile(tr: Trend) -> float:
    if not tr.scaled:
        return Z95
    from scipy.stats import t as student

    return float(student.ppf(0.975, tr.dof))


def forecast(tr: Trend, tol: float) -> dict:
    """``{"date", "interval": [lo, hi], "limit", "state"}`` of ``|value| <= tol`` on the
    trend ``tr`` (step 4); dates ISO or None (never reached / open end)."""
    v_last, _ = tr.at(tr.t0)
    side = math.copysign(1.0, tr.b) if tr.b != 0 else math.copysign(1.0, v_last)
    limit = side * tol
    state = "outside" if abs(v_last) > tol else "inside"
    if tr.b == 0 or (state == "inside" and (limit - v_last) * tr.b < 0):
        return {"date": None, "interval": [None, None], "limit": limit, "state": state,
                "note": "the trend does not move towards the tolerance"}
    tau = (limit - tr.a) / tr.b
    z = _quantile(tr)
    c = tr.cov
    da = tr.a - limit
    qa = tr.b ** 2 - z * z * c[1, 1]
    qb = 2 * (tr.b * da - z * z * c[0, 1])
    qc = da * da - z * z * c[0, 0]
    lo = hi = None                  # open ends unless the band closes
    disc = qb * qb - 4 * qa * qc
    if disc >= 0 and qa != 0:
        r1, r2 = sorted([(-qb - math.sqrt(disc)) / (2 * qa), (-qb + math.sqrt(disc)) / (2 * qa)])
        if qa > 0:                  # slope significant: the band reaches L between r1, r2
            lo, hi = r1, r2
        elif tau <= r1:             # not significant: an open interval on one side
            hi = r1
        else:
            lo = r2
    return {"date": date_of(tr.t0 + tau),
            "interval": [None if lo is None else date_of(tr.t0 + lo),
                         None if hi is None else date_of(tr.t0 + hi)],
            "limit": limit, "state": state, "days_from_last": round(tau, 1)}
