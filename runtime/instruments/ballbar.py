"""The ``ballbar`` instrument: a telescoping ballbar between a ball at the tool (tool-side ball,
at the probe / tool offset ``Xp, Yp, Zp`` from the tool point) and a pivot ball fixed to the
workpiece side (ISO 230-4 circular tests; ISO 10791-6 tests with rotary axes moving).

Reading (one per pose): ``dr`` = measured bar length minus the nominal length ``length_mm``,
positive when the balls are farther apart.  Model (:func:`volerr.derive.observations.ballbar`)::

    dr = |t + e - (p + dp)| - length_mm + dL

``t`` the nominal tool-ball centre in the workpiece frame (layout's nominal chain), ``e`` the
volumetric error there, ``p`` the nominal pivot centre (``pivot_x, pivot_y, pivot_z``,
workpiece frame), ``dp`` the pivot's unknown offset and ``dL`` the bar's unknown length offset:
four set-up unknowns per placement (``pivot_dx pivot_dy pivot_dz`` um, ``length`` um).  To first
order the reading sees the error along the bar, ``u . e`` with ``u = (t - p) / |t - p|``.

The direction of motion of every axis (``dir_X`` ... +1 / -1) is derived from the order of the
readings within each trace (one placement and one ``direction``) unless the file gives it: the
loop reads it as a covariate (reversal).  File format: ``volerr formats ballbar``.

Plans and simulated readings (``volerr ballbar simulate``, the demo, plan suggestions):
Circle test (ISO 230-4): the pivot ball at ``centre`` (workpiece frame, mm), the tool ball on a
circle of ``radius`` about it in the plane XY, YZ or ZX of the workpiece frame, the rotary axes
held at ``rotary`` (deg); angles counted from the plane's first axis towards its second (XY: from
+X to +Y; YZ: +Y to +Z; ZX: +Z to +X), counter-clockwise seen from the plane's positive normal.
Rotary test (ISO 10791-6:2014, kinematic tests with rotary and linear axes moving
together): one rotary axis sweeps its range (``rotary={"C": (0, 360)}``)
while the linear axes keep the tool ball at ``centre + radius * first axis of the plane`` in
the workpiece frame, i.e. on the table; counter-clockwise = the rotary position increasing.

The linear positions come from the layout's nominal chain (affine in the linear axes at fixed
rotary positions: solved exactly); the readings are the first-order model, ``u . e`` (bar
direction ``u``, volumetric error ``e`` of the error functions at the commanded positions),
plus Gaussian noise.  Units: mm, deg; readings um in the file.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, require
from ..generated import instruments as generated
from ..machine.model import Model
from ..units import MIN_CYCLE_SPREAD_UM
from . import _fields as f
from .observations import FileInfo, Observations, Setup

KIND = "ballbar"
#: default standard uncertainty of one reading, um (a ballbar with its calibrator)
DEFAULT_U_UM = 0.5
#: largest difference between |t - p| and length_mm (mm): beyond it the file's radius and its
#: positions disagree
RADIUS_TOLERANCE_MM = 0.5
SETUP_KEYS = tuple(generated.SETUP[KIND])
#: the shortest bar accepted, mm (telescoping ballbars are 50 mm and longer; a file whose
#: lengths are all in inches gives 150 mm as 5.9)
MIN_LENGTH_MM = 25.0


def detect(names) -> bool:
    """A ballbar file has a bar reading ``dr_um`` / ``dr_mm`` or names a pivot or a bar length
    (a file with some but not all of them is a ballbar file with a missing column)."""
    low = {n.lower() for n in names}
    return bool(low & {"dr_um", "dr_mm", "length_mm", "pivot_x", "pivot_y", "pivot_z"})


def read(path, model: Model, check_travel: bool = True) -> Observations:
    """Read a ballbar CSV into :class:`Observations` (InputError, one line, on a defect);
    ``check_travel`` False: positions outside the layout's travel accepted (a generic layout
    standing in for the machine)."""
    return f.read_file(path, model, columns_to_observations, unique_rows=False,
                       check_travel=check_travel)


def columns_to_observations(cols: dict, text: dict, raw: dict, model: Model,
                            where: str, check_travel: bool = True) -> Observations:
    needed = {"pivot_x", "pivot_y", "pivot_z", "length_mm", "dr_um", "dr_mm", "Xp", "Yp", "Zp",
              "direction", "u_um", "length_u_um"}
    f.refuse_repeated_block(cols, raw, MIN_TRACE_READINGS, where)
    find, warnings = f.open_columns(cols, text, model, where, needed, labels=("placement",))
    pos = f.positions(find, model, where, min_points=4, needs="a ballbar trace",
                      check_travel=check_travel)
    n = len(next(iter(pos.values())))
    probe = f.probe(find, n, where)
    pivot = f.vector(find, ("pivot_x", "pivot_y", "pivot_z"), "pivot ball centre", where)
    length = f.vector(find, ("length",), "nominal bar length", where, units=("_mm",))[:, 0]
    require(np.all(length > 0), f"{where}: length_mm must be positive")
    require(float(np.min(length)) >= MIN_LENGTH_MM, f"{where}: column length_mm: "
            f"{float(np.min(length)):g} mm is shorter than any ballbar ({MIN_LENGTH_MM:g} mm "
            f"and longer): likely every length in inches (x 25.4), or cm")
    dr = f.readings(find, ("dr",), n, where, limit_mm=1.0, what="a ballbar reading",
                    min_spread_um=MIN_CYCLE_SPREAD_UM)[:, 0]
    u = f.uncertainty(find, n, DEFAULT_U_UM, where)
    # a bar calibrated with its calibrator: its length offset known to within length_u_um
    length_u = f.known_uncertainty(find, "length_u", where)
    direction, direction_given = _direction(find, n, where)
    placement = f.labels(find, "placement", raw, n)
    check_geometry(model, pos, probe, pivot, length, dr, where)
    t = model.nominal_position(pos, probe)
    lin = generated.ballbar(t[:, 0], t[:, 1], t[:, 2], pivot[:, 0], pivot[:, 1], pivot[:, 2],
                            length)[0]                       # (8, n)
    off = lin[0]
    swept = np.zeros(n, bool)
    for a in model.rotary_axes:
        swept |= np.ptp(pos[a]) > 1.0
    trace, direction, placement = split_traces(t - pivot, pivot, length, placement, direction,
                                               direction_given, swept, where)
    groups, names = _placements(placement, pivot, length, where)
    proj = np.zeros((n, 3, 3))
    proj[:, 0, :] = lin[1:4].T
    local = np.zeros((n, 3, len(SETUP_KEYS)))
    local[:, 0, :] = lin[4:8].T
    dev = np.zeros((n, 3))
    dev[:, 0] = dr - off
    setup = Setup(groups[:, None], local, [f"{where}#{m}" if len(names) > 1 else where
                                           for m in names],
                  [SETUP_KEYS] * len(names), [("local", 0)] * len(names),
                  [("um",) * len(SETUP_KEYS)] * len(names),
                  [(None, None, None, length_u)] * len(names))
    covs = f.covariates(find, model, where, skip=())
    covs = {**motion_directions(model, pos, trace, np.ones(n)), **covs}
    info = {"pivot": pivot, "length": length, "dr": dr, "direction": direction,
            "placement": np.asarray(names, dtype=object)[groups], "trace": trace}
    return Observations(pos, probe, dev, covs, warnings, proj=proj, rows=np.ones(n, int),
                        setup=setup, files=(FileInfo(where, KIND, "um", 1),), sigma=u,
                        info=info)


def check_geometry(model, pos, probe, pivot, length, dr, where) -> None:
    """The tool ball lies the bar length from the pivot at every row, within
    :data:`RADIUS_TOLERANCE_MM` (:func:`volerr.instruments.geometry_check.ballbar_misfit`); a
    miss is refused naming the likely cause (radians, inches, the offset's sign, swapped
    columns, another layout, a diameter given for the bar length)."""
    from . import geometry_check as gc

    gc.require_consistent(where, model, gc.Geometry(
        pos, probe, {"the pivot": pivot, "the bar length": length},
        {"the pivot": "pivot_x, pivot_y, pivot_z", "the bar length": "length_mm"},
        gc.ballbar_misfit(dr, RADIUS_TOLERANCE_MM)),
        extra=[("twice the bar length in length_mm (a diameter for the radius?)", "length_mm",
                {"the bar length": length / 2.0}),
               ("half the bar length in length_mm (x 2 makes the file consistent)", "length_mm",
                {"the bar length": length * 2.0})])


def _direction(find, n: int, where: str) -> tuple[np.ndarray, bool]:
    """The ``direction`` column (+1 / -1) and whether the file has one (else all +1)."""
    h = find("direction", ("",), "direction")
    if h is None:
        return np.ones(n), False
    d = find.cols[h]
    require(np.all(np.isin(d, (-1.0, 1.0))), f"{where}: direction must be +1 (counter-"
                                              f"clockwise) or -1 (clockwise)")
    return d, True


#: a circle trace needs this many readings at distinct angles ...
MIN_TRACE_READINGS = 8
#: ... and no gap between consecutive angles wider than this (deg): at least half a circle
MAX_TRACE_GAP_DEG = 180.0
#: a reading lies in a plane through the pivot when its offset along the plane's normal is
#: below this fraction of the bar length
IN_PLANE_TOL = 1e-4


def split_traces(rel, pivot, length, placement, direction, direction_given, swept, where):
    """Trace of every reading, and the directions and placement labels completed.

    A trace is one circle (or rotary sweep) run in one direction.  With a ``placement``
    column: the readings of one placement and one direction.  Without: the file is cut into
    its traces by geometry -- consecutive readings with the same pivot, bar length, plane (the
    plane through the pivot holding the offsets ``rel`` = tool ball minus pivot, mm) and
    direction (the ``direction`` column, else the sense in which the angle turns) -- and each
    (plane, pivot, length) is a placement of its own, labelled by its plane (``XY``, ``YZ``
    ...).  Every circle trace is checked (:func:`check_trace`).  Returns (trace index (n,),
    direction (n,), placement labels (n,) or None)."""
    n = len(rel)
    if placement is not None:
        key = np.unique(np.column_stack([np.unique(placement.astype(str),
                                                   return_inverse=True)[1].ravel(),
                                         direction]), axis=0, return_inverse=True)[1].ravel()
        trace = key
    else:
        trace = _geometric_traces(rel, pivot, length, direction if direction_given else None,
                                  swept)
    if not direction_given:
        direction = _trace_senses(rel, trace, swept)
    else:
        _check_senses(rel, trace, swept, direction, placement, where)
    for k in np.unique(trace):
        idx = np.flatnonzero(trace == k)
        if not swept[idx].any():
            check_trace(rel[idx], where, _label(placement, rel, idx), direction[idx[0]])
    if placement is None:
        placement = _geometric_labels(rel, pivot, length, trace)
    return trace, direction, placement


def _plane_candidates(rel, length) -> np.ndarray:
    """(n, 3) bool: the plane with normal k holds the reading (offset along k ~ 0)."""
    return np.abs(rel) <= IN_PLANE_TOL * np.asarray(length)[:, None]


def _geometric_traces(rel, pivot, length, direction, swept) -> np.ndarray:
    """Trace index of every reading of a file without ``placement`` (see
    :func:`split_traces`): a new trace where the pivot, the length, the given direction or the
    plane changes (no plane holds every reading of the current trace any more), and, without
    a direction column, where the angle turns the other way for at least
    :data:`MIN_REVERSAL_RUN` readings."""
    n = len(rel)
    cand = _plane_candidates(rel, length)
    same = np.ones(n, bool)
    same[1:] = (np.all(np.isclose(pivot[1:], pivot[:-1], atol=1e-6), axis=1)
                & np.isclose(length[1:], length[:-1], atol=1e-6) & (swept[1:] == swept[:-1]))
    if direction is not None:
        same[1:] &= direction[1:] == direction[:-1]
    steps = np.abs(np.column_stack([_steps(rel, k) for k in range(3)]))    # (n, 3) rad
    code = cand @ np.array([1, 2, 4])
    # the running intersection of planes changes only where a reading's planes change
    events = np.flatnonzero(~same[1:] | (code[1:] != code[:-1])) + 1
    starts = [0]
    planes = cand[0].copy()
    for i in events:
        both = planes & cand[i]
        new = not same[i] or (not swept[i] and planes.any() and not both.any())
        if not new and not swept[i] and both.sum() == 1 and cand[i].sum() > 1:
            # a reading in two planes (where one circle ends and the next begins) after a
            # jump of the angle: the first reading of the next circle
            k = int(np.argmax(both))
            before = steps[starts[-1] + 1:i, k]
            new = len(before) >= 3 and steps[i, k] > 5 * np.median(before)
        if new:
            starts.append(int(i))
            planes = cand[i].copy()
        else:
            planes = both
    trace = np.zeros(n, int)
    trace[starts[1:]] = 1
    trace = np.cumsum(trace)
    if direction is None:
        trace = _split_reversals(rel, trace, swept)
    return trace


#: a trace is cut where its angle turns the other way for at least this many readings
MIN_REVERSAL_RUN = 3


def _split_reversals(rel, trace, swept) -> np.ndarray:
    """Cut the traces where the angle's sense of turning reverses (a counter-clockwise circle
    followed by a clockwise one, no direction column); shorter runs of the other sense (a
    reading shared by two planes) do not cut."""
    out = np.zeros(len(rel), int)
    label = 0
    for k in np.unique(trace):
        idx = np.flatnonzero(trace == k)
        cuts = []
        if not swept[idx].any() and len(idx) > 2:
            step = np.sign(_steps(rel[idx], _trace_plane(rel[idx]))[1:])
            moving = np.flatnonzero(step)
            sg = step[moving]
            run_starts = np.r_[0, np.flatnonzero(np.diff(sg)) + 1]
            run_lengths = np.diff(np.r_[run_starts, len(sg)])
            sense = 0.0
            for first, length in zip(run_starts, run_lengths):     # runs of one sense
                if length < MIN_REVERSAL_RUN:
                    continue
                if sense and sg[first] != sense:
                    cuts.append(int(moving[first]) + 1)
                sense = sg[first]
        piece = np.zeros(len(idx), int)
        for c in cuts:
            piece[c:] += 1
        out[idx] = label + piece
        label += int(piece[-1]) + 1 if len(idx) else 0
    return out


def _steps(rel, normal: int) -> np.ndarray:
    """(n,) angle (rad) turned from each reading's predecessor to it in the plane of the given
    normal (0 for the first reading)."""
    a, b = [(1, 2), (2, 0), (0, 1)][normal]
    ang = np.arctan2(rel[:, b], rel[:, a])
    d = np.zeros(len(rel))
    d[1:] = (np.diff(ang) + np.pi) % (2 * np.pi) - np.pi
    return d


def _trace_plane(rel) -> int:
    """Index of the normal of the plane of a trace's offsets (the smallest spread)."""
    return int(np.argmin(np.ptp(rel, axis=0)))


