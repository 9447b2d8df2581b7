"""Three-point (or more) laser-tracker identification of the six error motions of one axis.

What is identified
------------------
Points fixed on the moving component (spindle head for a linear axis, table for a rotary axis)
are measured at every commanded position.  The first position of each round is the reference:
the error motions are zero there by definition.  At a position ``s`` a point deviates from its
nominal position by (thesis eq. 30 linear, eq. 3.4 rotary; ``volerr.derive.three_point``)::

    Delta_i(s) = t(s) + e(s) x r_hat_i(s)

* ``t = (EX, EY, EZ)`` (mm): translation of the body point that coincided with the origin of the
  measurement frame at the reference position; for a rotary axis the frame origin lies on the
  axis (``origin`` moves it there if the frame was set up elsewhere).
* ``e = (EA, EB, EC)`` (rad): small right-hand rotations of the body about the frame axes x, y, z.
* ``r_hat_i``: the point's lever arm from the frame origin at its nominal pose: the reference
  coordinates for a linear axis, rotated by the nominal angle for a rotary axis.
* nominal pose: translation ``sense * (s - s_ref) * direction`` (linear) or rotation by
  ``sense * (s - s_ref)`` deg about ``direction`` through the origin (rotary).  ``direction`` is
  the layout's axis direction unless given; ``sense`` (+1/-1) is detected from the data by
  default, because it depends on whether the points ride on the tool or the table side and on
  the controller's rotation convention (the thesis turns the table by +C, eq. 3.2).

The results are the error motions of the component that carries the points, in the
measurement frame (INTERFACE.md), named ``E{X,Y,Z,A,B,C}{axis}``.

Estimation
----------
The default ``method="lsq"`` is (weighted) least squares over every point and all three
coordinates (``3n`` equations, 6 unknowns) at each position.  ``method="closed"`` uses the
Zhang & Hu closed forms of six selected equations (generated code, ``volerr.generated.
three_point``); ``cross_check`` compares them with least squares at every position.

Weights and uncertainty: without a tracker position the points are weighted equally and the
noise is estimated from the residuals (pooled over the round, ``3n - 6`` degrees of freedom per
position).  With ``tracker=(x, y, z)`` (mm, measurement frame) each point gets the covariance of
the thesis' laser-tracker figures (Leica AT960, sec. 2.8 of Appendix B): interferometer
MPE 0.4 um + 0.3 um/m along the beam, angle encoders MPE 15 um + 6 um/m across it, each MPE
taken as a rectangular distribution (standard uncertainty MPE / sqrt(3)); the deviation of a
point is a difference of two measurements (position and reference), so both covariances add.
Standard uncertainties of the identified motions are propagated from these (``(A^T W A)^-1``).

Degenerate geometry (coincident or collinear points) is refused: the condition number of the
coefficient matrix, with lever arms taken from the points' centroid and the rotation columns
scaled by the points' RMS spread, must stay below ``max_cond``.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from ..units import MM_PER_M, MM_PER_UM, UM_PER_MM, URAD_PER_RAD
from ..errors import InputError, require
from .motion import likely_cause, motion_fit, nominal as _nominal, rotation_matrix  # noqa: F401
from .tracker_io import Round, check_rounds

MOTION_PREFIX = ("EX", "EY", "EZ", "EA", "EB", "EC")
#: Leica AT960 MPE figures quoted in the thesis (Appendix B, 2.8): (constant um, um per m)
IFM_MPE = (0.4, 0.3)
ANGLE_MPE = (15.0, 6.0)


def tracker_covariance(points, tracker) -> np.ndarray:
    """Covariance (mm^2) of tracker-measured points: shape (..., 3, 3) for points (..., 3).

    Along the beam (tracker -> point) the interferometer, across it the angle encoders; MPE
    figures of the thesis turned into standard uncertainties by MPE / sqrt(3)."""
    p = np.asarray(points, dtype=float)
    b = p - np.asarray(tracker, dtype=float)
    L = np.linalg.norm(b, axis=-1)
    require(np.all(L > 1.0), "tracker position coincides with a measured point")
    u = b / L[..., None]
    Lm = L / MM_PER_M
    s_r = (IFM_MPE[0] + IFM_MPE[1] * Lm) * MM_PER_UM / math.sqrt(3.0)
    s_t = (ANGLE_MPE[0] + ANGLE_MPE[1] * Lm) * MM_PER_UM / math.sqrt(3.0)
    uu = u[..., :, None] * u[..., None, :]
    eye = np.eye(3)
    return s_r[..., None, None] ** 2 * uu + s_t[..., None, None] ** 2 * (eye - uu)


def _gen():
    from volerr.generated import three_point as gen  # numpy only

    return gen


def design(lever) -> np.ndarray:
    """Coefficient blocks ``[I, -[r]x]`` (Delta = A (t, e)): lever (..., 3) mm -> (..., 3, 6).

    Generated from :func:`volerr.derive.three_point.design_block` (thesis eq. 31)."""
    lever = np.asarray(lever, dtype=float)
    block = _gen().design_block(lever[..., 0], lever[..., 1], lever[..., 2])
    return np.moveaxis(block, (0, 1), (-2, -1))


def geometry_condition(lever) -> float:
    """Scale-free condition number of the identification for points at ``lever`` (n, 3), mm:
    lever arms from the centroid, rotation columns scaled by the RMS spread."""
    lever = np.asarray(lever, dtype=float)
    c = lever - lever.mean(axis=0)
    spread = math.sqrt(float(np.mean(np.sum(c ** 2, axis=1))))
    if spread < 1e-9:
        return math.inf
    A = design(c).reshape(-1, 6) / np.array([1, 1, 1, spread, spread, spread])
    s = np.linalg.svd(A, compute_uv=False)
    return math.inf if s[-1] <= s[0] * 1e-15 else float(s[0] / s[-1])


@dataclass
class RoundResult:
    """Identification of one round (positions in measurement order, reference first).

    ``values``/``u``: (n_positions, 6) error motions (mm, rad) and their standard uncertainties
    (propagated); ``residuals``: (n_positions, n_points, 3) mm; ``deltas``: measured deviations
    from the nominal pose, same shape."""

    name: str
    positions: np.ndarray
    labels: tuple
    values: np.ndarray
    u: np.ndarray
    residuals: np.ndarray
    deltas: np.ndarray
    condition: float
    sense: int
    sigma_mm: float
    outliers: list = field(default_factory=list)
    closed_form: dict = field(default_factory=dict)
    chi2: float = 0.0       # sum of squared residuals in units of u (fit_quality)


@dataclass
class Identification:
    """Result of :func:`identify`: positions sorted, values averaged over rounds.

    ``values``, ``std`` (Type A, experimental standard deviation of one round, ``ddof=1``, the
    thesis' C.2/D.2), ``u_tracker`` (propagated standard uncertainty, mean over rounds in
    quadrature): (n_positions, 6) in mm / rad, motions ordered EX EY EZ EA EB EC."""

    axis: str
    kind: str
    positions: np.ndarray
    values: np.ndarray
    std: np.ndarray | None
    u_tracker: np.ndarray
    rounds: list
    method: str
    weighted: bool
    direction: tuple
    origin: tuple

    @property
    def names(self) -> tuple:
        """ISO names of the six motions, e.g. ``EXX ... ECX``."""
        return tuple(p + self.axis for p in MOTION_PREFIX)

    def errors_table(self, with_u95: bool | None = None):
        """The averaged result as a :class:`volerr.tables.table.ErrorTable` (formerly
        ``table()``; :meth:`table` is the contract's rows now).

        With several (n) rounds: ``s`` = the experimental standard deviation of one round
        (ddof = 1, the repeatability of one reading, column ``_s``) and ``std`` = s / sqrt(n),
        the standard uncertainty (Type A) of the tabulated mean (column ``_std``); ``u95``
        (k = 2) columns combine the propagated tracker uncertainty and that Type A
        uncertainty: ``2 sqrt(u_tracker^2 + s^2 / n)``; written by default only when weighted
        by a tracker position."""
        from ..tables.table import ErrorTable

        with_u95 = self.weighted if with_u95 is None else with_u95
        values = {n: self.values[:, j] for j, n in enumerate(self.names)}
        n_rounds = len(self.rounds)
        rep = {n: self.std[:, j] for j, n in enumerate(self.names)} if self.std is not None \
            else {}
        std = {n: v / np.sqrt(n_rounds) for n, v in rep.items()}
        u95 = {}
        if with_u95:
            var = self.u_tracker ** 2
            if self.std is not None:
                var = var + self.std ** 2 / len(self.rounds)
            u95 = {n: 2.0 * np.sqrt(var[:, j]) for j, n in enumerate(self.names)}
        return ErrorTable(self.axis, self.positions, values, std, u95, s=rep)

    def fit_quality(self):
        """The residual of every round's fit against the points' uncertainty
        (:class:`volerr.fit_quality.FitQuality`): ``(K - 1)(3 n - 6)`` degrees of freedom
        per round (K positions, the reference's residual 0 by definition; n points)."""
        from ..fit_quality import TRACKER_U_UM, judge

        dof = sum((r.positions.size - 1) * (3 * len(r.labels) - 6) for r in self.rounds)
        u = ("u of each point from the AT960 MPE figures at its distance from --tracker"
             if self.weighted else
             f"u assumed {TRACKER_U_UM:.3g} um per coordinate (no --tracker: the AT960 angle "
             f"MPE at 3 m, / sqrt 3)")
        return judge(sum(r.chi2 for r in self.rounds), dof, u)

    def outliers(self) -> list:
        """All flagged (round, position, point, residual_um, ratio) over rounds."""
        return [o for r in self.rounds for o in r.outliers]

    def summary(self) -> str:
        """The console text of ``volerr identify`` for this identification (the table not
        written: the API's call writes nothing)."""
        from .report import summary_lines

        return "\n".join(summary_lines(self.axis, self.report(), "(not written)"))

    def table(self):
        """The result contract's rows (:meth:`volerr.results.ResultMixin.table`): every
        motion at every position, um / urad, with its Type A standard uncertainty (k = 1)
        where there are several rounds (the error table itself: :meth:`errors_table`)."""
        from ..results import as_table

        return as_table(error_table_rows(self.errors_table()))

    def report(self) -> dict:
        """The JSON-friendly summary (um, urad): ``volerr identify --json`` (formerly
        ``summary()``)."""
        res = np.concatenate([r.residuals[1:].reshape(-1, 3) for r in self.rounds])
        norms = np.linalg.norm(res, axis=1) * UM_PER_MM
        scale = np.array([UM_PER_MM] * 3 + [URAD_PER_RAD] * 3)
        out = {
            "axis": self.axis, "kind": self.kind, "method": self.method,
            "weighted_by_tracker": self.weighted,
            "direction": list(self.direction), "origin_mm": list(self.origin),
            "n_rounds": len(self.rounds), "n_positions": int(self.positions.size),
            "points": list(self.rounds[0].labels),
            "sense": [r.sense for r in self.rounds],
            "condition": max(r.condition for r in self.rounds),
            "residual_rms_um": float(np.sqrt(np.mean(norms ** 2))) if norms.size else 0.0,
            "residual_max_um": float(norms.max()) if norms.size else 0.0,
            "noise_sigma_um": [r.sigma_mm * UM_PER_MM for r in self.rounds],
            "max_abs": {n: float(np.max(np.abs(self.values[:, j])) * scale[j])
                        for j, n in enumerate(self.names)},
            "outliers": [{"round": o[0], "position": o[1], "point": o[2],
                          "residual_um": o[3], "ratio": o[4]} for o in self.outliers()],
        }
        if self.std is not None:
            out["max_std"] = {n: float(np.max(self.std[:, j]) * scale[j])
                              for j, n in enumerate(self.names)}
        if self.weighted:
            out["max_u_tracker"] = {n: float(np.max(self.u_tracker[:, j]) * scale[j])
                                    for j, n in enumerate(self.names)}
        cf = [r.closed_form for r in self.rounds if r.closed_form]
        if cf:
            out["closed_form"] = {
                "selection": cf[0]["selection"], "roles": cf[0]["roles"],
                "thesis_choice_everywhere": all(c["thesis_choice_everywhere"] for c in cf),
                "consistency_max": max(c["consistency_max"] for c in cf),
                "vs_lsq_max": {n: max(c["vs_lsq_max"][n] for c in cf) for n in self.names},
                "noise_gain_vs_lsq": {n: _mean_or_none([c.get("noise_gain_vs_lsq", {}).get(n)
                                                        for c in cf]) for n in self.names},
            }
        return out


def error_table_rows(t) -> list:
    """:class:`volerr.results.Row` of every value of the error table ``t``: ``NAME(q)`` in um
    (translational) or urad (angular), its ``std`` (k = 1) where the table has one."""
    from ..results import Row

    out = []
    for name, values in t.values.items():
        f, unit = (1e6, "urad") if name[1] in "ABC" else (1e3, "um")
        std = t.std.get(name) if t.std else None
        for i, q in enumerate(t.positions):
            out.append(Row(f"{name}({q:g})", f * float(values[i]),
                           None if std is None else f * float(std[i]), unit, 1.0))
    return out


def error_table_budgets(t, n_rounds: int) -> dict:
    """The GUM budget (:mod:`volerr.report.budget`) of every row of
    :func:`error_table_rows` with a standard uncertainty: the Type A u of a mean of
    ``n_rounds`` rounds is the experimental standard deviation s of one round (the table's
    ``s``) with the sensitivity 1 / sqrt(n_rounds)."""
    from ..report.budget import budget, source

    out = {}
    for name, s in (t.s or {}).items():
        f, unit = (1e6, "urad") if name[1] in "ABC" else (1e3, "um")
        for i, q in enumerate(t.positions):
            row = f"{name}({q:g})"
            out[row] = budget(row, unit, [source(
                f"scatter of {n_rounds} rounds (Type A: s of one round; the tracker's own "
                f"u is in the _u95 column)", f * float(s[i]), unit,
                1.0 / math.sqrt(n_rounds))], 2.0, rows=[row])
    return out


def _mean_or_none(values):
    """Mean of the finite values (None when there is none: JSON null, never NaN)."""
    v = [float(x) for x in values if x is not None and math.isfinite(x)]
    return float(np.mean(v)) if v else None


def _layout_number(value, params: dict) -> float:
    """A layout coordinate: a number or an arithmetic expression in the layout parameters."""
    from ..machine.expressions import number

    return number(value, params, "the layout coordinate")


def _axis_geometry(layout, axis, direction, origin):
    require(axis in layout.axes, f"axis {axis!r} is not an axis of layout {layout.name} "
                                 f"(axes: {' '.join(layout.axis_names)})")
    ax = layout.axes[axis]
    if direction is None:
        direction = ax.direction
    d = np.asarray(direction, dtype=float)
    require(d.shape == (3,) and np.all(np.isfinite(d)) and np.linalg.norm(d) > 1e-12,
            "axis direction must be three finite numbers, not all zero")
    if isinstance(origin, str) and origin == "layout":
        require(ax.kind == "rotary", f"origin 'layout' applies to rotary axes; {axis} is linear")
        origin = [_layout_number(v, layout.parameters) for v in ax.point]
    o = np.zeros(3) if origin is None else np.asarray(origin, dtype=float)
    require(o.shape == (3,) and np.all(np.isfinite(o)), "origin must be three finite numbers")
    return ax.kind, d / np.linalg.norm(d), o


def _detect_sense(kind, pts, steps, d, o, name, sense, others=None):
    """Choose the sense (+1/-1) of the nominal motion that fits the data; refuse points that
    do not follow it, naming the likely cause (:mod:`volerr.identify.motion`); ``others``:
    {axis: (kind, direction)} of the layout's other axes."""
    senses = (1, -1) if sense in (None, 0, "auto") else (int(sense),)
    s, dev, limit = motion_fit(kind, pts, steps, d, o, senses)
    if dev > limit:
        cause = likely_cause(kind, pts, steps, d, o, senses, others or {})
        raise InputError(f"round {name}: measured points deviate up to {dev:.3g} mm from the "
                         f"nominal {'translation' if kind == 'linear' else 'rotation'} (limit "
                         f"{limit:.3g} mm): {cause}")
    return s


def _same_everywhere(M: np.ndarray) -> bool:
    """True when every position has the same matrix (a linear axis: the lever arms do not
    change along the travel), so that one inverse serves all."""
    return bool(len(M)) and bool(np.all(M == M[:1]))


def _solve(A, W, delta):
    """Batched weighted least squares. A (K, n, 3, 6), W (K, n, 3, 3) or None, delta (K, n, 3).
    Returns theta (K, 6), Ninv (K, 6, 6)."""
    K, n = A.shape[:2]
    A2 = A.reshape(K, 3 * n, 6)
    if W is None and _same_everywhere(A2):
        # one design for all positions (a linear axis): one normal matrix, one inverse, and
        # the right-hand sides of all positions in one matrix product
        Ninv1 = np.linalg.inv(A2[0].T @ A2[0])
        theta = (delta.reshape(K, 3 * n) @ A2[0]) @ Ninv1.T
        return theta, np.broadcast_to(Ninv1, (K, 6, 6))
    if W is None:
        N = np.einsum("knai,knaj->kij", A, A)
        rhs = np.einsum("knai,kna->ki", A, delta)
    else:
        WA = np.einsum("knab,knbj->knaj", W, A)
        N = np.einsum("knai,knaj->kij", A, WA)
        rhs = np.einsum("knai,knab,knb->ki", A, W, delta)
    Ninv = np.linalg.inv(N)
    theta = np.einsum("kij,kj->ki", Ninv, rhs)
    return theta, Ninv


@dataclass
class _ClosedChoice:
    """The Zhang & Hu candidate used at each position: ``cands`` lists (selection, point
    permutation) pairs, ``choice`` (K,) indexes them; ``pref`` is the axis' printed selection and
    ``spread`` the RMS distance of the points from their centroid, mm."""

    cands: list
    choice: np.ndarray
    pref: str
    spread: float


_ROLES = ("P", "Q", "K")


def _closed_choice(lever, axis, kind) -> _ClosedChoice:
    """Score every candidate by its normalised determinant N at every position and choose: the
    thesis' candidate unless it is below 0.1 of the best one there.  lever: (K, n, 3) mm."""
    from volerr.generated import three_point as gen

    K = lever.shape[0]
    pref = gen.AXIS_SELECTION.get(axis if kind == "linear" else "C", "x")
    c0 = lever[0] - lever[0].mean(axis=0)
    spread = math.sqrt(float(np.mean(np.sum(c0 ** 2, axis=1))))
    cands, scores, ranks = [], [], []
    # a linear axis has the same lever arms at every position: score them once
    geo = lever[:1] if kind == "linear" else lever
    for perm in itertools.permutations((0, 1, 2), 3):
        L = geo[:, perm, :]
        args = [L[:, i, c] for i in range(3) for c in range(3)]
        for sel in sorted(gen.SELECTIONS):
            N = np.broadcast_to(getattr(gen, f"det_{sel}")(*args)["N"], (geo.shape[0],))
            N = np.broadcast_to(N, (K,))
            cands.append((sel, perm))
            scores.append(np.abs(N) / spread ** 3)
            ranks.append((sel == pref) + (perm == (0, 1, 2)))
    scores = np.array(scores)                      # (n_cand, K)
    best = scores.max(axis=0)
    require(np.all(best[1:] > 1e-9) if K > 1 else True,
            "closed form: every Zhang & Hu selection is singular for these points (denominator "
            "N = 0); use the least-squares method")
    ok = scores >= 0.1 * best
    key = np.where(ok, np.array(ranks)[:, None] * 10.0 + scores / np.maximum(best, 1e-300), -1)
    return _ClosedChoice(cands, np.argmax(key, axis=0), pref, spread)


def _closed_solve(ch: _ClosedChoice, lever, dl, kind) -> np.ndarray:
    """The six error motions (K, 6) from the deviations ``dl`` (K, n, 3) by the chosen
    candidate at each position."""
    from volerr.generated import three_point as gen

    out = np.zeros((lever.shape[0], 6))
    for c in np.unique(ch.choice):
        sel, perm = ch.cands[c]
        m = ch.choice == c
        # lever arms: constants for a linear axis, per position for a rotary one
        L = lever[:1, perm, :] if kind == "linear" else lever[m][:, perm, :]
        D = dl[m][:, perm, :]
        ds = [D[:, _ROLES.index(lab), "xyz".index(co)] for lab, co in gen.SELECTIONS[sel]]
        solve = getattr(gen, f"solve_{sel}")
        out[m] = np.asarray(solve(*[L[:, i, co] for i in range(3) for co in range(3)],
                                  *ds)).T
    return out


def _closed_form(lever, delta, theta_lsq, axis, kind, A=None):
    """Zhang & Hu closed form on three points at every position; cross-check vs ``theta_lsq``.

    Candidates: the three row selections (eq. 32/3.6, 36, 37) x the 3! assignments of the first
    three points to the roles P, Q, K.  At each position the thesis' choice (the axis'
    selection, points in the given order) is used unless its determinant N is below 0.1 of the
    best candidate's there (for a rotary axis N changes with the angle and can pass through
    zero).  lever, delta: (K, n, 3)."""
    from volerr.generated import three_point as gen

    K = lever.shape[0]
    ch = _closed_choice(lever, axis, kind)
    cands, choice = ch.cands, ch.choice
    values = _closed_solve(ch, lever, delta, kind)
    A = design(lever) if A is None else A
    fitted = np.einsum("knij,kj->kni", A, theta_lsq)
    consistent = _closed_solve(ch, lever, fitted, kind)
    scale = np.array([1.0, 1.0, 1.0, ch.spread, ch.spread, ch.spread])
    used = [cands[c] for c in np.unique(choice[1:] if K > 1 else choice)]
    rows = {}
    for c in np.unique(choice):
        sel, perm = cands[c]
        rows[int(c)] = [(perm[_ROLES.index(lab)], "xyz".index(co)) for lab, co in
                        gen.SELECTIONS[sel]]
    return {
        "values": values,
        "selection": ",".join(sorted({sel for sel, _ in used})),
        "roles": [{_ROLES[i]: int(perm[i]) for i in range(3)} for _, perm in used],
        "consistency_max": float(np.max(np.abs((consistent - theta_lsq) * scale))),
        "vs_lsq": values - theta_lsq,
        "row_index": rows,
        "choice": choice,
        "thesis_choice_everywhere": bool(np.all([cands[c][0] == ch.pref and cands[c][1] ==
                                                 (0, 1, 2) for c in choice])),
    }


@dataclass
class _Geometry:
    """Step 1 of a round: nominal poses and measured deviations (K positions, n points)."""

    condition: float
    sense: int
    lever: np.ndarray   # (K, n, 3) mm, lever arms at the nominal pose
    delta: np.ndarray   # (K, n, 3) mm, measured minus nominal
    A: np.ndarray       # (K, n, 3, 6) design blocks


@dataclass
class _LsqFit:
    """Step 2 of a round: (weighted) least squares at every position."""

    theta: np.ndarray   # (K, 6) mm / rad, zero at the reference
    resid: np.ndarray   # (K, n, 3) mm
    u: np.ndarray       # (K, 6) propagated standard uncertainties
    sigma: float        # per-coordinate noise, mm
    W: np.ndarray | None


def _round_geometry(rnd: Round, kind, direction, origin, sense, max_cond,
                    others=None) -> _Geometry:
    """Check the point geometry, detect the sense and build the nominal pose (``others``:
    the layout's other axes, for naming what a round that does not follow the axis is)."""
    pts = rnd.points
    steps = rnd.positions - rnd.positions[0]
    cond = geometry_condition(pts[0])
    if not math.isfinite(cond):  # exactly singular: report the number a solver would give up at
        cond = 1.0 / np.finfo(float).eps
    require(cond <= max_cond,
            f"round {rnd.name}: degenerate point geometry (condition number {cond:.3g} > "
            f"{max_cond:.3g}): points {','.join(rnd.labels)} are coincident or (nearly) "
            f"collinear; use three well-spread, non-collinear points")
    s = _detect_sense(kind, pts, steps, direction, origin, rnd.name, sense, others)
    nom, lever = _nominal(kind, pts[0], steps, direction, origin, s)
    return _Geometry(cond, s, lever, pts - nom, design(lever))


def _round_lsq(rnd: Round, geo: _Geometry, tracker) -> _LsqFit:
    """Weighted (tracker covariance) or equal-weight least squares; noise pooled over the
    round (``3n - 6`` degrees of freedom per position) without a tracker position."""
    pts = rnd.points
    K, n, _ = pts.shape
    W = None
    if tracker is not None:
        cov = tracker_covariance(pts, tracker) + tracker_covariance(pts[0], tracker)[None]
        W = np.linalg.inv(cov)
    theta, Ninv = _solve(geo.A, W, geo.delta)
    theta[0] = 0.0
    resid = geo.delta - np.einsum("knij,kj->kni", geo.A, theta)
    resid[0] = 0.0
    if W is None:
        pooled = float(np.sum(resid[1:] ** 2)) / max((K - 1) * (3 * n - 6), 1)
        sigma = math.sqrt(pooled)
        cov_theta = pooled * Ninv
    else:
        cov_theta = Ninv
        sigma = float(np.sqrt(np.mean([np.trace(c) / 3 for c in
                                        tracker_covariance(pts[0], tracker)])))
    u = np.sqrt(np.clip(np.einsum("kii->ki", cov_theta), 0, None))
    u[0] = 0.0
    return _LsqFit(theta, resid, u, sigma, W)


def _closed_summary(closed: dict, rnd: Round, axis: str, u_closed, u_lsq) -> dict:
    """JSON-friendly comparison of the closed form with least squares (um, urad)."""
    K = u_lsq.shape[0]
    names = tuple(p + axis for p in MOTION_PREFIX)
    diff = np.abs(closed["vs_lsq"][1:]) if K > 1 else np.zeros((1, 6))
    out = {"selection": closed["selection"],
           "roles": [{k: rnd.labels[v] for k, v in r.items()} for r in closed["roles"]],
           "thesis_choice_everywhere": closed["thesis_choice_everywhere"],
           "consistency_max": closed["consistency_max"],
           "vs_lsq_max": {nm: float(diff[:, j].max()) * (UM_PER_MM if j < 3 else URAD_PER_RAD)
                          for j, nm in enumerate(names)}}
    if K > 1:
        import warnings

        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN: noise-free data
            gain = np.nanmedian(u_closed[1:] / u_lsq[1:], axis=0)
        out["noise_gain_vs_lsq"] = {nm: float(gain[j]) if np.isfinite(gain[j]) else None
                                    for j, nm in enumerate(names)}
    return out


def identify_round(rnd: Round, kind: str, axis: str, direction, origin, *, method="lsq",
                   tracker=None, sense="auto", max_cond=1e4, outlier_k=5.0,
                   cross_check=True, others=None) -> RoundResult:
    """Identify the six error motions of one round (see the module docstring).

    Steps: geometry and nominal pose, least squares, closed form (method or cross-check),
    outliers (always judged on the least-squares residuals: the closed form fits six equations
    exactly and leaves all misfit in the other three)."""
    n = rnd.points.shape[1]
    geo = _round_geometry(rnd, kind, direction, origin, sense, max_cond, others)
    lsq = _round_lsq(rnd, geo, tracker)
    closed = {}
    if method == "closed":
        closed = _closed_form(geo.lever, geo.delta, lsq.theta, axis, kind, geo.A)
    elif cross_check and n >= 3:
        # only a cross-check: points at one height (a common set-up on a rotary table) make
        # every Zhang & Hu selection singular, while least squares is well determined
        try:
            closed = _closed_form(geo.lever, geo.delta, lsq.theta, axis, kind, geo.A)
        except InputError:
            closed = {}
    u_closed = _closed_uncertainty(geo.A, closed, lsq.W, lsq.sigma) if closed else None
    outliers = _flag_outliers(rnd, lsq.resid, lsq.W, lsq.sigma, n, outlier_k)
    theta, resid, u = lsq.theta, lsq.resid, lsq.u
    if method == "closed":
        theta = closed["values"].copy()
        theta[0] = 0.0
        resid = geo.delta - np.einsum("knij,kj->kni", geo.A, theta)
        resid[0] = 0.0
        u = u_closed
    summary_cf = _closed_summary(closed, rnd, axis, u_closed, lsq.u) if closed else {}
    return RoundResult(rnd.name, rnd.positions.copy(), rnd.labels, theta, u, resid, geo.delta,
                       geo.condition, geo.sense, lsq.sigma, outliers, summary_cf,
                       _chi2(resid, lsq.W))


def _chi2(resid, W) -> float:
    """The round's residuals (K, n, 3) mm in units of their standard uncertainty: the
    tracker covariance ``W`` (inverse, with ``--tracker``), else
    :data:`volerr.fit_quality.TRACKER_U_UM` per coordinate (:mod:`volerr.fit_quality`)."""
    from ..fit_quality import TRACKER_U_UM

    r = resid[1:]
    if W is not None:
        return float(np.einsum("kna,knab,knb->", r, W[1:], r))
    return float(np.sum(r ** 2)) / (TRACKER_U_UM * MM_PER_UM) ** 2


def _closed_uncertainty(A, closed, W, sigma):
    """Standard uncertainties (K, 6) of the closed form: propagated through the six selected
    equations of every position (equal weights: per-coordinate noise ``sigma``)."""
    K = A.shape[0]
    choice = closed["choice"]
    As = np.empty((K, 6, 6))
    S = np.zeros((K, 6, 6))
    cov_full = np.linalg.inv(W) if W is not None else None
    for c, rows in closed["row_index"].items():
        m = choice == c
        for a, (i, co) in enumerate(rows):
            As[m, a, :] = A[m, i, co, :]
            if cov_full is not None:
                for b, (j, d) in enumerate(rows):
                    if i == j:
                        S[m, a, b] = cov_full[m, i, co, d]
    if W is None and _same_everywhere(As):
        As = As[:1]     # one design for all positions: one inverse, one covariance
    Ainv = np.linalg.inv(As)
    if W is None:
        covs = sigma ** 2 * np.einsum("kij,klj->kil", Ainv, Ainv)
    else:
        covs = np.einsum("kij,kjl,kml->kim", Ainv, S, Ainv)
    u = np.broadcast_to(np.sqrt(np.clip(np.einsum("kii->ki", covs), 0, None)), (K, 6)).copy()
    u[0] = 0.0
    return u


def _flag_outliers(rnd, resid, W, sigma, n, k):
    """Points whose residual is far above the tracker noise: (round, position, point, um, ratio).

    The expected squared (weighted) residual of one point is ``(3n - 6) / n`` times its noise
    variance per coordinate; with equal weights the noise is estimated robustly (median)."""
    K = resid.shape[0]
    if K < 2:
        return []
    frac = (3 * n - 6) / n
    if W is not None:
        z2 = np.einsum("kna,knab,knb->kn", resid, W, resid)
    else:
        r2 = np.sum(resid[1:] ** 2, axis=-1)
        # median of chi2(3)/3 is 0.7887: robust per-coordinate variance of the residuals
        robust = float(np.median(r2)) / (3 * 0.7887 * frac) if r2.size else 0.0
        var = max(robust, (1e-7) ** 2)
        z2 = np.sum(resid ** 2, axis=-1) / var
    ratio = np.sqrt(z2 / (3 * frac))
    out = []
    for kk, i in zip(*np.nonzero(ratio > k)):
        if kk == 0:
            continue
        out.append((rnd.name, float(rnd.positions[kk]), rnd.labels[i],
                    float(np.linalg.norm(resid[kk, i]) * UM_PER_MM), float(ratio[kk, i])))
    return out


def _check_travel(rounds, layout, axis: str) -> None:
    """Refuse commanded positions outside the travel of ``axis`` of ``layout`` (one line
    naming the file and the column position: a file of another machine, a wrong layout, or
    positions negated when every negated one lies inside the travel)."""
    ax = layout.axes.get(axis)
    if ax is None or not rounds:
        return
    lo, hi = (float(v) for v in ax.travel)
    pos = np.concatenate([np.asarray(r.positions, dtype=float) for r in rounds])
    pad = 1e-6 * max(1.0, hi - lo)
    bad = pos[(pos < lo - pad) | (pos > hi + pad)]
    if bad.size:
        unit = "deg" if ax.kind == "rotary" else "mm"
        negated = bool(np.all((-pos >= lo - pad) & (-pos <= hi + pad)))
        cause = ("likely the positions with the wrong sign (negated, every one lies inside the "
                 "travel: a controller counting the other way?), or a file of another machine"
                 if negated else "a file of another machine, or the wrong layout?")
        raise InputError(f"{rounds[0].name.rsplit(':', 1)[0]}: column position: {axis} = "
                         f"{float(bad[np.argmax(np.abs(bad))]):g} {unit} lies outside the travel "
                         f"of {layout.name}'s {axis} ({lo:g} .. {hi:g} {unit}): {cause}")


#: no laser tracker measures closer than this, mm (their ranges start at 0.5 .. 1 m; the
#: interferometer's figures of :data:`IFM_MPE` hold from there)
TRACKER_MIN_RANGE_MM = 200.0


def _check_tracker_range(tracker: np.ndarray, rounds) -> None:
    """Refuse a tracker position closer than :data:`TRACKER_MIN_RANGE_MM` to a measured point
    (one line naming ``--tracker``): a position typed in m (1.5 -2 0.3 for 1500 -2000 300)."""
    pts = np.concatenate([r.points.reshape(-1, 3) for r in rounds])
    near = float(np.min(np.linalg.norm(pts - tracker, axis=1)))
    if near >= TRACKER_MIN_RANGE_MM:
        return
    t = " ".join(f"{v:g}" for v in tracker)
    far = float(np.min(np.linalg.norm(pts - tracker * MM_PER_M, axis=1)))
    hint = (f"likely given in m: write {' '.join(f'{v * MM_PER_M:g}' for v in tracker)} (mm)"
            if far >= TRACKER_MIN_RANGE_MM else "a wrong unit or a wrong position?")
    raise InputError(f"--tracker {t}: the tracker stands {near:.0f} mm from the nearest measured "
                     f"point, closer than any laser tracker measures "
                     f"({TRACKER_MIN_RANGE_MM:g} mm); {hint}")


def identify(rounds, layout, axis: str, *, method: str = "lsq", tracker=None, direction=None,
             origin=None, sense="auto", max_cond: float = 1e4, outlier_k: float = 5.0,
             cross_check: bool = True) -> Identification:
    """Identify the six error motions of ``axis`` of ``layout`` from tracker rounds.

    Parameters
    ----------
    rounds : list of :class:`volerr.identify.tracker_io.Round`
        Measurements, mm in the measurement frame; every round the same points and positions.
    layout : Layout or str
        The machine layout (name or file) declaring ``axis``.
    method : "lsq" (default, weighted least squares over all points) or "closed" (Zhang & Hu).
    tracker : (3,) mm, optional
        Tracker position in the measurement frame: weights and propagated uncertainty from the
        AT960 figures.
    direction, origin : (3,), optional
        Axis direction (default: the layout's) and a point of a rotary axis in the measurement
        frame (default 0, 0, 0: the frame origin lies on the axis; ``"layout"``: the layout's
        ``point`` of the axis, for a measurement frame that is the machine frame).
    sense : "auto", +1 or -1
        Sense of the nominal motion (default: detected from the data).
    max_cond : float
        Largest accepted condition number of the point geometry (default 1e4).
    outlier_k : float
        Points whose residual exceeds ``outlier_k`` x the noise are flagged (default 5).
    cross_check : bool
        With ``method="closed"``: also report the closed form against least squares.

    Returns
    -------
    Identification
        Positions (n_positions,) sorted, mm or deg; ``values`` (n_positions, 6), the error
        motions EX EY EZ (mm) EA EB EC (rad) of the component carrying the points, zero at each
        round's reference position (the first position), averaged over the rounds; ``std``
        (Type A) and ``u_tracker`` the same shape.  ``.errors_table()`` gives the
        :class:`volerr.tables.ErrorTable`.
    """
    from ..machine.layout import Layout, read_layout

    if not isinstance(layout, Layout):
        layout = read_layout(layout)
    require(method in ("lsq", "closed"), f"unknown method {method!r} (lsq, closed)")
    kind, d, o = _axis_geometry(layout, axis, direction, origin)
    _check_travel(rounds, layout, axis)
    others = {n: (a.kind, tuple(np.asarray(a.direction, float) / np.linalg.norm(a.direction)))
              for n, a in layout.axes.items() if n != axis}
    rounds = list(rounds)
    check_rounds(rounds)
    # one reference for all rounds: the first position of the first round.  A round measured
    # in another order (e.g. backwards) is referred to it too, so that the rounds average
    # error motions of the same reference pose (their values at ``ref`` are zero).
    ref = rounds[0].positions[0]
    for i, r in enumerate(rounds):
        k = int(np.argmin(np.abs(r.positions - ref)))
        if k:
            order = [k] + [j for j in range(r.positions.size) if j != k]
            rounds[i] = Round(r.name, r.positions[order], r.labels, r.points[order])
    if tracker is not None:
        tracker = np.asarray(tracker, dtype=float)
        require(tracker.shape == (3,) and np.all(np.isfinite(tracker)),
                "tracker position must be three finite numbers (mm)")
        _check_tracker_range(tracker, rounds)
    # the same point order in every round
    labels = rounds[0].labels
    aligned = []
    for r in rounds:
        order = [r.labels.index(lab) for lab in labels]
        aligned.append(Round(r.name, r.positions, labels, r.points[:, order, :]))
    results = [identify_round(r, kind, axis, d, o, method=method, tracker=tracker, sense=sense,
                              max_cond=max_cond, outlier_k=outlier_k, cross_check=cross_check,
                              others=others)
               for r in aligned]
    positions = np.sort(rounds[0].positions)
    stack = np.empty((len(results), positions.size, 6))
    ustack = np.empty_like(stack)
    for i, res in enumerate(results):
        order = np.searchsorted(positions, res.positions)
        # positions of later rounds match within 1e-9; map by nearest
        order = np.array([int(np.argmin(np.abs(positions - p))) for p in res.positions]) \
            if not np.allclose(positions[order.clip(0, positions.size - 1)], res.positions) \
            else order
        stack[i, order] = res.values
        ustack[i, order] = res.u
    values = stack.mean(axis=0)
    std = stack.std(axis=0, ddof=1) if len(results) > 1 else None
    u_tr = np.sqrt(np.mean(ustack ** 2, axis=0))
    return Identification(axis, kind, positions, values, std, u_tr, results, method,
                          tracker is not None, tuple(float(v) for v in d),
                          tuple(float(v) for v in o))


def to_model_signs(table, layout, reference=None):
    """An identified table (error motions of the component carrying the points) in the
    volerr model's convention (tool relative to workpiece, ``volerr.machine.layout``).

    Tool-side axes keep their signs; the model's carriage frame pivots about the carriage point
    that is at the origin at ``q = 0``, the tracker's about the one there at the reference
    position ``q0``, so a linear tool-side axis measured from ``q0 != 0`` gets
    ``delta = t + q0 (e x u)`` (unchanged for ``q0 = 0``).  For a table axis the model gives the tool's
    error relative to the table with rotations pivoting about the tool reference point, which
    stays put while the table travels, whereas the tracker's pivot is the table point that was
    there at the reference position.  With ``t, e`` the table's own motions, ``u`` the axis
    direction and ``q - q0`` the travel from the reference position:

    * linear table axis: ``delta = -t - (q - q0) (e x u)``, ``eps = -e``;
    * rotary table axis (frame origin on the axis): ``delta = -t``, ``eps = -e``.

    Assumes the measurement frame origin at the tool reference point and its axes along the
    machine axes; for other measuring points use :meth:`volerr.machine.model.Model.transfer`.

    Parameters
    ----------
    table : volerr.tables.ErrorTable
        The identified table of one axis (:meth:`Identification.errors_table`): positions (n,) mm or
        deg, values mm (translational) / rad (angular).
    layout : Layout
        The machine layout declaring the axis (which chain carries it).
    reference : float, optional
        The reference position ``q0`` (errors zero there), mm or deg; default: the table's
        first position.

    Returns
    -------
    volerr.tables.ErrorTable
        The same positions, values in the model's convention (mm / rad); the table itself when
        nothing changes (a tool-side axis measured from ``q0 = 0`` or a tool-side rotary axis).
    """
    from ..tables.table import ErrorTable

    axis = table.axis
    require(axis in layout.axes, f"axis {axis} is not an axis of layout {layout.name}")
    tool_side = axis not in layout.workpiece_chain
    # the reference position q0 (errors zero there): the first position of the first round
    q0 = float(table.positions[0] if reference is None else reference)
    if tool_side and (layout.axes[axis].kind != "linear" or q0 == 0):
        return table
    zero = np.zeros_like(table.positions)
    motions = [table.values.get(p + axis, zero) for p in MOTION_PREFIX]
    u = np.asarray(layout.axes[axis].direction, dtype=float)
    if tool_side:
        # generated: t + q0 (e x u), e (volerr.derive.three_point.tool_side_signs)
        out = _gen().tool_side_signs(q0, *motions, *u)
        values = dict(table.values)
        for j, p in enumerate(MOTION_PREFIX[:3]):
            if p + axis in values or np.any(out[j]):
                values[p + axis] = out[j]
        return ErrorTable(axis, table.positions, values, table.std, table.u95, s=table.s)
    # generated: -t - travel (e x u), -e (volerr.derive.three_point.table_side_signs)
    travel = table.positions - q0 if layout.axes[axis].kind == "linear" else zero
    out = _gen().table_side_signs(travel, *motions, *u)
    values = {p + axis: out[j] for j, p in enumerate(MOTION_PREFIX) if p + axis in table.values}
    return ErrorTable(axis, table.positions, values, table.std, table.u95, s=table.s)
