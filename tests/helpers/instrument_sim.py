"""An exact simulator of instrument readings (ballbar, sphere probing / R-test, 3-D deviations)
for the acceptance tests of issue 19, independent of the runtime.

It uses only numpy / scipy and the parsed layout (:func:`volerr.machine.layout.read_layout`);
it never calls generated code, ``Model.volumetric_error``, or volerr's loop / instrument code.

Chain (exact, vectorised over readings) -- the conventions of
``tests/helpers/reference_chain.py`` (which the derivation is checked against), rewritten with
(N, 4, 4) homogeneous matrices and exact rotations (``scipy`` rotation vectors):

* linear axis: ``T(q * u_actual) T(d) R(e)``, ``u_actual`` the axis direction turned by the
  squareness errors the layout assigns to it;
* rotary axis with point ``c``: tool side ``T(c) L E R(u q) T(-c)``, workpiece (table) side
  ``T(c) R(u q) L E T(-c)`` (``L`` the location errors, ``E`` the component errors); the
  workpiece chain is applied in reverse order (tool relative to workpiece);
* the tool point is the chain applied to the tool offset ``probe`` (tool frame, mm); the result
  is in the workpiece frame.

Units at the public API: positions mm (linear) and DEGREES (rotary); error values inside the
chain mm / rad; fitted parameters in the JSON units of ``volerr calibrate``: constants um or
urad (``EC0Y`` urad, ``EX0C`` um, ``EA0C`` urad), series terms ``EXX@slope`` um/mm (urad/mm,
um/deg, urad/deg), ``EXX@offset`` um/urad, ``EXX@Pk`` Legendre coefficients um/urad over the
measured range.  Readings in um.

Instrument reading models (exact, the definitions of /work/notes/issue19_contract.md):

* ballbar: ``dr = |t_act - (p + dp)| - L + dL``: ``t_act`` the actual tool-ball centre
  (chain with the errors, offset ``Xp,Yp,Zp``), ``p`` the nominal pivot, ``dp`` the pivot's
  set-up offset and ``dL`` the bar-length set-up offset of the placement;
* sphere: ``d = R (t_act - c - dc)``, the tool offset lengthened by ``tool_dz`` along the
  tool's own z axis, ``dc`` the centre offset of the placement, ``R = I`` (frame ``work``) or
  the nominal orientation of the workpiece frame in the base frame (frame ``machine``);

* deviations: ``R(e) t_act + d - t_nominal`` (work frame; ``d``, ``e`` the instrument's
  rigid placement).

Set-up unknowns are named ``"<file>#<placement>:<key>"`` (ballbar ``pivot_dx pivot_dy
pivot_dz length``, sphere ``centre_dx centre_dy centre_dz``) and ``"<file>:<key>"`` (sphere
``tool_dz``; deviations ``dx dy dz`` um, ``ex ey ez`` urad); values in um / urad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from volerr.machine.layout import SQUARENESS, read_layout

_LETTER = {"X": 0, "Y": 1, "Z": 2, "A": 0, "B": 1, "C": 2}
PLANES = {"XY": (0, 1), "YZ": (1, 2), "ZX": (2, 0)}   # in-plane axes (a1, a2); normal a1 x a2
#: set-up of a deviations file: the instrument's rigid placement (um, urad)
DEVIATION_SETUP = ("dx", "dy", "dz", "ex", "ey", "ez")


# ---- exact chain -------------------------------------------------------------------------
def _T(v: np.ndarray) -> np.ndarray:
    m = np.broadcast_to(np.eye(4), v.shape[:-1] + (4, 4)).copy()
    m[..., :3, 3] = v
    return m


def _R(rotvec: np.ndarray) -> np.ndarray:
    rv = np.asarray(rotvec, float)
    m = np.broadcast_to(np.eye(4), rv.shape[:-1] + (4, 4)).copy()
    m[..., :3, :3] = Rotation.from_rotvec(rv.reshape(-1, 3)).as_matrix().reshape(
        rv.shape[:-1] + (3, 3))
    return m


def is_angular(name: str) -> bool:
    """ISO name (or a series term of one) of an angular error: second letter A, B or C."""
    return name[1] in "ABC"


class Machine:
    """The exact chain of a layout (shipped name or path)."""

    def __init__(self, layout):
        self.layout = read_layout(layout)
        lay = self.layout
        self.name = lay.name
        self.axes = lay.axis_names
        self.rotary = tuple(a for a in self.axes if lay.axes[a].kind == "rotary")
        self.travel = {a: lay.axes[a].travel for a in self.axes}
        env = dict(lay.parameters)
        ev = lambda v: float(eval(str(v), {}, env))  # noqa: E731  (layout expressions)
        self._frames = {}
        for n, f in lay.frames.items():
            t = np.array([ev(c) for c in f.translation])
            ax = np.asarray(f.rotation_axis, float)
            ang = math.radians(ev(f.angle_deg))
            self._frames[n] = _T(t[None])[0] @ _R((ax / np.linalg.norm(ax) * ang)[None])[0]
        self._points = {a: np.array([ev(c) for c in lay.axes[a].point]) for a in self.rotary}
        self._dir = {a: np.asarray(lay.axes[a].direction, float)
                     / np.linalg.norm(lay.axes[a].direction) for a in self.axes}

    # -- stages
    def _stage(self, entry, q, errors, n, table):
        if entry in self._frames:
            return np.broadcast_to(self._frames[entry], (n, 4, 4))
        lay = self.layout
        u = self._dir[entry]

        def val(name):
            return np.broadcast_to(np.asarray(errors.get(name, 0.0), float), (n,))

        d = np.stack([val(f"E{t}{entry}") for t in "XYZ"], -1)
        e = np.stack([val(f"E{r}{entry}") for r in "ABC"], -1)
        err = _T(d) @ _R(e)
        if lay.axes[entry].kind == "linear":
            omega = np.zeros((n, 3))
            for name, carrier in lay.squareness.items():
                if carrier == entry:
                    about, moving, _ = SQUARENESS[name]
                    omega[:, about] += (1 if carrier == moving else -1) * val(name)
            u_act = Rotation.from_rotvec(omega).apply(np.tile(u, (n, 1)))
            return _T(q[entry][:, None] * u_act) @ err
        c = self._points[entry]
        loc_d = np.zeros((n, 3))
        loc_e = np.zeros((n, 3))
        for name in lay.axes[entry].location_errors:
            (loc_d if name[1] in "XYZ" else loc_e)[:, _LETTER[name[1]]] = val(name)
        errs = _T(loc_d) @ _R(loc_e) @ err
        turn = _R(u[None, :] * q[entry][:, None])
        tc, tmc = _T(np.broadcast_to(c, (n, 3))), _T(np.broadcast_to(-c, (n, 3)))
        if table:
            return tc @ turn @ errs @ tmc
        return tc @ errs @ turn @ tmc

    def _q(self, pos):
        n = len(np.atleast_1d(pos[self.axes[0]]))
        q = {}
        for a in self.axes:
            v = np.broadcast_to(np.asarray(pos[a], float), (n,))
            q[a] = np.deg2rad(v) if a in self.rotary else v
        return q, n

    def work_matrix(self, pos, errors=None):
        """(N,4,4) product of the workpiece-chain stages (tool relative): the inverse of the
        pose of the workpiece frame in the base frame."""
        q, n = self._q(pos)
        m = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
        for entry in reversed(self.layout.workpiece_chain):
            m = m @ self._stage(entry, q, errors or {}, n, True)
        return m

    def tool_matrix(self, pos, errors=None):
        """(N,4,4) pose of the tool frame in the workpiece frame (exact, with the errors)."""
        q, n = self._q(pos)
        m = self.work_matrix(pos, errors)
        for entry in self.layout.tool_chain:
            m = m @ self._stage(entry, q, errors or {}, n, False)
        return m

    def tool_point(self, pos, errors=None, probe=(0.0, 0.0, 0.0)):
        """Actual tool point in the workpiece frame (N,3) mm; ``errors=None``: nominal."""
        m = self.tool_matrix(pos, errors)
        p = np.broadcast_to(np.asarray(probe, float), (len(m), 3))
        return np.einsum("nij,nj->ni", m[:, :3, :3], p) + m[:, :3, 3]

    def tool_axis(self, pos):
        """Nominal tool z axis in the workpiece frame (N,3)."""
        return self.tool_matrix(pos)[:, :3, 2]

    def work_orientation(self, pos):
        """Nominal orientation of the workpiece frame in the base frame (N,3,3)."""
        return np.transpose(self.work_matrix(pos)[:, :3, :3], (0, 2, 1))

    def inverse(self, targets, rotary=None, probe=(0.0, 0.0, 0.0), check_travel=True):
        """Linear axis positions putting the nominal tool point on ``targets`` (N,3, workpiece
        frame) at the given rotary positions (dict axis -> deg, scalars or (N,)).  The nominal
        chain is affine in X, Y, Z for fixed rotary positions: solved exactly."""
        t = np.atleast_2d(np.asarray(targets, float))
        n = len(t)
        rot = {a: np.broadcast_to(np.asarray((rotary or {}).get(a, 0.0), float), (n,))
               for a in self.rotary}
        lin = [a for a in self.axes if a not in self.rotary]
        base = {**rot, **{a: np.zeros(n) for a in lin}}
        b = self.tool_point(base, None, probe)
        A = np.empty((n, 3, 3))
        for j, a in enumerate(lin):
            unit = dict(base)
            unit[a] = np.ones(n)
            A[:, :, j] = self.tool_point(unit, None, probe) - b
        xyz = np.linalg.solve(A, (t - b)[..., None])[..., 0]
        pos = {**{a: xyz[:, j] for j, a in enumerate(lin)}, **{a: rot[a].copy() for a in rot}}
        for _ in range(2):   # refine the rounding of the affine solve
            xyz += np.linalg.solve(A, (t - self.tool_point(pos, None, probe))[..., None])[..., 0]
            pos.update({a: xyz[:, j] for j, a in enumerate(lin)})
        if check_travel:
            for a in self.axes:
                lo, hi = self.travel[a]
                bad = (pos[a] < lo) | (pos[a] > hi)
                if bad.any():
                    raise ValueError(f"{self.name}: axis {a} outside its travel [{lo}, {hi}]: "
                                     f"{pos[a][bad][:3]}")
        return pos


# ---- planted error model -----------------------------------------------------------------
def legendre(k: int, u):
    return np.polynomial.legendre.legval(u, [0.0] * k + [1.0])


@dataclass
class Term:
    """``param`` (JSON units) times ``basis(block)`` (mm or rad per unit) added to the ISO
    error ``target`` at every reading of a block."""

    param: str
    target: str
    basis: object


def _scale(target):
    return 1e-6 if is_angular(target) else 1e-3


def constant(name: str) -> Term:
    """A constant (squareness, location error): um or urad."""
    s = _scale(name)
    return Term(name, name, lambda b: np.full(b.n, s))


def series(comp: str, k: int, lo: float, hi: float) -> Term:
    """Term k of a component error's series over the measured range [lo, hi] of its axis:
    k = 0 ``@offset`` (um | urad), 1 ``@slope`` (per mm | deg: the slope of the line),
    k >= 2 ``@Pk`` (Legendre coefficient of P_k(u), u = (2 q - lo - hi) / (hi - lo))."""
    axis, s = comp[2], _scale(comp)
    mid, half = (lo + hi) / 2, (hi - lo) / 2
    if k == 0:
        return Term(f"{comp}@offset", comp, lambda b: np.full(b.n, s))
    if k == 1:
        return Term(f"{comp}@slope", comp, lambda b: s * (b.pos[axis] - mid))
    return Term(f"{comp}@P{k}", comp, lambda b: s * legendre(k, (b.pos[axis] - mid) / half))


def covariate_scale(comp: str, covariate: str = "T_C", ref: float = 20.0,
                    name: str | None = None) -> Term:
    """``comp += param * q_axis * (cov - ref)``: param in um/m/K (or urad/m/K) for a linear
    axis, e.g. the X scale growing with temperature."""
    axis, s = comp[2], _scale(comp) * 1e-3
    return Term(name or f"{comp}*{axis}*{covariate}", comp,
                lambda b: s * b.pos[axis] * (b.cov[covariate] - ref))


def covariate_constant(target: str, covariate: str = "T_C", ref: float = 20.0,
                       name: str | None = None) -> Term:
    """``target += param * (cov - ref)`` (um/K or urad/K), e.g. a location error drifting."""
    s = _scale(target)
    return Term(name or f"{target}*{covariate}", target,
                lambda b: s * (b.cov[covariate] - ref))


def reversal(comp: str, axis: str) -> Term:
    """``comp += param/2 * sign(velocity of axis)`` (um): a backlash of ``axis`` (needs the
    block's ``vel`` sign per axis)."""
    s = _scale(comp)
    return Term(f"{comp}@reversal", comp, lambda b: 0.5 * s * b.vel[axis])


def errors_at(block, terms, values) -> dict:
    """ISO name -> (N,) error values (mm / rad) of the planted model at a block's readings."""
    out: dict = {}
    for t in terms:
        v = values.get(t.param, 0.0)
        if v:
            out[t.target] = out.get(t.target, 0.0) + v * t.basis(block)
    return out


# ---- measurement blocks (one file each) ----------------------------------------------------
@dataclass
class Block:
    """Readings of one file.  ``pos`` axis -> (N,) mm | deg; ``probe`` (N,3) tool offset;
    ``placement`` (N,) labels; ``cov`` covariate columns; ``u_um`` standard uncertainty."""

    kind: str
    name: str
    pos: dict
    probe: np.ndarray
    placement: np.ndarray
    u_um: float
    cov: dict = field(default_factory=dict)
    vel: dict = field(default_factory=dict)
    pivot: np.ndarray | None = None        # ballbar (N,3) nominal pivot, workpiece frame
    length: np.ndarray | None = None       # ballbar (N,) nominal bar length mm
    direction: np.ndarray | None = None    # ballbar (N,) +1 CCW / -1 CW
    plane: np.ndarray | None = None        # ballbar (N,) plane names (informative)
    centre: np.ndarray | None = None       # sphere (N,3) nominal centre, workpiece frame
    frame: np.ndarray | None = None        # sphere (N,) "work" | "machine"

    @property
    def n(self) -> int:
        return len(self.probe)

    @property
    def rows_per_reading(self) -> int:
        return 1 if self.kind == "ballbar" else 3

    def setup_names(self) -> list[str]:
        labels = list(dict.fromkeys(self.placement.tolist()))
        keys = {"ballbar": ("pivot_dx", "pivot_dy", "pivot_dz", "length"),
                "sphere": ("centre_dx", "centre_dy", "centre_dz")}.get(self.kind, ())
        out = [f"{self.name}#{p}:{k}" for p in labels for k in keys]
        if self.kind == "sphere":
            out.append(f"{self.name}:tool_dz")
        if self.kind == "deviations":
            out += [f"{self.name}:{k}" for k in DEVIATION_SETUP]
        return out

    def subset(self, idx):
        idx = np.asarray(idx)
        pick = lambda v: None if v is None else np.asarray(v)[idx]  # noqa: E731
        return Block(self.kind, self.name, {a: v[idx] for a, v in self.pos.items()},
                     self.probe[idx], self.placement[idx], self.u_um,
                     {c: v[idx] for c, v in self.cov.items()},
                     {a: v[idx] for a, v in self.vel.items()},
                     pick(self.pivot), pick(self.length), pick(self.direction),
                     pick(self.plane), pick(self.centre), pick(self.frame))


def concat(blocks, name=None) -> Block:
    """Readings of several blocks of one kind as one block (one file)."""
    b0 = blocks[0]
    cat = lambda attr: None if getattr(b0, attr) is None else np.concatenate(  # noqa: E731
        [getattr(b, attr) for b in blocks])
    return Block(b0.kind, name or b0.name,
                 {a: np.concatenate([b.pos[a] for b in blocks]) for a in b0.pos},
                 np.concatenate([b.probe for b in blocks]),
                 np.concatenate([b.placement for b in blocks]), b0.u_um,
                 {c: np.concatenate([b.cov[c] for b in blocks]) for c in b0.cov},
                 {a: np.concatenate([b.vel[a] for b in blocks]) for a in b0.vel},
                 cat("pivot"), cat("length"), cat("direction"), cat("plane"), cat("centre"),
                 cat("frame"))


def _velocity_signs(machine, pos):
    """Sign of each axis' velocity along a trace (closed loop, central differences)."""
    out = {}
    for a in machine.axes:
        v = np.asarray(pos[a], float)
        d = np.roll(v, -1) - np.roll(v, 1)
        out[a] = np.sign(d)
    return out


def ballbar_circle(machine: Machine, name: str, plane: str, pivot, radius: float, n: int,
                   direction: int = 1, placement: str = "P1", rotary=None, probe=(0, 0, 0),
                   start_deg: float = 0.0, u_um: float = 0.5, cov=None) -> Block:
    """A circle of the tool-ball centre about ``pivot`` (workpiece frame) in ``plane``:
    angle theta measured from the first in-plane axis towards the second (XY: x to y; YZ:
    y to z; ZX: z to x), ``direction`` +1 CCW (theta increasing) / -1 CW, rotary axes fixed
    at ``rotary`` (deg)."""
    i1, i2 = PLANES[plane]
    th = np.deg2rad(start_deg) + direction * 2 * np.pi * np.arange(n) / n
    p = np.asarray(pivot, float)
    t = np.tile(p, (n, 1))
    t[:, i1] += radius * np.cos(th)
    t[:, i2] += radius * np.sin(th)
    probe = np.tile(np.asarray(probe, float), (n, 1))
    pos = machine.inverse(t, rotary, probe)
    return Block("ballbar", name, pos, probe, np.full(n, placement, dtype=object), u_um,
                 {k: np.broadcast_to(np.asarray(v, float), (n,)).copy()
                  for k, v in (cov or {}).items()},
                 _velocity_signs(machine, pos), np.tile(p, (n, 1)),
                 np.full(n, float(radius)), np.full(n, direction), np.full(n, plane, dtype=object))


def ballbar_sweep(machine: Machine, name: str, axis: str, start: float, stop: float, n: int,
                  pivot, bar, placement: str = "P1", rotary=None, probe=(0, 0, 0),
                  u_um: float = 0.5, cov=None) -> Block:
    """ISO 10791-6 style: the rotary ``axis`` sweeps from ``start`` to ``stop`` deg (n readings,
    direction +1 when stop > start) with the pivot fixed on the table and the tool ball
    following a point fixed relative to the table: ``pivot + bar`` (workpiece frame; the
    length is |bar|)."""
    ang = np.linspace(start, stop, n)
    p = np.asarray(pivot, float)
    t = np.tile(p + np.asarray(bar, float), (n, 1))
    rot = dict(rotary or {})
    rot[axis] = ang
    probe = np.tile(np.asarray(probe, float), (n, 1))
    pos = machine.inverse(t, rot, probe)
    direction = 1 if stop > start else -1
    return Block("ballbar", name, pos, probe, np.full(n, placement, dtype=object), u_um,
                 {k: np.broadcast_to(np.asarray(v, float), (n,)).copy()
                  for k, v in (cov or {}).items()},
                 _velocity_signs(machine, pos), np.tile(p, (n, 1)),
                 np.full(n, float(np.linalg.norm(bar))), np.full(n, direction),
                 np.full(n, "sweep", dtype=object))


def deviations_block(machine: Machine, name: str, n: int, rng, probes=((0, 0, 0),),
                     rotary_choices=None, u_um: float = 0.5, cov=None) -> Block:
    """3-D deviations (CMM against a reference, tracker): random positions inside the travel
    (rotary axes at random among ``rotary_choices`` when given), tool offsets at random among
    ``probes``."""
    pos = {a: rng.uniform(*machine.travel[a], n) for a in machine.axes}
    for a in machine.rotary:
        if rotary_choices and a in rotary_choices:
            pos[a] = rng.choice(np.asarray(rotary_choices[a], float), n)
    probe = np.asarray(probes, float)[rng.integers(0, len(probes), n)]
    return Block("deviations", name, pos, probe, np.full(n, "P1", dtype=object), u_um,
                 {k: np.asarray(v, float) for k, v in (cov or {}).items()})


def sphere_block(machine: Machine, name: str, centres: dict, rotary_grid, probe=(0, 0, 0),
                 frame: str = "work", u_um: float = 1.0, cov=None) -> Block:
    """Touch probe / R-test: for each placement label -> nominal centre (workpiece frame), the
    tool point sent to it at every rotary pose of ``rotary_grid`` (list of dicts axis -> deg).
    ``cov``: covariate name -> function(placement index, pose index) -> value."""
    pos_rows, cen, lab, covs = [], [], [], {k: [] for k in (cov or {})}
    for pi, (label, c) in enumerate(centres.items()):
        for gi, pose in enumerate(rotary_grid):
            pos_rows.append(pose)
            cen.append(c)
            lab.append(label)
            for k, f in (cov or {}).items():
                covs[k].append(f(pi, gi))
    n = len(cen)
    cen = np.asarray(cen, float)
    rot = {a: np.array([r.get(a, 0.0) for r in pos_rows], float) for a in machine.rotary}
    probe = np.tile(np.asarray(probe, float), (n, 1))
    pos = machine.inverse(cen, rot, probe)
    return Block("sphere", name, pos, probe, np.asarray(lab, dtype=object), u_um,
                 {k: np.asarray(v, float) for k, v in covs.items()}, {}, centre=cen,
                 frame=np.full(n, frame, dtype=object))


# ---- readings ------------------------------------------------------------------------------
def readings(machine: Machine, block: Block, terms, values, setup=None,
             tool=None) -> np.ndarray:
    """Exact readings in um: (N,) ballbar; (N,3) sphere and deviations.  ``tool``: the actual
    tool point when already computed (ballbar; sphere without a tool-length change)."""
    setup = setup or {}
    err = errors_at(block, terms, values)
    n = block.n
    if block.kind == "ballbar":
        t = machine.tool_point(block.pos, err, block.probe) if tool is None else tool
        dp = np.zeros((n, 3))
        dl = np.zeros(n)
        for p in np.unique(block.placement):
            m = block.placement == p
            key = f"{block.name}#{p}:"
            dp[m] = [setup.get(key + k, 0.0) * 1e-3 for k in ("pivot_dx", "pivot_dy", "pivot_dz")]
            dl[m] = setup.get(key + "length", 0.0) * 1e-3
        return 1e3 * (np.linalg.norm(t - block.pivot - dp, axis=1) - block.length + dl)
    if block.kind == "sphere":
        dz = setup.get(f"{block.name}:tool_dz", 0.0)
        probe = block.probe + np.array([0, 0, 1.0]) * dz * 1e-3
        t = machine.tool_point(block.pos, err, probe) if tool is None or dz else tool
        dc = np.zeros((n, 3))
        for p in np.unique(block.placement):
            m = block.placement == p
            key = f"{block.name}#{p}:"
            dc[m] = [setup.get(key + k, 0.0) * 1e-3
                     for k in ("centre_dx", "centre_dy", "centre_dz")]
        v = t - block.centre - dc
        mach = block.frame == "machine"
        if mach.any():
            R = machine.work_orientation(block.subset(np.flatnonzero(mach)).pos)
            v[mach] = np.einsum("nij,nj->ni", R, v[mach])
        return 1e3 * v
    if block.kind == "deviations":
        # the instrument's rigid placement (per file): measured = R(e) t_act + d
        d = np.array([setup.get(f"{block.name}:{k}", 0.0) for k in DEVIATION_SETUP[:3]]) * 1e-3
        e = np.array([setup.get(f"{block.name}:{k}", 0.0) for k in DEVIATION_SETUP[3:]]) * 1e-6
        t = machine.tool_point(block.pos, err, block.probe) if tool is None else tool
        meas = Rotation.from_rotvec(e).apply(t) + d
        return 1e3 * (meas - machine.tool_point(block.pos, None, block.probe))
    raise ValueError(block.kind)


def simulate(machine, block, terms, values, setup=None, rng=None, noise_um=None):
    """Readings (um) with Gaussian noise of standard deviation ``noise_um`` (default
    ``block.u_um``); returns (readings, noise)."""
    exact = readings(machine, block, terms, values, setup)
    s = block.u_um if noise_um is None else noise_um
    noise = (rng or np.random.default_rng(0)).normal(0.0, s, exact.shape)
    return exact + noise, noise


# ---- design, fit, identifiability ----------------------------------------------------------
@dataclass
class Design:
    """Stacked first-order design by central differences of the exact simulator about zero
    errors and zero set-ups.  ``rows``: (block index, data row) of every scalar row."""

    J: np.ndarray
    columns: list
    n_params: int
    rows: np.ndarray            # (m, 2) block index, data row
    weights: np.ndarray         # (m,) 1/u

    @property
    def params(self):
        return self.columns[: self.n_params]


def _steps(blocks, terms, params):
    """Finite-difference step per parameter: the largest error it causes over the readings is
    1 um (translational) or 1 urad (angular): central differences are then exact to ~1e-10
    relative (third-order terms and rounding)."""
    out = {}
    for p in params:
        big = max((float(np.max(np.abs(t.basis(b)))) / (1e-3 if not is_angular(t.target)
                                                           else 1e-6)
                   for t in terms if t.param == p for b in blocks), default=0.0)
        out[p] = 1.0 / big if big > 0 else 1.0
    return out


def design(machine, blocks, terms, step=1.0) -> Design:
    """``step``: of the set-up unknowns (um); parameters get :func:`_steps`."""
    params = list(dict.fromkeys(t.param for t in terms))
    hs = _steps(blocks, terms, params)
    setups = [s for b in blocks for s in b.setup_names()]
    cols = params + setups
    parts, rows, w = [], [], []
    for bi, b in enumerate(blocks):
        k = b.rows_per_reading
        m = b.n * k
        Jb = np.zeros((m, len(cols)))
        for j, p in enumerate(params):
            plus = readings(machine, b, terms, {p: hs[p]})
            minus = readings(machine, b, terms, {p: -hs[p]})
            Jb[:, j] = ((plus - minus) / (2 * hs[p])).ravel()
        mine = set(b.setup_names())
        t0 = machine.tool_point(b.pos, None, b.probe)
        for j, s in enumerate(setups):
            if s in mine:
                plus = readings(machine, b, terms, {}, {s: step}, tool=t0)
                minus = readings(machine, b, terms, {}, {s: -step}, tool=t0)
                Jb[:, len(params) + j] = ((plus - minus) / (2 * step)).ravel()
        parts.append(Jb)
        rows.append(np.stack([np.full(m, bi), np.repeat(np.arange(b.n), k)], -1))
        w.append(np.full(m, 1.0 / b.u_um))
    return Design(np.vstack(parts), cols, len(params), np.vstack(rows), np.concatenate(w))


def wls(d: Design, y: np.ndarray, mask=None):
    """Weighted least squares on the rows ``mask``: (estimate, covariance, residual of all
    rows).  The covariance is (J'WJ)^-1 (weights 1/u^2, u as declared)."""
    mask = np.ones(len(y), bool) if mask is None else mask
    A = d.J[mask] * d.weights[mask, None]
    theta, *_ = np.linalg.lstsq(A, y[mask] * d.weights[mask], rcond=None)
    cov = np.linalg.pinv(A.T @ A)
    return theta, cov, y - d.J @ theta


def identifiability(d: Design, tol: float = 1e-5, names=None):
    """Per parameter column (or per column of ``names``): relative norm of its part outside
    the span of all other columns (set-ups included); identifiable iff > tol.  Returns
    (dict name -> bool, dict name -> relative residual)."""
    A = d.J * d.weights[:, None]
    A = A / np.maximum(np.linalg.norm(A, axis=0), 1e-300)
    if A.shape[0] > A.shape[1]:
        # A = Q R, Q with orthonormal columns: the columns of R have the same linear
        # relations and residual norms as those of A (and R is small)
        A = np.linalg.qr(A, mode="r")
    rel, ok = {}, {}
    for name in (d.params if names is None else names):
        j = d.columns.index(name)
        others = np.delete(A, j, axis=1)
        coef, *_ = np.linalg.lstsq(others, A[:, j], rcond=None)
        r = float(np.linalg.norm(A[:, j] - others @ coef))
        if not np.isfinite(r) or np.linalg.norm(d.J[:, j]) == 0:
            r = 0.0
        rel[name] = r
        ok[name] = r > tol
    return ok, rel


def seen_by(d: Design, blocks, tol: float = 1e-5) -> dict:
    """Parameter -> names of the files whose rows depend on it once that file's own set-up
    columns are projected out (relative residual > tol)."""
    out = {p: [] for p in d.params}
    for bi, b in enumerate(blocks):
        m = d.rows[:, 0] == bi
        own = [d.columns.index(s) for s in b.setup_names()]
        S = d.J[m][:, own] * d.weights[m, None]
        for j, p in enumerate(d.params):
            a = d.J[m, j] * d.weights[m]
            na = np.linalg.norm(a)
            if na == 0:
                continue
            if S.shape[1]:
                coef, *_ = np.linalg.lstsq(S, a, rcond=None)
                a = a - S @ coef
            ref = np.linalg.norm(d.J[:, j] * d.weights)
            if np.linalg.norm(a) > tol * ref:
                out[p].append(b.name)
    return out


# ---- files ---------------------------------------------------------------------------------
def _fmt(v) -> str:
    if isinstance(v, str):
        return v
    return repr(float(v))


def columns(machine: Machine, block: Block, values_um: np.ndarray, covariates=True,
            u_column=True) -> dict:
    """CSV columns of a block in the documented format (contract of issue 19)."""
    cols = {a: block.pos[a] for a in machine.axes}
    cols.update({"Xp": block.probe[:, 0], "Yp": block.probe[:, 1], "Zp": block.probe[:, 2]})
    if block.kind == "ballbar":
        cols.update({"pivot_x": block.pivot[:, 0], "pivot_y": block.pivot[:, 1],
                     "pivot_z": block.pivot[:, 2], "length_mm": block.length,
                     "dr_um": values_um, "direction": block.direction.astype(int),
                     "placement": block.placement})
    elif block.kind == "sphere":
        cols.update({"sphere_x": block.centre[:, 0], "sphere_y": block.centre[:, 1],
                     "sphere_z": block.centre[:, 2], "dx_um": values_um[:, 0],
                     "dy_um": values_um[:, 1], "dz_um": values_um[:, 2],
                     "placement": block.placement, "frame": block.frame})
    else:
        cols.update({"dx_um": values_um[:, 0], "dy_um": values_um[:, 1],
                     "dz_um": values_um[:, 2]})
    if u_column and block.kind != "deviations":
        cols["u_um"] = np.full(block.n, block.u_um)
    if covariates:
        cols.update(block.cov)
    return cols


def write_csv(path, cols: dict) -> str:
    names = list(cols)
    n = len(next(iter(cols.values())))
    lines = [",".join(names)]
    for i in range(n):
        lines.append(",".join(_fmt(cols[c][i]) if not isinstance(cols[c][i], (int, np.integer))
                              else str(int(cols[c][i])) for c in names))
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return str(path)


# ---- ISO 230-4 evaluation (independent, from a trace's columns) ----------------------------
def ls_circle(pts: np.ndarray):
    """Geometric least-squares circle (minimises sum (|p_i - c| - rho)^2) of 2-D points:
    algebraic (Kasa) start, then Gauss-Newton to convergence.  Returns (centre, rho)."""
    ctr0 = pts.mean(axis=0)
    q = pts - ctr0
    A = np.column_stack([2 * q, np.ones(len(q))])
    sol, *_ = np.linalg.lstsq(A, (q ** 2).sum(1), rcond=None)
    c = sol[:2]
    for _ in range(100):
        d = q - c
        r = np.linalg.norm(d, axis=1)
        rho = r.mean()
        J = np.column_stack([-d / r[:, None], -np.ones(len(q))])
        step, *_ = np.linalg.lstsq(J, -(r - rho), rcond=None)
        c = c + step[:2]
        if np.max(np.abs(step[:2])) < 1e-16 * (1 + np.abs(c).max()):
            break
    d = q - c
    return ctr0 + c, float(np.linalg.norm(d, axis=1).mean())


def trace_angles(plane: str, t: np.ndarray, pivot: np.ndarray) -> np.ndarray:
    i1, i2 = PLANES[plane]
    return np.arctan2(t[:, i2] - pivot[:, i2], t[:, i1] - pivot[:, i1])


def evaluate_trace(theta, dr_um, length_mm):
    """G, F_max, F_min, centre offset (um) of one trace, the contract's definitions."""
    r = length_mm + dr_um / 1000.0
    pts = r[:, None] * np.column_stack([np.cos(theta), np.sin(theta)])   # p_i - pivot
    c, _ = ls_circle(pts)
    dist = np.linalg.norm(pts - c, axis=1)
    return {"G_um": 1e3 * (dist.max() - dist.min()), "F_max_um": float(dr_um.max()),
            "F_min_um": float(dr_um.min()), "centre_offset_um": (1e3 * c).tolist()}


def hysteresis(theta_ccw, dr_ccw, theta_cw, dr_cw) -> float:
    """max over the CCW readings of |dr_ccw - dr_cw(theta)|, dr_cw interpolated linearly and
    periodically in theta at the CCW angles (um)."""
    tw = np.mod(theta_cw, 2 * np.pi)
    o = np.argsort(tw)
    interp = np.interp(np.mod(theta_ccw, 2 * np.pi), tw[o], dr_cw[o], period=2 * np.pi)
    return float(np.max(np.abs(dr_ccw - interp)))
