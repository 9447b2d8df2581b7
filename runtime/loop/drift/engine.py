"""Blocked cross-validation of linear drift models from cross-products, for many candidate
columns at once (:mod:`volerr.loop.drift.select` selects with it).

A model of one channel is ``y = Z W b`` (``Z`` the run indicators and the basis columns of
:func:`volerr.loop.drift.basis.library`, ``W`` the combinations chosen so far: a run's zero,
a column, a difference of two columns).  For a fold k the fit on the other folds and its
squared error on fold k follow from the cross-products ``Z'Z``, ``Z'y``, ``y'y`` of fold k
and of all training readings: no pass over the readings per candidate.  Adding a candidate
column ``c = Z (e_a - e_b)`` to ``W`` is a bordered system solved in closed form (the Schur
complement ``v - u' M^-1 u``), vectorised over all candidates.

A fold of whole runs is predicted from each run's zero (its first reading: the basis columns
are zero there), so its test cross-products use ``y - y_first`` and no run indicator.
"""

from __future__ import annotations

import numpy as np

SINGULAR = 1e-9         # a candidate whose Schur complement is below this share of c'c: dependent
SOLVES = 4              # models whose folds' pseudo-inverses are kept (Engine._fit)


class Engine:
    """Cross-products of one channel per fold.

    ``Z`` (N, mz): run indicators then basis columns; ``y`` (N,); ``fold`` (N,) fold index of
    each training reading (-1 held out); ``by_runs``: folds are whole runs (anchored test)."""

    def __init__(self, Z, y, fold, by_runs: bool, run, n_runs: int, cache=None, zero=None):
        """``cache``: a dict shared by the channels of one basis (the cross-products of
        ``Z`` with itself do not depend on the channel: computed once); ``zero`` (N,) each
        reading's run zero of ``y`` (:meth:`~volerr.loop.drift.series.DriftSeries.zero`;
        None: the run's first reading)."""
        cache = {} if cache is None else cache
        self.n_runs = n_runs
        self._cache, self._by_runs, self._rhs = cache, by_runs, {}
        self.K = int(fold.max()) + 1
        self.n = int((fold >= 0).sum())
        first = np.zeros(n_runs)
        for r in range(n_runs):
            idx = np.flatnonzero(run == r)
            first[r] = (y if zero is None else zero)[idx[0]] if len(idx) else 0.0
        self.fold_fit, self.fold_test = [], []
        for k in range(self.K):
            m = _rows_of(fold == k, Z, y)
            Zk = Z[m]
            if ("fit", k) not in cache:
                cache[("fit", k)] = Zk.T @ Zk
                if by_runs:
                    Zt = Zk.copy()
                    Zt[:, :n_runs] = 0.0
                    cache[("test", k)] = (Zt, Zt.T @ Zt)
            Gk, yk = cache[("fit", k)], y[m]
            fit = (Gk, Zk.T @ yk, float(yk @ yk))
            self.fold_fit.append(fit)
            if by_runs:
                Zt, TG = cache[("test", k)]
                yt = yk - first[run[m]]
                self.fold_test.append((TG, Zt.T @ yt, float(yt @ yt), len(yk)))
            else:
                self.fold_test.append(fit + (len(yk),))
        self._data = (Z, y, fold, run, first)
        self.G = sum(f[0] for f in self.fold_fit)
        self.h = sum(f[1] for f in self.fold_fit)
        self.yy = sum(f[2] for f in self.fold_fit)

    # ---- the model so far, and one candidate more --------------------------------------
    def _active(self, W, G):
        """Columns of ``W`` (a :class:`Sel`) that the fit on ``G`` determines (a run without
        training readings in it has no zero there)."""
        return np.einsum("ij,ij->j", W.W, W.right(G)) > 0

    def cv_sse(self, W) -> float:
        """Cross-validated sum of squared errors of the model ``W`` (mz, s)."""
        return float(self.cv_many(W, np.zeros((0, 2), int))[1])

    def cv_many(self, W, cands) -> tuple[np.ndarray, float]:
        """(cross-validated SSE (nc,) of ``W`` plus each candidate, SSE of ``W`` alone).
        ``cands`` (nc, 2) index pairs (a, b) into Z's columns, b = -1 for a single column;
        dependent candidates get +inf.  From cross-products, an exact fit (a noise-free run)
        lands at the rounding floor, which may fall below 0: returned as 0."""
        a, b = cands[:, 0], cands[:, 1]
        tot = np.zeros(len(cands))
        base, key, W = 0.0, W.tobytes(), Sel(W)
        for k, ((Gk, hk, _), (TG, Th, Tyy, _)) in enumerate(zip(self.fold_fit, self.fold_test)):
            Gt, ht = self.G - Gk, self.h - hk
            Wf = W.take(self._active(W, Gt))
            sse, sse0 = _bordered_test(self._fit(key, k, Gt, ht, Wf, a, b), TG, Th, Tyy, Wf,
                                       a, b)
            tot += sse
            base += sse0
        return np.maximum(tot, 0.0), max(base, 0.0)

    def _fit(self, key, k, Gt, ht, W, a, b) -> tuple:
        """:func:`_bordered_fit` on fold ``k``'s training cross-products; the
        pseudo-inverse of ``W' Gt W`` (the same numbers every time: it depends on the basis,
        the fold and the model, not on the channel) kept for the last ``SOLVES`` models
        (``key`` the whole model's bytes: a step's candidates, then its alternatives, then
        the next stage and the other channels start from one model)."""
        kept = self._cache.setdefault("solves", {})
        if key not in kept:
            if len(kept) >= SOLVES:
                del kept[next(iter(kept))]
            kept[key] = {}
        if k not in kept[key]:
            kept[key][k] = _pinv(W.right(W.left(Gt)))
        return _bordered_fit(Gt, ht, W, a, b, kept[key][k])

    def cv_blocks(self, W, cands, sub: int) -> tuple[np.ndarray, np.ndarray]:
        """Cross-validated mean squares over ``sub`` consecutive blocks of every fold (the
        blocks of :func:`volerr.loop.drift.family.block_mse`, in fold then time order): (nc,
        B) of ``W`` plus each candidate (+inf where dependent) and (B,) of ``W`` alone.  Each
        block is predicted by the fit on the other folds, as in :meth:`cv_many`; the blocks'
        test cross-products of ``Z`` are computed once per basis (``cache``)."""
        fold = self._data[2]
        a, b = cands[:, 0], cands[:, 1]
        out, base, key, W = [], [], W.tobytes(), Sel(W)
        for k, (Gk, hk, _) in enumerate(self.fold_fit):
            Gt, ht = self.G - Gk, self.h - hk
            Wf = W.take(self._active(W, Gt))
            fit = self._fit(key, k, Gt, ht, Wf, a, b)     # one fit per fold, its blocks tested
            for j, part in enumerate(np.array_split(np.flatnonzero(fold == k), sub)):
                if not len(part):
                    continue
                TG, Th, Tyy = self._block(k, j, sub, part)
                sse, sse0 = _bordered_test(fit, TG, Th, Tyy, Wf, a, b)
                out.append(sse / len(part))
                base.append(sse0 / len(part))
        return np.array(out).T.reshape(len(cands), len(base)), np.array(base)

    def _block(self, k: int, j: int, sub: int, part) -> tuple:
        """The test cross-products (Z'Z, Z'y, y'y) of block j of fold k (readings ``part``;
        a fold of whole runs anchored at each run's first reading): Z'Z once per basis, the
        rest once per channel."""
        key = ("block", k, j, sub)
        if key not in self._rhs:
            Z, y, _, run, first = self._data
            Zb = Z[part]
            yb = y[part]
            if self._by_runs:                  # predicted from the run's first reading
                Zb[:, :self.n_runs] = 0.0
                yb = yb - first[run[part]]
            if key not in self._cache:
                self._cache[key] = Zb.T @ Zb
            self._rhs[key] = (Zb.T @ yb, float(yb @ yb))
        return (self._cache[key],) + self._rhs[key]

    def train_rss_many(self, W, cands) -> tuple[np.ndarray, float]:
        """(training RSS (nc,) with each candidate, RSS of ``W``), fitted on all training."""
        a, b = cands[:, 0], cands[:, 1]
        W = Sel(W)
        return _bordered(self.G, self.h, self.G, self.h, self.yy,
                         W.take(self._active(W, self.G)), a, b)


