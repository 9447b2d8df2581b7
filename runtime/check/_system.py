"""The check's readings against the reference as one linear system (the model of
:mod:`volerr.check`):

    r = y - A_p theta_ref = A_s s + A_p delta + e,      e ~ N(0, diag u^2),
    0 = delta - E_S Delta_S + eps,                      eps ~ N(0, Sigma_ref),

``y`` the readings, ``A_s`` the check's own set-up columns (sphere centres, pivots, stations,
with the files' priors), ``A_p`` the reference's parameters, ``theta_ref`` and ``Sigma_ref``
the reference's values and covariance, ``delta = theta_now - theta_ref``.  The second line is
the reference as a measurement: every parameter is where the reference put it, within its
covariance, except those of the set ``S`` allowed to change, whose change ``Delta_S`` is free.
The generalised least-squares fit gives the changes with uncertainties that hold the
reference's covariance, ``chi2(S)`` for the selection, and the values after the check
(``theta_ref + delta``, covariance the ``delta`` block of the inverse).

Rows are weighted by ``1 / u`` (dimensionless; ``u`` times the reference's Birge ratio
``sqrt(variance_factor)`` when that exceeds 1, as calibrate scales its covariance); parameter
columns per report unit (um, urad,
um/mm: the natural column divided by :meth:`volerr.check._reference.Reference.factors`),
set-up columns per um / urad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..estimate import blocks
from ..estimate.design import parameter_labels

#: relative eigenvalue below which a direction of the normal matrix counts as undetermined
SOLVE_TOL = 1e-12
#: folds of the cross-validation (:mod:`volerr.check._select`)
FOLDS = 5


@dataclass
class System:
    """Weighted rows ``A`` (n_rows, ns + p): set-up columns first, ``r`` (n_rows,) the weighted
    residual of the readings against the reference, ``point`` (n_rows,) the point of each row,
    ``prior_s`` (ns,) the set-ups' prior weights (0: unknown), ``Sinv`` (p, p) the inverse of
    the reference's covariance (report units), ``n_readings``, ``folds`` of the
    cross-validation (point ``i`` in fold ``i mod folds``)."""

    A: np.ndarray
    r: np.ndarray
    point: np.ndarray
    ns: int
    prior_s: np.ndarray
    Sinv: np.ndarray
    n_readings: int
    folds: int = FOLDS

    def __post_init__(self):
        # the normal equations of each fold (point i in fold i mod folds), accumulated once
        fold = self.point % self.folds
        self.fold_of_row = fold
        self._parts = []
        for k in range(self.folds):
            m = fold == k
            A, r = self.A[m], self.r[m]
            self._parts.append((A.T @ A, A.T @ r, float(r @ r)))

    @property
    def p(self) -> int:
        return self.A.shape[1] - self.ns

    def normal(self, leave_out=None) -> tuple[np.ndarray, np.ndarray, float]:
        """(G, b, r.r) of the data rows, all or all but fold ``leave_out``, with the set-up
        priors."""
        parts = [q for k, q in enumerate(self._parts) if k != leave_out]
        G = sum((q[0] for q in parts), np.zeros((self.A.shape[1],) * 2))
        b = sum((q[1] for q in parts), np.zeros(self.A.shape[1]))
        G[:self.ns, :self.ns] += np.diag(self.prior_s)
        return G, b, float(sum(q[2] for q in parts))

    def solve(self, changed, leave_out=None) -> "Fit":
        """The fit with the parameters ``changed`` (indices into the reference's) free to
        change, on all data rows or all but the fold ``leave_out``."""
        G, b, rr = self.normal(leave_out)
        ns, p, k = self.ns, self.p, len(changed)
        N = self.matrix(G, changed)
        bb = np.concatenate([b, np.zeros(k)])
        Ni = _inverse(N)
        z = Ni @ bb
        return Fit(list(changed), z, Ni, max(rr - float(bb @ z), 0.0), ns, p)

    def matrix(self, G: np.ndarray, changed) -> np.ndarray:
        """The normal matrix of the fit with ``changed`` free: the data's ``G`` (set-ups and
        parameters) plus the reference's information ``Sinv`` on the parameters before the
        change (``G`` = 0: the reference's part alone, :meth:`CheckResult.budgets`)."""
        ns, p, k = self.ns, self.p, len(changed)
        E = np.zeros((p, k))
        E[list(changed), np.arange(k)] = 1.0
        N = np.zeros((ns + p + k, ns + p + k))
        N[:ns + p, :ns + p] = G
        d = slice(ns, ns + p)
        N[d, d] += self.Sinv
        N[d, ns + p:] = -self.Sinv @ E
        N[ns + p:, d] = -E.T @ self.Sinv
        N[ns + p:, ns + p:] = E.T @ self.Sinv @ E
        return N

    def data_information(self) -> np.ndarray:
        """(p, p) the check's information on the parameters alone, set-ups eliminated (the
        Schur complement of the set-up block), report units."""
        G, _, _ = self.normal()
        ns = self.ns
        S, B = G[:ns, :ns], G[:ns, ns:]
        return G[ns:, ns:] - B.T @ _inverse(S) @ B if ns else G


@dataclass
class Fit:
    """One fit: ``changed`` indices, ``z`` (s, delta, Delta), ``Ni`` the inverse normal
    matrix, ``chi2`` the weighted residual sum of squares (readings and reference)."""

    changed: list
    z: np.ndarray
    Ni: np.ndarray
    chi2: float
    ns: int
    p: int

    def change(self) -> tuple[np.ndarray, np.ndarray]:
        """(Delta, std) of the changed parameters, report units."""
        k = self.ns + self.p
        return self.z[k:], np.sqrt(np.maximum(np.diag(self.Ni)[k:], 0.0))

    def delta(self) -> tuple[np.ndarray, np.ndarray]:
        """(delta (p,), covariance (p, p)): the values after the check minus the reference's,
        and their covariance, report units."""
        d = slice(self.ns, self.ns + self.p)
        return self.z[d], self.Ni[d, d]


def _inverse(N: np.ndarray) -> np.ndarray:
    """Pseudo-inverse of a symmetric PSD matrix, unit-scaled first, eigenvalues below
    ``SOLVE_TOL`` x the largest cut."""
    if N.size == 0:
        return N
    d = np.sqrt(np.maximum(np.diag(N), 0.0))
    d[d == 0] = 1.0
    return blocks.eig_inverse(N / np.outer(d, d), SOLVE_TOL) / np.outer(d, d)


def build(model, ref, obs) -> System:
    """The :class:`System` of the check's readings ``obs`` against the reference ``ref``
    (:class:`volerr.check._reference.Reference`)."""
    labels = ref.labels(model)
    fac = ref.factors(model)
    plabels = parameter_labels(model, ref.degree)
    keep = np.concatenate([np.ones(len(obs.setup_labels), bool),
                           np.array([lab in labels for lab in plabels])])
    design = blocks.Design(model, obs, ref.degree, ref.ranges, keep)
    ns = len(obs.setup_labels)
    order = [design.labels.index(lab) - ns for lab in labels]    # ref order -> parameter row
    units = obs.setup_units
    sfac = np.array([1e6 if u in ("urad", "ppm") else 1e3 for u in units])
    theta = ref.values / fac                                     # natural units
    # the readings' u inflated by the reference's Birge ratio when it exceeds 1 (its
    # covariance is scaled by its variance factor the same way)
    sigma = obs._sigmas() * np.sqrt(max(float(ref.data.get("variance_factor") or 1.0), 1.0))
    rows_A, rows_r, rows_pt = [], [], []
    y_all = obs.deviation.ravel()
    for _, idx in blocks.blocks(np.arange(obs.n)):
        At = design.block(idx)
        w = blocks.wrows(1.0 / sigma[idx])
        Ap = At[ns:][order]
        r = (blocks.yrows(y_all, idx) - theta @ Ap) * w
        cols = np.vstack([At[:ns] / sfac[:, None], Ap / fac[:, None]]) * w
        live = np.any(cols != 0, axis=0) | (r != 0)
        rows_A.append(cols[:, live].T)
        rows_r.append(r[live])
        rows_pt.append(np.tile(idx, 3)[live])
    prior = np.array([0.0 if not u else (1.0 / (u * f)) ** 2
                      for u, f in zip(obs.setup_priors, sfac)])
    d = ref.std
    Sinv = np.linalg.pinv(ref.cov / np.outer(d, d), hermitian=True) / np.outer(d, d)
    return System(np.vstack(rows_A), np.concatenate(rows_r), np.concatenate(rows_pt), ns,
                  prior, Sinv, int(obs.n_readings))
