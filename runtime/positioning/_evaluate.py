"""The ISO 230-2:2014 clause 3 quantities of a positioning run.

Notation of the standard: target P_i (i = 1..m), cycle j (j = 1..n), up arrow = forward
(approach in the positive direction), down arrow = backward; x_ij = positional deviation
(actual minus target).  Per target::

    mean unidirectional deviation     xm_i_up = (1/n) sum_j x_ij_up           (xm_i_dn likewise)
    mean bidirectional deviation      xm_i    = (xm_i_up + xm_i_dn) / 2
    reversal value                    B_i     = xm_i_up - xm_i_dn
    unidirectional repeatability estimator
                                      S_i_up  = sqrt(sum_j (x_ij_up - xm_i_up)^2 / (n - 1))
    unidirectional repeatability      R_i_up  = 4 S_i_up                      (R_i_dn likewise)
    bidirectional repeatability       R_i     = max(2 S_i_up + 2 S_i_dn + |B_i|, R_i_up, R_i_dn)

For the axis::

    B  = max_i |B_i|                  B_avg = (1/m) sum_i B_i   (signed: forward minus backward)
    R_up = max_i R_i_up,  R_dn = max_i R_i_dn,  R = max_i R_i
    E_up = max_i xm_i_up - min_i xm_i_up                        (E_dn likewise)
    E  = max(xm_i_up, xm_i_dn over all i) - min(xm_i_up, xm_i_dn over all i)
         (over BOTH directions, so E >= max(E_up, E_dn); it is not max(E_up, E_dn))
    M  = max_i xm_i - min_i xm_i
    A_up = max_i (xm_i_up + 2 S_i_up) - min_i (xm_i_up - 2 S_i_up)       (A_dn likewise)
    A  = max over i and both directions of (xm + 2 S) - min over i and both directions of
         (xm - 2 S)

All in mm here (um in the reports).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..units import UM_PER_MM

from ._io import BWD, FWD, PositioningRun

#: axis figures: JSON key (um) -> attribute name
FIGURES = {"A_um": "A", "A_fwd_um": "A_fwd", "A_bwd_um": "A_bwd", "B_um": "B",
           "B_avg_um": "B_avg", "R_um": "R", "R_fwd_um": "R_fwd", "R_bwd_um": "R_bwd",
           "E_um": "E", "E_fwd_um": "E_fwd", "E_bwd_um": "E_bwd", "M_um": "M"}
#: per-target arrays: JSON key (um) -> attribute name; the repeatabilities at a position are
#: ``R_i_*_um`` (the standard's R_i), distinct from the axis figures ``R_um`` ``R_fwd_um`` ...
PER_TARGET = {"mean_fwd_um": "mean_fwd", "mean_bwd_um": "mean_bwd", "mean_um": "mean",
              "reversal_um": "reversal", "s_fwd_um": "s_fwd", "s_bwd_um": "s_bwd",
              "R_i_fwd_um": "R_i_fwd", "R_i_bwd_um": "R_i_bwd", "R_i_um": "R_i"}


@dataclass(frozen=True)
class Evaluation:
    """ISO 230-2 results of one run, mm.  Per-target arrays have shape (m,)."""

    run: PositioningRun
    mean_fwd: np.ndarray
    mean_bwd: np.ndarray
    mean: np.ndarray
    reversal: np.ndarray
    s_fwd: np.ndarray
    s_bwd: np.ndarray
    R_i_fwd: np.ndarray
    R_i_bwd: np.ndarray
    R_i: np.ndarray
    A: float
    A_fwd: float
    A_bwd: float
    B: float
    B_avg: float
    R: float
    R_fwd: float
    R_bwd: float
    E: float
    E_fwd: float
    E_bwd: float
    M: float

    def figures_um(self) -> dict:
        """The axis figures, um, keyed as in the JSON report."""
        return {k: float(getattr(self, a)) * UM_PER_MM for k, a in FIGURES.items()}

    def per_target_um(self) -> dict:
        """The per-target arrays as lists, um (targets in mm), keyed as in the JSON report."""
        out = {"targets_mm": [float(v) for v in self.run.targets]}
        out.update({k: [float(v) * UM_PER_MM for v in getattr(self, a)] for k, a in PER_TARGET.items()})
        return out


def _range(values) -> float:
    return float(np.max(values) - np.min(values))


def evaluate(run: PositioningRun) -> Evaluation:
    """All ISO 230-2:2014 clause 3 quantities of ``run`` (definitions in the module docstring).

    Parameters
    ----------
    run : PositioningRun
        Deviations (actual minus target) at m targets x 2 directions x n cycles, mm
        (:func:`volerr.positioning.read_run`, optionally :func:`correct_to_20C`).

    Returns
    -------
    Evaluation
        Per-target arrays, shape (m,), and the axis figures A, B, E, M, R (bidirectional and
        per direction), mm; :meth:`Evaluation.figures_um` and :meth:`Evaluation.per_target_um`
        give them in um.
    """
    x = run.deviation                                   # (m, 2, n) mm
    xm = x.mean(axis=2)                                 # (m, 2)
    s = x.std(axis=2, ddof=1)                           # (m, 2): n - 1 in the denominator
    up, dn = xm[:, FWD], xm[:, BWD]
    s_up, s_dn = s[:, FWD], s[:, BWD]
    mean = 0.5 * (up + dn)
    b = up - dn
    r_up, r_dn = 4.0 * s_up, 4.0 * s_dn
    r_i = np.maximum.reduce([2.0 * s_up + 2.0 * s_dn + np.abs(b), r_up, r_dn])
    hi, lo = xm + 2.0 * s, xm - 2.0 * s                 # (m, 2)
    return Evaluation(
        run=run, mean_fwd=up, mean_bwd=dn, mean=mean, reversal=b, s_fwd=s_up, s_bwd=s_dn,
        R_i_fwd=r_up, R_i_bwd=r_dn, R_i=r_i,
        A=float(hi.max() - lo.min()),
        A_fwd=float(hi[:, FWD].max() - lo[:, FWD].min()),
        A_bwd=float(hi[:, BWD].max() - lo[:, BWD].min()),
        B=float(np.abs(b).max()), B_avg=float(b.mean()),
        R=float(r_i.max()), R_fwd=float(r_up.max()), R_bwd=float(r_dn.max()),
        E=_range(xm), E_fwd=_range(up), E_bwd=_range(dn), M=_range(mean))