def _rows_of(mask, *arrays):
    """The readings of ``mask`` (N,) as an index into the rows of ``arrays``: a slice (a view,
    no copy) where they are one contiguous block and every array is C-contiguous, else their
    indices.  A contiguous block of a C-contiguous array has the layout of its gathered copy,
    so the products of either have the same bits."""
    idx = np.flatnonzero(mask)
    if (len(idx) and idx[-1] - idx[0] + 1 == len(idx)
            and all(a.flags.c_contiguous for a in arrays)):
        return slice(int(idx[0]), int(idx[-1]) + 1)
    return idx


def _pair(Mat, a, b):
    """Rows ``Mat[a] - Mat[b]`` (b = -1: ``Mat[a]``)."""
    out = Mat[a].copy()
    m = b >= 0
    out[m] -= Mat[b[m]]
    return out


def _quad(G, a, b):
    """``c' G c`` for c = e_a - e_b (b = -1: e_a)."""
    v = G[a, a].copy()
    m = b >= 0
    v[m] += G[b[m], b[m]] - 2.0 * G[a[m], b[m]]
    return v


class Sel:
    """A model's columns ``W`` (mz, s) and, where every column is one column of ``Z`` or a
    difference of two (a run's zero, a term: the models of :mod:`volerr.loop.drift.select`),
    their index pairs: then ``M @ W`` and ``W.T @ M`` are columns (rows) of ``M`` picked and
    subtracted, the same numbers as the products (each entry sums one or two nonzero terms,
    the rest exact zeros: one rounding either way; ``+ 0.0`` makes a zero +0 as the sum's)
    without the ``mz^2 s`` multiplications.  ``pa`` None: any other ``W`` (the products)."""

    def __init__(self, W):
        self.W, self.pa, self.pb = W, None, None
        nz = W != 0
        count = nz.sum(0)
        plus, minus = W == 1.0, W == -1.0
        if W.size and np.all(plus.sum(0) == 1) and np.all(count == plus.sum(0) + minus.sum(0)) \
                and np.all(minus.sum(0) <= 1):
            self.pa = plus.argmax(0)
            self.pb = np.where(minus.any(0), minus.argmax(0), -1)

    def take(self, on) -> "Sel":
        """The columns ``on`` (bool) of the model."""
        out = Sel.__new__(Sel)
        out.W = self.W[:, on]
        out.pa, out.pb = (None, None) if self.pa is None else (self.pa[on], self.pb[on])
        return out

    def right(self, M):
        """``M @ W``."""
        if self.pa is None:
            return M @ self.W
        out = M[..., self.pa]
        m = self.pb >= 0
        if m.any():
            out[..., m] -= M[..., self.pb[m]]
        return out + 0.0

    def left(self, M):
        """``W.T @ M`` (``M`` a matrix or a vector)."""
        if self.pa is None:
            return self.W.T @ M
        out = M[self.pa]
        m = self.pb >= 0
        if m.any():
            out[m] -= M[self.pb[m]]
        return out + 0.0


