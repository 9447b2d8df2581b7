"""NC programs of a plan, safe along their whole path (``volerr formats plan``): the layout's
machine axes (linear mm, rotary deg), written in a controller's dialect
(:mod:`volerr.plan._dialect`).

Every program: first the retract along Z alone to the clearance height (the top of the Z
travel, +Z moves the tool away from the workpiece, ISO 841) in machine coordinates, then the
modes (metric, absolute, feed per minute, work offset G54 with zero offsets, tool length
compensation off: the positions carry the plan's probe / tool offset), the set-ups in order
(a set-up change is a program stop with a comment saying what to move), ``M30``.  Every reading
position of the plan file is, in order, the end point of a motion block (ballbar, sphere /
R-test, distances, interferometer) -- a ball of an artifact is probed instead (below).

* **ballbar circle** (ISO 230-4): down to the mounting point on the circle (the bar at its
  nominal length, mounted there at the program stop), the run-in arc :data:`RUN_DEG` to the
  first reading, the readings as ``G2``/``G3`` arcs at :data:`FEED` (counter-clockwise first,
  both directions each a whole turn), the run-out arc, back over it in the other direction as
  its run-in, the clockwise turn, its run-out ending at the mounting point (remove the bar
  there).  The tool ball stays on the circle all the way: the bar at its length.  A circle
  that is not a circle of the machine axes (a plane not of the axes) is written as chords of
  at most :data:`BAR_TOL_MM` sag.
* **ballbar sweep** (ISO 10791-6): the bar mounted at the first reading; between readings
  blocks so close that the axes interpolated linearly block by block (as a controller without
  TCPM interpolates them) keep the bar within :data:`BAR_TOL_MM` of its length.
* **sphere / R-test**: up to the clearance height, across with the rotary axes turned there,
  down to a point ``RETRACT_MM`` back along the tool axis, along the tool axis to the reading
  at the feed, dwell, back out the same way (rotary axes still near the sphere).
* **artifact** (ball plate): each ball probed by probing moves (``G38.2`` ...) towards its
  centre from :data:`PROBE_START_MM` away, at the points a centre needs (a plate lying flat:
  four round the equator and the pole; a standing plate: the pole on its free side, both
  horizontal equator points and the top), the stylus moving between them on a box
  :data:`PROBE_START_MM` round the ball on its free side; between balls up to the clearance
  height.  Ball :data:`BALL_D_MM`, stylus tip :data:`STYLUS_D_MM` (stated in the program;
  the geometry: :mod:`volerr.plan._probing`).
* **interferometer** (ISO 230-2:2014 linear cycle, cl. 4.3 / 5.3; the standard's text as GOST
  ISO 230-2, docs.cntd.ru/document/1200146046: the moving component is positioned at a series
  of targets where it stays at rest long enough for the position to be reached, measured and
  recorded, moving between them at an agreed feed): each target approached from its declared
  direction, an overshoot :data:`OVERSHOOT_MM` beyond the last target before each reversal
  and before the first target, a dwell at each.
* **distances** (tracking interferometer): straight feed moves between the targets, a dwell
  at each.
"""

from __future__ import annotations

import numpy as np

from . import _dialect, _probing, _spec
from ._candidates import home
from ._dialect import Op
from ._probing import BALL_D_MM, PROBE_START_MM, STYLUS_D_MM

#: feed of the motion blocks, mm/min (ballbar circles: the ISO 230-4 test feed)
FEED = {"ballbar": _spec.BALLBAR_FEED_MM_MIN, "sphere": 1000.0, "distances": 2000.0,
        "interferometer": 2000.0, "artifact": 1000.0}
#: distances tried, largest first, for the point back along the tool axis from a sphere reading
#: (the first whose axis positions lie inside the travel), mm
RETRACT_MM = (20.0, 10.0, 5.0, 2.0)
#: run-in and run-out arc of a ballbar circle, deg (a quarter turn a direction in all, the time
#: model of volerr formats plan)
RUN_DEG = 45.0
#: largest change of the bar's length along the path after mounting, mm (a ballbar reads
#: +-1 mm)
BAR_TOL_MM = 0.05
#: interferometer overshoot beyond the end targets before a reversal, mm (at most the room
#: left in the travel)
OVERSHOOT_MM = 5.0
#: ball plate: probing feed, mm/min (the geometry: :mod:`volerr.plan._probing`)
PROBE_FEED = 200.0


