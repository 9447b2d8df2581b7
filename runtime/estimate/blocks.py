"""Least squares on the loop's designs without the (3N, p) matrix: columns generated per block of
points, weighted normal equations (A^T W A, A^T W y) and cross-products accumulated blockwise,
held-out residuals per block.  Memory: p x p matrices, p-vectors and one block of rows; where a
sequence of passes reads the same points (a :class:`BlockBase`, :func:`cv_sq`, the loop's robust
weights) the blocks of its first pass are kept for the others when they fit in ``KEEP_BYTES``
(:class:`Kept`: 10^5 points of a 78-column design, 187 MB; at 10^6 points every pass generates
them again).

A :class:`Design` is the declared model's kept columns (generated from the model's sensitivity
per block, :func:`volerr.estimate.design.declared_design`) followed by dense extra columns (accepted
effects, (N, 3, m)).  Rows are point-major (3 per point), deviations in mm; weights are the
square roots of the robust point weights (one per point).
"""

from __future__ import annotations

import numpy as np

from ..selection.linalg import pinv_sym
from ..selection.rules import delta_bic
from .design import SV_TOL, declared_design, series_basis, twist_sensitivity

#: points per block (a block of rows is 3 * BLOCK x p floats)
BLOCK = 8192


def blocks(points, size: int | None = None):
    """Consecutive slices of ``points`` (index arrays) of at most ``size`` points."""
    points, size = np.asarray(points), size or BLOCK
    for i in range(0, len(points), size):
        yield slice(i, i + size), points[i:i + size]


class Design:
    """Columns of a linear model at the data points, generated per block.

    ``keep``: mask of the columns of :func:`volerr.estimate.design.declared_design` kept (gauge and
    identifiability); ``extra``: dense (N, 3, m) column groups appended in order.

    :meth:`block` returns the columns transposed, (p, 3n), with the rows of a block in
    component-major order (all dx rows, then dy, then dz): each column is then one contiguous
    product of a generated sensitivity (3, n) and a Legendre basis (n,).  :func:`yrows` and
    :func:`wrows` give the deviations and weights of a block in that order."""

    def __init__(self, model, data, degree: int, ranges: dict, keep, extra=()):
        self.model, self.data, self.degree, self.ranges = model, data, degree, ranges
        self.keep = np.asarray(keep, bool)
        self.extra = [np.asarray(e) for e in extra]
        labels = declared_design(model, data.subset(np.arange(1)), degree, ranges).labels
        self.labels = [lab for lab, k in zip(labels, self.keep) if k]
        pidx = {p: j for j, p in enumerate(model.parameters)}
        sidx = {k: j for j, k in enumerate(data.setup_labels)}
        self._ops = []
        for p, k in self.labels:
            if p == "setup":
                self._ops.append((0, sidx[k], None, None))
            elif k is None:
                self._ops.append((1, pidx[p], None, None))
            else:
                self._ops.append((1, pidx[p], model.parameter_axis[p], k))
        self.p = len(self.labels) + sum(e.shape[-1] for e in self.extra)

    def plus(self, extra) -> "Design":
        """This design with more dense column groups appended."""
        return Design(self.model, self.data, self.degree, self.ranges, self.keep,
                      self.extra + [np.asarray(e) for e in extra])

    def block(self, idx) -> np.ndarray:
        """(p, 3n) columns at the points ``idx``, rows component-major."""
        sub = self.data.subset(idx)
        n = len(idx)
        sens = np.moveaxis(sub.sensitivity(self.model), 0, -1)         # (3, P, n)
        tw = twist_sensitivity(self.model, sub)
        setup = np.moveaxis(sub.setup_columns(tw), 0, -1)              # (3, m, n)
        bases = {a: series_basis(self.model, a, sub.positions[a], self.ranges, self.degree).T
                 for a in self.model.axes}
        At = np.empty((self.p, 3, n))
        for i, (src, j, axis, k) in enumerate(self._ops):
            col = (setup if src == 0 else sens)[:, j, :]
            if axis is None:
                At[i] = col
            else:
                np.multiply(col, bases[axis][k], out=At[i])
        i = len(self._ops)
        for e in self.extra:
            m = e.shape[-1]
            At[i:i + m] = np.transpose(e[idx], (2, 1, 0))
            i += m
        return At.reshape(self.p, 3 * n)

    def rows(self, idx) -> np.ndarray:
        """(3n, p) rows at the points ``idx``, point-major (3 per point)."""
        At = self.block(idx).reshape(self.p, 3, len(idx))
        return np.ascontiguousarray(np.transpose(At, (2, 1, 0))).reshape(-1, self.p)