def _bordered(Gt, ht, TG, Th, Tyy, W, a, b):
    """SSE on the test cross-products (TG, Th, Tyy) of the fit on (Gt, ht) with the columns
    ``W`` (a :class:`Sel`) plus each candidate, and of ``W`` alone."""
    return _bordered_test(_bordered_fit(Gt, ht, W, a, b), TG, Th, Tyy, W, a, b)


def _pinv(M):
    return np.linalg.pinv(M, rcond=1e-12, hermitian=True) if M.size else M


def _bordered_fit(Gt, ht, W, a, b, Minv=None) -> tuple:
    """The fits on (Gt, ht): of ``W`` (a :class:`Sel`) alone (b0) and of ``W`` plus each
    candidate (B, beta; ``ok`` False where the candidate is dependent); ``Minv`` the
    pseudo-inverse of ``W' Gt W`` where known."""
    if Minv is None:
        Minv = _pinv(W.right(W.left(Gt)))
    b0 = Minv @ W.left(ht)
    if len(a) == 0:
        return b0, None, None, None
    U = _pair(W.right(Gt), a, b).T            # (s, nc)  W' Gt c
    v = _quad(Gt, a, b)
    hc = _pair(ht[:, None], a, b)[:, 0]
    Zm = Minv @ U
    schur = v - np.einsum("ij,ij->j", U, Zm)
    ok = schur > SINGULAR * np.maximum(v, 1e-300)
    beta = np.where(ok, (hc - U.T @ b0) / np.where(ok, schur, 1.0), 0.0)
    B = b0[:, None] - Zm * beta
    return b0, B, beta, ok