def program(model, pf, header: list, dialect: str = "iso", name: str = "PLAN") -> str:
    """The NC program of plan file ``pf`` (a :class:`volerr.plan._files.PlanFile`) in
    ``dialect`` (:data:`volerr.plan._dialect.NAMES`); ``header`` comment lines first."""
    return _dialect.dialect(dialect, model.axes).render(operations(model, pf, header), name)


def nc_program(model, instrument, setups, dialect: str = "iso", header=(),
               name: str = "PLAN") -> str:
    """The NC program of ``setups`` [(SetUp, readings)] of one instrument (an ``--instrument``
    SPEC text or a parsed :class:`volerr.plan._spec.Instrument`), as ``volerr plan`` writes
    it, in ``dialect``: for a caller with its own set-ups (an interim check)."""
    from ._files import PlanFile, columns_of

    inst = _spec.parse(instrument) if isinstance(instrument, str) else instrument
    pf = PlanFile("program.csv", inst.kind, 0, list(setups))
    pf.columns = columns_of(inst, pf.setups)
    return program(model, pf, list(header), dialect, name)


def program_name(file_name: str) -> str:
    """A program name a controller takes (Heidenhain ``BEGIN PGM``): the file's stem, letters
    digits and ``_`` only."""
    stem = str(file_name).rsplit("/", 1)[-1].rsplit(".", 1)[0]
    return "".join(ch if ch.isalnum() or ch == "_" else "_" for ch in stem) or "PLAN"


def operations(model, pf, header: list) -> list:
    """The program of ``pf`` as :class:`~volerr.plan._dialect.Op` (module docstring)."""
    ops = [Op("start", {"Z": _top(model)})] + [Op("comment", text=h) for h in header]
    build = {"ballbar": _ballbar, "sphere": _sphere, "artifact": _artifact,
             "interferometer": _interferometer, "distances": _distances}[pf.kind]
    for k, (setup, rows) in enumerate(_setups(model, pf)):
        if k:
            ops += [Op("rapid", {"Z": _top(model)}),
                    Op("stop", text=f"set-up change: {setup.text}")]
        ops.append(Op("comment", text=f"set-up {setup.label}: {setup.text}"))
        ops += build(model, pf, setup, rows)
    return ops + [Op("rapid", {"Z": _top(model)}), Op("end")]


def _setups(model, pf) -> list:
    """[(SetUp, (n, n_axes) positions of its rows)] in the file's order."""
    col = "station" if pf.kind == "distances" else "placement"
    labels = np.asarray(pf.columns[col]).astype(str)
    q = np.column_stack([np.asarray(pf.columns[a], float) for a in model.axes])
    by_label = {s.label: s for s, _ in pf.setups}
    out, start = [], 0
    for i in range(1, len(labels) + 1):
        if i == len(labels) or labels[i] != labels[start]:
            out.append((by_label[labels[start]], q[start:i]))
            start = i
    return out


def _top(model) -> float:
    return float(model.travel["Z"][1])


def _at(model, row) -> dict:
    return {a: float(v) for a, v in zip(model.axes, np.round(row, 4))}


def _down_to(model, row) -> list:
    """Across at the clearance height (rotary axes turned there), then down along Z alone."""
    to = _at(model, row)
    return [Op("rapid", {a: v for a, v in to.items() if a != "Z"}), Op("rapid", {"Z": to["Z"]})]


def _probe_of(pf):
    return tuple(float(np.asarray(pf.columns[c], float)[0]) for c in ("Xp", "Yp", "Zp"))