def yrows(y, idx) -> np.ndarray:
    """Rows of ``y`` (3N,) at the points ``idx`` in a block's component-major order."""
    return np.ascontiguousarray(y.reshape(-1, 3)[idx].T).ravel()


def wrows(sw) -> np.ndarray:
    """Row weights of a block (component-major) from the points' weights."""
    return np.tile(sw, 3)


def group_block(cols) -> np.ndarray:
    """(n, 3, m) columns of a block -> (m, 3n), rows component-major."""
    return np.transpose(cols, (2, 1, 0)).reshape(cols.shape[-1], -1)


def to_point_major(r, n: int) -> np.ndarray:
    """Block rows component-major (3n,) -> point-major."""
    return np.ascontiguousarray(r.reshape(3, n).T).ravel()


def normal(design, points, sw, y, kept: "Kept | None" = None):
    """Weighted normal equations on ``points``: (G, b, colsq) with G = A^T W A, b = A^T W y
    and colsq the weighted column sums of squares (= diag G).  ``sw`` (len(points),) square
    roots of the point weights; ``y`` all rows (3N,).  ``kept``: an empty :class:`Kept` of
    ``design`` at ``points`` that keeps the blocks generated here (unweighted), for further
    passes over the same points without generating them again."""
    G = np.zeros((design.p, design.p))
    b = np.zeros(design.p)
    for s, idx in blocks(points):
        w = wrows(sw[s])
        if kept is None:
            At = design.block(idx)
            At *= w
        else:
            kept.append(design.block(idx))
            At = kept[-1] * w
        G += At @ At.T
        b += At @ (yrows(y, idx) * w)
    return G, b, np.diag(G).copy()


#: bytes of generated blocks a sequence of passes over the same points may keep (the passes
#: of :class:`BlockBase` and of the loop's robust weights): above it (10^6 points) every pass
#: generates its blocks again
KEEP_BYTES = 256 * 2 ** 20


class Kept(list):
    """The blocks of a design at some points (:meth:`Design.block`, unweighted, in the order
    of :func:`blocks`), filled by :func:`normal` and read by index by the passes after it."""

    @staticmethod
    def fits(design, points) -> bool:
        """Whether the blocks of ``design`` at ``points`` fit in ``KEEP_BYTES``."""
        return 8 * design.p * 3 * len(points) <= KEEP_BYTES

    @classmethod
    def of(cls, design, points) -> "Kept | None":
        """An empty ``Kept`` where the blocks fit (:meth:`fits`), else None."""
        return cls() if cls.fits(design, points) else None


def unit_scale(colsq, n_rows: int) -> np.ndarray:
    """Column scale to unit RMS (as :class:`volerr.estimate.design.Problem`): sqrt(mean square)."""
    s = np.sqrt(np.maximum(colsq, 0.0) / max(n_rows, 1))
    s[s == 0] = 1.0
    return s


#: the one symmetric pseudo-inverse (:func:`volerr.selection.linalg.pinv_sym`), by its former name
eig_inverse = pinv_sym


def predict(design, points, coef, kept: Kept | None = None) -> np.ndarray:
    """Rows A c at ``points`` (point-major, 3 per point); ``kept``: the blocks at ``points``
    (:func:`normal`'s), else generated."""
    out = np.empty(3 * len(points))
    for k, (s, idx) in enumerate(blocks(points)):
        At = design.block(idx) if kept is None else kept[k]
        out[3 * s.start:3 * s.start + 3 * len(idx)] = to_point_major(coef @ At, len(idx))
    return out


