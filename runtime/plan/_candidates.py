"""Candidate set-ups of each instrument: every place a pivot, a sphere or a station can go in
the layout's working volume, each with a template of readings (the poses it can read at),
every axis position inside the travel (a set-up whose poses leave it is not a candidate).

A set-up is what costs a set-up change (mount and centre a pivot, move the sphere, move the
tracking interferometer); its readings are chosen afterwards.  :class:`SetUp.build` gives the
columns of the instrument's file (``volerr formats KIND``) for ``m`` readings spread evenly
over the template, reading columns zero (filled with nothing when written).

Geometry (workpiece frame, mm): the working volume is the box the nominal tool point sweeps
over the linear travel with the rotary axes at their home position (0 deg, else the middle of
the travel) and the instrument's tool offset.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..instruments import ballbar, distances, sphere

#: points per direction of a ballbar circle in the template (both directions are read)
BALLBAR_TEMPLATE = 36
#: steps of every rotary axis in a sphere placement's template (over its travel, one turn)
SPHERE_STEPS = {"tilt": 7, "turn": 12}
#: share of a sphere placement's template poses that must lie inside the travel
SPHERE_INSIDE = 0.25
#: most readings of one ballbar circle (both directions)
MAX_CIRCLE = 3600
#: most repetitions of a sphere placement's or a station's cycle of poses
REPEATS = 20
#: decimals of every commanded position (mm, deg): file and NC program carry the same numbers
DECIMALS = 4


@dataclass
class SetUp:
    """One candidate set-up: ``kind``, ``label`` (the file's ``placement`` / ``station``),
    ``build(m)`` -> file columns for m readings, ``template`` readings of the information
    computed, ``min_readings`` and ``max_readings`` (the poses it has), ``geometry`` (for
    the set-up sheet) and a one-line ``text``."""

    kind: str
    label: str
    build: Callable
    template: int
    min_readings: int
    max_readings: int
    geometry: dict = field(default_factory=dict)
    text: str = ""
    line: object = None         # an interferometer line (volerr.instruments.interferometer.Line)
    hidden: tuple = ()          # columns kept for the NC program, not written into the file


def home(model) -> dict:
    """The rotary axes' home positions: 0 deg when inside the travel, else the middle."""
    out = {}
    for a in model.rotary_axes:
        lo, hi = model.travel[a]
        out[a] = 0.0 if lo <= 0.0 <= hi else 0.5 * (lo + hi)
    return out


def volume(model, tool) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) corners (3,) of the working volume in the workpiece frame (module docstring)."""
    lin = [a for a in model.axes if a not in model.rotary_axes]
    corners = list(itertools.product(*[model.travel[a] for a in lin]))
    pos = {a: np.array([c[i] for c in corners], float) for i, a in enumerate(lin)}
    pos.update({a: np.full(len(corners), v) for a, v in home(model).items()})
    t = model.nominal_position({a: pos[a] for a in model.axes}, np.asarray(tool, float))
    return t.min(axis=0), t.max(axis=0)


def rounded(pos: dict) -> dict:
    return {a: np.round(np.asarray(v, float), DECIMALS) + 0.0 for a, v in pos.items()}


def inside(model, pos: dict) -> np.ndarray:
    ok = np.ones(len(next(iter(pos.values()))), bool)
    for a in model.axes:
        lo, hi = model.travel[a]
        ok &= (pos[a] >= lo - 1e-9) & (pos[a] <= hi + 1e-9)
    return ok


# ---- ballbar ----------------------------------------------------------------------------
def ballbar_setups(model, inst) -> list:
    """Circles (ISO 230-4) in the planes XY, YZ, ZX of every length, centred on a 3 x 3 x 3
    grid of the volume the circle fits in, rotary axes at home; both directions."""
    lo, hi = volume(model, inst.tool)
    out = []
    for plane, length in itertools.product(("XY", "YZ", "ZX"), inst.lengths):
        i, j, _ = ballbar.PLANES[plane]
        a, b = lo.copy(), hi.copy()
        for k in (i, j):
            a[k], b[k] = lo[k] + length + 1.0, hi[k] - length - 1.0
        if np.any(a > b):
            continue
        ticks = [np.unique(np.round(np.linspace(a[k], b[k], 3), 1)) for k in range(3)]
        for centre in itertools.product(*ticks):
            s = _circle(model, inst, plane, length, np.array(centre), len(out) + 1)
            if s is not None:
                out.append(s)
    return out


def _circle(model, inst, plane, length, centre, number, sweep=None) -> SetUp | None:
    """A circle (rotary axes at home) or, with ``sweep`` = (axis, (start, stop)), an ISO
    10791-6 sweep: the rotary axis turns, the tool ball held at ``centre + length`` along the
    plane's first axis on the table."""
    label = f"{'R' if sweep else 'C'}{number}"
    rotary = home(model)
    if sweep:
        rotary[sweep[0]] = sweep[1]

    def build(m: int) -> dict:
        m = max(m, 16)
        ccw = ballbar.simulate(model, None, plane, length, centre, inst.tool, rotary,
                               points=m - m // 2, direction="ccw")
        cw = ballbar.simulate(model, None, plane, length, centre, inst.tool, rotary,
                              points=m // 2, direction="cw")
        cols = {k: np.concatenate([ccw[k], cw[k]]) for k in ccw}
        pos = rounded({a: cols[a] for a in model.axes})
        cols.update(pos)
        n = len(cols["dr_um"])
        cols["placement"] = np.full(n, label, dtype=object)
        return cols

    try:
        cols = build(2 * BALLBAR_TEMPLATE)
    except Exception:           # the circle leaves the travel: not a candidate
        return None
    if not inside(model, {a: cols[a] for a in model.axes}).all():
        return None
    where = f"({centre[0]:g}, {centre[1]:g}, {centre[2]:g}) mm"
    if sweep:
        a, (lo, hi) = sweep
        text = (f"ballbar {length:g} mm, pivot on the table at {where}, bar along "
                f"{plane[0]}, {a} sweeping {lo:g}..{hi:g} deg (ISO 10791-6), both directions")
        geometry = {"pivot": centre, "length": length, "plane": plane, "sweep": a}
    else:
        text = f"ballbar {length:g} mm, circle in {plane} about the pivot at {where}, both " \
               f"directions"
        geometry = {"pivot": centre, "length": length, "plane": plane}
    return SetUp("ballbar", label, build, 2 * BALLBAR_TEMPLATE, 16, MAX_CIRCLE, geometry,
                 text)


def sweep_setups(model, inst) -> list:
    """ISO 10791-6 sweeps of every rotary axis (a turning axis one turn, a tilting axis its
    travel; the others at home): the pivot on the table at x = -1/3, 1/3 of the volume's half
    width and two heights, the bar along x, y or z of the table, every length."""
    if not model.rotary_axes:
        return []
    lo, hi = volume(model, inst.tool)
    half = 0.5 * min(hi[0] - lo[0], hi[1] - lo[1])
    pivots = [np.round(np.array([x, 0.0, lo[2] + f * (hi[2] - lo[2])]), 1)
              for x in (-half / 3.0, half / 3.0) for f in (0.1, 0.3)]
    out = []
    for a in model.rotary_axes:
        tlo, thi = model.travel[a]
        span = (0.0, 360.0) if thi - tlo >= 360.0 else (tlo, thi)
        for plane, length, p in itertools.product(("XY", "YZ", "ZX"), inst.lengths, pivots):
            s = _circle(model, inst, plane, length, p, len(out) + 1, (a, span))
            if s is not None:
                out.append(s)
    return out


def spread(m: int, n_t: int) -> np.ndarray:
    """Indices of ``m`` readings over a template of ``n_t`` poses in order: whole cycles of
    the template (repeated readings), the rest spread evenly over one more cycle."""
    m = max(int(m), 1)
    whole, rest = divmod(m, n_t)
    idx = [np.arange(n_t)] * whole
    if rest:
        idx.append(np.round(np.linspace(0, n_t - 1, rest)).astype(int))
    return np.concatenate(idx)


# ---- sphere / R-test --------------------------------------------------------------------
def rotary_grid(model, tilt: int | None = None, turn: int | None = None) -> dict:
    """Template positions of every rotary axis: a turning axis (travel >= 300 deg) in ``turn``
    equal steps over one turn, a tilting axis in ``tilt`` over its travel (defaults
    :data:`SPHERE_STEPS`)."""
    tilt, turn = tilt or SPHERE_STEPS["tilt"], turn or SPHERE_STEPS["turn"]
    out = {}
    for a in model.rotary_axes:
        lo, hi = model.travel[a]
        if hi - lo >= 300.0:
            start = 0.0 if lo <= 0.0 and hi - lo >= 360.0 else lo
            out[a] = start + np.arange(turn) * min(hi - lo, 360.0) / turn
        else:
            out[a] = np.linspace(lo, hi, tilt)
    return out


def sphere_placement(model, inst, centre, grid: dict, label: str) -> SetUp | None:
    """One sphere placement read at the rotary positions ``grid`` (inside the travel), or
    None when no pose of it is inside."""
    try:
        poses = sphere.plan(model, np.asarray(centre, float), grid, inst.tool)
    except Exception:       # no pose inside the travel
        return None
    return _placement(model, inst, np.asarray(centre, float), poses, label)


def sphere_setups(model, inst) -> list:
    """Sphere placements on a grid of the table (x, y at 0, +-1/3, +-2/3 of the volume's half
    width about the workpiece origin; three heights), each read at the rotary template
    positions inside the travel."""
    lo, hi = volume(model, inst.tool)
    half = 0.5 * min(hi[0] - lo[0], hi[1] - lo[1])
    xy = np.round(np.array([-2.0, -1.0, 0.0, 1.0, 2.0]) * half / 3.0, 1)
    zs = np.round(lo[2] + np.array([0.1, 0.25, 0.4]) * (hi[2] - lo[2]), 1)
    grid = rotary_grid(model)
    n_grid = int(np.prod([len(v) for v in grid.values()])) if grid else 1
    out = []
    for x, y, z in itertools.product(xy, xy, zs):
        c = np.array([x, y, z])
        try:
            poses = sphere.plan(model, c, grid, inst.tool)
        except Exception:       # no pose inside the travel
            continue
        if len(poses["placement"]) < SPHERE_INSIDE * n_grid:
            continue
        out.append(_placement(model, inst, c, poses, f"S{len(out) + 1}"))
    return out


def _placement(model, inst, centre, poses, label) -> SetUp:
    full = rounded(poses["positions"])
    n_t = len(poses["placement"])

    def build(m: int) -> dict:
        idx = spread(m, n_t)
        sub = {"positions": {a: v[idx] for a, v in full.items()},
               "centre": poses["centre"][idx],
               "placement": np.full(len(idx), label, dtype=object)}
        cols = sphere.simulate(model, {}, sub, inst.tool)
        cols.update(sub["positions"])
        return cols

    text = (f"sphere at ({centre[0]:g}, {centre[1]:g}, {centre[2]:g}) mm on the table, "
            f"rotary axes {', '.join(model.rotary_axes)} in steps")
    return SetUp("sphere", label, build, n_t, min(n_t, 6), REPEATS * n_t, {"centre": centre},
                 text)


# ---- distances (tracking interferometer) ----------------------------------------------------
def targets(model, inst) -> dict:
    """Target poses every station reads: a 5 x 5 x 4 grid of the linear travel (10 % in from
    its ends), rotary axes at home."""
    lin = [a for a in model.axes if a not in model.rotary_axes]
    ticks = []
    for a, k in zip(lin, (5, 5, 4)):
        lo, hi = model.travel[a]
        pad = 0.1 * (hi - lo)
        ticks.append(np.linspace(lo + pad, hi - pad, k))
    mesh = [g.ravel() for g in np.meshgrid(*ticks, indexing="ij")]
    pos = {a: m for a, m in zip(lin, mesh)}
    pos.update({a: np.full(len(mesh[0]), v) for a, v in home(model).items()})
    return rounded({a: pos[a] for a in model.axes})


def distances_setups(model, inst) -> list:
    """Stations on the corners and side middles of the working volume, 10 % outside it, at
    its bottom and its middle height; each reads every target."""
    lo, hi = volume(model, inst.tool)
    mid, span = 0.5 * (lo + hi), hi - lo
    pos = targets(model, inst)
    n_t = len(pos[model.axes[0]])
    out = []
    for fx, fy in [(-1, -1), (1, -1), (1, 1), (-1, 1), (0, -1), (1, 0), (0, 1), (-1, 0)]:
        for fz in (-0.5, 0.0):
            s = mid + 0.55 * span * np.array([fx, fy, 0.0])
            s[2] = mid[2] + fz * span[2]
            out.append(_station(model, inst, np.round(s, 1), pos, n_t, f"T{len(out) + 1}"))
    return out


def _station(model, inst, where, pos, n_t, label) -> SetUp:
    def build(m: int) -> dict:
        idx = spread(max(m, 8), n_t)
        sub = {a: v[idx] for a, v in pos.items()}
        cols = distances.simulate(model, sub, {label: where}, inst.tool, noise=False)
        k = len(idx)
        cols["station"] = np.asarray(cols["station"], dtype=object)
        for i, c in enumerate(("station_x", "station_y", "station_z")):
            cols[c] = np.full(k, float(where[i]))
        return cols

    text = f"tracking interferometer at ({where[0]:g}, {where[1]:g}, {where[2]:g}) mm"
    return SetUp("distances", label, build, n_t, 12, REPEATS * n_t, {"station": where}, text)


def ballbar_all(model, inst) -> list:
    """Circles and, on a layout with rotary axes, sweeps."""
    return ballbar_setups(model, inst) + sweep_setups(model, inst)


MAKERS = {"ballbar": ballbar_all, "sphere": sphere_setups, "distances": distances_setups}


def setups(model, inst) -> list:
    """Every candidate set-up of the instrument ``inst`` on ``model``."""
    return MAKERS[inst.kind](model, inst)


# ---- interferometer (laser lines) ---------------------------------------------------------
#: targets of an interferometer line (ISO 230-2: equally spaced over the travel, 5 % in from
#: its ends), cycles of its template and the fewest / most cycles of a run (ISO 230-2: 5)
LINE_TARGETS, LINE_CYCLES, LINE_MIN_CYCLES, LINE_MAX_CYCLES = 11, 1, 2, 5
#: optic of the spec -> interferometer mode (``volerr formats interferometer``)
OPTIC_MODE = {"linear": "positioning", "straightness": "straightness", "angular": "angular"}
#: where the other linear axes stand for a line (share of their travel): the Abbe offsets
LINE_AT = (0.1, 0.5, 0.9)


def line_targets(model, axis) -> np.ndarray:
    """ISO 230-2 targets of a line along ``axis``: :data:`LINE_TARGETS` equally spaced over
    the travel, 5 % in from its ends (mm)."""
    lo, hi = model.travel[axis]
    pad = 0.05 * (hi - lo)
    return np.round(np.linspace(lo + pad, hi - pad, LINE_TARGETS), 3)


def interferometer_setups(model, inst) -> list:
    """Beam lines along each linear axis, the other linear axes at :data:`LINE_AT` of their
    travel (a 3 x 3 grid of Abbe offsets), rotary axes at home, the moving optic at the
    instrument's tool offset; for each optic asked (straightness and angular optics: both
    directions normal to the beam)."""
    from ..instruments import interferometer

    lin = [a for a in model.axes if a not in model.rotary_axes]
    out = []
    for axis in lin:
        others = [a for a in lin if a != axis]
        ticks = [[round(model.travel[a][0] + f * (model.travel[a][1] - model.travel[a][0]), 1)
                  for f in LINE_AT] for a in others]
        normals = [v for v in np.eye(3) if abs(v[lin.index(axis)]) < 0.5]
        for optic in inst.optics:
            mode = OPTIC_MODE[optic]
            senses = [None] if mode == "positioning" else normals
            for values, sense in itertools.product(itertools.product(*ticks), senses):
                at = dict(zip(others, values), **home(model))
                line = interferometer.Line(axis, mode, at, np.asarray(inst.tool, float),
                                           sense=sense, u=inst.u_urad if mode == "angular"
                                           else inst.u_um)
                out.append(_line(model, line, f"L{len(out) + 1}"))
    return out


def _line(model, line, label) -> SetUp:
    targets = line_targets(model, line.axis)
    k = len(targets)
    reading = "deviation_urad" if line.mode == "angular" else "deviation_um"

    def build(m: int) -> dict:
        cycles = max(int(round(m / (2 * k))), 1)
        rows = [(p, c, d) for c in range(1, cycles + 1) for d in (1.0, -1.0)
                for p in (targets if d > 0 else targets[::-1])]
        n = len(rows)
        cols = {"target_mm": np.array([r[0] for r in rows]),
                "cycle": np.array([str(r[1]) for r in rows], dtype=object),
                "direction": np.array([r[2] for r in rows]), reading: np.zeros(n)}
        pos = {a: (cols["target_mm"] if a == line.axis else np.full(n, float(line.at[a])))
               for a in model.axes}
        cols.update(rounded(pos))
        cols["placement"] = np.full(n, label, dtype=object)
        for j, c in enumerate(("Xp", "Yp", "Zp")):
            cols[c] = np.full(n, float(line.optics[j]))
        return cols

    at = ", ".join(f"{a}={v:g}" for a, v in line.at.items())
    what = {"positioning": "linear optics",
            "straightness": "straightness optics, displacement along {}",
            "angular": "angular optics, rotation about {}"}[line.mode]
    if line.sense is not None:
        what = what.format("XYZ"[int(np.argmax(np.abs(line.sense)))])
    text = f"laser line along {line.axis} at {at}, {what}, {k} targets both directions"
    start = model.nominal_position({a: np.array([targets[0] if a == line.axis else line.at[a]])
                                    for a in model.axes}, line.optics)[0]
    geometry = {"start": np.round(start, 3), "axis": line.axis, "mode": line.mode}
    return SetUp("interferometer", label, build, 2 * k * LINE_CYCLES, 2 * k * LINE_MIN_CYCLES,
                 2 * k * LINE_MAX_CYCLES, geometry, text, line)


MAKERS["interferometer"] = interferometer_setups


# ---- artifact (ball plate) ------------------------------------------------------------------
#: where a plate lies along its plane's normal (share of the working volume)
PLATE_LEVELS = (0.15, 0.5, 0.85)
#: plane -> (workpiece axis of the plate's u, of its v) at 0 deg; turned 90 deg: u along the
#: second, v along minus the first (w = u x v, the plane's normal, either way)
PLATE_PLANES = {"XY": (0, 1), "YZ": (1, 2), "ZX": (2, 0)}


def plate_points(inst) -> np.ndarray:
    """(N M, 3) calibrated ball centres of the plate in its own frame (mm): a grid of
    ``balls`` at ``pitch``, origin at the first ball, w = 0."""
    n, m = inst.balls
    u, v = np.meshgrid(np.arange(n) * inst.pitch, np.arange(m) * inst.pitch, indexing="ij")
    return np.column_stack([u.ravel(), v.ravel(), np.zeros(n * m)])


def artifact_setups(model, inst) -> list:
    """Ball-plate placements in the planes XY, YZ, ZX, turned 0 and 90 deg in the plane,
    centred in the working volume in the plane, at :data:`PLATE_LEVELS` along the normal;
    every ball's nominal position and the touch probe's path round it inside the travel,
    rotary axes at home."""
    lo, hi = volume(model, inst.tool)
    pts = plate_points(inst)
    half = 0.5 * (pts.max(axis=0) - pts.min(axis=0))
    out = []
    for plane, (i, j) in PLATE_PLANES.items():
        k = 3 - i - j
        for turn, level in itertools.product((0, 90), PLATE_LEVELS):
            R = np.zeros((3, 3))
            a, b = (i, j) if turn == 0 else (j, i)
            R[a, 0] = 1.0
            R[b, 1] = 1.0 if turn == 0 else -1.0
            R[:, 2] = np.cross(R[:, 0], R[:, 1])
            centre = 0.5 * (lo + hi)
            centre[k] = lo[k] + level * (hi[k] - lo[k])
            origin = np.round(centre - R @ half, 1)
            s = _plate(model, inst, pts, R, origin, (plane, turn, level), f"P{len(out) + 1}")
            if s is not None:
                out.append(s)
    return out


def _plate(model, inst, pts, R, origin, where, label) -> SetUp | None:
    plane, turn, level = where
    nominal = pts @ R.T + origin
    n = len(pts)
    rot = {a: np.full(n, v) for a, v in home(model).items()}
    try:
        pos = rounded(model.linear_positions(nominal, rot, np.asarray(inst.tool, float)))
    except Exception:       # not reachable
        return None
    pos.update(rot)
    if not inside(model, pos).all() or not _probe_path_inside(model, inst, nominal, plane):
        return None
    lin = tuple(a for a in model.axes if a not in model.rotary_axes)

    def build(m: int) -> dict:
        cols = {"placement": np.full(n, label, dtype=object),
                "ball": np.array([f"B{b + 1}" for b in range(n)], dtype=object),
                "u_mm": pts[:, 0], "v_mm": pts[:, 1], "w_mm": pts[:, 2]}
        for c, name in enumerate(("x", "y", "z")):
            cols[f"{name}_mm"] = nominal[:, c]
        for c, name in enumerate(("x", "y", "z")):
            cols[f"{name}_nom_mm"] = nominal[:, c]
        for c, name in enumerate(("Xp", "Yp", "Zp")):
            cols[name] = np.full(n, float(inst.tool[c]))
        cols.update({a: v for a, v in pos.items()})
        return cols

    text = (f"ball plate {inst.balls[0]} x {inst.balls[1]} at {inst.pitch:g} mm in {plane}, "
            f"turned {turn} deg, first ball at ({origin[0]:g}, {origin[1]:g}, {origin[2]:g}) mm")
    geometry = {"start": origin, "plane": plane, "turn": turn, "level": level}
    return SetUp("artifact", label, build, n, n, n, geometry, text, hidden=lin)


def _probe_path_inside(model, inst, nominal, plane) -> bool:
    """Every point the touch probe goes to round the balls ``nominal`` (N, 3) inside the
    travel (:mod:`volerr.plan._probing`)."""
    from . import _probing

    rot = home(model)
    tool = np.asarray(inst.tool, float)
    n, dirs = _probing.directions(model, plane, tool, rot)
    pts = np.vstack([_probing.ball_path(c, n, dirs) for c in nominal])
    pos = model.linear_positions(pts, {a: np.full(len(pts), v) for a, v in rot.items()}, tool)
    pos.update({a: np.full(len(pts), v) for a, v in rot.items()})
    return bool(inside(model, pos).all())


MAKERS["artifact"] = artifact_setups
