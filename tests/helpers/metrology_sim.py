"""An exact simulator of artifact (ball / hole plate, step gauge), laser-interferometer and
tracking-interferometer (multilateration) readings for the acceptance tests of issue 20,
independent of the runtime.

It uses the exact chain of :class:`helpers.instrument_sim.Machine` (numpy / scipy and the
parsed layout only; never volerr's generated code, model or instrument readers) and the
planted-error terms of that module (:func:`helpers.instrument_sim.series`, ``constant``).
Definitions (docs/formats.md sections artifact, interferometer, distances), all exact:

* artifact: the machine reports the point ``x`` where its ACTUAL probe point is on the
  feature: ``tool_point(inverse(x), errors) = a``, solved by fixed-point iteration (the
  nominal chain is affine in the linear axes: ``inverse`` exact); ``a = o + R (d +
  Rot(r) p + c)`` -- placement pose ``(R, o)``, its set-up perturbation ``d`` (um, artifact
  frame) and ``r`` (urad, rotation vector about the artifact's origin), the feature's
  calibration error ``c`` (um, artifact frame).  Readings: the components of ``R^T (x - a0)``
  in the artifact frame, ``a0`` the true feature point (a ball three, a hole the first two, a
  face the first);
* distances: ``|tool_point(q, errors, reflector) - (s + ds)| + dd``;
* interferometer, the moving optic at ``optics`` (tool frame), ``t`` its actual position,
  ``r`` the nominal position at the first target, ``b`` the unit direction of nominal motion:
  positioning ``deviation = (1 + k) b . (t - r) + z - (P - P_first)``; straightness ``s . (t -
  r) + z + m b . (t - r)``; angular ``b . (t(optics + L m) - t(optics)) / L + z`` (rad) with
  ``m = b x a`` carried in the tool frame by the nominal tool orientation.

Set-up names ``"<file>#<placement>:<key>"`` (artifact pose ``du dv dw`` um, ``eu ev ew``
urad; distances ``station_dx station_dy station_dz dead_path`` um), ``"<file>@<ball>:<key>"``
(artifact calibration ``cu cv cw`` um), ``"<file>:<key>"`` (interferometer ``zero`` um or
urad, ``scale`` ppm, ``slope`` urad).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from helpers import instrument_sim as S

POSE_KEYS = {"ball": ("du", "dv", "dw", "eu", "ev", "ew"), "hole": ("du", "dv", "ew"),
             "face": ("du",)}
ROWS = {"ball": 3, "hole": 2, "face": 1}


@dataclass
class View:
    """What a planted term needs of a block: positions (mm / deg) and their number."""

    pos: dict
    cov: dict = field(default_factory=dict)
    vel: dict = field(default_factory=dict)

    @property
    def n(self):
        return len(next(iter(self.pos.values())))


# ---- artifact ------------------------------------------------------------------------------
@dataclass
class Artifact:
    """One artifact file: features ``points`` (n, 3) calibrated (artifact frame, mm), per row
    its ``placement`` label and ``ball`` label, one ``feature`` kind for the file; ``poses``
    placement -> (R (3, 3), origin (3,)) true pose in the workpiece frame; ``probe`` (3,)
    stylus offset; ``u_um`` probing noise per coordinate; ``u_std_um`` the calibration's
    stated uncertainty (None: exact)."""

    name: str
    points: np.ndarray
    placement: np.ndarray
    ball: np.ndarray
    feature: str
    poses: dict
    probe: np.ndarray
    u_um: float
    u_std_um: float | None = None
    kind: str = "artifact"
    nominal_pos: dict | None = None

    @property
    def n(self):
        return len(self.points)

    @property
    def rows_per_reading(self):
        return ROWS[self.feature]

    @property
    def pos(self):
        return self.nominal_pos

    def setup_names(self):
        out = [f"{self.name}#{p}:{k}" for p in dict.fromkeys(self.placement.tolist())
               for k in POSE_KEYS[self.feature]]
        if self.u_std_um:
            keys = ("cu", "cv", "cw")[:ROWS[self.feature]]
            out += [f"{self.name}@{b}:{k}" for b in dict.fromkeys(self.ball.tolist())
                    for k in keys]
        return out

    def actual_points(self, setup):
        a = np.empty((self.n, 3))
        for p in dict.fromkeys(self.placement.tolist()):
            m = self.placement == p
            R, o = self.poses[p]
            key = f"{self.name}#{p}:"
            d = np.array([setup.get(key + k, 0.0) for k in ("du", "dv", "dw")]) * 1e-3
            r = np.array([setup.get(key + k, 0.0) for k in ("eu", "ev", "ew")]) * 1e-6
            c = np.array([[setup.get(f"{self.name}@{b}:{k}", 0.0) for k in ("cu", "cv", "cw")]
                          for b in self.ball[m]]) * 1e-3
            inner = Rotation.from_rotvec(r).apply(self.points[m]) + c + d
            a[m] = inner @ np.asarray(R).T + o
        return a


def artifact_block(machine, name, points, poses: dict, feature="ball", probe=(0, 0, 0),
                   u_um=0.5, u_std_um=None, labels=None) -> Artifact:
    """The same features in every placement of ``poses`` (label -> (R, origin))."""
    p = np.asarray(points, float)
    labels = labels or [f"B{i + 1:02d}" for i in range(len(p))]
    blk = Artifact(name, np.tile(p, (len(poses), 1)),
                   np.repeat(np.array(list(poses), dtype=object), len(p)),
                   np.array(list(labels) * len(poses), dtype=object), feature, dict(poses),
                   np.asarray(probe, float), u_um, u_std_um)
    blk.nominal_pos = machine.inverse(blk.actual_points({}), None, blk.probe)
    return blk


def _affine(machine, probe):
    """Nominal tool point = A q + b of the linear axes (q mm, rotary axes at 0): (A, b)."""
    lin = [a for a in machine.axes if a not in machine.rotary]
    zero = {a: np.zeros(1) for a in machine.axes}
    b = machine.tool_point(zero, None, probe)[0]
    A = np.column_stack([machine.tool_point({**zero, a: np.ones(1)}, None, probe)[0] - b
                         for a in lin])
    return A, b, lin


def reported_points(machine, blk: Artifact, terms, values, setup=None, iterations=4):
    """The points (n, 3) mm the machine reports: ``actual(q) = a`` solved for the axis
    positions ``q`` by fixed-point iteration (exact to rounding: the errors change by ~1e-5 of
    a step), reported ``x = nominal(q)`` (the nominal chain is affine in the linear axes)."""
    a = blk.actual_points(setup or {})
    A, b, lin = _affine(machine, blk.probe)
    Ai = np.linalg.inv(A)
    q = (a - b) @ Ai.T
    for _ in range(iterations):
        pos = {ax: q[:, j] for j, ax in enumerate(lin)}
        pos.update({ax: np.zeros(len(q)) for ax in machine.rotary})
        err = S.errors_at(View(pos), terms, values)
        q = q + (a - machine.tool_point(pos, err, blk.probe)) @ Ai.T
    return q @ A.T + b


def _in_frame(blk, x):
    """Reported points minus the true feature points, in the artifact frame, um (n, k)."""
    out = np.empty((blk.n, 3))
    d = x - blk.actual_points({})
    for p in dict.fromkeys(blk.placement.tolist()):
        m = blk.placement == p
        out[m] = d[m] @ np.asarray(blk.poses[p][0])
    return 1e3 * out[:, :ROWS[blk.feature]]


def artifact_readings(machine, blk, terms, values, setup=None):
    """Readings um (n, k): the reported points minus the true feature points (true pose, no
    set-up perturbation), in the artifact frame of their placement."""
    return _in_frame(blk, reported_points(machine, blk, terms, values, setup))


def artifact_columns(blk: Artifact, x_mm: np.ndarray, calibrated=None) -> dict:
    """CSV columns (docs/formats.md artifact) of reported points ``x_mm`` (n, 3);
    ``calibrated`` the certificate's coordinates (default the true points)."""
    p = blk.points if calibrated is None else calibrated
    cols = {"placement": blk.placement, "ball": blk.ball,
            "feature": np.full(blk.n, blk.feature, dtype=object),
            "u_mm": p[:, 0], "v_mm": p[:, 1], "w_mm": p[:, 2],
            "x_mm": x_mm[:, 0], "y_mm": x_mm[:, 1], "z_mm": x_mm[:, 2],
            "Xp": np.full(blk.n, blk.probe[0]), "Yp": np.full(blk.n, blk.probe[1]),
            "Zp": np.full(blk.n, blk.probe[2]), "probe_u_um": np.full(blk.n, blk.u_um)}
    if blk.u_std_um:
        cols["u_std_um"] = np.full(blk.n, blk.u_std_um)
    return cols


