"""Tool-tip error map of a five-axis machine over the range of its two rotary axes.

For one point of the workpiece and every pair of rotary positions on a grid, the linear axes
are those of the nominal inverse that bring the tool tip to the point, so the map shows what
a five-axis move around that point would see.  :func:`tcp_map` returns a :class:`TcpMap`
(arrays only); :func:`volerr.fiveaxis.plots.plot_tcp_error_map` draws it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import require


@dataclass(frozen=True)
class TcpMap:
    """The map: rotary axes ``axis1`` (columns) and ``axis2`` (rows), their grid values ``q1``
    (n1,) and ``q2`` (n2,) deg; ``point`` (3,) and ``tool`` (3,) mm; ``positions``
    (n2, n1, n_axes) axis positions (mm / deg, in the order of ``axes``); ``err`` (n2, n1, 3)
    tool-tip error, mm, workpiece frame (actual minus nominal); ``orientation`` (n2, n1, 3)
    first-order tool-axis error, rad; ``valid`` (n2, n1): False where the linear axes leave
    their travel or a position leaves an error table's measured range (``err`` and
    ``orientation`` are NaN there)."""

    model_name: str
    axes: tuple
    axis1: str
    axis2: str
    q1: np.ndarray
    q2: np.ndarray
    point: np.ndarray
    tool: np.ndarray
    positions: np.ndarray
    err: np.ndarray
    orientation: np.ndarray
    valid: np.ndarray

    @property
    def linear(self) -> np.ndarray:
        """(n2, n1, 3) X Y Z positions, mm."""
        return self.positions[..., [self.axes.index(a) for a in ("X", "Y", "Z")]]


def tcp_map(model, funcs, point, tool=(0.0, 0.0, 0.0), n1: int = 73, n2: int = 73,
            range1=None, range2=None, orientation: bool = True, approach=None,
            progress=None) -> TcpMap:
    """:class:`TcpMap` of ``model`` with error functions ``funcs`` (None: no errors) at the
    workpiece point ``point`` (mm).  ``range1`` / ``range2``: (lo, hi) deg of the rotary axes
    (default: the travel inside the measured range, at most -180..180 for an endless axis).
    ``orientation=False`` skips the tool-axis error (NaN).  ``approach``: the approach
    directions of axes whose tables carry a reversal: {axis: +1 | -1}, or ``"sweep"`` -- the
    grid run as a program sweeping ``axis1`` upwards row by row, each linear axis approaching
    every point in the direction it moves there (default: the bidirectional mean).
    ``progress(n)``: called with the number of grid points done, block by block."""
    from .compensate import ErrorModel
    from ..machine.kinematics import is_five_axis

    require(is_five_axis(model), f"{model.name}: not a five-axis layout")
    a1, a2 = model.rotary_axes
    ranges = funcs.ranges() if funcs is not None else {}

    def default(a):
        lo, hi = model.travel[a]
        if a in ranges:  # the measured range, inside the travel
            lo, hi = max(lo, ranges[a][0]), min(hi, ranges[a][1])
        return (max(lo, -180.0), min(hi, 180.0)) if hi - lo > 360 else (lo, hi)

    q1 = np.linspace(*(range1 or default(a1)), n1)
    q2 = np.linspace(*(range2 or default(a2)), n2)
    g1, g2 = np.meshgrid(q1, q2)
    rot = {a1: np.deg2rad(g1.ravel()), a2: np.deg2rad(g2.ravel())}
    p = np.asarray(point, dtype=float)
    t = np.asarray(tool, dtype=float)
    lin = model.module.inverse_linear(*(rot[a] for a in model.rotary_axes),
                                      p[0], p[1], p[2], t[0], t[1], t[2])
    n = g1.size
    q = np.empty((n, len(model.axes)))
    for i, a in enumerate(model.axes):
        if a in rot:
            q[:, i] = np.rad2deg(rot[a])
        else:
            q[:, i] = np.broadcast_to(lin[("X", "Y", "Z").index(a)], (n,))
    em = ErrorModel(model, funcs, tool)
    valid = np.ones(n, dtype=bool)
    for i, a in enumerate(model.axes):
        lo, hi = model.travel[a]
        valid &= (q[:, i] >= lo) & (q[:, i] <= hi)
    if funcs is not None and not funcs.extrapolate:
        ql = em.lookup(q)
        for a, (lo, hi) in em.ranges.items():
            i = model.axes.index(a)
            valid &= (ql[:, i] >= lo) & (ql[:, i] <= hi)
    err = np.full((n, 3), np.nan)
    ori = np.full((n, 3), np.nan)
    d = _directions(model, q, approach, len(q1)) if approach else None
    for start in range(0, n, BLOCK):
        sl = slice(start, min(start + BLOCK, n))
        ok = np.flatnonzero(valid[sl]) + start
        if len(ok):
            dd = None if d is None else d[ok]
            err[ok] = em.position_error(q[ok], None, dd)
            if orientation:
                ori[ok] = em.orientation_error(q[ok], None, dd)
        if progress is not None:
            progress(sl.stop - sl.start)
    shape = (len(q2), len(q1))
    return TcpMap(model.name, tuple(model.axes), a1, a2, q1, q2, p, t,
                  q.reshape(*shape, len(model.axes)), err.reshape(*shape, 3),
                  ori.reshape(*shape, 3), valid.reshape(shape))


#: grid points per block of the evaluation
BLOCK = 16384


def _directions(model, q: np.ndarray, approach, n1: int) -> np.ndarray:
    """Approach directions (n, n_axes) of the grid: given per axis, or ``"sweep"`` (rows of
    ``n1`` points run with ``axis1`` rising; the first point of a row approached as the
    second)."""
    from ..tables.functions import approach_array
    from .reversal import along

    n = len(q)
    if approach != "sweep":
        return approach_array(approach, model.axes, n)
    rows = q.reshape(-1, n1, q.shape[1])
    step = np.diff(rows, axis=1)
    d = np.sign(np.concatenate([step[:, :1], step], axis=1)).astype(np.int8)
    out = np.stack([along(r, np.zeros(q.shape[1], np.int8)) for r in d])
    return out.reshape(n, q.shape[1]).astype(float)


def tcp_error_map(model, funcs, point, tool=(0.0, 0.0, 0.0), n1: int = 73, n2: int = 73,
                  range1=None, range2=None):
    """``(axis1, axis2, q1, q2, err (n2, n1, 3) mm, valid (n2, n1))`` of :func:`tcp_map`."""
    m = tcp_map(model, funcs, point, tool, n1, n2, range1, range2, orientation=False)
    return m.axis1, m.axis2, m.q1, m.q2, m.err, m.valid


def tool_axis_error_map(model, funcs, point, tool=(0.0, 0.0, 0.0), n1: int = 73, n2: int = 73,
                        range1=None, range2=None) -> np.ndarray:
    """First-order tool-axis error (rad) on the grid of :func:`tcp_map`, (n2, n1, 3)."""
    return tcp_map(model, funcs, point, tool, n1, n2, range1, range2).orientation