# ---- ballbar ------------------------------------------------------------------------------
def _ballbar(model, pf, setup, rows) -> list:
    g = setup.geometry
    if g.get("sweep"):
        return _sweep(model, pf, setup, rows)
    tool = np.asarray(_probe_of(pf))
    e1, e2 = _plane_axes(g["plane"])
    pivot, length = np.asarray(g["pivot"], float), float(g["length"])
    rot = home(model)

    def point(theta_deg):
        t = np.deg2rad(np.atleast_1d(theta_deg))
        tgt = pivot + length * (np.cos(t)[:, None] * e1 + np.sin(t)[:, None] * e2)
        pos = model.linear_positions(tgt, {a: np.full(len(t), v) for a, v in rot.items()},
                                     tool)
        return np.round(np.column_stack([pos[a] for a in model.axes]), 4)

    d = np.asarray(pf.columns["direction"], float)
    n_ccw = int(np.sum(d > 0))
    # mount at -RUN, run-in to the first reading (0 deg), the ccw readings, on to 360 and the
    # run-out 360 + RUN, back to 360 = 0 (the cw run-in) and the cw readings (the first at 0),
    # on to -360 and the run-out -360 - RUN: the mounting point again
    q = np.vstack([point(-RUN_DEG), rows[:n_ccw], point([360.0, 360.0 + RUN_DEG]),
                   rows[n_ccw:], point([-360.0, -360.0 - RUN_DEG])])
    ops = [*_down_to(model, q[0]),
           Op("stop", text=f"mount the ballbar [{length:g} mm] here: the tool cup on the "
                           f"circle at {-RUN_DEG:g} deg, the pivot at ({pivot[0]:g}, "
                           f"{pivot[1]:g}, {pivot[2]:g}) mm; start the data capture"),
           Op("comment", text=f"run-in arc {RUN_DEG:g} deg, the readings counter-clockwise, "
                              f"run-out {RUN_DEG:g} deg and back, the readings clockwise, "
                              f"run-out to the mounting point; feed {FEED['ballbar']:g} "
                              f"mm/min")]
    centre = model.linear_positions(pivot[None, :], {a: np.array([v]) for a, v in rot.items()},
                                    tool)
    centre = {a: float(np.round(centre[a][0], 4)) for a in model.axes}
    ops += _arcs(model, q, centre, length)
    return ops + [Op("stop", text="stop the data capture; remove the ballbar")]


def _plane_axes(plane: str):
    from ..instruments.ballbar import plane_axes

    return plane_axes(plane)


def _arcs(model, q, centre: dict, length: float) -> list:
    """Arc blocks through the axis positions ``q`` (n, n_axes), the first the current point:
    ``G2``/``G3`` about the one linear axis that stays put, chords where none does."""
    lin = [j for j, a in enumerate(model.axes) if a not in model.rotary_axes]
    spread = np.ptp(q, axis=0)
    still = [j for j in lin if spread[j] < 1e-6]
    if len(still) != 1 or any(spread[j] > 1e-9 for j in range(len(model.axes)) if j not in lin):
        return _chords(model, q, centre, length)
    normal = model.axes[still[0]]
    a, _, b, _ = _dialect.CENTRE_WORDS[normal]
    ia, ib = model.axes.index(a), model.axes.index(b)
    c = np.array([centre[a], centre[b]])
    ops = []
    for p0, p1 in zip(q[:-1], q[1:]):
        s, e = p0[[ia, ib]] - c, p1[[ia, ib]] - c
        cross = s[0] * e[1] - s[1] * e[0]
        if np.allclose(p0, p1):
            ops.append(Op("line", _at(model, p1), FEED["ballbar"]))
            continue
        ops.append(Op("arc", _at(model, p1), FEED["ballbar"], normal=normal, ccw=cross > 0,
                      centre={a: centre[a], b: centre[b]}))
    return ops


def _chords(model, q, centre, length) -> list:
    """Straight blocks along the circle between the points ``q``: each arc cut into chords of
    sag at most :data:`BAR_TOL_MM` (the circle through the points about ``centre``)."""
    c = np.array([centre[a] for a in model.axes])
    max_step = 2.0 * np.arccos(1.0 - BAR_TOL_MM / length)
    ops = []
    for p0, p1 in zip(q[:-1], q[1:]):
        u, v = p0 - c, p1 - c
        ang = np.arccos(np.clip(u @ v / max(np.linalg.norm(u) * np.linalg.norm(v), 1e-12),
                                -1, 1))
        k = max(int(np.ceil(ang / max_step)), 1)
        w = v - (u @ v) / (u @ u) * u       # in the plane of u, v, normal to u
        w = w / max(np.linalg.norm(w), 1e-12) * np.linalg.norm(u)
        for f in np.arange(1, k + 1) / k:
            p = c + np.cos(f * ang) * u + np.sin(f * ang) * w if f < 1 else p1
            ops.append(Op("line", _at(model, p), FEED["ballbar"]))
    return ops


