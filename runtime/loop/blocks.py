"""Least squares on the loop's designs without the (3N, p) matrix: columns generated per block of
points, weighted normal equations (A^T W A, A^T W y) and cross-products accumulated blockwise,
held-out residuals per block.  Memory: p x p matrices, p-vectors and one block of rows.

A :class:`Design` is the declared model's kept columns (generated from the model's sensitivity
per block, :func:`volerr.loop.fit.declared_design`) followed by dense extra columns (accepted
effects, (N, 3, m)).  Rows are point-major (3 per point), deviations in mm; weights are the
square roots of the robust point weights (one per point).
"""

from __future__ import annotations

import math

import numpy as np

from volerr.loop.fit import SV_TOL, declared_design, point_norm, rows_of

#: points per block (a block of rows is 3 * BLOCK x p floats)
BLOCK = 8192


def blocks(points, size: int = BLOCK):
    """Consecutive slices of ``points`` (index arrays) of at most ``size`` points."""
    points = np.asarray(points)
    for i in range(0, len(points), size):
        yield slice(i, i + size), points[i:i + size]


class Design:
    """Columns of a linear model at the data points, generated per block.

    ``keep``: mask of the columns of :func:`volerr.loop.fit.declared_design` kept (gauge and
    identifiability); ``extra``: dense (N, 3, m) column groups appended in order."""

    def __init__(self, model, data, degree: int, ranges: dict, keep, extra=()):
        self.model, self.data, self.degree, self.ranges = model, data, degree, ranges
        self.keep = np.asarray(keep, bool)
        self.extra = [np.asarray(e) for e in extra]
        self.p = int(self.keep.sum()) + sum(e.shape[-1] for e in self.extra)

    def plus(self, extra) -> "Design":
        """This design with more dense column groups appended."""
        return Design(self.model, self.data, self.degree, self.ranges, self.keep,
                      self.extra + [np.asarray(e) for e in extra])

    def cols(self, idx) -> np.ndarray:
        """(n, 3, p) columns at the points ``idx``."""
        d = declared_design(self.model, self.data.subset(idx), self.degree, self.ranges)
        A = d.A[:, :, self.keep]
        if self.extra:
            A = np.concatenate([A] + [e[idx] for e in self.extra], axis=2)
        return A

    def rows(self, idx) -> np.ndarray:
        """(3n, p) rows at the points ``idx``."""
        return self.cols(idx).reshape(-1, self.p)


def normal(design, points, sw, y):
    """Weighted normal equations on ``points``: (G, b, colsq) with G = A^T W A, b = A^T W y
    and colsq the weighted column sums of squares (= diag G).  ``sw`` (len(points),) square
    roots of the point weights; ``y`` all rows (3N,)."""
    G = np.zeros((design.p, design.p))
    b = np.zeros(design.p)
    for s, idx in blocks(points):
        w = np.repeat(sw[s], 3)
        A = design.rows(idx) * w[:, None]
        G += A.T @ A
        b += A.T @ (y[rows_of(idx)] * w)
    return G, b, np.diag(G).copy()


def unit_scale(colsq, n_rows: int) -> np.ndarray:
    """Column scale to unit RMS (as :class:`volerr.loop.fit.Problem`): sqrt(mean square)."""
    s = np.sqrt(np.maximum(colsq, 0.0) / max(n_rows, 1))
    s[s == 0] = 1.0
    return s


def eig_inverse(G, tol: float):
    """Pseudo-inverse of a symmetric PSD matrix by eigh: eigenvalues below tol*max cut."""
    w, V = np.linalg.eigh(G)
    ok = w > tol * max(float(w[-1]), 1e-300)
    return (V[:, ok] / w[ok]) @ V[:, ok].T


def predict(design, points, coef) -> np.ndarray:
    """Rows A c at ``points`` (3 per point)."""
    out = np.empty(3 * len(points))
    for s, idx in blocks(points):
        out[3 * s.start:3 * s.start + 3 * len(idx)] = design.rows(idx) @ coef
    return out


