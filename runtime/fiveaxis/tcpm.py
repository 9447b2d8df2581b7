"""TCPM programs: the tool tip in the workpiece frame, the controller's nominal kinematics.

Under TCPM (tool centre point management: Fanuc ``G43.4`` / ``G43.5``, Heidenhain ``M128`` /
``FUNCTION TCPM``, Siemens ``TRAORI``) a motion block gives the tool tip ``X Y Z`` (mm) in
the workpiece frame and the tool orientation, either as the rotary axis angles (deg; G43.4,
M128, TRAORI with rotary words) or as a tool vector (``I J K`` of G43.5, ``A3 B3 C3`` of
TRAORI: the unit tool-axis direction, from the tip towards the spindle, in the workpiece
frame).  The controller turns them into axis positions with the machine's nominal inverse
kinematics and the tool length ``L`` of the active tool:

* rotary angles: the rotary axes go to the angles, the linear axes to the generated
  ``inverse_linear`` of the layout (derived in :mod:`volerr.derive.inverse`), so that the
  nominal tool tip lands on ``X Y Z``;
* tool vector: the rotary axes come from the generated ``inverse_rotary`` (two solutions, and
  a turn of 360 deg for each): the one nearest the previous block, branch by branch and turn
  by turn as a controller continues a path (:func:`rotary_from_vector`); on a singular
  orientation (the tool along the first rotary axis) the undetermined axis stays where it was.

The tool tip lies ``L`` from the point the axis positions refer to, against the tool axis: a
tool offset ``(0, 0, -L)`` in the tool frame (the same offset ``volerr compensate --tool``
gives a program in axis positions).

Compensation moves the programmed tip (and, with ``--orientation``, the orientation) to the
forward kinematics of the compensated axis positions: after the controller's inverse, the
actual tool tip lands on the programmed one (:func:`words_from_axes`).
"""

from __future__ import annotations

import numpy as np

from .kinematics import _axis_sensitivity, is_five_axis, linear_axes
from ..errors import InputError, require

#: frames of a row: axis positions, TCPM with rotary angles, TCPM with a tool vector
AXES, ANGLES, VECTOR = 0, 1, 2


def tool_offset(length) -> np.ndarray:
    """The tool offset (N, 3) of tool lengths ``length`` (N,) mm: ``(0, 0, -L)``."""
    length = np.asarray(length, dtype=float)
    out = np.zeros((len(length), 3))
    out[:, 2] = -length
    return out


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
    k = vector / np.linalg.norm(vector, axis=1, keepdims=True)
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


def length_rule(tool_length: float | None = None, table: dict | None = None):
    """The tool length a TCPM block uses, as the interpreter asks for it: ``rule(tools,
    where)`` with ``tools`` the last ``T H D`` words (letter -> number) -> mm.  A given
    ``tool_length`` always; else the ``table`` (tool number -> mm) at the ``H`` word (Fanuc
    tool length offset), else at ``T`` (Siemens, Heidenhain ``TOOL CALL``), else at ``D``;
    plus a Heidenhain ``DL`` (delta length).  None when neither is given."""
    if tool_length is None and not table:
        return None

    def rule(tools: dict, where: str) -> float:
        delta = float(tools.get("DL", 0.0))
        if tool_length is not None:
            return float(tool_length) + delta
        for letter in ("H", "T", "D"):
            if letter in tools:
                number = tools[letter]
                key = int(number) if float(number).is_integer() else number
                if key in table:
                    return float(table[key]) + delta
                raise InputError(f"{where}: tool {letter}{key:g} is not in the tool table "
                                 f"(tools {' '.join(f'{k:g}' for k in sorted(table))})")
        raise InputError(f"{where}: TCPM with no T / H / D word before it: the tool length "
                         "is unknown (give --tool-length)")
    return rule


def read_tool_table(path) -> dict:
    """A tool table CSV ``tool,length_mm`` (tool number, tool length in mm; other columns
    ignored) -> {tool number: mm}."""
    from ..fileio import read_csv_rows
    from ..units import parse_number

    rows = read_csv_rows(path, missing=f"tool table not found: {path}",
                         empty=f"{path}: empty tool table")
    header = [h.lower() for h in rows[0][1]]
    require("tool" in header and "length_mm" in header,
            f"{path}: a tool table needs the columns tool,length_mm (got {','.join(header)})")
    it, il = header.index("tool"), header.index("length_mm")
    out = {}
    for lineno, cells in rows[1:]:
        require(len(cells) == len(header), f"{path}:{lineno}: {len(cells)} fields, header "
                                           f"has {len(header)}")
        t = parse_number(cells[it], f"{path}:{lineno}", "tool")
        key = int(t) if float(t).is_integer() else t
        require(key not in out, f"{path}:{lineno}: tool {key:g} given twice")
        length = parse_number(cells[il], f"{path}:{lineno}", "length_mm")
        require(0 <= length <= 2000, f"{path}:{lineno}: tool length {length:g} mm is not "
                                     "plausible (0 .. 2000 mm)")
        out[key] = length
    require(out, f"{path}: no tools in the tool table")
    return out