def _angles(rel) -> np.ndarray:
    """Angles (rad) of a circle trace's offsets in its plane (first axis towards second)."""
    a, b = [(1, 2), (2, 0), (0, 1)][_trace_plane(rel)]
    return np.arctan2(rel[:, b], rel[:, a])


def _trace_senses(rel, trace, swept) -> np.ndarray:
    """+1 / -1 of every reading: the sense in which its trace's angle turns (a rotary sweep:
    +1, the sweep's own order is its direction)."""
    out = np.ones(len(rel))
    for k in np.unique(trace):
        idx = np.flatnonzero(trace == k)
        if swept[idx].any() or len(idx) < 2:
            continue
        out[idx] = -1.0 if np.sum(_steps(rel[idx], _trace_plane(rel[idx]))) < 0 else 1.0
    return out


#: a trace's readings run in one sense when at least this share of its steps turn that way
#: (rows in the order they were measured; a shuffled or sorted file is not judged)
SENSE_SHARE = 0.9


def _check_senses(rel, trace, swept, direction, placement, where: str) -> None:
    """Refuse a ``direction`` column that contradicts the sense in which the trace's positions
    run (one line naming the file and the column): every step of a circle trace turns one
    way (:data:`SENSE_SHARE` of them), and that way is not the column's +1 (ccw) / -1 (cw)."""
    for k in np.unique(trace):
        idx = np.flatnonzero(trace == k)
        if swept[idx].any() or len(idx) < MIN_TRACE_READINGS:
            continue
        steps = _steps(rel[idx], _trace_plane(rel[idx]))[1:]
        steps = steps[np.abs(steps) > 1e-9]
        if not len(steps) or np.max(np.abs(steps)) > np.radians(45.0):
            continue        # not a sequence of neighbouring readings: not judged
        share = float(np.mean(steps > 0))
        sense = 1.0 if share >= SENSE_SHARE else -1.0 if share <= 1 - SENSE_SHARE else 0.0
        if sense and sense != direction[idx[0]]:
            said = "+1 (ccw)" if direction[idx[0]] > 0 else "-1 (cw)"
            runs = "counter-clockwise" if sense > 0 else "clockwise"
            raise InputError(f"{where}: column direction: trace "
                             f"{_label(placement, rel, idx)} says {said} but its positions "
                             f"run {runs}: the direction column inverted (cw/ccw swapped), or "
                             f"the rows not in the order they were measured")


