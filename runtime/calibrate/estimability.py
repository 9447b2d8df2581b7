"""Which parameters a campaign determines, and which file sees which.

Estimable: a parameter (one column of the design) can be determined on its own from the
stacked readings of all files, whatever values the others and the set-up unknowns take, iff
its column is not in the span of all the other columns: its relative distance to that span
(columns scaled to unit length first: mm and rad columns differ by orders of magnitude) is
above :data:`DISTANCE_TOL`.  Whom it is confounded with: the columns sharing its null-space
directions.

Seen by a file: the file's readings depend on the parameter after that file's own set-up
unknowns are removed (a ballbar circle in XY does not see EZZ at all; a pure offset of a
translational error is absorbed by the pivot's position).

Not seen at all (:func:`negligible`): a parameter column whose RMS over the readings is below
:data:`NEGLIGIBLE` times its RMS over an ideal 3-D plan of the measured volume -- a step gauge
along X reads a Z error through the gauge's micro-radian misalignment only, a series term of
an axis that moved by micrometres (the positions of an artifact come from the points the
machine reports) spans nothing.  Scale-free tests would take such columns for information;
they are zeroed before any test.
"""

from __future__ import annotations

import numpy as np

#: null-space eigenvalues of the unit-scaled Gram matrix, relative to the largest
NULL_TOL = 1e-10
#: relative distance of a unit column to the span of the others below which it is not estimable:
#: the Gram matrix resolves distances only to about sqrt(eps * condition) (~1e-5 on the
#: designs of five-axis chains); a column closer than 1e-4 would have a standard uncertainty
#: 10^4 times that of an orthogonal design anyway
DISTANCE_TOL = 1e-4
#: eigenvalues of the unit-scaled Gram matrix below this fraction of the largest are rounding
#: noise: their directions are exact dependencies of the columns
ROUNDING_TOL = 1e-13
#: a column whose component in an exact dependency exceeds this (unit-scaled; eigenvector noise
#: is ~1e-13 / eigenvalue gap) is not estimable, however small its coefficient in it
PARTICIPATION_TOL = 1e-7
#: a parameter column below this fraction of its RMS on an ideal plan is not seen at all
NEGLIGIBLE = 1e-6
#: a file sees a column when what its set-up leaves of the column's squared norm exceeds
#: this fraction of the largest squared norm the column has in any file
SEEN_TOL = 1e-9


