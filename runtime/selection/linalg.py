"""The linear algebra that selection and estimation share: one symmetric pseudo-inverse, one
normal-equations solve (plain or column-scaled).  Small dense matrices (the Gram matrices of
a few to a few hundred columns); no units of their own."""

from __future__ import annotations

import numpy as np


def pinv_sym(G, tol: float = 1e-12) -> np.ndarray:
    """Pseudo-inverse of a symmetric positive semi-definite ``G`` by eigh: eigenvalues below
    ``tol`` times the largest are cut."""
    w, V = np.linalg.eigh(G)
    ok = w > tol * max(float(w[-1]), 1e-300)
    return (V[:, ok] / w[ok]) @ V[:, ok].T


def solve_normal(G: np.ndarray, b: np.ndarray, tol: float) -> np.ndarray:
    """Minimum-norm solution of ``G x = b`` (``G`` symmetric PSD): eigenvalues below ``tol``
    times the largest cut."""
    w, V = np.linalg.eigh(G)
    wmax = max(float(w[-1]), 1e-300)
    ok = w > tol * wmax
    return V[:, ok] @ ((V[:, ok].T @ b) / w[ok])


def solve_scaled(G: np.ndarray, h: np.ndarray, rcond: float = 1e-12) -> np.ndarray:
    """The least-squares coefficients from the normal equations ``G b = h`` solved with the
    columns scaled to unit norm (pseudo-inverse, ``rcond``); a column all zero (a run without
    readings) gets 0.  Coefficients in the units of the unscaled columns.

    numpy's Hermitian pseudo-inverse, not :func:`pinv_sym`: the two agree to the last bits
    only, and the drift loop's static regression (nearly collinear temperatures) moves by
    2e-12 relative between them (FL_THERMAL, measured): kept as the drift figures were
    measured."""
    d = np.sqrt(np.diag(G))
    on = d > 0
    b = np.zeros(len(h))
    Gs = G[np.ix_(on, on)] / np.outer(d[on], d[on])
    b[on] = np.linalg.pinv(Gs, rcond=rcond, hermitian=True) @ (h[on] / d[on])
    b[on] /= d[on]
    return b
