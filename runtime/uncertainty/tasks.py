"""Measurement tasks: nominal probing points and their evaluation, vectorised over samples.

Task CSV (one row per probing point)::

    X,Y,Z[,i,j,k][,Xp,Yp,Zp][,B,C ...]

* ``X,Y,Z``: axis positions of the probing point, mm (as in the ``loop`` input); for the CMM
  layouts the nominal probe-tip point in the workpiece frame is ``(X+Xp, Y+Yp, Z+Zp)``.
* ``i,j,k``: probing direction (outward surface normal, sphere centre -> ball centre), any
  length, normalised on read; optional (the probe noise is then isotropic).
* ``Xp,Yp,Zp``: probe offset, mm, default 0; rotary axis columns (deg) default 0.

Evaluations (``points`` shape (S, P, 3) mm: S samples of the P measured points):

* ``distance``: exactly two points, |p2 - p1|.
* ``circle``: least-squares plane, then the least-squares (geometric) circle in that plane:
  ``diameter``, ``centre_x/y/z``.
* ``sphere``: least-squares (geometric, Gauss-Newton) sphere: ``diameter``, ``centre_x/y/z``.
* ``plane``: ``flatness`` = peak-to-valley of the residuals to the least-squares plane
  (least-squares reference, not minimum zone).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError, require
from ..fileio import read_csv_rows
from ..units import parse_number

EVALUATIONS = {
    "distance": ("distance",),
    "circle": ("diameter", "centre_x", "centre_y", "centre_z"),
    "sphere": ("diameter", "centre_x", "centre_y", "centre_z"),
    "plane": ("flatness",),
}
#: fewest points each evaluation needs, and why
MIN_POINTS = {"distance": (2, "a distance needs exactly 2 points"),
              "circle": (3, "a circle needs at least 3 points"),
              "sphere": (4, "a sphere needs at least 4 points"),
              "plane": (4, "flatness needs at least 4 points (3 define the plane)")}


@dataclass
class Task:
    """Probing points of a task.

    ``positions``: axis -> (P,) mm / deg; ``probe``: (P, 3) mm; ``directions``: (P, 3) unit
    vectors or None; ``source``: where it came from (for messages)."""

    positions: dict
    probe: np.ndarray
    directions: np.ndarray | None = None
    source: str = "task"

    @property
    def n_points(self) -> int:
        return int(self.probe.shape[0])


def read_task(path, axes=("X", "Y", "Z")) -> Task:
    """Read a task CSV (format in the module docstring) for a machine with ``axes``."""
    path = Path(path)
    rows = read_csv_rows(path, empty=f"{path}: empty task file")
    (_, header), body = rows[0], rows[1:]
    low = [h.strip() for h in header]
    up = [h.upper() for h in low]
    require(len(set(up)) == len(up), f"{path}: duplicate column in header")
    for c in ("X", "Y", "Z"):
        require(c in up, f"{path}: missing column {c} (task CSV: X,Y,Z[,i,j,k][,Xp,Yp,Zp])")
    require(body, f"{path}: no probing points")
    data = []
    for lineno, cells in body:
        require(len(cells) == len(header), f"{path}:{lineno}: {len(cells)} fields, header has "
                                           f"{len(header)}")
        data.append([parse_number(c, f"{path}:{lineno}", h) for h, c in zip(low, cells)])
    arr = np.asarray(data, dtype=float)

    def col(name):
        return arr[:, up.index(name.upper())] if name.upper() in up else None

    n = arr.shape[0]
    positions = {}
    for a in axes:
        v = col(a)
        positions[a] = np.zeros(n) if v is None else v
    probe = np.stack([col(c) if col(c) is not None else np.zeros(n) for c in ("Xp", "Yp", "Zp")],
                     axis=1)
    dirs = None
    have = [col(c) is not None for c in ("i", "j", "k")]
    if any(have):
        require(all(have), f"{path}: probing direction needs all of i,j,k")
        dirs = np.stack([col(c) for c in ("i", "j", "k")], axis=1)
        norm = np.linalg.norm(dirs, axis=1)
        bad = np.flatnonzero(norm == 0)
        require(bad.size == 0, f"{path}: probing direction of point {bad[0] + 1 if bad.size else 0} "
                               f"is the zero vector")
        dirs = dirs / norm[:, None]
    return Task(positions, probe, dirs, str(path))


def check_travel(model, positions: dict, what: str = "task point") -> None:
    """Refuse axis positions outside the layout's travel (every axis of the layout, rotary
    axes too where their travel is finite), whatever the machine knowledge is: error tables
    would refuse positions outside their measured range, but a specification or a perfect
    machine would otherwise be extrapolated silently beyond the machine.

    ``positions``: axis -> (P,) mm (linear) or deg (rotary), the layout's units; an axis
    missing from ``positions`` is not checked.  Raises InputError naming the first point
    (1-based) and axis, e.g. ``task point 3: X = 1000 mm outside the travel 0..900 mm of
    MB1``."""
    bad = []  # (point index, axis order, axis, value, lo, hi)
    for k, a in enumerate(model.axes):
        if a not in positions:
            continue
        lo, hi = (float(v) for v in model.travel[a])
        v = np.atleast_1d(np.asarray(positions[a], dtype=float))
        tol = 1e-9 * max(1.0, hi - lo if np.isfinite(hi - lo) else 1.0)
        out = np.zeros(v.shape, bool)
        if np.isfinite(lo):
            out |= v < lo - tol
        if np.isfinite(hi):
            out |= v > hi + tol
        out |= ~np.isfinite(v)
        if out.any():
            i = int(np.flatnonzero(out)[0])
            bad.append((i, k, a, float(v[i]), lo, hi))
    if bad:
        i, _, a, v, lo, hi = min(bad)
        unit = "deg" if a in model.rotary_axes else "mm"
        raise InputError(f"{what} {i + 1}: {a} = {v:g} {unit} outside the travel {lo:g}..{hi:g} "
                         f"{unit} of {model.name}")


def check_task(task: Task, evaluation: str, nominal: np.ndarray) -> None:
    """Refuse an unknown evaluation, too few points, or a degenerate nominal geometry."""
    require(evaluation in EVALUATIONS, f"unknown evaluation {evaluation!r} "
                                       f"(one of {', '.join(EVALUATIONS)})")
    need, why = MIN_POINTS[evaluation]
    n = task.n_points
    if evaluation == "distance":
        require(n == 2, f"{why}, the task has {n}")
    else:
        require(n >= need, f"{why}, the task has {n}")
    c = nominal - nominal.mean(axis=0)
    sv = np.linalg.svd(c, compute_uv=False)
    scale = max(float(sv[0]), 1e-300)
    if evaluation == "distance":
        require(sv[0] > 0, "the two points of the distance coincide")
    elif evaluation in ("circle", "plane"):
        require(sv[1] > 1e-9 * scale, f"the points of the {evaluation} are collinear")
    elif evaluation == "sphere":
        require(sv[2] > 1e-9 * scale, "the points of the sphere are coplanar (use circle)")


# ---------------------------------------------------------------------------------------------
# vectorised evaluations: points (S, P, 3) -> (S, n_quantities)
def _solve(jtj, jtr):
    return np.linalg.solve(jtj, jtr[..., None])[..., 0]


def _normal(J, r):
    """J^T J (S, k, k) and J^T r (S, k) of a batch of Jacobians J (S, P, k), residuals (S, P)."""
    Jt = np.swapaxes(J, 1, 2)
    return Jt @ J, (Jt @ r[..., None])[..., 0]


def _plane(points):
    """Centroid (S, 3), unit normal (S, 3) of the least-squares plane."""
    c = points.mean(axis=1)
    d = points - c[:, None, :]
    cov = np.einsum("spi,spj->sij", d, d)
    w, v = np.linalg.eigh(cov)
    n = v[..., 0]
    # one sign for all samples (of the first sample's normal) so centres and bases agree
    ref = n[0]
    n = n * np.where(np.einsum("si,i->s", n, ref) < 0, -1.0, 1.0)[:, None]
    return c, n


def _circle2d(u, v, iterations=3):
    """Geometric least-squares circle of 2-D points (S, P) -> centre (S, 2), radius (S,)."""
    # algebraic (Kasa) start, then Gauss-Newton on the geometric residual |p - c| - r
    A = np.stack([u, v, np.ones_like(u)], axis=-1)
    b = u ** 2 + v ** 2
    sol = _solve(*_normal(A, b))
    cu, cv = sol[:, 0] / 2, sol[:, 1] / 2
    r = np.sqrt(sol[:, 2] + cu ** 2 + cv ** 2)
    for _ in range(iterations):
        du, dv = u - cu[:, None], v - cv[:, None]
        rho = np.sqrt(du ** 2 + dv ** 2)
        res = rho - r[:, None]
        J = np.stack([-du / rho, -dv / rho, -np.ones_like(rho)], axis=-1)
        step = _solve(*_normal(J, -res))
        cu, cv, r = cu + step[:, 0], cv + step[:, 1], r + step[:, 2]
    return np.stack([cu, cv], axis=-1), r


def fit_sphere(points, iterations=3):
    """Geometric least-squares sphere of (S, P, 3) points -> centre (S, 3), radius (S,)."""
    o = points.mean(axis=1, keepdims=True)
    q = points - o
    A = np.concatenate([q, np.ones(q.shape[:2] + (1,))], axis=-1)
    b = np.sum(q ** 2, axis=-1)
    sol = _solve(*_normal(A, b))
    c = sol[:, :3] / 2
    r = np.sqrt(sol[:, 3] + np.sum(c ** 2, axis=1))
    for _ in range(iterations):
        d = q - c[:, None, :]
        rho = np.linalg.norm(d, axis=-1)
        res = rho - r[:, None]
        J = np.concatenate([-d / rho[..., None], -np.ones(rho.shape + (1,))], axis=-1)
        step = _solve(*_normal(J, -res))
        c, r = c + step[:, :3], r + step[:, 3]
    return c + o[:, 0, :], r


def fit_circle(points):
    """Least-squares plane, then geometric circle in it: centre (S, 3), radius (S,), normal."""
    c0, n = _plane(points)
    a = np.where(np.abs(n[:, :1]) < 0.9, np.array([1.0, 0, 0]), np.array([0, 1.0, 0]))
    e1 = a - np.einsum("si,si->s", a, n)[:, None] * n
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(n, e1)
    d = points - c0[:, None, :]
    u, v = np.einsum("spi,si->sp", d, e1), np.einsum("spi,si->sp", d, e2)
    cc, r = _circle2d(u, v)
    centre = c0 + cc[:, :1] * e1 + cc[:, 1:] * e2
    return centre, r, n


def evaluate(evaluation: str, points) -> np.ndarray:
    """Evaluate ``points`` (S, P, 3) or (P, 3), mm -> (S, n_quantities) mm in the order of
    ``EVALUATIONS[evaluation]``."""
    require(evaluation in EVALUATIONS, f"unknown evaluation {evaluation!r} "
                                       f"(one of {', '.join(EVALUATIONS)})")
    p = np.asarray(points, dtype=float)
    p = p[None] if p.ndim == 2 else p
    if evaluation == "distance":
        return np.linalg.norm(p[:, 1] - p[:, 0], axis=-1)[:, None]
    if evaluation == "sphere":
        c, r = fit_sphere(p)
        return np.column_stack([2 * r, c])
    if evaluation == "circle":
        c, r, _ = fit_circle(p)
        return np.column_stack([2 * r, c])
    c, n = _plane(p)
    h = np.einsum("spi,si->sp", p - c[:, None, :], n)
    return (h.max(axis=1) - h.min(axis=1))[:, None]