def _sweep(model, pf, setup, rows) -> list:
    """ISO 10791-6 sweep: mounted at the first reading, blocks fine enough between readings
    (module docstring)."""
    tool = np.asarray(_probe_of(pf))
    g = setup.geometry
    pivot, length = np.asarray(g["pivot"], float), float(g["length"])
    ops = [*_down_to(model, rows[0]),
           Op("stop", text=f"mount the ballbar [{length:g} mm] here, the pivot on the table "
                           f"at ({pivot[0]:g}, {pivot[1]:g}, {pivot[2]:g}) mm; start the data "
                           f"capture"),
           Op("comment", text=f"{g['sweep']} sweeps with the linear axes following; blocks "
                              f"close enough that linear interpolation of every axis between "
                              f"them keeps the bar within {BAR_TOL_MM:g} mm of its length "
                              f"[no TCPM needed]")]
    tip = model.nominal_position({a: rows[:1, j] for j, a in enumerate(model.axes)}, tool)[0]
    for r0, r1 in zip(rows[:-1], rows[1:]):
        for p in _fine(model, r0, r1, tip, tool, pivot, length)[1:]:
            ops.append(Op("line", _at(model, p), FEED["ballbar"]))
    return ops + [Op("stop", text="stop the data capture; remove the ballbar")]


def _fine(model, r0, r1, tip, tool, pivot, length) -> np.ndarray:
    """(k + 1, n_axes) positions from ``r0`` to ``r1`` (both included): the rotary axes in k
    equal steps, the linear axes holding the tool point at ``tip``; k the smallest power of two
    whose blocks keep ``|tool point - pivot| - length`` within :data:`BAR_TOL_MM` (checked at
    quarter points of every block)."""
    rot_j = [j for j, a in enumerate(model.axes) if a in model.rotary_axes]
    if np.allclose(r0[rot_j], r1[rot_j]):
        return np.array([r0, r1])
    k = 1
    while True:
        f = np.arange(k + 1) / k
        rot = {model.axes[j]: r0[j] + f * (r1[j] - r0[j]) for j in rot_j}
        pos = model.linear_positions(np.tile(tip, (k + 1, 1)), rot, tool)
        q = np.column_stack([pos[a] for a in model.axes])
        q[0], q[-1] = r0, r1
        q = np.round(q, 4)
        if _bar_ok(model, q, tool, pivot, length) or k >= 4096:
            return q
        k *= 2


def _bar_ok(model, q, tool, pivot, length) -> bool:
    s = np.array([0.25, 0.5, 0.75])
    mid = (q[:-1, None, :] + s[None, :, None] * (q[1:] - q[:-1])[:, None, :]).reshape(-1,
                                                                                   q.shape[1])
    t = model.nominal_position({a: mid[:, j] for j, a in enumerate(model.axes)}, tool)
    return bool(np.all(np.abs(np.linalg.norm(t - pivot, axis=1) - length) <= BAR_TOL_MM))


# ---- sphere / R-test --------------------------------------------------------------------
def _sphere(model, pf, setup, rows) -> list:
    above = _retract_positions(model, rows, _probe_of(pf))
    dwell = _spec.DWELL_S["sphere"]
    ops = []
    for q, a in zip(rows, above):
        across, down = _down_to(model, a)
        if np.allclose(a, q):       # no room to stop short: the whole descent at the feed
            ops += [Op("rapid", {"Z": _top(model)}), across,
                    Op("line", _at(model, q), FEED["sphere"]), Op("dwell", seconds=dwell)]
            continue
        ops += [Op("rapid", {"Z": _top(model)}), across, down,
                Op("line", _at(model, q), FEED["sphere"]), Op("dwell", seconds=dwell),
                Op("line", _at(model, a), FEED["sphere"])]
    return ops


def _retract_positions(model, q, probe) -> np.ndarray:
    """(N, n_axes) axis positions of the points :data:`RETRACT_MM` back along the tool axis from
    each reading ``q``, rotary axes held (mm / deg): the largest distance whose positions lie
    inside the travel; the reading itself where none does."""
    tip = model.forward(q, probe=probe)
    rotary = {a: q[:, j] for j, a in enumerate(model.axes) if a in model.rotary_axes}
    lo = np.array([model.travel[a][0] for a in model.axes])
    hi = np.array([model.travel[a][1] for a in model.axes])
    out, todo = q.copy(), np.ones(len(q), bool)
    for d in RETRACT_MM:
        pos = model.linear_positions(tip[:, :3] + d * tip[:, 3:], rotary, probe)
        cand = np.column_stack([pos[a] for a in model.axes])
        ok = todo & np.all((cand >= lo) & (cand <= hi), axis=1)
        out[ok], todo = cand[ok], todo & ~ok
    return out


