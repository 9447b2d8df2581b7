"""The predicted path of compensated straight feed moves ``G1`` between their corrected ends.

Compensation corrects the end point of every block (:mod:`volerr.fiveaxis.compensate`);
between two corrected ends the controller interpolates the axes linearly (joint space, without
TCPM), so along the move the actual tool tip follows ``p(q(t)) + e(q(t))`` with
``q(t) = a' + t (b' - a')``, ``a'`` / ``b'`` the written start / end.  Its deviation from the
nominal path (the programmed move from ``a`` to ``b``, joint space as well) is measured as
for arcs (:mod:`volerr.fiveaxis.arc_compensation`): the actual tip is mapped back into axis
space through the nominal kinematics (:func:`~volerr.fiveaxis.arc_compensation.actual_in_axes`)
and its distance (mm; with orthogonal linear axes the distance of the tool tip) to the nominal
segment in the linear axes is taken: to the nearest point of the segment.

Which moves are sampled: ``G1`` moves in axis positions whose start and end are both known
(the first known block of a program, and a block after one whose position is unknown, have
no known start).  ``G0`` rapids are not: their path is not cut (and controllers do not
interpolate rapids linearly anyway).  Arcs have their own path check (``arcs`` in the
report).  TCPM moves are not sampled: under TCPM the controller interpolates the tool tip
linearly in the workpiece frame, not the axes, and what the axes do between the blocks is the
controller's (counted as ``tcpm_not_sampled``).

Sampling rule, per move: both ends, every point where an axis with an error table crosses
one of its table's positions (knots), and the fractions :data:`CHECK_AT` of every interval
between these points.  With ``--method linear`` each table value is linear in ``t`` between
knot crossings; the tool-tip error is then linear there (translational errors) or quadratic
(an angular error times its lever arm, which also moves linearly), and a quadratic's largest
value on the interval is found by the quarter points to within 1/16 of its curvature term
(about 0.01 um on the shipped examples' tables).  With ``cubic`` / ``poly`` the correction is
smooth but not piecewise polynomial of low degree between knots: the same points are a
sampling, not a bound (the knots are still where it changes the most).  Rotary tables of an
endless axis are read in their raw positions (a move past 360 deg is sampled at its quarter
points only between the knots it crosses there).
"""

from __future__ import annotations

import numpy as np

from ..nc import tcpm
from .arc_compensation import CHECK_AT, actual_in_axes


class LinePaths:
    """The path deviation of the ``G1`` moves of a program, chunk by chunk: the last block's
    nominal and written positions are carried from one chunk to the next."""

    def __init__(self):
        #: (nominal, written) positions (n_axes,) of the last known block, or None
        self.last = None

    def chunk(self, em, b, q_out: np.ndarray) -> dict:
        """Row -> largest predicted deviation (um) of the tool tip from the nominal path
        along the ``G1`` move of that row (rows of ``b`` with a known start; see the module
        docstring), also counting ``tcpm_not_sampled`` rows under the key -1."""
        moves, tcpm_rows = [], 0
        feed = b.feed if b.feed is not None else np.zeros(len(q_out), dtype=bool)
        for r in b.order:
            if r < 0:
                self.last = None        # a block whose position is unknown: no start
                continue
            if feed[r] and self.last is not None and r not in b.arcs:
                if b.frame is not None and b.frame[r] != tcpm.AXES:
                    tcpm_rows += 1
                else:
                    moves.append((r, self.last[0], self.last[1]))
            self.last = (b.q_nom[r].copy(), q_out[r].copy())
        out = deviations(em, moves, b, q_out) if moves else {}
        if tcpm_rows:
            out[-1] = tcpm_rows
        return out


def sample_fractions(em, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """The fractions ``t`` of the move from ``start`` to ``end`` (axis positions) sampled:
    both ends, the knots crossed, and :data:`CHECK_AT` of every interval between them."""
    ts = [0.0, 1.0]
    funcs = em.funcs
    for a, table in (funcs.tables.items() if funcs is not None else ()):
        i = em.model.axes.index(a)
        d = end[i] - start[i]
        if d == 0.0:
            continue
        k = np.asarray(table.positions, dtype=float)
        t = (k - start[i]) / d
        ts.extend(t[(t > 0.0) & (t < 1.0)].tolist())
    edges = np.unique(ts)
    inner = edges[:-1, None] + np.diff(edges)[:, None] * np.asarray(CHECK_AT)[None, :]
    return np.unique(np.concatenate([edges, inner.ravel()]))


def deviations(em, moves: list, b, q_out: np.ndarray) -> dict:
    """Row -> deviation (um) of the moves ``[(row, nominal start, written start)]``."""
    lin = [em.model.axes.index(a) for a in em.lin]
    pts, owner, dirs = [], [], []
    for r, a_nom, a_out in moves:
        t = sample_fractions(em, a_out, q_out[r])
        pts.append(a_out[None, :] + t[:, None] * (q_out[r] - a_out)[None, :])
        owner.append((r, a_nom, len(t)))
        if b.direction is not None:
            dirs.append(np.repeat(b.direction[r][None, :], len(t), axis=0))
    q = np.concatenate(pts)
    back = actual_in_axes(em, q, lin, np.concatenate(dirs) if dirs else None)[:, lin]
    out, at = {}, 0
    for r, a_nom, k in owner:
        p0, p1 = a_nom[lin], b.q_nom[r][lin]
        out[r] = float(segment_distance(back[at:at + k], p0, p1).max()) * 1e3
        at += k
    return out


def segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of the points ``p`` (k, d) from the segment ``a`` -> ``b`` (d,): to the
    nearest point of it (an end where the projection falls outside)."""
    d = b - a
    dd = float(d @ d)
    t = np.zeros(len(p)) if dd == 0.0 else np.clip((p - a) @ d / dd, 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * d), axis=1)