def _unit(G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    d = np.sqrt(np.maximum(np.diag(G), 0.0))
    s = np.where(d > 0, d, 1.0)
    return G / np.outer(s, s), d > 0


def null_space(G: np.ndarray) -> np.ndarray:
    """Orthonormal basis (p, k) of the directions the readings do not determine."""
    C, nonzero = _unit(G)
    w, V = np.linalg.eigh(C)
    return V[:, w < NULL_TOL * max(float(w[-1]), 1e-300)]


def distances(G: np.ndarray) -> np.ndarray:
    """Relative distance (p,) of each unit-scaled column to the span of all the others (0 for
    a zero column): ``sqrt(C_jj - C_j,o C_o,o^+ C_o,j)`` from the Gram matrix."""
    C, nonzero = _unit(G)
    p = len(C)
    out = np.zeros(p)
    for j in np.flatnonzero(nonzero):
        o = np.r_[0:j, j + 1:p]
        if not len(o):          # a lone column: nothing to be in the span of (distance 1)
            out[j] = 1.0
            continue
        Co = C[np.ix_(o, o)]
        w, V = np.linalg.eigh(Co)
        keep = w > 1e-13 * max(float(w[-1]), 1e-300)
        c = V[:, keep].T @ C[o, j]
        out[j] = np.sqrt(max(1.0 - float(np.sum(c * c / w[keep])), 0.0))
    return out


def in_exact_dependency(G: np.ndarray) -> np.ndarray:
    """(p,) bool: the unit-scaled column takes part in an exact linear dependency of the
    columns (an eigenvector of a rounding-level eigenvalue, component above
    :data:`PARTICIPATION_TOL`).  :func:`distances` cannot see a column that enters a dependency
    with a tiny coefficient (``a = b + 1e-5 c``): from the Gram matrix its distance to the span
    of the others is resolved only to ``sqrt(eps / smallest eigenvalue of the others)``; the
    eigenvector of the whole matrix resolves it to ``eps / eigenvalue gap``."""
    C, _ = _unit(G)
    w, V = np.linalg.eigh(C)
    N = V[:, w < ROUNDING_TOL * max(float(w[-1]), 1e-300)]
    return np.sqrt(np.sum(N * N, axis=1)) > PARTICIPATION_TOL


def estimable(G: np.ndarray) -> tuple[np.ndarray, dict]:
    """(mask of individually estimable columns, column -> the columns it is confounded with).
    Estimable: the unit-scaled column is farther than :data:`DISTANCE_TOL` from the span of
    the others and takes part in no exact dependency (:func:`in_exact_dependency`)."""
    est = (distances(G) > DISTANCE_TOL) & ~in_exact_dependency(G)
    N = null_space(G)
    P = N @ N.T
    partners = {}
    _, nonzero = _unit(G)
    for j in np.flatnonzero(~est & nonzero):
        w = np.abs(P[j]) / max(P[j, j], 1e-300)
        partners[int(j)] = [int(k) for k in np.argsort(-w) if k != j and w[k] > 0.05]
    return est, partners


def seen_by(G_files: list, setup_cols: list) -> np.ndarray:
    """(files, p) bool: file f's readings depend on column j after f's own set-up columns
    (``setup_cols[f]``, indices) are removed.  ``G_files[f]``: the Gram matrix of f's rows."""
    p = G_files[0].shape[0]
    left = np.zeros((len(G_files), p))
    for f, (G, S) in enumerate(zip(G_files, setup_cols)):
        diag = np.diag(G).copy()
        if len(S):
            GS = G[np.ix_(S, S)]
            Gi = np.linalg.pinv(GS, rcond=1e-12, hermitian=True)
            B = G[S, :]
            diag = diag - np.einsum("ij,ik,kj->j", B, Gi, B)
        left[f] = np.maximum(diag, 0.0)
    top = np.max(np.stack([np.diag(G) for G in G_files]), axis=0)
    return left > SEEN_TOL * np.where(top > 0, top, np.inf)


def negligible(model, obs, labels, degree: int, ranges: dict, colsq: np.ndarray,
               n_readings: int) -> np.ndarray:
    """(p,) bool: the parameter columns of ``labels`` (a design's) whose RMS over the readings
    (``colsq`` their sums of squares over ``n_readings`` readings) is below
    :data:`NEGLIGIBLE` times their RMS on the ideal plan of the measured volume
    (:func:`volerr.estimate.design.ideal_data`); set-up columns never."""
    from ..estimate.design import declared_design, ideal_data

    ideal = declared_design(model, ideal_data(model, obs, ranges), degree, ranges)
    A = ideal.A.reshape(-1, ideal.A.shape[-1])
    rms_ideal = dict(zip(ideal.labels, np.sqrt(np.mean(A ** 2, axis=0))))
    rms = np.sqrt(np.maximum(colsq, 0.0) / max(n_readings, 1))
    out = np.zeros(len(labels), bool)
    for j, lab in enumerate(labels):
        if lab[0] == "setup" or lab not in rms_ideal:
            continue
        out[j] = rms[j] < NEGLIGIBLE * rms_ideal[lab]
    return out


#: a column left out enters a kept column's combination when its unit-scaled coefficient
#: exceeds this (smaller contributions are below what any campaign resolves)
COMBINATION_TOL = 1e-3


def combinations(G: np.ndarray, kept: np.ndarray, parameter: np.ndarray) -> dict:
    """What the solution's kept columns estimate where the design is rank-deficient.

    The solution keeps the columns ``kept`` (indices) and holds the others at 0; a column
    ``d`` left out lies in the span of the kept ones, ``A_d = sum_k B_kd A_k``, so the kept
    column ``k`` estimates ``x_k + sum_d B_kd x_d``.  Returns ``{k: {d: B_kd}}`` (natural
    units of the columns: mm, rad) for the kept ``parameter`` columns (bool mask, set-up
    unknowns excluded) whose estimate mixes in any left-out parameter column (unit-scaled
    coefficient above :data:`COMBINATION_TOL`)."""
    C, nonzero = _unit(G)
    norms = np.sqrt(np.maximum(np.diag(G), 0.0))
    kept = np.asarray(kept)
    left = [d for d in np.flatnonzero(parameter & nonzero) if d not in set(kept.tolist())]
    if not left or not len(kept):
        return {}
    B = np.linalg.lstsq(C[np.ix_(kept, kept)], C[np.ix_(kept, left)], rcond=1e-12)[0]
    out: dict = {}
    for a, k in enumerate(kept):
        if not parameter[k]:
            continue
        for b, d in enumerate(left):
            if abs(B[a, b]) > COMBINATION_TOL:
                out.setdefault(int(k), {})[int(d)] = float(B[a, b] * norms[d] / norms[k])
    return out
