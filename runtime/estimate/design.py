"""Fit a layout's model to measured volumetric deviations: linear least squares.

Model of the measured deviation ``d`` (actual minus nominal, mm) at point ``i``::

    d_i = sum_p S_p(q_i, probe_i) e_p(q_{axis(p), i})  +  S_setup(q_i, probe_i) s  +  noise

``S = model.sensitivity`` (generated from the layout's chain).  Every component error ``e_p`` is
a Legendre series of degree ``K`` in its own axis position (normalised to [-1, 1] over the
measured range); squareness, rotary location errors and effect parameters are constants; ``s``
is the rigid placement of the measuring instrument (three translations, three small rotations
of the workpiece end).  ``K`` is chosen by k-fold cross-validation.

Gauge.  Some combinations are not determined by *any* volumetric measurement: a constant of a
translational error against the instrument's translation, a straightness slope against
squareness and the instrument's rotation, and so on.  They are fixed by convention: columns
are taken in the order set-up, constants (squareness, location), degrees >= 2, angular slopes,
angular constants, translational slopes, translational constants, and a column
is dropped when it lies in the span of those before it on an *ideal* plan (the measured volume
filled, probe offsets along every axis).  What the ideal plan determines but the actual data
does not is a property of the measurement plan: it is reported (:func:`identifiability`),
never silently absorbed.

Columns are scaled to unit RMS before solving; solutions use the normal equations with an
eigenvalue cut-off (minimum norm in the scaled parameters along undetermined directions).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import require
from ..instruments.observations import Observations
from ..machine.model import Model
from ..selection.linalg import solve_normal as _solve_normal

SETUP = ("dx", "dy", "dz", "ex", "ey", "ez")
#: relative singular value below which a direction counts as undetermined
SV_TOL = 1e-6
#: relative distance below which a column counts as gauge on the ideal plan
GAUGE_TOL = 1e-4


#: the readings of any instrument (3-D deviations, ballbar lengths, sphere centres ...)
Data = Observations


def unit(q, lo, hi):
    """Position normalised to [-1, 1] over [lo, hi]."""
    return (2.0 * np.asarray(q, dtype=float) - (lo + hi)) / (hi - lo)


def legendre(u, degree: int) -> np.ndarray:
    """Legendre polynomials P_0 .. P_degree at u, shape (N, degree + 1)."""
    out = np.empty((len(u), degree + 1))
    out[:, 0] = 1.0
    if degree >= 1:
        out[:, 1] = u
    for k in range(2, degree + 1):
        out[:, k] = ((2 * k - 1) * u * out[:, k - 1] - (k - 1) * out[:, k - 2]) / k
    return out


#: measured ranges (deg) over which a rotary axis' component errors are Fourier series: the
#: axis turns (nearly) once round, its errors repeat every revolution.  Over several turns the
#: data tell positions a turn apart from each other and the series stays a polynomial.
FULL_TURN_DEG = (300.0, 370.0)


def periodic(model: Model, axis: str, ranges: dict) -> bool:
    """A rotary axis measured over about one full turn: its component errors are Fourier
    series in the angle (ISO 230-7: error motions repeat every revolution)."""
    lo, hi = ranges[axis]
    return (axis in model.rotary_axes
            and FULL_TURN_DEG[0] <= hi - lo <= FULL_TURN_DEG[1])


def series_basis(model: Model, axis: str, q, ranges: dict, degree: int) -> np.ndarray:
    """(N, degree + 1) basis of a component error of ``axis`` at positions ``q`` (mm | deg):
    Legendre polynomials P_0 .. P_degree over the measured range, or for a periodic rotary
    axis (:func:`periodic`) the Fourier terms 1, cos q, sin q, cos 2q, sin 2q, ... (the first
    harmonic of a radial or tilt error is the axis' location error, ISO 230-7: the gauge puts
    it there)."""
    if not periodic(model, axis, ranges):
        return legendre(unit(q, *ranges[axis]), degree)
    th = np.deg2rad(np.asarray(q, dtype=float))
    out = np.empty((len(th), degree + 1))
    out[:, 0] = 1.0
    for k in range(1, degree + 1):
        h = (k + 1) // 2
        out[:, k] = np.cos(h * th) if k % 2 else np.sin(h * th)
    return out


def data_ranges(model: Model, data: Data) -> dict:
    """Axis -> (lo, hi) of the measured positions (widened when an axis does not move)."""
    out = {}
    for a in model.axes:
        lo, hi = float(np.min(data.positions[a])), float(np.max(data.positions[a]))
        if hi - lo < 1e-9:
            lo, hi = lo - 0.5, hi + 0.5
        out[a] = (lo, hi)
    return out


def rotary_rad(model: Model, positions: dict) -> dict:
    """Positions with rotary axes in rad (the unit of the chain and of effect bases)."""
    return {a: (np.deg2rad(v) if a in model.rotary_axes else np.asarray(v, dtype=float))
            for a, v in positions.items()}


#: target name -> column of the generated ``setup_sensitivity`` (work end, then tool end)
TWIST = {f"{side}.{k}": 6 * i + j for i, side in enumerate(("work", "tool"))
         for j, k in enumerate(SETUP)}


def twist_sensitivity(model: Model, data: Data) -> np.ndarray:
    """(N, 3, 12) d(readings)/d(rigid twist) of the workpiece frame (columns 0-5: dx, dy, dz
    mm, ex, ey, ez rad; the instrument's placement) and of the tool end (6-11, tool frame): the
    generated ``setup_sensitivity`` of the layout's chain, seen by the instrument."""
    return data.twist(model)


@dataclass
class Design:
    """Columns of the declared model at the data points: ``A`` (N, 3, P), labels."""

    A: np.ndarray
    labels: list            # (parameter, degree) ; degree None for constants; ("setup", key)
    sens: np.ndarray        # model sensitivity (N, 3, n_parameters)
    twist: np.ndarray       # rigid-twist sensitivity (N, 3, 12), see twist_sensitivity


def parameter_labels(model: Model, degree: int) -> list:
    """Labels of the parameter columns: ``(name, None)`` for a constant, ``(name, k)`` for the
    term k of a component error's series (:func:`series_basis`)."""
    labels = []
    for p in model.parameters:
        labels += ([(p, None)] if model.parameter_axis.get(p) is None
                   else [(p, k) for k in range(degree + 1)])
    return labels


def declared_design(model: Model, data: Data, degree: int, ranges: dict) -> Design:
    """All columns of the declared model with component errors of degree ``degree``: the
    instruments' set-up columns (labels ``("setup", key)``), then the parameters."""
    sens = data.sensitivity(model)
    tw = twist_sensitivity(model, data)
    setup = data.setup_columns(tw)
    labels = [("setup", key) for key in data.setup_labels] + parameter_labels(model, degree)
    A = np.empty((data.n, 3, len(labels)))
    A[:, :, :setup.shape[2]] = setup
    bases = {a: series_basis(model, a, data.positions[a], ranges, degree) for a in model.axes}
    i = setup.shape[2]
    for j, p in enumerate(model.parameters):
        axis = model.parameter_axis.get(p)
        if axis is None:
            A[:, :, i] = sens[:, :, j]
            i += 1
            continue
        A[:, :, i:i + degree + 1] = sens[:, :, j, None] * bases[axis][:, None, :]
        i += degree + 1
    return Design(A, labels, sens, tw)


def _priority(label) -> int:
    p, k = label
    if p == "setup":
        return 0
    if k is None:
        return 1
    angular = p[1] in "ABC"
    if k >= 2:
        return 2
    if angular:
        return 3 if k == 1 else 4
    return 5 if k == 1 else 6


def independent_columns(G: np.ndarray, order, tol: float = 1e-7) -> np.ndarray:
    """Boolean mask of columns kept in ``order``: a column is dropped when its distance to the
    span of the kept ones is below ``tol`` times its norm.  ``G`` is the Gram matrix A^T A
    (incremental Cholesky on it: no tall decompositions)."""
    n = G.shape[0]
    keep = np.zeros(n, bool)
    L = np.zeros((n, n))
    kept: list[int] = []
    for j in order:
        gjj = G[j, j]
        if gjj <= 0:
            continue
        if kept:
            w = _forward(L[:len(kept), :len(kept)], G[kept, j])
            r2 = gjj - float(w @ w)
        else:
            w, r2 = np.zeros(0), gjj
        if r2 > tol * tol * gjj:
            k = len(kept)
            L[k, :k] = w
            L[k, k] = np.sqrt(r2)
            kept.append(j)
            keep[j] = True
    return keep


def _forward(L: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Solve L w = b for lower-triangular L."""
    from scipy.linalg import solve_triangular

    return solve_triangular(L, b, lower=True, check_finite=False)


def ideal_data(model: Model, data: Data, ranges: dict, n: int = 400, seed: int = 1) -> Data:
    """An ideal plan over the measured volume: probe offsets along every axis (gauge test)."""
    rng = np.random.default_rng(seed)
    pos = {a: rng.uniform(*ranges[a], n) for a in model.axes}
    lin = [ranges[a][1] - ranges[a][0] for a in model.axes if a not in model.rotary_axes]
    arm = 0.25 * max(lin or [400.0])
    base = np.mean(data.probe, axis=0)
    offs = np.array([[0, 0, 0], [arm, 0, 0], [-arm, 0, 0], [0, arm, 0], [0, -arm, 0],
                     [0, 0, arm], [0, 0, -arm]]) + base
    probe = offs[np.arange(n) % len(offs)]
    cov = {c: np.resize(np.asarray(data.covariates[c]), n) for c in model.covariates}
    return Data(pos, probe, np.zeros((n, 3)), cov)


def gauge_mask(model: Model, data: Data, degree: int, ranges: dict,
               parameters=None, constants: bool = True) -> tuple[np.ndarray, list]:
    """Columns of :func:`declared_design` on ``data`` kept after gauge fixing (see the module
    docstring) and the dropped labels.  The gauge is a property of the chain, found with all
    its parameters on an ideal 3-D plan with the instrument's rigid placement, whatever
    instruments ``data`` holds (so that the straightness slopes are carried by squareness on
    every instrument, as ISO 230-1's reference lines define them); every set-up column of
    ``data`` is kept.  ``parameters``: the names fitted (None: all); the others are left out
    (held at zero).  ``constants`` False: only terms of the component series are fixed by the
    gauge (offsets, straightness slopes), every constant fitted is kept and left to the
    identifiability analysis of the actual readings (what a sphere or a ballbar determines of
    a location error is not what a 3-D instrument with a rigid placement determines)."""
    ideal = ideal_data(model, data, ranges)
    d = declared_design(model, ideal, degree, ranges)
    A2 = d.A.reshape(-1, d.A.shape[-1])
    # correlation-scaled Gram (columns in mm and rad differ by orders of magnitude): on the
    # ideal plan a kept column is >= ~0.1 of its norm away from the span of the others and
    # a gauge column ~1e-7 (rounding), so 1e-4 separates them whatever the seed
    keep = independent_columns(_correlation(A2.T @ A2), priority_order(d.labels), GAUGE_TOL)
    chosen = np.array([p == "setup" or parameters is None or p in parameters
                       for p, _ in d.labels])
    if not constants:
        keep |= np.array([k is None and p != "setup" for p, k in d.labels])
    gauge = [d.labels[j] for j in np.flatnonzero(~keep & chosen)]
    keep &= chosen
    n_setup = len(data.setup_labels)
    keep = np.concatenate([np.ones(n_setup, bool), keep[len(SETUP):]])
    return keep, gauge


def _correlation(G: np.ndarray) -> np.ndarray:
    """Gram matrix of the columns scaled to unit norm (zero columns stay zero)."""
    s = np.sqrt(np.diag(G))
    s[s == 0] = 1.0
    return G / np.outer(s, s)


def priority_order(labels) -> list:
    """Column order of gauge fixing (see the module docstring)."""
    return sorted(range(len(labels)), key=lambda j: (_priority(labels[j]), j))


# ---- linear algebra -----------------------------------------------------------------
def solve_normal(G: np.ndarray, b: np.ndarray, tol: float = SV_TOL ** 2) -> np.ndarray:
    """Minimum-norm solution of G x = b (G symmetric PSD): eigenvalues below tol*max cut
    (:func:`volerr.selection.linalg.solve_normal`)."""
    return _solve_normal(G, b, tol)


def rows_of(points: np.ndarray) -> np.ndarray:
    """Row indices (point-major, 3 rows per point) of the given points."""
    return (3 * np.asarray(points)[:, None] + np.arange(3)).ravel()


class Problem:
    """A scaled linear least-squares problem on rows ``y`` (3 per point)."""

    def __init__(self, A2: np.ndarray, y: np.ndarray):
        self.scale = np.sqrt(np.mean(A2 ** 2, axis=0))
        self.scale[self.scale == 0] = 1.0
        self.A = A2 / self.scale
        self.y = y

    def fit(self, points=None) -> np.ndarray:
        """Coefficients (in unscaled column units) fitted on ``points`` (all when None)."""
        A, y = (self.A, self.y) if points is None else (self.A[rows_of(points)],
                                                          self.y[rows_of(points)])
        return solve_normal(A.T @ A, A.T @ y) / self.scale

    def predict(self, coef, points=None) -> np.ndarray:
        A = self.A if points is None else self.A[rows_of(points)]
        return A @ (coef * self.scale)

    def cv_residuals(self, folds, points) -> np.ndarray:
        """Held-out residual rows of ``points`` (k-fold, ``folds`` = fold label per point)."""
        r = np.empty(3 * len(points))
        rows = rows_of(points)
        A, y = self.A[rows], self.y[rows]
        G, b = A.T @ A, A.T @ y
        for f in np.unique(folds):
            m = np.repeat(folds == f, 3)
            Af, yf = A[m], y[m]
            c = solve_normal(G - Af.T @ Af, b - Af.T @ yf)
            r[m] = yf - Af @ c
        return r


    def loo_residuals(self, points) -> np.ndarray:
        """Leave-one-point-out residual rows of ``points`` (exact, one factorisation):
        r_loo_i = (I - H_ii)^-1 r_i with the 3x3 diagonal blocks H_ii of the hat matrix."""
        rows = rows_of(points)
        A, y = self.A[rows], self.y[rows]
        w, V = np.linalg.eigh(A.T @ A)
        ok = w > SV_TOL ** 2 * max(float(w[-1]), 1e-300)
        Gi = (V[:, ok] / w[ok]) @ V[:, ok].T
        r = y - A @ (Gi @ (A.T @ y))
        n, P = len(points), A.shape[1]
        B = (A @ Gi).reshape(n, 3, P)                  # one gemm, then 3x3 blocks
        A3 = A.reshape(n, 3, P)
        h = np.stack([np.sum(B[:, i, None, :] * A3, axis=2) for i in range(3)], axis=1)
        m = np.eye(3) - h
        det = np.linalg.det(m)
        m[np.abs(det) < 1e-9] = np.eye(3)      # a point that alone fixes a parameter
        return np.linalg.solve(m, r.reshape(n, 3, 1)).ravel()

def point_norm(rows: np.ndarray) -> np.ndarray:
    """Length of each point's 3-D residual from point-major rows."""
    return np.linalg.norm(rows.reshape(-1, 3), axis=1)


def rms(rows: np.ndarray) -> float:
    """RMS of the 3-D residual vector length."""
    return float(np.sqrt(np.mean(point_norm(rows) ** 2))) if len(rows) else float("nan")


# ---- identifiability ----------------------------------------------------------------
def _name(label) -> str:
    return label[0] if label[0] != "setup" else f"setup.{label[1]}"


def _term(label) -> str:
    p, k = label
    if p == "setup":
        return f"setup.{k}"
    return p if k is None else f"{p}[P{k}]"


def identifiability(A2: np.ndarray, labels: list, tol: float = SV_TOL) -> tuple[np.ndarray, list]:
    """Columns the data determine, and what they cannot separate.

    ``A2`` (rows, P) holds the gauge-fixed columns.  Columns are taken in the gauge order; one
    that lies (within ``tol``) in the span of those kept before it cannot be separated from
    them by these data.  Returns the mask of kept columns and one entry per parameter with
    dropped terms: ``{"parameters": [that parameter, then the partners it is confounded
    with], "terms": [dropped basis terms], "confounded_with": {partner: weight}}``."""
    return identifiability_gram(A2.T @ A2, labels, tol)


def identifiability_gram(G: np.ndarray, labels: list, tol: float = SV_TOL, prefer=None):
    """:func:`identifiability` from the Gram matrix A2^T A2 of the columns.  ``prefer``: (p,)
    bool, the columns the instruments are used for (a ballbar's squareness before the angular
    slopes it shares a null direction with): taken before all other parameter columns."""
    G = _correlation(G)   # scale-free: mm and rad columns alike
    first = np.zeros(len(labels), bool) if prefer is None else np.asarray(prefer, bool)
    # translational terms before angular ones: an angular error is what a plan without the
    # lever arms cannot see, not the scale or straightness it would be confused with
    order = sorted(range(len(labels)), key=lambda j: (
        0 if labels[j][0] == "setup" else 1 if first[j] else 2,
        0 if labels[j][0] == "setup" else 1 if labels[j][1] is None else
        2 if labels[j][1] == "extra" or labels[j][0][1] in "XYZ" else 3, j))
    keep = independent_columns(G, order, tol)
    dropped = np.flatnonzero(~keep)
    if len(dropped) == 0:
        return keep, []
    kept = np.flatnonzero(keep)
    Gk = G[np.ix_(kept, kept)]
    groups: dict = {}
    for j in dropped:
        p = _name(labels[j])
        g = groups.setdefault(p, {"parameters": [p], "terms": [], "confounded_with": {}})
        g["terms"].append(_term(labels[j]))
        if G[j, j] <= 0:
            g["no_sensitivity"] = True
            continue
        coef = np.linalg.lstsq(Gk, G[kept, j], rcond=1e-12)[0]
        contrib = np.abs(coef) * np.sqrt(np.diag(Gk)) / np.sqrt(G[j, j])
        for c, w in zip(kept, contrib):
            if w > 0.05:
                q = _name(labels[c])
                if q != p:
                    g["confounded_with"][q] = round(max(g["confounded_with"].get(q, 0.0),
                                                        float(w)), 3)
    out = []
    for g in groups.values():
        partners = sorted(g["confounded_with"], key=lambda q: -g["confounded_with"][q])
        g["parameters"] = g["parameters"] + partners
        out.append(g)
    return keep, out


def weakly_determined(A2: np.ndarray, labels: list, limit: float = 1e4) -> list:
    """Parameters the data determine only poorly: variance inflation factor of each column
    (1 / squared relative distance to the span of the others) above ``limit``, i.e. a
    standard error inflated more than sqrt(limit) times by near-confounding.  Returns
    ``[{"parameter", "vif", "terms"}]`` sorted by decreasing VIF."""
    return weakly_determined_gram(A2.T @ A2, labels, limit)


def weakly_determined_gram(G: np.ndarray, labels: list, limit: float = 1e4) -> list:
    """:func:`weakly_determined` from the Gram matrix A2^T A2 of the columns."""
    d = np.sqrt(np.diag(G))
    d[d == 0] = 1.0
    C = G / np.outer(d, d)
    w, V = np.linalg.eigh(C)
    ok = w > 1e-14 * w[-1]
    vif = np.einsum("ij,j,ij->i", V[:, ok], 1.0 / w[ok], V[:, ok])
    out: dict = {}
    for j in np.flatnonzero(vif > limit):
        p = _name(labels[j])
        e = out.setdefault(p, {"parameter": p, "vif": 0.0, "terms": []})
        e["vif"] = max(e["vif"], round(float(vif[j]), 1))
        e["terms"].append(_term(labels[j]))
    return sorted(out.values(), key=lambda e: -e["vif"])


def require_points(n_points: int, n_columns: int, what: str) -> None:
    """Refuse a fit with too few points for its basis."""
    require(3 * n_points >= 2 * n_columns + 10,
            f"too few points for the basis: {n_points} points give {3 * n_points} equations, "
            f"the {what} needs at least {n_columns * 2 + 10} (reduce --degree or add points)")