# ---- distances -----------------------------------------------------------------------------
@dataclass
class Distances:
    """One distances file: every station measures the tool point at every pose of ``pos``
    (reflector offset ``probe``); ``stations`` label -> true position (mm); ``dead`` label ->
    true dead path (mm); noise 0.3 um + 0.3 um/m."""

    name: str
    pos: dict
    probe: np.ndarray
    station: np.ndarray
    stations: dict
    dead: dict
    kind: str = "distances"
    rows_per_reading: int = 1
    cov: dict = field(default_factory=dict)

    @property
    def n(self):
        return len(self.station)

    def setup_names(self):
        return [f"{self.name}#{s}:{k}" for s in dict.fromkeys(self.station.tolist())
                for k in ("station_dx", "station_dy", "station_dz", "dead_path")]

    def u_um(self, machine):
        t = machine.tool_point(self.pos, None, self.probe)
        s = np.array([self.stations[k] for k in self.station])
        return 0.3 + 0.3e-3 * np.linalg.norm(t - s, axis=1)


def distances_block(name, pos_one: dict, probe, stations: dict, dead: dict) -> Distances:
    n = len(next(iter(pos_one.values())))
    k = len(stations)
    pos = {a: np.tile(np.asarray(v, float), k) for a, v in pos_one.items()}
    return Distances(name, pos, np.tile(np.asarray(probe, float), (n * k, 1)),
                     np.repeat(np.array(list(stations), dtype=object), n), dict(stations),
                     dict(dead))