def cv_sq(design, y, folds, points, sw) -> np.ndarray:
    """Per-point squared length of the cross-validated (weighted) residual on ``points``:
    leave-one-point-out when ``folds`` is None (exact, through the 3x3 diagonal blocks of the
    hat matrix), else k-fold (``folds``: fold label per point).  Equals
    :meth:`volerr.estimate.design.Problem.loo_residuals` / ``cv_residuals`` on the weighted rows."""
    n_rows = 3 * len(points)
    kept = Kept.of(design, points)          # the blocks of the first pass, for the second
    if folds is None:
        G, b, colsq = normal(design, points, sw, y, kept)
        sc = unit_scale(colsq, n_rows)
        Gi = eig_inverse(G / np.outer(sc, sc), SV_TOL ** 2)
        c = Gi @ (b / sc)
        out = np.empty(len(points))
        for kb, (s, idx) in enumerate(blocks(points)):
            w = wrows(sw[s])
            At = design.block(idx) if kept is None else kept[kb]
            At *= w / sc[:, None]
            n = len(idx)
            r = (yrows(y, idx) * w - c @ At).reshape(3, n).T          # (n, 3)
            A3 = At.reshape(-1, 3, n)
            B3 = (Gi @ At).reshape(-1, 3, n)
            h = np.einsum("kin,kjn->nij", B3, A3)
            m = np.eye(3) - h
            det = np.linalg.det(m)
            m[np.abs(det) < 1e-9] = np.eye(3)      # a point that alone fixes a parameter
            out[s] = np.sum(np.linalg.solve(m, r[:, :, None])[:, :, 0] ** 2, axis=1)
        return out
    labels = np.unique(folds)
    p = design.p
    Gf = np.zeros((len(labels), p, p))
    bf = np.zeros((len(labels), p))
    for s, idx in blocks(points):
        w = wrows(sw[s])
        At = design.block(idx)
        if kept is not None:
            kept.append(At)
            At = At * w
        else:
            At *= w
        yw = yrows(y, idx) * w
        f = np.tile(folds[s], 3)
        for k, lab in enumerate(labels):
            m = f == lab
            Gf[k] += At[:, m] @ At[:, m].T
            bf[k] += At[:, m] @ yw[m]
    G, b = Gf.sum(axis=0), bf.sum(axis=0)
    sc = unit_scale(np.diag(G), n_rows)
    S = np.outer(sc, sc)
    coef = np.array([solve_sym((G - Gf[k]) / S, (b - bf[k]) / sc) / sc
                     for k in range(len(labels))])
    out = np.empty(len(points))
    for kb, (s, idx) in enumerate(blocks(points)):
        w = wrows(sw[s])
        n = len(idx)
        At = (design.block(idx) if kept is None else kept[kb]).reshape(p, 3, n)
        k = np.searchsorted(labels, folds[s])
        pred = np.einsum("pin,np->ni", At, coef[k])
        yw = (yrows(y, idx) * w).reshape(3, n).T
        out[s] = np.sum((yw - pred * w.reshape(3, n).T) ** 2, axis=1)
    return out


def solve_sym(G, b, tol: float = SV_TOL ** 2):
    """Minimum-norm solution of G x = b (as :func:`volerr.estimate.design.solve_normal`)."""
    from .design import solve_normal

    return solve_normal(G, b, tol)


#: columns of candidate groups multiplied by a block's design columns in one product
STACK_COLUMNS = 64


def _stacked(groups, idx, w):
    """The groups' weighted columns at the points ``idx`` (row weights ``w``), stacked:
    [(group numbers, (M, 3n) rows, offsets of the groups' rows (len + 1))], each stack at
    most ``STACK_COLUMNS`` rows (a wider group alone)."""
    out, ks, parts, cuts = [], [], [], [0]
    for k, g in enumerate(groups):
        Bt = group_block(g(idx))
        if parts and cuts[-1] + len(Bt) > STACK_COLUMNS:
            out.append((ks, np.concatenate(parts) * w, cuts))
            ks, parts, cuts = [], [], [0]
        ks.append(k)
        parts.append(Bt)
        cuts.append(cuts[-1] + len(Bt))
    if parts:
        out.append((ks, np.concatenate(parts) * w, cuts))
    return out