def check_trace(rel, where: str, label: str, direction) -> None:
    """Refuse a degenerate circle trace (InputError, one line): fewer than
    :data:`MIN_TRACE_READINGS` readings at distinct angles (all readings at one point), or a
    gap between consecutive angles wider than :data:`MAX_TRACE_GAP_DEG` (less than half a
    circle: its least-squares centre, G and the diagnosis are not determined)."""
    deg = np.sort(np.unique(np.round(np.rad2deg(np.mod(_angles(rel), 2 * np.pi)), 3)))
    name = f"{where}: trace {label} ({'ccw' if direction > 0 else 'cw'})"
    require(len(deg) >= MIN_TRACE_READINGS,
            f"{name} has {len(rel)} readings at {len(deg)} distinct angle(s); a circle trace "
            f"needs at least {MIN_TRACE_READINGS} over at least half a circle")
    gaps = np.diff(np.concatenate([deg, [deg[0] + 360.0]]))
    require(gaps.max() <= MAX_TRACE_GAP_DEG,
            f"{name} covers only {360.0 - gaps.max():.0f} deg; a circle trace needs readings "
            f"over at least half a circle (no gap wider than {MAX_TRACE_GAP_DEG:.0f} deg)")


def _label(placement, rel, idx) -> str:
    if placement is not None:
        return str(placement[idx[0]])
    return PLANE_NAMES[_trace_plane(rel[idx])]


