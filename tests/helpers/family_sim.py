"""Campaigns of every shipped layout family for the closing loop's acceptance tests (issue 21),
made with the exact chain of ``tests/helpers/instrument_sim.py`` (independent of the runtime: it
parses the layout file and never calls generated code or volerr's model, loop or instrument
code).

What this adds to the instrument simulator: effects on the *nominal symbols* of a chain, planted
in the simulator's own way --

* a layout parameter (``d``, ``h``, ``L``) that changes from reading to reading: the rotary axis
  points and frame translations are evaluated per reading with the changed value (the exact
  chain moves the axis, nothing is linearised);
* a stylus / tool that grows: the actual offset of every reading is its nominal offset scaled
  by ``1 + k (T - 20)``, while the reading is referred to the nominal offset (what the
  controller or the CMM software believes).

Static errors are polynomials of low degree (constants, slopes, P2 terms of the
instrument simulator) so that the loop's declared model holds the truth and the floor -- the
held-out RMS of the true model (its planted parameters and every set-up unknown) fitted by
weighted least squares on the loop's own split -- is what a perfect model reaches.  Columns
of the true model are central differences of the exact readings.

Units: as ``instrument_sim`` (positions mm / deg, readings um, planted values um, urad,
um/mm ...; growth of a length in ppm per basis unit; a parameter change in um per basis unit).
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from helpers import instrument_sim as S


@dataclass
class Growth:
    """A nominal symbol changed by ``param * basis(block)`` at every reading: ``symbol``
    ``"probe.length"`` (the offset vector scaled, param in ppm per basis unit) or
    ``"param.<p>"`` (a layout parameter, param in um per basis unit)."""

    param: str
    symbol: str
    basis: object


class Machine(S.Machine):
    """The instrument simulator's exact chain, with layout parameters per reading."""

    @contextmanager
    def parameters(self, values: dict, n: int):
        """Rotary axis points and frames evaluated with ``values`` (name -> (n,) mm) in
        place of the layout's parameters while inside the block."""
        saved_points, saved_frames = dict(self._points), dict(self._frames)
        env = {**{k: np.full(n, float(v)) for k, v in self.layout.parameters.items()}, **values}

        def ev(c):
            return np.broadcast_to(np.asarray(eval(str(c), {}, env), float), (n,))  # noqa: S307

        try:
            for a in self.rotary:
                self._points[a] = np.stack([ev(c) for c in self.layout.axes[a].point], -1)
            for name, f in self.layout.frames.items():
                t = np.stack([ev(c) for c in f.translation], -1)
                ax = np.asarray(f.rotation_axis, float)
                ang = np.deg2rad(ev(f.angle_deg))
                m = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
                m[:, :3, :3] = Rotation.from_rotvec(ax[None] / np.linalg.norm(ax)
                                                    * ang[:, None]).as_matrix()
                m[:, :3, 3] = t
                self._frames[name] = m
            yield self
        finally:
            self._points, self._frames = saved_points, saved_frames