def distance_readings(machine, blk: Distances, terms, values, setup=None):
    setup = setup or {}
    err = S.errors_at(blk, terms, values)
    t = machine.tool_point(blk.pos, err, blk.probe)
    s = np.empty((blk.n, 3))
    dd = np.empty(blk.n)
    for k in dict.fromkeys(blk.station.tolist()):
        m = blk.station == k
        key = f"{blk.name}#{k}:"
        s[m] = np.asarray(blk.stations[k], float) + 1e-3 * np.array(
            [setup.get(key + c, 0.0) for c in ("station_dx", "station_dy", "station_dz")])
        dd[m] = blk.dead.get(k, 0.0) + 1e-3 * setup.get(key + "dead_path", 0.0)
    return 1e3 * (np.linalg.norm(t - s, axis=1) + dd)


def distance_columns(machine, blk: Distances, d_um: np.ndarray, relative=True) -> dict:
    cols = {a: blk.pos[a] for a in machine.axes}
    cols.update({"Xp": blk.probe[:, 0], "Yp": blk.probe[:, 1], "Zp": blk.probe[:, 2],
                 "station": blk.station})
    d = d_um * 1e-3
    if relative:
        first = {}
        for i, k in enumerate(blk.station):
            first.setdefault(k, d[i])
        cols["dd_mm"] = d - np.array([first[k] for k in blk.station])
    else:
        cols["d_mm"] = d
    cols["u_um"] = blk.u_um(machine)
    return cols