def _geometric_labels(rel, pivot, length, trace) -> np.ndarray:
    """Placement label of every reading of a file without ``placement``: one placement per
    (plane, pivot, bar length), named by its plane (``XY``; ``XY-2`` ... when the plane
    recurs with another pivot or length)."""
    out = np.empty(len(rel), dtype=object)
    seen: dict = {}
    for k in np.unique(trace):
        idx = np.flatnonzero(trace == k)
        plane = PLANE_NAMES[_trace_plane(rel[idx])]
        key = (plane, *np.round(pivot[idx[0]], 6), round(float(length[idx[0]]), 6))
        if key not in seen:
            count = sum(1 for q in seen if q[0] == plane)
            seen[key] = plane if count == 0 else f"{plane}-{count + 1}"
        out[idx] = seen[key]
    return out


def _placements(placement, pivot, length, where) -> tuple[np.ndarray, list]:
    """Group index of each reading and the group labels: the ``placement`` column, else one
    group per distinct (pivot, length)."""
    if placement is not None:
        names, idx = np.unique(placement.astype(str), return_inverse=True)
        return idx, [str(x) for x in names]
    key = np.round(np.column_stack([pivot, length]), 6)
    uniq, idx = np.unique(key, axis=0, return_inverse=True)
    return idx.ravel(), [str(i + 1) for i in range(len(uniq))]


