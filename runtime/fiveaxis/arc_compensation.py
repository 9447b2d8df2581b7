"""The compensation of arcs ``G2``/``G3`` (their geometry: :mod:`volerr.nc.arcs`).

An arc is compensated in one of two ways, chosen per arc with the tolerance ``T``
(``--arc-tolerance-um``, default 1 um):

* **kept as an arc**, when the correction the model asks for (compensated minus nominal axis
  position, :func:`volerr.fiveaxis.compensate.solve`) varies by less than ``T`` along it
  (sampled at the points of the linearisation below): the end point gets its own correction
  and the centre the correction of the end point, so the whole arc moves with it; the centre
  words are written relative to the start as written (``I J K``) or the radius from the
  corrected centre (``R``).  What is left along the arc is the variation of the correction,
  less than ``T``.
* **linearised** otherwise: the arc becomes straight ``G1`` moves between compensated points
  of the nominal arc.  The points are spaced so that the chord deviates from the arc by at
  most ``T / 2``; then the predicted actual tool tip (model) on every segment, at a quarter,
  half and three quarters of it, must lie within ``T`` of the nominal arc, else the arc's
  segments are halved until it does (at most :data:`MAX_REFINE` times).

The tool tip follows the axis arc through the nominal kinematics, which for fixed rotary
positions is a rigid motion (orthogonal linear axes), so the deviation from the nominal arc is
measured in axis space.
"""

from __future__ import annotations

import numpy as np

from ..nc.arcs import ArcResult, segments_for_chord
from ..machine.kinematics import linear_jacobian
from .reversal import along

#: halvings of the segments of one arc at most
MAX_REFINE = 8
#: points along a segment where the predicted path is checked
CHECK_AT = (0.25, 0.5, 0.75)


def compensate(em, paths: list, solve, tol_mm: float, keep: bool = True,
               start_dirs=None) -> list:
    """:class:`ArcResult` of every :class:`ArcPath` in ``paths``.  ``solve(q, direction)`` ->
    the compensated positions (k, n_axes) of nominal positions ``q`` approached in
    ``direction`` (None without reversal; the same rule as for every block); ``em`` the
    :class:`volerr.fiveaxis.compensate.ErrorModel` (predicted actual tool tip); ``tol_mm``
    the tolerance; ``keep=False``: always linearise; ``start_dirs``: per arc the approach
    directions (n_axes,) before it (None: no reversal), the points along the arc approached
    as the arc moves through them (:mod:`volerr.fiveaxis.reversal`)."""
    out = [None] * len(paths)
    if not paths:
        return out
    lin = [em.model.axes.index(a) for a in em.lin]
    n_seg = [segments_for_chord(p, tol_mm / 2) for p in paths]
    todo = list(range(len(paths)))
    for rnd in range(MAX_REFINE + 1):
        # the compensated points of every arc still to decide, in one solve
        ts = [np.linspace(0.0, 1.0, n_seg[i] + 1) for i in todo]
        pts = [paths[i].points(t) for i, t in zip(todo, ts)]
        q_nom = np.concatenate(pts)
        dirs = None
        if start_dirs is not None:
            dirs = np.concatenate([
                along(np.vstack([np.zeros((1, p.shape[1]), np.int8),
                                 np.sign(np.diff(p, axis=0)).astype(np.int8)]),
                      np.asarray(start_dirs[i], np.int8)) for i, p in zip(todo, pts)])
        q_c = solve(q_nom, dirs)
        corr = q_c - q_nom
        # the predicted tool tip between the points: straight moves in axis space
        mids, mid_dirs, owner = [], [], []
        at = 0
        for i, t in zip(todo, ts):
            k = len(t)
            a, b = q_c[at:at + k - 1], q_c[at + 1:at + k]
            for f in CHECK_AT:
                mids.append(a + f * (b - a))
                if dirs is not None:
                    mid_dirs.append(dirs[at + 1:at + k])   # a segment moves as its end
            owner.append((i, at, k))
            at += k
        # mids: for each arc, len(CHECK_AT) blocks of (k - 1) rows
        mid = np.concatenate(mids)
        tip_dev = _path_deviation(em, mid, paths, owner, lin,
                                  np.concatenate(mid_dirs) if dirs is not None else None)
        again = []
        pos = 0
        for (i, at0, k) in owner:
            m = len(CHECK_AT) * (k - 1)
            dev = float(tip_dev[pos:pos + m].max()) if m else 0.0
            pos += m
            c = corr[at0:at0 + k][:, lin]
            variation = float(np.max(np.linalg.norm(c - c[-1], axis=1)))
            if keep and variation < tol_mm:
                end_corr = corr[at0 + k - 1]
                a, b, _ = paths[i].plane
                centre = paths[i].centre + end_corr[[a, b]]
                out[i] = ArcResult(True, centre, None, variation * 1e3, variation * 1e3)
            elif dev <= tol_mm or rnd == MAX_REFINE:
                out[i] = ArcResult(False, None, q_c[at0 + 1:at0 + k], variation * 1e3,
                                   dev * 1e3)
            else:
                n_seg[i] *= 2
                again.append(i)
        todo = again
        if not todo:
            break
    return out


def _path_deviation(em, q_mid: np.ndarray, paths, owner, lin, direction=None) -> np.ndarray:
    """Distance (mm) of the predicted actual tool tip at the axis positions ``q_mid`` from
    the nominal arc of their owner: the actual tip mapped back into axis space through the
    nominal kinematics (affine in the linear axes for fixed rotary positions)."""
    q_back = actual_in_axes(em, q_mid, lin, direction)
    out = np.empty(len(q_mid))
    pos = 0
    nf = len(CHECK_AT)
    for i, _, k in owner:
        m_rows = nf * (k - 1)
        out[pos:pos + m_rows] = paths[i].distance(q_back[pos:pos + m_rows])
        pos += m_rows
    return out


def actual_in_axes(em, q: np.ndarray, lin, direction=None) -> np.ndarray:
    """The predicted actual tool tip at the axis positions ``q`` (k, n_axes), expressed as
    the axis positions (mm / deg) whose nominal tip it is: the rotary axes held, the linear
    axes (indices ``lin``) moved by ``M^-1 e(q)``, ``M`` the derivative of the nominal tip by
    the linear axes (one Newton step is exact: the nominal chain is affine in them)."""
    m = em.model
    actual = m.nominal_position(q, em.tool) + em.position_error(q, None, direction)
    jac = linear_jacobian(m, q, em.tool)
    q_back = q.copy()
    q_back[:, lin] += np.linalg.solve(jac, (actual - m.nominal_position(q, em.tool))
                                      [:, :, None])[:, :, 0]
    return q_back
