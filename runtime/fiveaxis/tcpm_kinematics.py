"""The controller's nominal kinematics under TCPM: TCPM words <-> axis positions.

A TCPM block (:mod:`volerr.nc.tcpm`) gives the tool tip ``X Y Z`` (mm) in the workpiece frame
and the tool orientation as rotary angles or a tool vector; the controller turns them into
axis positions (:func:`axes_from_words`) with the machine's nominal inverse kinematics and
the tool length ``L`` of the active tool:

* rotary angles: the rotary axes go to the angles, the linear axes to the generated
  ``inverse_linear`` of the layout (derived in :mod:`volerr.derive.inverse`), so that the
  nominal tool tip lands on ``X Y Z``;
* tool vector: the rotary axes come from the generated ``inverse_rotary`` (two solutions, and
  a turn of 360 deg for each): the one nearest the previous block, branch by branch and turn
  by turn as a controller continues a path (:func:`rotary_from_vector`); on a singular
  orientation (the tool along the first rotary axis) the undetermined axis stays where it was.

Compensation moves the programmed tip (and, with ``--orientation``, the orientation) to the
forward kinematics of the compensated axis positions: after the controller's inverse, the
actual tool tip lands on the programmed one (:func:`words_from_axes`).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, require
from ..nc.tcpm import AXES, VECTOR, tool_offset
from ..machine.kinematics import is_five_axis, linear_axes, nominal_jacobian


def linear_from_tip(model, tip: np.ndarray, rot_deg: np.ndarray, length) -> np.ndarray:
    """Linear axis positions (N, 3) that put the nominal tool tip on ``tip`` (N, 3) mm for the
    rotary positions ``rot_deg`` (N, 2) deg (``model.rotary_axes`` order)."""
    t = tool_offset(np.broadcast_to(np.asarray(length, dtype=float), (len(tip),)))
    r = np.deg2rad(rot_deg)
    lin = model.module.inverse_linear(r[:, 0], r[:, 1], tip[:, 0], tip[:, 1], tip[:, 2],
                                      t[:, 0], t[:, 1], t[:, 2])
    return np.column_stack([np.broadcast_to(np.asarray(v, dtype=float), (len(tip),))
                            for v in lin])


def rotary_from_vector(model, vector: np.ndarray, previous: np.ndarray,
                       guess: np.ndarray | None = None) -> np.ndarray:
    """Rotary positions (N, 2) deg for the tool vectors ``vector`` (N, 3), continuing from the
    rotary positions ``previous`` (2,) deg held before the first row, block by block as a
    controller does (:func:`decide`): of the two solutions, each turned (multiples of 360 deg)
    to the value nearest the previous block's, the one inside the travel and nearest the
    previous block; an axis undetermined on a singular orientation keeps its previous value.
    Raises :class:`InputError` (row index in the message) for an unreachable orientation.

    All rows at once: a guess (:func:`_guess`; or ``guess`` (N, 2) deg, rotary positions
    near the result, e.g. those of the same vectors continued from another start, improved by
    :func:`_follow`) checked row by row against the rule (:func:`_settle`): the result is bit
    for bit that of the block-by-block rule (:func:`block_by_block`, the reference) whatever
    the guess."""
    n = len(vector)
    if not n:
        return np.zeros((0, 2))
    cand = _candidates(model, vector)
    lo, hi = _limits(model)
    prev = np.asarray(previous, dtype=float)
    if guess is None or np.shape(guess) != (n, 2):
        q = _guess(cand, prev, lo, hi)
    else:
        q = _follow(cand, np.array(guess, dtype=float), prev, lo, hi)
    return _settle(cand, q, prev, lo, hi)


def _follow(cand, q, previous, lo, hi, rounds: int = 4) -> np.ndarray:
    """``q`` (N, 2) deg decided again from its own rows (:func:`decide`, all rows at once),
    up to ``rounds`` times or until it no longer changes: after round r the first r rows are
    the rule's; a guess that differs from the result in the last bits only (the start moved
    by an ulp) becomes it in a round or two."""
    for _ in range(rounds):
        new = decide(cand, np.vstack([previous[None, :], q[:-1]]), lo, hi)[0]
        if np.array_equal(new, q):
            break
        q = new
    return q


def _candidates(model, vector: np.ndarray) -> np.ndarray:
    """The two solutions (2, N, 2) deg of the generated ``inverse_rotary`` for each tool
    vector; NaN for an axis that does not turn the tool there (singular orientation)."""
    n = len(vector)
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
    # an axis turns the tool by |axis direction x tool vector|: for the axis next to the
    # workpiece that depends on the vector alone, for the other it is constant, so both
    # solutions of a vector share it (evaluated once, at the first solution)
    rot = model.rotary_axes
    j = nominal_jacobian(model, _rotary_positions(model, cand[0]))
    for i, a in enumerate(rot):
        sens = np.linalg.norm(j[:, 3:6, model.axes.index(a)], axis=1)
        cand[:, sens < 1e-9, i] = np.nan
    return cand


def _rotary_positions(model, rot_deg: np.ndarray) -> np.ndarray:
    q = np.zeros((len(rot_deg), len(model.axes)))
    for i, a in enumerate(model.rotary_axes):
        q[:, model.axes.index(a)] = rot_deg[:, i]
    return q


def _limits(model):
    rot = model.rotary_axes
    return (np.array([model.travel[a][0] - 1e-9 for a in rot]),
            np.array([model.travel[a][1] + 1e-9 for a in rot]))


def decide(cand: np.ndarray, prev: np.ndarray, lo, hi):
    """The controller's rule for rows each of which follows the rotary positions ``prev``
    (n, 2) deg: per solution ``cand`` (2, n, 2) and axis, the value nearest ``prev`` (an
    undetermined axis stays), turned by 360 deg into the travel ``lo .. hi`` where it is not;
    the solution inside the travel with the smaller move (the first on a tie) -> (positions
    (n, 2), solution index (n,))."""
    best = score0 = None
    choice = np.zeros(len(prev), dtype=np.int8)
    for b in (0, 1):
        v = np.empty_like(prev)
        inside = np.ones(len(prev), dtype=bool)
        dist = np.zeros(len(prev))
        for j in (0, 1):
            p = prev[:, j]
            x = cand[b, :, j]
            x = np.where(x != x, p, x)
            x = p + (x - p + 180.0) % 360.0 - 180.0
            up, down = x + 360.0, x - 360.0
            ok0 = (lo[j] <= x) & (x <= hi[j])
            ok1 = (lo[j] <= up) & (up <= hi[j])
            ok2 = (lo[j] <= down) & (down <= hi[j])
            v[:, j] = np.where(ok0, x, np.where(ok1, up, np.where(ok2, down, x)))
            inside &= ok0 | ok1 | ok2
            dist = dist + np.abs(v[:, j] - p)
        score = dist + np.where(inside, 0.0, 1e6)
        if best is None:
            best, score0 = v, score
        else:
            take = score < score0
            best = np.where(take[:, None], v, best)
            choice[take] = 1
    return best, choice


def _guess(cand, previous, lo, hi) -> np.ndarray:
    """Rotary positions equal to the block-by-block result up to rounding: the solution each
    row chooses after a row of either solution (:func:`decide` on all rows at once, values
    taken as they are, which is right unless a turn into the travel or an undetermined axis
    is involved), followed along the rows in one loop that carries the axes' values and
    decides the few rows where a turn or an undetermined axis is involved one by one."""
    n = cand.shape[1]
    own = np.nan_to_num((cand + 180.0) % 360.0 - 180.0)
    for j in (0, 1):
        for t in (360.0, -360.0):
            out = (own[:, :, j] < lo[j]) | (own[:, :, j] > hi[j])
            own[:, :, j] += np.where(out & (lo[j] <= own[:, :, j] + t)
                                     & (own[:, :, j] + t <= hi[j]), t, 0.0)
    after = [decide(cand, np.vstack([previous[None, :], own[p, :-1]]), lo, hi)[1].tolist()
             for p in (0, 1)]
    stay = np.isnan(cand).any(axis=(0, 2))
    special = (stay | np.r_[True, stay[:-1]]).tolist()
    # an axis turning less than a turn has one value in the travel (that of ``own``); one
    # turning more moves to the value nearest the last, unless that leaves the travel (then
    # decided one by one: the other solution's move only grows by a turn, never the choice)
    wide0, wide1 = (bool(hi[j] - lo[j] >= 360.0) for j in (0, 1))
    (c00, c01), (c10, c11) = ([cand[b, :, j].tolist() for j in (0, 1)] for b in (0, 1))
    lo0, lo1, hi0, hi1 = float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])
    out0, out1 = [0.0] * n, [0.0] * n
    x0, x1 = float(previous[0]), float(previous[1])
    c = 0
    for i in range(n):
        if not special[i]:
            # the chosen solution's values by the rule's own arithmetic (exact); a turn into
            # the travel of a wide axis may change the choice: decided one by one
            b = after[c][i]
            v0 = x0 + ((c10[i] if b else c00[i]) - x0 + 180.0) % 360.0 - 180.0
            v1 = x1 + ((c11[i] if b else c01[i]) - x1 + 180.0) % 360.0 - 180.0
            ok = True
            if not lo0 <= v0 <= hi0:
                ok = not wide0
                v0 = _turn(v0, lo0, hi0)
            if not lo1 <= v1 <= hi1:
                ok = ok and not wide1
                v1 = _turn(v1, lo1, hi1)
            if ok:
                x0, x1, c = v0, v1, b
                out0[i], out1[i] = v0, v1
                continue
        (x0, x1), c = _decide_one([[c00[i], c01[i]], [c10[i], c11[i]]], [x0, x1],
                                  [lo0, lo1], [hi0, hi1])
        out0[i], out1[i] = x0, x1
    return np.column_stack([out0, out1])


def _turn(v: float, lo: float, hi: float) -> float:
    """``v`` turned by 360 deg into ``lo .. hi`` (as the rule tries: up, then down)."""
    if lo <= v + 360.0 <= hi:
        return v + 360.0
    return v - 360.0 if lo <= v - 360.0 <= hi else v


def _decide_one(cand_row, prev, lo, hi):
    """:func:`decide` of one row in plain Python -> (positions [2], solution index)."""
    best, best_score, choice = None, None, 0
    for b in (0, 1):
        v, inside, dist = [], True, 0.0
        for j in (0, 1):
            x = cand_row[b][j]
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
            best, best_score, choice = v, score, b
    return best, choice


def _settle(cand, q, previous, lo, hi) -> np.ndarray:
    """``q`` checked against the rule: every row decided again from the row before it
    (:func:`decide`, all rows at once); from the first row that differs (a near tie the
    guess decided otherwise) on, block by block."""
    prev = np.vstack([np.asarray(previous, dtype=float)[None, :], q[:-1]])
    differs = ~np.all(decide(cand, prev, lo, hi)[0] == q, axis=1)
    if differs.any():
        k = int(np.argmax(differs))
        q[k:] = block_by_block(cand[:, k:], prev[k], lo, hi)
    return q


def block_by_block(cand, previous, lo, hi) -> np.ndarray:
    """:func:`decide` row after row, each from the row before (the reference of
    :func:`rotary_from_vector`)."""
    lo, hi = [float(v) for v in lo], [float(v) for v in hi]
    prev, out = [float(previous[0]), float(previous[1])], []
    for row in np.moveaxis(cand, 1, 0).tolist():
        prev = _decide_one(row, prev, lo, hi)[0]
        out.append(prev)
    return np.array(out).reshape(-1, 2)


def axes_from_words(model, w: np.ndarray, frame: np.ndarray, length: np.ndarray,
                    previous_rot: np.ndarray, guess_rot: np.ndarray | None = None) -> np.ndarray:
    """Axis positions (N, n_axes) the controller goes to: ``w`` (N, n_axes + 3) the words
    (for TCPM rows the linear columns the tip, rotary columns the angles of :data:`ANGLES`
    rows, the last three the tool vector of :data:`VECTOR` rows; :data:`AXES` rows the axis
    positions themselves), ``frame`` (N,), ``length`` (N,) mm (TCPM rows);
    ``previous_rot`` (2,) deg the rotary positions before the first row (vector rows continue
    from the row before them); ``guess_rot`` (N, 2) deg or None: rotary positions near those
    of the vector rows, which speed up their solve (:func:`rotary_from_vector`), never
    change it."""
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
            rot[part] = rotary_from_vector(model, w[part, nax:nax + 3], p,
                                           None if guess_rot is None else guess_rot[part])
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