def motion_directions(model: Model, pos: dict, groups, direction) -> dict:
    """``dir_<axis>`` (+1 / -1) of every moving axis: the sign of its motion between
    consecutive readings of the same trace (placement and direction), in file order; a reading
    where an axis turns takes the sign of the motion that brought it there."""
    n = len(groups)
    out = {}
    trace = np.asarray(groups) * 2 + (np.asarray(direction) > 0)
    for a in model.axes:
        q = np.asarray(pos[a], dtype=float)
        if np.ptp(q) == 0:
            continue
        d = np.zeros(n)
        for t in np.unique(trace):
            idx = np.flatnonzero(trace == t)
            if len(idx) < 2:
                continue
            step = np.sign(np.diff(q[idx]))
            s = np.concatenate([[step[0]], step])       # a reading: the motion that came to it
            for i in range(1, len(s)):                   # standing still: keep the last sign
                if s[i] == 0:
                    s[i] = s[i - 1]
            d[idx] = s
        if np.any(d != 0):
            d[d == 0] = 1.0
            out[f"dir_{a}"] = d
    return out


def extensions(model, obs) -> list:
    """Plan extensions a calibration can try when the file leaves parameters undetermined:
    ``[(text, hypothetical Observations)]`` -- circles in the planes the file lacks, a second
    radius, and the bar length calibrated (``length_u_um``)."""
    if "pivot" not in obs.info:
        return []
    where = obs.files[0].name if obs.files else "ballbar"
    pivot = obs.info["pivot"][0]
    radius = float(obs.info["length"][0])
    tool = obs.probe[0]
    t = model.nominal_position(obs.positions, obs.probe)
    have = {PLANE_NAMES[plane_of(t - obs.info["pivot"])]}
    rotary = {a: float(np.median(obs.positions[a])) for a in model.rotary_axes}
    trials = [(f"a circle in the {p} plane", p, radius) for p in ("XY", "YZ", "ZX")
              if p not in have]
    trials.append((f"a second radius ({1.5 * radius:g} mm)", next(iter(have)), 1.5 * radius))
    out = []
    for text, plane, r in trials:
        try:
            cols = simulate(model, None, plane, r, pivot, tool, rotary, points=72)
        except Exception:      # the trial leaves the travel or the chain: not a suggestion
            continue
        ext = columns_to_observations({k: np.asarray(v, float) for k, v in cols.items()}, {},
                                      {}, model, f"{where} + {text}")
        out.append((text, ext))
    if obs.setup is not None and obs.setup.priors[0][-1] is None:
        calibrated = obs.subset(np.arange(obs.n))
        calibrated.setup.priors = [(None, None, None, 1e-3)] * len(calibrated.setup.keys)
        out.append(("the bar length calibrated to 1 um (length_u_um)", calibrated))
    return out


