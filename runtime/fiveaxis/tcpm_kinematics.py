"""The controller's nominal kinematics under TCPM: TCPM words <-> axis positions.

A TCPM block (:mod:`volerr.nc.tcpm`) gives the tool tip ``X Y Z`` (mm) in the workpiece frame
and the tool orientation as rotary angles or a tool vector; the controller turns them into
axis positions with the machine's nominal inverse kinematics (:func:`axes_from_words`).
Compensation moves the programmed tip (and, with ``--orientation``, the orientation) to the
forward kinematics of the compensated axis positions: after the controller's inverse, the
actual tool tip lands on the programmed one (:func:`words_from_axes`).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, require
from ..nc.tcpm import ANGLES, AXES, VECTOR, tool_offset  # noqa: F401
from .kinematics import _axis_sensitivity, is_five_axis, linear_axes


def linear_from_tip(model, tip: np.ndarray, rot_deg: np.ndarray, length) -> np.ndarray:
    """Linear axis positions (N, 3) that put the nominal tool tip on ``tip`` (N, 3) mm for the
    rotary positions ``rot_deg`` (N, 2) deg (``model.rotary_axes`` order)."""
    t = tool_offset(np.broadcast_to(np.asarray(length, dtype=float), (len(tip),)))
    r = np.deg2rad(rot_deg)
    lin = model.module.inverse_linear(r[:, 0], r[:, 1], tip[:, 0], tip[:, 1], tip[:, 2],
                                      t[:, 0], t[:, 1], t[:, 2])
    return np.column_stack([np.broadcast_to(np.asarray(v, dtype=float), (len(tip),))
                            for v in lin])


def rotary_from_vector(model, vector: np.ndarray, previous: np.ndarray) -> np.ndarray:
    """Rotary positions (N, 2) deg for the tool vectors ``vector`` (N, 3), continuing from the
    rotary positions ``previous`` (2,) deg held before the first row, block by block as a
    controller does: of the two solutions, each turned (multiples of 360 deg) to the value
    nearest the previous block's, the one inside the travel and nearest the previous block;
    an axis undetermined on a singular orientation keeps its previous value.  Raises
    :class:`InputError` (row index in the message) for an unreachable orientation."""
    n = len(vector)
    if not n:
        return np.zeros((0, 2))
    norm = np.linalg.norm(vector, axis=1, keepdims=True)
    if not np.all(norm > 0):
        raise InputError(f"row {int(np.argmin(norm[:, 0] > 0))}: the tool vector is zero")
    k = vector / norm
    cand = np.empty((2, n, 2))
    for b, branch in enumerate((1.0, -1.0)):
        sol = model.module.inverse_rotary(k[:, 0], k[:, 1], k[:, 2], branch)
        for j, v in enumerate(sol):
            cand[b, :, j] = np.rad2deg(np.broadcast_to(np.asarray(v, dtype=float), (n,)))
    bad = ~np.all(np.isfinite(cand), axis=(0, 2))
    if bad.any():
        raise InputError(f"row {int(np.argmax(bad))}: tool orientation unreachable")
    rot = model.rotary_axes
    for b in range(2):
        for j, a in enumerate(rot):
            sens = _axis_sensitivity(model, {rot[0]: cand[b, :, 0], rot[1]: cand[b, :, 1]}, a)
            cand[b, sens < 1e-9, j] = np.nan
    lo = [model.travel[a][0] - 1e-9 for a in rot]
    hi = [model.travel[a][1] + 1e-9 for a in rot]
    out = np.empty((n, 2))
    prev = [float(previous[0]), float(previous[1])]
    c = cand.tolist()
    for i in range(n):
        best, best_score = None, None
        for b in (0, 1):
            v, inside, dist = [], True, 0.0
            for j in (0, 1):
                x = c[b][i][j]
                if x != x:
                    x = prev[j]                                 # undetermined: stays
                x = prev[j] + (x - prev[j] + 180.0) % 360.0 - 180.0
                for turn in (0.0, 360.0, -360.0):
                    if lo[j] <= x + turn <= hi[j]:
                        x += turn
                        break
                else:
                    inside = False
                v.append(x)
                dist += abs(x - prev[j])
            score = dist + (0.0 if inside else 1e6)
            if best_score is None or score < best_score:
                best, best_score = v, score
        out[i] = best
        prev = best
    return out


def axes_from_words(model, w: np.ndarray, frame: np.ndarray, length: np.ndarray,
                    previous_rot: np.ndarray) -> np.ndarray:
    """Axis positions (N, n_axes) the controller goes to: ``w`` (N, n_axes + 3) the words
    (for TCPM rows the linear columns the tip, rotary columns the angles of :data:`ANGLES`
    rows, the last three the tool vector of :data:`VECTOR` rows; :data:`AXES` rows the axis
    positions themselves), ``frame`` (N,), ``length`` (N,) mm (TCPM rows);
    ``previous_rot`` (2,) deg the rotary positions before the first row (vector rows continue
    from the row before them)."""
    require(is_five_axis(model), f"{model.name}: TCPM needs a five-axis layout with its "
                                 "inverse kinematics")
    axes = model.axes
    rot_idx = [axes.index(a) for a in model.rotary_axes]
    lin_idx = [axes.index(a) for a in linear_axes(model)]
    nax = len(axes)
    n = len(w)
    q = np.full((n, nax), np.nan)
    rot = np.full((n, 2), np.nan)
    ang = frame != VECTOR               # rotary words: TCPM angles, or axis positions
    rot[ang] = w[ang][:, rot_idx]
    vec = np.flatnonzero(frame == VECTOR)
    if len(vec):
        # a vector row continues from the rotary positions of the row before it
        prev = previous_rot.astype(float)
        breaks = np.flatnonzero(np.diff(vec) != 1) + 1
        for part in np.split(vec, breaks):
            before = part[0] - 1
            p = rot[before] if before >= 0 and np.all(np.isfinite(rot[before])) else prev
            rot[part] = rotary_from_vector(model, w[part, nax:nax + 3], p)
    q[:, rot_idx] = rot
    tc = frame != AXES
    q[np.ix_(tc, lin_idx)] = linear_from_tip(model, w[tc][:, lin_idx], rot[tc], length[tc])
    q[~tc] = w[~tc, :nax]               # axis positions as they are
    return q


def words_from_axes(model, q: np.ndarray, length: np.ndarray) -> np.ndarray:
    """The TCPM words (N, n_axes + 3) of axis positions ``q`` (N, n_axes): the nominal tool
    tip in the linear columns, the rotary positions in the rotary columns, the unit tool
    vector in the last three (forward kinematics with the tool offset of ``length``)."""
    axes = model.axes
    lin_idx = [axes.index(a) for a in linear_axes(model)]
    rot_idx = [axes.index(a) for a in model.rotary_axes]
    f = model.forward(q, tool_offset(length))
    out = np.empty((len(q), len(axes) + 3))
    out[:, lin_idx] = f[:, :3]
    out[:, rot_idx] = q[:, rot_idx]
    out[:, len(axes):] = f[:, 3:6]
    return out
