"""ISO 230-4 evaluation of ballbar traces (circular tests of numerically controlled machine
tools, ISO 230-4:2005 clause 3 definitions).

A trace is one circle run in one direction: the readings of one file with the same
``placement`` and ``direction``; a file without ``placement`` is cut into its circles by their
geometry (plane, pivot, radius, direction: :func:`volerr.instruments.ballbar.split_traces`).  For each reading ``i``:

* ``theta_i``: the angle of the nominal tool-ball centre about the pivot in the trace's plane
  (from the plane's first axis towards its second: XY from +X to +Y, YZ from +Y to +Z, ZX from
  +Z to +X; the plane is the one whose normal the nominal positions do not move along); for a
  trace in which a rotary axis sweeps (ISO 10791-6), the position of that axis;
* ``r_i = length_mm + dr_i``: the actual bar length, so the actual path point is
  ``P_i = r_i (cos theta_i, sin theta_i)`` about the pivot.

Quantities (um):

* circular deviation ``G``: the radial range of the actual path about the centre of its
  least-squares circle (the circle minimising ``sum (|P_i - c| - rho)^2``, geometric, solved to
  convergence by Gauss-Newton from the algebraic fit): ``max |P_i - c| - min |P_i - c|``;
* radial deviation ``F``: the deviation of the actual path from the nominal circle about the
  pivot, ``F_max = max dr``, ``F_min = min dr``;
* ``centre_offset``: the least-squares centre minus the pivot, in the plane (um);
* ``range``: ``F_max - F_min``, the deviation range of the reading (for a rotary sweep the
  quantity ISO 10791-6 reports);
* circular hysteresis ``H`` (a clockwise and a counter-clockwise trace of the same placement):
  the largest radial difference of the two paths at the same angle,
  ``max_i |dr_ccw(theta_i) - dr_cw(theta_i)|`` over the counter-clockwise readings, the clockwise
  readings interpolated linearly (and periodically) in theta.

Source: ISO 230-4:2005, Test code for machine tools -- Part 4: Circular tests for numerically
controlled machine tools (terms 3.3 circular deviation G, 3.5 radial deviation F, 3.4 circular
hysteresis H); the ballbar as the measuring instrument of its annex.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import require
from ..instruments.ballbar import PLANE_AXES, PLANE_NAMES, plane_of  # noqa: F401



@dataclass
class Trace:
    """One circle in one direction: ``file``, ``placement``, ``direction`` (+1 CCW, -1 CW),
    ``plane``, ``radius_mm`` (nominal bar length), ``theta`` (rad), ``dr`` (mm), ``rows`` (data
    rows of the file), ``pivot`` (mm)."""

    file: str
    placement: str
    direction: int
    plane: str
    radius_mm: float
    theta: np.ndarray
    dr: np.ndarray
    rows: np.ndarray
    pivot: np.ndarray


def traces(obs, model) -> list:
    """The traces of one ballbar file (its :class:`volerr.instruments.Observations`): as the
    reader cut them (``info["trace"]``: one placement and direction, or, without a
    ``placement`` column, one circle by its geometry)."""
    where = obs.files[0].name if obs.files else "ballbar"
    t = model.nominal_position(obs.positions, obs.probe)
    pivot, length = obs.info["pivot"], obs.info["length"]
    place = np.asarray(obs.info["placement"], dtype=str)
    dirs = np.asarray(obs.info["direction"], dtype=float)
    ids = np.asarray(obs.info["trace"])
    out = []
    for k in dict.fromkeys(ids.tolist()):
        idx = np.flatnonzero(ids == k)
        pl, d = place[idx[0]], dirs[idx[0]]
        rel = t[idx] - pivot[idx]
        swept = [a for a in model.rotary_axes if np.ptp(obs.positions[a][idx]) > 1.0]
        if swept:       # ISO 10791-6: the deviation against the swept axis' angle
            theta = np.deg2rad(obs.positions[swept[0]][idx])
            plane = f"{swept[0]} sweep"
        else:
            k_normal = plane_of(rel)
            i, j = PLANE_AXES[k_normal]
            theta = np.arctan2(rel[:, j], rel[:, i])
            plane = PLANE_NAMES[k_normal]
        require(len(idx) >= 8, f"{where}: trace {pl} ({'ccw' if d > 0 else 'cw'}) has "
                               f"{len(idx)} readings; ISO 230-4 needs a full circle")
        out.append(Trace(where, str(pl), int(d), plane, float(length[idx[0]]),
                         theta, obs.info["dr"][idx], idx, pivot[idx[0]]))
    return out


def least_squares_circle(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Centre (a, b) and radius of the geometric least-squares circle of the points (x, y)."""
    A = np.column_stack([x, y, np.ones_like(x)])
    sol = np.linalg.lstsq(A, x * x + y * y, rcond=None)[0]      # algebraic (Kasa) start
    a, b = sol[0] / 2, sol[1] / 2
    rho = float(np.sqrt(sol[2] + a * a + b * b))
    for _ in range(100):
        dx, dy = x - a, y - b
        d = np.hypot(dx, dy)
        J = np.column_stack([-dx / d, -dy / d, -np.ones_like(d)])
        res = d - rho
        step = np.linalg.lstsq(J, -res, rcond=None)[0]
        a, b, rho = a + step[0], b + step[1], rho + step[2]
        if np.max(np.abs(step)) < 1e-15 * max(1.0, abs(rho)):
            break
    return float(a), float(b), float(rho)


def evaluate(tr: Trace) -> dict:
    """G, F and the least-squares centre of one trace (um)."""
    r = tr.radius_mm + tr.dr
    x, y = r * np.cos(tr.theta), r * np.sin(tr.theta)
    a, b, _ = least_squares_circle(x, y)
    d = np.hypot(x - a, y - b)
    return {"file": tr.file, "placement": tr.placement, "plane": tr.plane,
            "radius_mm": tr.radius_mm, "direction": "ccw" if tr.direction > 0 else "cw",
            "n": int(len(tr.dr)), "G_um": float(1e3 * (d.max() - d.min())),
            "F_max_um": float(1e3 * tr.dr.max()), "F_min_um": float(1e3 * tr.dr.min()),
            "range_um": float(1e3 * np.ptp(tr.dr)),
            "centre_offset_um": [float(1e3 * a), float(1e3 * b)]}


def hysteresis(ccw: Trace, cw: Trace) -> float:
    """H (um) of a counter-clockwise and a clockwise trace of one placement."""
    order = np.argsort(cw.theta)
    th, dr = cw.theta[order], cw.dr[order]
    other = np.interp(ccw.theta, th, dr, period=2 * np.pi)
    return float(1e3 * np.max(np.abs(ccw.dr - other)))


def evaluate_all(trs: list) -> list:
    """The evaluation of every trace, with ``H_um`` on both traces of a placement run in both
    directions."""
    out = [evaluate(t) for t in trs]
    for i, t in enumerate(trs):
        if t.direction < 0:
            continue
        for j, u in enumerate(trs):
            if u.direction < 0 and u.file == t.file and u.placement == t.placement:
                h = hysteresis(t, u)
                out[i]["H_um"] = out[j]["H_um"] = h
    return out