# ---- planes of a trace ----------------------------------------------------------------------
#: plane name -> (first axis, second axis, normal) indices in the workpiece frame
PLANES = {"XY": (0, 1, 2), "YZ": (1, 2, 0), "ZX": (2, 0, 1)}
#: normal index -> plane name, and the plane's in-plane axes (first, second)
PLANE_NAMES = {2: "XY", 0: "YZ", 1: "ZX"}
PLANE_AXES = {2: (0, 1), 0: (1, 2), 1: (2, 0)}


def plane_of(offsets: np.ndarray) -> int:
    """Index of the plane normal: the coordinate along which the nominal tool ball does not
    move about the pivot (the smallest spread)."""
    return int(np.argmin(np.ptp(offsets, axis=0)))


# ---- plans and simulated readings (ballbar simulate, the demo, plan suggestions) -------------


def plane_axes(plane: str) -> tuple[np.ndarray, np.ndarray]:
    """The plane's first and second unit axes in the workpiece frame."""
    require(plane in PLANES, f"plane must be one of {' '.join(PLANES)}, got {plane!r}")
    i, j, _ = PLANES[plane]
    e = np.eye(3)
    return e[i], e[j]


def trace(model, plane: str, radius: float, centre, tool=(0.0, 0.0, 0.0), rotary=None,
          points: int = 360, direction: int = 1) -> dict:
    """Commanded positions and geometry of one trace: ``{"positions", "pivot", "angle_deg",
    "direction"}``; ``rotary``: {axis: deg} fixed or {axis: (start, stop)} swept."""
    require(radius > 0, "radius must be positive")
    require(points >= 8, "a trace needs at least 8 points")
    e1, e2 = plane_axes(plane)
    centre = np.asarray(centre, float)
    rotary = dict(rotary or {})
    swept = [a for a, v in rotary.items() if np.ndim(v) == 1 and len(v) == 2]
    require(len(swept) <= 1, "at most one rotary axis can sweep")
    for a in rotary:
        require(a in model.rotary_axes, f"{a} is not a rotary axis of {model.name}")
    frac = np.arange(points) / points
    if swept:
        a = swept[0]
        lo, hi = map(float, rotary[a])
        q = lo + (hi - lo) * (frac if (hi - lo) % 360 == 0 else np.linspace(0, 1, points))
        if direction < 0:
            q = q[::-1]
        rot = {**{k: v for k, v in rotary.items() if k != a}, a: q}
        targets = np.tile(centre + radius * e1, (points, 1))
        angle = q
    else:
        theta = 2 * np.pi * frac * (1 if direction > 0 else -1)
        targets = centre + radius * (np.cos(theta)[:, None] * e1 + np.sin(theta)[:, None] * e2)
        rot = rotary
        angle = np.rad2deg(np.mod(theta, 2 * np.pi))
    pos = model.linear_positions(targets, rot, tool)
    for a in model.axes:
        lo, hi = model.travel[a]
        bad = np.flatnonzero((pos[a] < lo - 1e-9) | (pos[a] > hi + 1e-9))
        require(len(bad) == 0, f"the trace needs {a} = {pos[a][bad[0]] if len(bad) else 0:g}, "
                               f"outside the travel [{lo:g}, {hi:g}] of {model.name}: move "
                               f"the centre or shorten the radius")
    return {"positions": pos, "pivot": centre, "angle_deg": angle, "direction": direction}