# ---- distances, interferometer ------------------------------------------------------------
def _distances(model, pf, setup, rows) -> list:
    dwell = Op("dwell", seconds=_spec.DWELL_S["distances"])
    ops = [*_down_to(model, rows[0]), dwell]
    for q in rows[1:]:
        ops += [Op("line", _at(model, q), FEED["distances"]), dwell]
    return ops


def _interferometer(model, pf, setup, rows) -> list:
    """ISO 230-2 linear cycle: every target approached from its declared direction, an
    overshoot before each reversal (module docstring)."""
    axis = setup.line.axis
    j = model.axes.index(axis)
    d = np.asarray(pf.columns["direction"], float)
    lo, hi = model.travel[axis]
    ops, moving = [], None
    for i, q in enumerate(rows):
        if d[i] != moving:          # a reversal (or the start): overshoot, then come back
            over = q.copy()
            room = (q[j] - lo) if d[i] > 0 else (hi - q[j])
            over[j] = q[j] - d[i] * min(OVERSHOOT_MM, max(room, 0.0))
            if moving is None:
                ops += _down_to(model, over)
                ops.append(Op("comment", text=f"ISO 230-2 linear cycle along {axis}: "
                                              f"overshoot {OVERSHOOT_MM:g} mm before each "
                                              f"reversal, {_spec.DWELL_S['interferometer']:g}"
                                              f" s at each target"))
            else:
                ops.append(Op("line", _at(model, over), FEED["interferometer"]))
            moving = d[i]
        ops += [Op("line", _at(model, q), FEED["interferometer"]),
                Op("dwell", seconds=_spec.DWELL_S["interferometer"])]
    return ops


# ---- artifact (ball plate) ------------------------------------------------------------------
def _artifact(model, pf, setup, rows) -> list:
    """Each ball probed from outside on its free side (module docstring)."""
    tool = _probe_of(pf)
    balls = np.asarray(pf.columns["ball"]).astype(str)
    labels = np.asarray(pf.columns["placement"]).astype(str)
    mine = np.flatnonzero(labels == setup.label)
    centres = np.column_stack([np.asarray(pf.columns[f"{c}_nom_mm"], float)[mine]
                               for c in "xyz"])
    rot = home(model)
    normal, dirs = _probing.directions(model, setup.geometry["plane"], tool, rot)
    ops = [Op("comment", text=f"ball {BALL_D_MM:g} mm, stylus tip {STYLUS_D_MM:g} mm: each "
                              f"ball probed at {len(dirs)} points towards its centre from "
                              f"{PROBE_START_MM:g} mm, on the plate's free side "
                              f"({', '.join(_dialect.number(v) for v in normal)}): the "
                              f"plate behind its balls' plane")]
    for b, c in zip(balls[mine], centres):
        where = ", ".join(_dialect.number(v) for v in c)
        ops.append(Op("comment", text=f"ball {b}: centre ({where}) mm"))
        ops += _ball(model, c, normal, dirs, rot, tool)
    return ops


def _ball(model, c, n, dirs, rot, tool) -> list:
    """The blocks of one ball: up, across, down to the point :data:`PROBE_START_MM` out along
    the free-side normal, then each probing point by the box corner (module docstring)."""
    pts = _probing.ball_path(c, n, dirs)
    pos = model.linear_positions(pts, {a: np.full(len(pts), v) for a, v in rot.items()}, tool)
    q = np.round(np.column_stack([pos[a] for a in model.axes]), 4)
    ops = [Op("rapid", {"Z": _top(model)}), *_down_to(model, q[0])]
    for k, d in enumerate(dirs):
        corner, start, past = q[1 + 5 * k], q[2 + 5 * k], q[3 + 5 * k]
        j = int(np.argmax(np.abs(d)))
        ops += [Op("line", _at(model, corner), FEED["artifact"]),
                Op("line", _at(model, start), FEED["artifact"]),
                Op("probe", _at(model, past), PROBE_FEED, axis="XYZ"[j],
                   sign=int(np.sign(-d[j]))),
                Op("line", _at(model, start), FEED["artifact"]),
                Op("line", _at(model, corner), FEED["artifact"])]
    return ops + [Op("line", _at(model, q[-1]), FEED["artifact"])]