# ---- interferometer ------------------------------------------------------------------------
@dataclass
class Line:
    """One interferometer file: ``mode``, moving ``axis``, other axes ``at``, ``optics``
    (3,) tool frame, ``targets`` (n,) with ``direction`` and ``cycle`` per reading, ``sense``
    (3,) for straightness / angular, ``separation`` mm, ``u`` um or urad."""

    name: str
    mode: str
    axis: str
    at: dict
    optics: np.ndarray
    targets: np.ndarray
    direction: np.ndarray
    cycle: np.ndarray
    sense: np.ndarray | None = None
    separation: float = 30.0
    u: float = 0.2
    kind: str = "interferometer"
    rows_per_reading: int = 1
    cov: dict = field(default_factory=dict)
    pos: dict | None = None

    @property
    def n(self):
        return len(self.targets)

    @property
    def u_um(self):
        return self.u

    def setup_names(self):
        keys = {"positioning": ("zero",), "straightness": ("zero", "slope"),
                "angular": ("zero",)}[self.mode]
        return [f"{self.name}:{k}" for k in keys]


def line_block(machine, name, mode, axis, at, optics, targets, cycles=2, sense=None,
               separation=30.0, u=None) -> Line:
    rows = [(p, c, d) for c in range(1, cycles + 1) for d in (1, -1)
            for p in (targets if d > 0 else targets[::-1])]
    blk = Line(name, mode, axis, dict(at), np.asarray(optics, float),
               np.array([r[0] for r in rows], float), np.array([r[2] for r in rows]),
               np.array([str(r[1]) for r in rows], dtype=object),
               None if sense is None else np.asarray(sense, float), separation,
               u if u is not None else (0.5 if mode == "angular" else 0.2))
    blk.pos = {a: (blk.targets.copy() if a == axis else np.full(blk.n, float(at[a])))
               for a in machine.axes}
    return blk


def _beam(machine, blk: Line):
    lo, hi = machine.travel[blk.axis]
    ends = {a: (np.array([lo, hi]) if a == blk.axis else np.full(2, float(blk.at[a])))
            for a in machine.axes}
    te = machine.tool_point(ends, None, blk.optics)
    b = te[1] - te[0]
    return b / np.linalg.norm(b)


def line_readings(machine, blk: Line, terms, values, setup=None):
    """Readings (n,): um (positioning: the ISO 230-2 deviation; straightness) or urad."""
    setup = setup or {}
    err = S.errors_at(blk, terms, values)
    b = _beam(machine, blk)
    first = int(np.argmin(blk.targets))
    r = machine.tool_point({a: v[first:first + 1] for a, v in blk.pos.items()}, None,
                           blk.optics)[0]
    t = machine.tool_point(blk.pos, err, blk.optics)
    z = setup.get(f"{blk.name}:zero", 0.0)
    if blk.mode == "positioning":
        k = setup.get(f"{blk.name}:scale", 0.0) * 1e-6
        dev = (1 + k) * (t - r) @ b + 1e-3 * z - (blk.targets - blk.targets[first])
        return 1e3 * dev
    if blk.mode == "straightness":
        s = blk.sense / np.linalg.norm(blk.sense)
        m = setup.get(f"{blk.name}:slope", 0.0) * 1e-6
        return 1e3 * ((t - r) @ s + 1e-3 * z + m * ((t - r) @ b))
    a = blk.sense / np.linalg.norm(blk.sense)
    m_work = np.cross(b, a)
    R = machine.tool_matrix(blk.pos)[:, :3, :3]                     # nominal tool frame
    p2 = blk.optics + blk.separation * np.einsum("nji,j->ni", R, m_work)
    t2 = machine.tool_point(blk.pos, err, p2)
    return 1e6 * ((t2 - t) @ b / blk.separation) + z


def write_run(path, blk: Line, values_read):
    """ISO 230-2 long format with the line's header lines (docs/formats.md)."""
    unit = "urad" if blk.mode == "angular" else "um"
    head = [f"# axis: {blk.axis}", f"# mode: {blk.mode}",
            "# at: " + ", ".join(f"{a}={v!r}" for a, v in blk.at.items()),
            "# optics: " + ", ".join(repr(float(v)) for v in blk.optics),
            f"# u_{unit}: {blk.u!r}"]
    if blk.sense is not None:
        head.append("# sense: " + ", ".join(repr(float(v)) for v in blk.sense))
    if blk.mode == "angular":
        head.append(f"# separation: {blk.separation!r}")
    lines = head + [f"target_mm,cycle,direction,deviation_{unit}"]
    for t, c, d, v in zip(blk.targets, blk.cycle, blk.direction, values_read):
        lines.append(f"{float(t)!r},{c},{int(d):+d},{float(v)!r}")
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return str(path)


