"""The one Legendre polynomial fit of volerr: weighted least squares on the measured range
mapped to [-1, 1], degree by leave-one-out cross-validation with the one-standard-error rule.

Used by the error tables (:func:`volerr.tables.functions.make_function` ``method="poly"``) and the
error-function fits (:mod:`volerr.tables.errorfit`); importable by any other capability.
Positions in any unit (mm or deg), values in any unit (mm or rad): the fit is linear.
"""

from __future__ import annotations

import math

import numpy as np

#: largest degree the automatic choice considers
MAX_AUTO_DEGREE = 12


def scaled(x, lo: float, hi: float) -> np.ndarray:
    """Positions mapped linearly from [lo, hi] to [-1, 1]."""
    return (np.asarray(x, dtype=float) - 0.5 * (lo + hi)) / (0.5 * (hi - lo))


def loo_errors(x, y, degree: int, weights=None) -> np.ndarray:
    """Leave-one-out prediction errors, shape (n,), of the (weighted) least-squares Legendre
    polynomial of ``degree`` through ``(x, y)`` (hat-matrix form, no refits).

    With ``weights`` w the fit minimises ``sum(w^2 r^2)`` (numpy ``legfit`` convention) and
    the errors are the unweighted ``y_i - yhat_(-i)``."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    w = np.ones_like(y) if weights is None else np.asarray(weights, dtype=float)
    t = scaled(x, float(np.min(x)), float(np.max(x)))
    V = np.polynomial.legendre.legvander(t, degree) * w[:, None]
    Q, _ = np.linalg.qr(V)
    h = np.sum(Q ** 2, axis=1)
    r = y * w - Q @ (Q.T @ (y * w))
    return r / np.clip(1.0 - h, 1e-12, None) / w


def choose_degree(x, y, max_degree: int | None = None, weights=None) -> int:
    """Degree by leave-one-out cross-validation (mean of the squared, weighted LOO errors),
    taking the lowest degree within one standard error of the best (at most ``n - 2`` and
    :data:`MAX_AUTO_DEGREE`)."""
    n = len(x)
    w = np.ones(n) if weights is None else np.asarray(weights, dtype=float)
    top = n - 2 if max_degree is None else min(max_degree, n - 2)
    top = max(0, min(top, MAX_AUTO_DEGREE))
    scores, ses = [], []
    for d in range(top + 1):
        e2 = (loo_errors(x, y, d, weights) * w) ** 2
        scores.append(e2.mean())
        ses.append(e2.std(ddof=1) / math.sqrt(n) if n > 1 else 0.0)
    best = int(np.argmin(scores))
    return next(d for d in range(best + 1) if scores[d] <= scores[best] + ses[best])


class LegendreFit:
    """A fitted Legendre series on the range [lo, hi] of the nodes; callable on positions.

    Attributes: ``coef`` (Legendre coefficients, values' unit), ``lo``, ``hi`` (positions'
    unit), ``degree``."""

    def __init__(self, x, y, degree: int, weights=None):
        x = np.asarray(x, dtype=float)
        self.lo, self.hi = float(np.min(x)), float(np.max(x))
        self.coef = np.polynomial.legendre.legfit(scaled(x, self.lo, self.hi),
                                                  np.asarray(y, dtype=float), degree, w=weights)
        self.degree = int(degree)

    def __call__(self, q) -> np.ndarray:
        return np.polynomial.legendre.legval(scaled(q, self.lo, self.hi), self.coef)


def fit(x, y, degree: int | None = None, weights=None, max_degree: int | None = None
        ) -> LegendreFit:
    """Fit a Legendre polynomial; ``degree=None`` chooses it (:func:`choose_degree`)."""
    if degree is None:
        degree = choose_degree(x, y, max_degree, weights)
    return LegendreFit(x, y, degree, weights)