def _bordered_test(fit, TG, Th, Tyy, W, a, b):
    """SSE on the test cross-products (TG, Th, Tyy) of the fits ``fit``
    (:func:`_bordered_fit`): (per candidate, +inf where dependent; of ``W`` alone)."""
    b0, B, beta, ok = fit
    TGW = W.right(TG)
    GkSS, hkS = W.left(TGW), W.left(Th)
    sse0 = Tyy - 2 * b0 @ hkS + b0 @ GkSS @ b0
    if len(a) == 0:
        return np.zeros(0), float(sse0)
    GkSc = _pair(TGW, a, b).T
    Gkcc = _quad(TG, a, b)
    hkc = _pair(Th[:, None], a, b)[:, 0]
    sse = (Tyy - 2 * (B.T @ hkS + beta * hkc) + np.einsum("ij,ij->j", B, GkSS @ B)
           + 2 * beta * np.einsum("ij,ij->j", B, GkSc) + beta ** 2 * Gkcc)
    return np.where(ok, sse, np.inf), float(sse0)


def rss_stack(G, h, yy: float, fixed, cands) -> np.ndarray:
    """RSS (X, nc) of the least-squares fits on one set of cross-products ``G`` = Z'Z, ``h``
    = Z'y, ``yy`` = y'y with Z's columns ``fixed[x]`` (``fixed`` (X, s) indices: a stack of
    models, one a row) plus each single column ``cands[c]`` in turn: the bordered system of
    :func:`_bordered_fit` batched over the models (one pseudo-inverse of ``G[f, f]`` per
    model, rcond 1e-12; the candidate's gain ``(h_c - u' b0)^2 / schur`` taken from the
    model's RSS).  A candidate dependent on the model (Schur complement below ``SINGULAR``
    of c'c) adds nothing: the model's RSS, as a pseudo-inverse of the whole system gives it.
    An exact fit lands at the rounding floor: returned as 0."""
    g = G[fixed[:, :, None], fixed[:, None, :]]                     # (X, s, s)
    hf = h[fixed]                                                   # (X, s)
    Minv = np.linalg.pinv(g, rcond=1e-12, hermitian=True)
    b0 = (Minv @ hf[..., None])[..., 0]
    rss0 = yy - 2 * np.einsum("xi,xi->x", b0, hf) + np.einsum("xi,xij,xj->x", b0, g, b0)
    U = G[fixed[:, :, None], cands[None, None, :]]                  # (X, s, nc)
    v = G[cands, cands]
    Zm = Minv @ U
    schur = v - np.einsum("xic,xic->xc", U, Zm)
    r = h[cands] - np.einsum("xic,xi->xc", U, b0)
    ok = schur > SINGULAR * np.maximum(v, 1e-300)
    gain = np.where(ok, r ** 2 / np.where(ok, schur, 1.0), 0.0)
    return np.maximum(rss0[:, None] - gain, 0.0)