# ---- readings of any block, design -----------------------------------------------------------
def readings(machine, blk, terms, values, setup=None) -> np.ndarray:
    """Exact readings of any block (this module's or :mod:`helpers.instrument_sim`'s) minus
    those of the nominal machine with zero set-ups (what a linear fit explains)."""
    if blk.kind == "artifact":
        return artifact_readings(machine, blk, terms, values, setup)
    if blk.kind == "distances":
        return (distance_readings(machine, blk, terms, values, setup)
                - distance_readings(machine, blk, terms, {}, {}))
    if blk.kind == "interferometer":
        return line_readings(machine, blk, terms, values, setup)
    return S.readings(machine, blk, terms, values, setup)


def sigma(machine, blk) -> np.ndarray:
    """Standard uncertainty (um / urad) of every scalar reading of a block, flattened."""
    k = blk.rows_per_reading
    if blk.kind == "distances":
        return np.repeat(blk.u_um(machine), k)
    return np.full(blk.n * k, float(blk.u_um))


def simulate(machine, blk, terms, values, setup, rng):
    """(readings as :func:`readings` with Gaussian noise of the stated uncertainty, what the
    file holds): artifact -- the reported points x (n, 3) mm, noise on every coordinate;
    distances -- the absolute distances (um); others -- the readings themselves."""
    if blk.kind == "artifact":
        x = reported_points(machine, blk, terms, values, setup)
        x = x + rng.normal(0.0, blk.u_um * 1e-3, x.shape)
        return _in_frame(blk, x), x
    exact = readings(machine, blk, terms, values, setup)
    noise = rng.normal(0.0, 1.0, np.shape(exact)) * sigma(machine, blk).reshape(
        np.shape(exact))
    if blk.kind == "distances":
        return exact + noise, exact + noise + distance_readings(machine, blk, terms, {}, {})
    return exact + noise, exact + noise


def _steps(blocks, terms, params):
    out = {}
    for p in params:
        big = max((float(np.max(np.abs(t.basis(View(b.pos) if b.kind == "artifact" else b))))
                   / (1e-6 if S.is_angular(t.target) else 1e-3)
                   for t in terms if t.param == p for b in blocks), default=0.0)
        out[p] = 1.0 / big if big > 0 else 1.0
    return out


def design(machine, blocks, terms, setup_step=1.0) -> S.Design:
    """Stacked design by central differences of the exact readings about zero errors and the
    planted set-ups zero; rows (block, data row), weights 1 / u."""
    params = list(dict.fromkeys(t.param for t in terms))
    hs = _steps(blocks, terms, params)
    setups = [s for b in blocks for s in b.setup_names()]
    cols = params + setups
    parts, rows, w = [], [], []
    for bi, b in enumerate(blocks):
        k = b.rows_per_reading
        J = np.zeros((b.n * k, len(cols)))
        for j, p in enumerate(params):
            J[:, j] = ((readings(machine, b, terms, {p: hs[p]}) -
                        readings(machine, b, terms, {p: -hs[p]})) / (2 * hs[p])).ravel()
        mine = set(b.setup_names())
        for j, s in enumerate(setups):
            if s in mine:
                J[:, len(params) + j] = ((readings(machine, b, terms, {}, {s: setup_step}) -
                                          readings(machine, b, terms, {}, {s: -setup_step}))
                                         / (2 * setup_step)).ravel()
        parts.append(J)
        rows.append(np.stack([np.full(b.n * k, bi), np.repeat(np.arange(b.n), k)], -1))
        w.append(1.0 / sigma(machine, b))
    return S.Design(np.vstack(parts), cols, len(params), np.vstack(rows), np.concatenate(w))


def write_csv(path, cols: dict) -> str:
    return S.write_csv(path, cols)
