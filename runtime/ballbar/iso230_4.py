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
    u: np.ndarray | None = None     # standard uncertainty of each reading, mm (the file's)


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
                         theta, obs.info["dr"][idx], idx, pivot[idx[0]],
                         None if obs.sigma is None else np.asarray(obs.sigma)[idx]))
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


def row_name(quantity: str, r: dict) -> str:
    """The result row of ``quantity`` (G, F_max, F_min; H of a placement) of the evaluated
    trace ``r``: ``G ballbar_XY.csv 1 ccw``, ``H ballbar_XY.csv 1``."""
    tail = "" if quantity == "H" else f" {r['direction']}"
    return f"{quantity} {r['file']} {r['placement']}{tail}"


def budgets(trs: list, results: list) -> dict:
    """The GUM budgets (:mod:`volerr.report.budget`, um) of G, F_max, F_min of every trace
    and H of every placement run both ways, from the readings' stated standard
    uncertainties (the file's ``u_um``, else the ballbar's default: bar and calibrator);
    each result gets its ``u_G_um`` ... (k = 1).

    * F_max, F_min: one reading each (the largest / smallest dr), sensitivity 1;
    * G = max d - min d about the least-squares centre: the two readings, sensitivity 1
      each, and the centre (u per coordinate sqrt(2 / n) times the readings' RMS u, the
      least-squares circle's), sensitivity ``|n_max - n_min|`` (the difference of the two
      readings' radial directions: a centre error moves both radii);
    * H = ``max |dr_ccw - dr_cw(theta)|``: the counter-clockwise reading and the clockwise
      path linearly interpolated at its angle (its two readings' u with the interpolation
      weights), sensitivity 1 each.

    A steady length offset of the bar (its calibration, a constant temperature) shifts
    every reading alike: it cancels in G and H and is in the readings' u for F."""
    from ..report.budget import budget, source

    out = {}
    for tr, r in zip(trs, results):
        if tr.u is None:
            continue
        u = tr.u * 1e3
        rad = tr.radius_mm + tr.dr
        x, y = rad * np.cos(tr.theta), rad * np.sin(tr.theta)
        a, b, _ = least_squares_circle(x, y)
        d = np.hypot(x - a, y - b)
        i, j = int(np.argmax(d)), int(np.argmin(d))
        n_i = np.array([x[i] - a, y[i] - b]) / d[i]
        n_j = np.array([x[j] - a, y[j] - b]) / d[j]
        u_c = float(np.sqrt(np.mean(u ** 2)) * np.sqrt(2.0 / len(u)))
        g = [source("reading at the largest radius (its stated u)", u[i], "um"),
             source("reading at the smallest radius (its stated u)", u[j], "um"),
             source("least-squares centre (u per coordinate)", u_c, "um",
                    float(np.linalg.norm(n_i - n_j)))]
        k, m = int(np.argmax(tr.dr)), int(np.argmin(tr.dr))
        for q, srcs in (("G", g),
                        ("F_max", [source("reading of the largest dr (its stated u)", u[k],
                                          "um")]),
                        ("F_min", [source("reading of the smallest dr (its stated u)",
                                          u[m], "um")])):
            name = row_name(q, r)
            out[name] = budget(name, "um", srcs, 2.0)
            r[f"u_{q}_um"] = out[name]["u"]
    out.update(_hysteresis_budgets(trs, results))
    return out


def _hysteresis_budgets(trs: list, results: list) -> dict:
    """The budget of H of every placement run both ways (:func:`budgets`)."""
    from ..report.budget import budget, source

    out = {}
    for t, rt in zip(trs, results):
        if t.direction < 0 or "H_um" not in rt or t.u is None:
            continue
        for c, rc in zip(trs, results):
            if c.direction > 0 or c.file != t.file or c.placement != t.placement \
                    or c.u is None:
                continue
            order = np.argsort(c.theta)
            th, dr = c.theta[order], c.dr[order]
            other = np.interp(t.theta, th, dr, period=2 * np.pi)
            i = int(np.argmax(np.abs(t.dr - other)))
            w = np.array([np.interp(t.theta[i], th, e, period=2 * np.pi)
                          for e in np.eye(len(th))])
            u_cw = float(np.sqrt(np.sum((w * c.u[order] * 1e3) ** 2)))
            name = row_name("H", rt)
            out[name] = budget(name, "um", [
                source("counter-clockwise reading (its stated u)", t.u[i] * 1e3, "um"),
                source("clockwise path interpolated at that angle", u_cw, "um")], 2.0)
            rt["u_H_um"] = rc["u_H_um"] = out[name]["u"]
    return out