def readings(model, functions, positions: dict, pivot, tool, noise_um: float = 0.0,
             seed: int = 0) -> np.ndarray:
    """Bar length minus nominal length (N,) mm of the first-order model: ``u . e``."""
    t = model.nominal_position(positions, tool)
    errors = functions(positions) if functions is not None else {}
    e = model.volumetric_error(positions, errors, probe=tool)
    u = (t - pivot) / np.linalg.norm(t - pivot, axis=1)[:, None]
    dr = np.sum(u * e, axis=1)
    if noise_um:
        dr = dr + np.random.default_rng(seed).normal(0.0, noise_um * 1e-3, len(dr))
    return dr


def simulate(model, functions, plane: str, radius: float, centre, tool=(0.0, 0.0, 0.0),
             rotary=None, points: int = 360, noise_um: float = 0.0, direction: str = "both",
             seed: int = 0) -> dict:
    """Columns of a ballbar file (``volerr formats ballbar``) for one circle (both directions
    by default: counter-clockwise first)."""
    require(direction in ("both", "ccw", "cw"), "direction must be both, ccw or cw")
    dirs = {"both": (1, -1), "ccw": (1,), "cw": (-1,)}[direction]
    tool = np.asarray(tool, float)
    cols: dict = {}
    for k, d in enumerate(dirs):
        tr = trace(model, plane, radius, centre, tool, rotary, points, d)
        dr = readings(model, functions, tr["positions"], tr["pivot"], tool, noise_um, seed + k)
        n = len(dr)
        part = {**{a: tr["positions"][a] for a in model.axes},
                "Xp": np.full(n, tool[0]), "Yp": np.full(n, tool[1]), "Zp": np.full(n, tool[2]),
                "pivot_x": np.full(n, tr["pivot"][0]), "pivot_y": np.full(n, tr["pivot"][1]),
                "pivot_z": np.full(n, tr["pivot"][2]), "length_mm": np.full(n, float(radius)),
                "dr_um": dr * 1e3, "direction": np.full(n, float(d))}
        for key, v in part.items():
            cols[key] = np.concatenate([cols[key], v]) if key in cols else np.asarray(v, float)
    return cols


def write_csv(path, cols: dict, inputs=()):
    """Write ballbar columns (6 decimals for mm/deg, 5 for um; no negative zero)."""
    from ..fileio import write_text

    from ..units import num

    names = list(cols)
    n = len(cols[names[0]])
    fmt = [".5f" if k.endswith("_um") else ".0f" if k == "direction" else ".6f" for k in names]
    lines = [",".join(names)]
    for i in range(n):
        lines.append(",".join(num(cols[k][i], f) for f, k in zip(fmt, names)))
    return write_text(path, "\n".join(lines) + "\n", inputs=list(inputs))