def cv_sq(design, y, folds, points, sw) -> np.ndarray:
    """Per-point squared length of the cross-validated (weighted) residual on ``points``:
    leave-one-point-out when ``folds`` is None (exact, through the 3x3 diagonal blocks of the
    hat matrix), else k-fold (``folds``: fold label per point).  Equals
    :meth:`volerr.loop.fit.Problem.loo_residuals` / ``cv_residuals`` on the weighted rows."""
    n_rows = 3 * len(points)
    if folds is None:
        G, b, colsq = normal(design, points, sw, y)
        sc = unit_scale(colsq, n_rows)
        Gi = eig_inverse(G / np.outer(sc, sc), SV_TOL ** 2)
        c = Gi @ (b / sc)
        out = np.empty(len(points))
        for s, idx in blocks(points):
            w = np.repeat(sw[s], 3)
            A = design.rows(idx) * (w[:, None] / sc)
            r = y[rows_of(idx)] * w - A @ c
            n = len(idx)
            B = (A @ Gi).reshape(n, 3, -1)
            A3 = A.reshape(n, 3, -1)
            h = np.einsum("nik,njk->nij", B, A3)
            m = np.eye(3) - h
            det = np.linalg.det(m)
            m[np.abs(det) < 1e-9] = np.eye(3)      # a point that alone fixes a parameter
            out[s] = point_norm(np.linalg.solve(m, r.reshape(n, 3, 1)).ravel()) ** 2
        return out
    labels = np.unique(folds)
    p = design.p
    Gf = np.zeros((len(labels), p, p))
    bf = np.zeros((len(labels), p))
    for s, idx in blocks(points):
        w = np.repeat(sw[s], 3)
        A = design.rows(idx) * w[:, None]
        yw = y[rows_of(idx)] * w
        f = np.repeat(folds[s], 3)
        for k, lab in enumerate(labels):
            m = f == lab
            Gf[k] += A[m].T @ A[m]
            bf[k] += A[m].T @ yw[m]
    G, b = Gf.sum(axis=0), bf.sum(axis=0)
    sc = unit_scale(np.diag(G), n_rows)
    S = np.outer(sc, sc)
    coef = np.array([solve_sym((G - Gf[k]) / S, (b - bf[k]) / sc) / sc
                     for k in range(len(labels))])
    out = np.empty(len(points))
    for s, idx in blocks(points):
        w = np.repeat(sw[s], 3)
        A = design.rows(idx) * w[:, None]
        k = np.searchsorted(labels, folds[s])
        pred = np.einsum("nip,np->ni", A.reshape(len(idx), 3, -1), coef[k])
        out[s] = np.sum((y[rows_of(idx)].reshape(-1, 3) * w.reshape(-1, 3) - pred) ** 2, axis=1)
    return out


def solve_sym(G, b, tol: float = SV_TOL ** 2):
    """Minimum-norm solution of G x = b (as :func:`volerr.loop.fit.solve_normal`)."""
    from volerr.loop.fit import solve_normal

    return solve_normal(G, b, tol)


class BlockBase:
    """The current design on the weighted training rows, column-scaled, with its Gram
    pseudo-inverse and residual: :class:`volerr.loop.select.Base` without the rows.

    ``score_many`` gives the RSS reduction of adding column groups, from the blockwise
    cross-products A_c^T r, A_c^T A_c and A_c^T A (one pass for all groups)."""

    def __init__(self, design, points, sw, y):
        self.design, self.points, self.sw = design, np.asarray(points), np.asarray(sw)
        G, b, colsq = normal(design, self.points, self.sw, y)
        self.n = 3 * len(self.points)
        self.scale = unit_scale(colsq, self.n)
        self.Gi = eig_inverse(G / np.outer(self.scale, self.scale), 1e-12)
        c = self.Gi @ (b / self.scale) / self.scale
        self.r = np.empty(self.n)
        for s, idx in blocks(self.points):
            w = np.repeat(self.sw[s], 3)
            self.r[3 * s.start:3 * s.start + 3 * len(idx)] = (
                (y[rows_of(idx)] - design.rows(idx) @ c) * w)
        self.rss = float(self.r @ self.r)

    def score_many(self, groups) -> list:
        """[(RSS reduction, effective rank)] of adding each column group; a group is a function
        ``idx -> (n, 3, m)`` columns at the points ``idx``."""
        acc = [None] * len(groups)
        for s, idx in blocks(self.points):
            w = np.repeat(self.sw[s], 3)
            A = self.design.rows(idx) * (w[:, None] / self.scale)
            r = self.r[3 * s.start:3 * s.start + 3 * len(idx)]
            for k, g in enumerate(groups):
                B = g(idx)
                B = B.reshape(-1, B.shape[-1]) * w[:, None]
                parts = (A.T @ B, B.T @ B, B.T @ r)
                acc[k] = parts if acc[k] is None else tuple(x + y for x, y in zip(acc[k], parts))
        return [self._score(*a) for a in acc]

    def _score(self, AB, BB, Br) -> tuple[float, int]:
        """As :meth:`volerr.loop.select.Base.score`, from the cross-products."""
        sc = np.sqrt(np.maximum(np.diag(BB), 0.0) / self.n)
        sc[sc == 0] = 1.0
        C = AB / sc
        M = BB / np.outer(sc, sc) - C.T @ self.Gi @ C
        w, V = np.linalg.eigh((M + M.T) / 2)
        ok = w > 1e-9 * self.n
        if not ok.any():
            return 0.0, 0
        g = V[:, ok].T @ (Br / sc)
        return float(np.sum(g * g / w[ok])), int(ok.sum())

    def score(self, group) -> tuple[float, int]:
        return self.score_many([group])[0]

    def dbic(self, gain: float, m_eff: int) -> float:
        new = max(self.rss - gain, 1e-300)
        return self.n * math.log(new / self.rss) + m_eff * math.log(self.n)