def readings(machine: Machine, block: S.Block, terms, values, setup=None,
             nominal=None) -> np.ndarray:
    """Exact readings (um) of a ``deviations`` or ``sphere`` block: (N, 3).  ``terms``: the
    instrument simulator's error terms and :class:`Growth` terms; ``nominal``: the block's
    nominal tool points (mm) when the caller already has them (:func:`design`)."""
    setup = setup or {}
    n = block.n
    err = S.errors_at(block, [t for t in terms if isinstance(t, S.Term)], values)
    scale = np.zeros(n)
    params = {}
    for t in terms:
        v = values.get(t.param, 0.0) if isinstance(t, Growth) else 0.0
        if not v:
            continue
        if t.symbol == "probe.length":
            scale = scale + v * 1e-6 * t.basis(block)
        else:
            p = t.symbol.split(".", 1)[1]
            base = params.get(p, np.full(n, float(machine.layout.parameters[p])))
            params[p] = base + v * 1e-3 * t.basis(block)
    probe = block.probe * (1.0 + scale)[:, None]
    if block.kind == "sphere":
        probe = probe + np.array([0.0, 0.0, 1e-3 * setup.get(f"{block.name}:tool_dz", 0.0)])
    with machine.parameters(params, n):
        t_act = machine.tool_point(block.pos, err, probe)
    if block.kind == "deviations":
        d = np.array([setup.get(f"{block.name}:{k}", 0.0) for k in S.DEVIATION_SETUP[:3]])
        e = np.array([setup.get(f"{block.name}:{k}", 0.0) for k in S.DEVIATION_SETUP[3:]])
        meas = Rotation.from_rotvec(1e-6 * e).apply(t_act) + 1e-3 * d
        if nominal is None:
            nominal = machine.tool_point(block.pos, None, block.probe)
        return 1e3 * (meas - nominal)
    if block.kind == "sphere":
        dc = np.zeros((n, 3))
        for p in np.unique(block.placement):
            m = block.placement == p
            dc[m] = [1e-3 * setup.get(f"{block.name}#{p}:{k}", 0.0)
                     for k in ("centre_dx", "centre_dy", "centre_dz")]
        return 1e3 * (t_act - block.centre - dc)
    raise ValueError(block.kind)


def design(machine: Machine, blocks, terms) -> S.Design:
    """True-model design: central differences of :func:`readings` with respect to every
    parameter of ``terms`` and every set-up unknown of the blocks, each step chosen so that it
    changes the readings by at most 1 um (the readings are linear in them to well below the
    noise: the planted errors are small)."""
    params = list(dict.fromkeys(t.param for t in terms))
    setups = [s for b in blocks for s in b.setup_names()]
    cols = params + setups
    parts, rows, w = [], [], []
    for bi, b in enumerate(blocks):
        m = b.n * 3
        J = np.zeros((m, len(cols)))
        mine = set(b.setup_names())
        # the unperturbed readings: the same for every column (a zero value or set-up is
        # skipped exactly like a missing one), computed once per block
        nom = machine.tool_point(b.pos, None, b.probe) if b.kind == "deviations" else None
        f0 = readings(machine, b, terms, {}, None, nom)
        for j, c in enumerate(cols):
            if j >= len(params) and c not in mine:
                continue

            def f(h, c=c, j=j):
                if j < len(params):
                    return readings(machine, b, terms, {c: h}, None, nom)
                return readings(machine, b, terms, {}, {c: h}, nom)

            big = np.max(np.abs(f(1.0) - f0))
            h = 1.0 / big if big > 0 else 1.0
            J[:, j] = ((f(h) - f(-h)) / (2 * h)).ravel()
        parts.append(J)
        rows.append(np.stack([np.full(m, bi), np.repeat(np.arange(b.n), 3)], -1))
        w.append(np.full(m, 1.0 / b.u_um))
    return S.Design(np.vstack(parts), cols, len(params), np.vstack(rows), np.concatenate(w))


class Campaign:
    """Simulated files: blocks, terms, planted values and set-ups, noisy readings (um)."""

    def __init__(self, machine, blocks, terms, values, setup, seed):
        self.machine, self.blocks, self.terms = machine, blocks, terms
        self.values, self.setup = values, setup
        rng = np.random.default_rng(seed)
        self.y = []
        for b in blocks:
            exact = readings(machine, b, terms, values, setup)
            self.y.append(exact + rng.normal(0.0, b.u_um, exact.shape))

    def write(self, folder) -> list:
        out = []
        for b, y in zip(self.blocks, self.y):
            out.append(S.write_csv(folder / b.name, S.columns(self.machine, b, y)))
        return out

    def floor(self, test_rows: dict) -> dict:
        """Held-out RMS per file (um, length of each point's residual vector) of the true model
        (the planted nonzero parameters and every set-up unknown) fitted by weighted least
        squares on the other rows; ``test_rows``: file name -> held-out data rows."""
        planted = [t for t in self.terms if self.values.get(t.param, 0.0)]
        d = design(self.machine, self.blocks, planted)
        y = np.concatenate([np.ravel(v) for v in self.y])
        test = np.zeros(len(y), bool)
        for bi, b in enumerate(self.blocks):
            test |= (d.rows[:, 0] == bi) & np.isin(d.rows[:, 1], test_rows[b.name])
        _, _, res = S.wls(d, y, ~test)
        out = {}
        for bi, b in enumerate(self.blocks):
            r = res[test & (d.rows[:, 0] == bi)].reshape(-1, 3)
            out[b.name] = float(np.sqrt(np.mean(np.sum(r ** 2, axis=1))))
        return out