def rss_gain(M, g, floor: float) -> tuple[float, int]:
    """(RSS reduction, effective rank) of adding columns (scaled to unit RMS) whose Gram
    matrix off the current design's span is ``M`` (m, m) and whose products with the
    residual are ``g`` (m,): the eigen-directions of ``M`` above ``floor`` count (the others
    lie inside the span).  One column: its 1 x 1 eigen-decomposition is the number itself
    (what LAPACK returns, bit for bit), taken without the call."""
    if len(g) == 1:
        w = float(M[0, 0])
        return (float(g[0] * g[0] / w), 1) if w > floor else (0.0, 0)
    w, V = np.linalg.eigh((M + M.T) / 2)
    ok = w > floor
    if not ok.any():
        return 0.0, 0
    h = V[:, ok].T @ g
    return float(np.sum(h * h / w[ok])), int(ok.sum())


class BlockBase:
    """The current design on the weighted training rows, column-scaled, with its Gram
    pseudo-inverse and residual: :class:`volerr.loop.select.Base` without the rows.

    ``score_many`` gives the RSS reduction of adding column groups, from the blockwise
    cross-products A_c^T r, A_c^T A_c and A_c^T A (one pass for all groups).

    Where they fit in ``KEEP_BYTES`` (:meth:`Kept.fits`), the design's blocks are generated once
    and kept, weighted and scaled, for every ``score_many`` (a lag's profile scores 13
    values of its time constant a pass, several passes on one base)."""

    def __init__(self, design, points, sw, y):
        self.design, self.points, self.sw = design, np.asarray(points), np.asarray(sw)
        kept = Kept.of(design, self.points)
        G, b, colsq = normal(design, self.points, self.sw, y, kept)
        n_rows = 3 * len(self.points)
        #: readings (rows that carry one: a ballbar point has one), the n of the BIC
        self.n = int(design.data.readings_per_point()[self.points].sum())
        self.scale = unit_scale(colsq, n_rows)
        self.Gi = eig_inverse(G / np.outer(self.scale, self.scale), 1e-12)
        c = self.Gi @ (b / self.scale) / self.scale
        self.r = np.empty(n_rows)         # weighted residual rows, component-major per block
        for k, (s, idx) in enumerate(blocks(self.points)):
            w = wrows(self.sw[s])
            At = design.block(idx) if kept is None else kept[k]
            self.r[3 * s.start:3 * s.start + 3 * len(idx)] = (yrows(y, idx) - c @ At) * w
            if kept is not None:
                At *= w / self.scale[:, None]       # as score_many weighs and scales it
        self._kept = kept
        self.rss = float(self.r @ self.r)

    def score_many(self, groups) -> list:
        """[(RSS reduction, effective rank)] of adding each column group; a group is a function
        ``idx -> (n, 3, m)`` columns at the points ``idx``.

        Per block the groups' columns are stacked (at most ``STACK_COLUMNS`` at a time) and
        multiplied by the block's design columns in one matrix product: the (p, 3n) block
        is read once per stack, not once per group (a product with a few columns is bound by
        that read)."""
        acc = [None] * len(groups)
        for kb, (s, idx) in enumerate(blocks(self.points)):
            w = wrows(self.sw[s])
            if self._kept is not None:
                At = self._kept[kb]
            else:
                At = self.design.block(idx)
                At *= w / self.scale[:, None]
            r = self.r[3 * s.start:3 * s.start + 3 * len(idx)]
            for ks, Ball, cuts in _stacked(groups, idx, w):
                AB, Br = At @ Ball.T, Ball @ r
                for k, a, b in zip(ks, cuts[:-1], cuts[1:]):
                    Bt = Ball[a:b]
                    parts = (AB[:, a:b], Bt @ Bt.T, Br[a:b])
                    acc[k] = parts if acc[k] is None else tuple(
                        x + y for x, y in zip(acc[k], parts))
        return [self._score(*a) for a in acc]

    def _score(self, AB, BB, Br) -> tuple[float, int]:
        """As :meth:`volerr.loop.select.Base.score`, from the cross-products."""
        sc = np.sqrt(np.maximum(np.diag(BB), 0.0) / len(self.r))
        sc[sc == 0] = 1.0
        C = AB / sc
        M = BB / np.outer(sc, sc) - C.T @ self.Gi @ C
        return rss_gain(M, Br / sc, 1e-9 * len(self.r))

    def score(self, group) -> tuple[float, int]:
        return self.score_many([group])[0]

    def dbic(self, gain: float, m_eff: int) -> float:
        """BIC change of a group that lowers the RSS by ``gain`` with ``m_eff`` parameters."""
        return delta_bic(self.n, self.rss - gain, self.rss, m_eff)