def parse_rotary(text: str) -> dict:
    """``"B=0,C=0:360"`` (``--rotary``) -> ``{"B": 0.0, "C": (0.0, 360.0)}``: a rotary axis
    held at DEG, or swept from START to STOP (deg)."""
    out = {}
    for item in [t.strip() for t in text.split(",") if t.strip()]:
        name, sep, value = item.partition("=")
        require(sep == "=" and name.strip(), f"--rotary expects AXIS=DEG or AXIS=START:STOP, "
                                             f"got {item!r}")
        try:
            parts = [float(v) for v in value.split(":")]
        except ValueError:
            raise InputError(f"--rotary {item!r}: not a number") from None
        require(len(parts) in (1, 2), f"--rotary {item!r}: AXIS=DEG or AXIS=START:STOP")
        out[name.strip().upper()] = parts[0] if len(parts) == 1 else tuple(parts)
    return out


class SimulatedTrace:
    """A simulated ballbar file (:func:`simulated_trace`): ``columns`` as :func:`write_csv`
    writes them (``dr_um`` in um, positions mm / deg); :meth:`summary` what ``volerr ballbar
    simulate`` prints."""

    def __init__(self, columns: dict, layout: str, plane: str, radius: float):
        self.columns, self.layout, self.plane, self.radius = columns, layout, plane, radius

    def summary(self, written: str = "(not written)") -> str:
        """The line ``volerr ballbar simulate`` prints, the file named ``written``."""
        dr = self.columns["dr_um"]
        return (f"{self.layout}: ballbar trace {self.plane}, radius {self.radius:g} mm, "
                f"{len(dr)} readings -> {written} (dr {dr.min():.3f} .. {dr.max():.3f} um)")

    def write_csv(self, path, inputs=()):
        """The ballbar file ('volerr formats ballbar')."""
        return write_csv(path, self.columns, inputs=inputs)


def simulated_trace(model: Model, functions, plane: str, radius: float, centre,
                    tool=(0.0, 0.0, 0.0), rotary=None, points: int = 360,
                    noise_um: float = 0.0, direction: str = "both", seed: int = 0, *,
                    method: str = "linear", degree: int | None = None, extrapolate: bool = False,
                    accept_implausible: bool = False) -> SimulatedTrace:
    """A ballbar trace of ``model`` with the error ``functions`` (``volerr ballbar simulate``):
    :func:`simulate`, its options checked first.

    Parameters
    ----------
    model : Model
        The machine (its first-order observation model).
    functions : volerr.tables.functions.ErrorFunctions, str or path
        The error functions (mm / rad) the readings see, or an error directory, read with
        ``method``, ``degree``, ``extrapolate`` and ``accept_implausible`` (the ``--errors``
        options; :meth:`volerr.tables.functions.ErrorFunctions.from_dir`).
    plane : {"XY", "YZ", "ZX"}
        Plane of the circle in the workpiece frame.
    radius : float
        Bar length, mm, in (0, 1e5].
    centre, tool : 3-vectors
        Pivot ball centre (workpiece frame) and tool-side ball offset from the tool point, mm.
    rotary : dict or str, optional
        Rotary axes held (deg) or swept (START, STOP), or its ``--rotary`` text
        (:func:`parse_rotary`); None: none.
    points : int
        Readings per direction, 8 .. 10^6.
    noise_um : float
        Standard deviation of the Gaussian noise of a reading, um, not negative.
    direction : {"both", "ccw", "cw"}
        Counter-clockwise, clockwise or both (CCW first).
    seed : int
        Seed of the noise.

    Returns
    -------
    SimulatedTrace
        ``columns`` (``dr_um`` in um: bar longer than nominal positive), ``write_csv``,
        ``summary()`` the line the command prints.

    Raises
    ------
    volerr.InputError
        An option out of range, with the command's one-line message.
    """
    if isinstance(functions, (str, bytes)) or hasattr(functions, "__fspath__"):
        from ..tables.functions import ErrorFunctions

        functions = ErrorFunctions.from_dir(functions, model, method, degree, extrapolate,
                                            accept_implausible=accept_implausible)
    require(noise_um >= 0, "--noise-um must not be negative")
    require(0 < radius <= 1e5, f"--radius must be a positive length of at most 1e5 mm, "
                               f"got {radius:g}")
    require(8 <= points <= 10 ** 6, f"--points must be between 8 and 10^6 readings per "
                                    f"direction, got {points}")
    if rotary is None or isinstance(rotary, str):
        rotary = parse_rotary(rotary or "")
    cols = simulate(model, functions, plane, radius, centre, tool, rotary, points, noise_um,
                    direction, seed)
    return SimulatedTrace(cols, model.name, plane, radius)