def placement(rng, blocks, trans_um=20.0, rot_urad=15.0, centre_um=40.0, tool_um=10.0) -> dict:
    """Planted set-up unknowns of every block (um, urad)."""
    out = {}
    for b in blocks:
        for s in b.setup_names():
            key = s.split(":")[-1]
            size = (tool_um if key == "tool_dz" else centre_um if key.startswith("centre")
                    else rot_urad if key[0] == "e" else trans_um)
            out[s] = float(rng.normal(0.0, size))
    return out


def channels(t_h: np.ndarray, rng, names) -> dict:
    """Temperature channels (degC) over the time ``t_h`` (h): a room that cycles and parts that
    warm up with their own time constants (not functions of each other)."""
    out = {}
    def warm_stop(t):           # warms up, then the machine stops and it cools down
        on = 4.5 * (1 - np.exp(-t / 1.1))
        off = np.where(t > 3.4, 1 - np.exp(-np.clip(t - 3.4, 0, None) / 0.7), 0.0)
        return 20.3 + on - 3.5 * off

    shapes = {"T_C": lambda t: 20.6 + 1.2 * np.sin(2 * np.pi * t / 5.3 + 0.4),
              0: warm_stop,
              1: lambda t: 20.8 + 2.0 * np.sin(2 * np.pi * t / 3.7 + 2.1) + 0.5 * t / 6,
              2: lambda t: 21.0 + 1.5 * np.sin(2 * np.pi * t / 2.3 + 0.3)
              + (1 - np.exp(-t / 2.0))}
    k = 0
    for name in names:
        f = shapes["T_C"] if name == "T_C" else shapes[k]
        k += name != "T_C"
        out[name] = f(t_h) + rng.normal(0.0, 0.02, len(t_h))
    return out


def legendre_term(comp: str, k: int, lo: float, hi: float, name=None) -> S.Term:
    """``comp += param * P_k(u)`` over [lo, hi] of its axis (um | urad)."""
    t = S.series(comp, k, lo, hi)
    return S.Term(name or t.param, t.target, t.basis)


def coupling(comp: str, on: str, travel: dict, name: str) -> S.Term:
    """``comp += param * u_own * u_on`` (u: positions normalised to [-1, 1] over the travel):
    a component error that depends on another axis' position (um | urad)."""
    own = comp[2]
    s = 1e-6 if S.is_angular(comp) else 1e-3

    def u(b, a):
        lo, hi = travel[a]
        return (2 * b.pos[a] - lo - hi) / (hi - lo)

    return S.Term(name, comp, lambda b: s * u(b, own) * u(b, on))


def scale(comp: str, covariate: str, name: str, fixed_point: float = 0.0) -> S.Term:
    """``comp += param * (q - fixed_point) * (cov - 20)``, param in um/m/K: a scale growing
    with a temperature about a fixed point of the axis."""
    axis = comp[2]
    return S.Term(name, comp, lambda b: 1e-6 * (b.pos[axis] - fixed_point)
                  * (b.cov[covariate] - 20.0))


def drift(target: str, covariate: str, name: str) -> S.Term:
    """``target += param * (cov - 20)``, um/K or urad/K."""
    return S.covariate_constant(target, covariate, 20.0, name=name)
