"""Executes a measurement plan of ``volerr plan`` on an exact simulator, for the acceptance tests
of issue 29, independent of the runtime (never reads or calls ``volerr.plan`` nor volerr's
observation models: numpy / scipy, the parsed layout and the exact chain of
:class:`helpers.instrument_sim.Machine`).

A plan folder holds instrument files in their documented formats (docs/formats.md sections
ballbar, sphere, distances) whose reading columns are present and EMPTY.  This module

* reads such a file, keeping every line that is not a data row as it is (``# key: value``
  header lines, the column row) and the cells of the data rows as text;
* fills the reading columns with EXACT readings of a planted machine (the named parameters,
  :func:`planted_terms`), planted set-up errors and Gaussian noise of the file's declared
  ``u_um``:

  - ballbar ``dr_um = 1e3 (|t_act - (p + dp)| - L) + dL``: ``t_act`` the actual tool-ball
    centre (exact chain with the planted errors, offset ``Xp,Yp,Zp``), ``p`` the nominal pivot,
    ``dp`` the pivot's set-up offset and ``dL`` the bar's length error (um) of the placement;
  - sphere ``d = R (t_act - c - dc)`` (um), the tool offset lengthened by the file's tool-length
    error ``tool_dz`` along the tool's own z axis, ``dc`` the centre offset of the placement,
    ``R`` identity (frame ``work``) or the nominal orientation of the workpiece frame in the
    base frame (frame ``machine``);
  - distances ``d_mm = |t_act - (s + ds)| + dd``: ``s`` the planned station position
    (``station_x,station_y,station_z``), ``ds`` its set-up offset and ``dd`` the dead path of
    the station; ``dd_mm`` files: minus the station's first true distance;

* parses an NC program back (:func:`nc_blocks`): ``G0 G1 G2 G3`` modal motion, ``G90/G91``,
  ``G20/G21``, ``G4`` dwell, comments ``( )`` and ``;``, block numbers, ``%`` and ``O`` lines.
"""

from __future__ import annotations

import csv
import io
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from helpers import instrument_sim as S

#: the reading columns each kind's plan file carries empty (the contract)
READING_COLUMNS = {"ballbar": ("dr_um",), "sphere": ("dx_um", "dy_um", "dz_um"),
                   "distances": ("d_mm",)}
#: instruments that read at a stop (the NC program dwells after the block)
READS_AT_A_STOP = ("sphere", "distances", "interferometer", "artifact")


# ---- plan files ----------------------------------------------------------------------------
@dataclass
class PlanFile:
    """One plan file: every line as written, the index of the column row, the data rows'
    line indices and cells (text), and the ``# key: value`` header lines."""

    path: Path
    kind: str
    lines: list
    column_line: int
    columns: list
    data_lines: list
    cells: list
    meta: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        return len(self.cells)

    def has(self, name) -> bool:
        return name in self.columns

    def text(self, name) -> list:
        j = self.columns.index(name)
        return [r[j].strip() for r in self.cells]

    def number(self, name, default=None) -> np.ndarray:
        """A numeric column; else the header line ``# name: value``; else ``default``."""
        if self.has(name):
            return np.array([float(v) for v in self.text(name)])
        if name.lower() in self.meta:
            return np.full(self.n, self.meta_number(name))
        if default is None:
            raise KeyError(f"{self.path.name}: no column or header {name!r}")
        return np.full(self.n, float(default))

    def meta_number(self, name) -> float:
        """The number a header line ``# name: value [remark]`` declares."""
        m = re.match(r"\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)", self.meta[name.lower()])
        assert m, (self.path.name, name, self.meta[name.lower()])
        return float(m.group(1))

    def declared(self, name):
        """The value of ``name`` declared as a column (one value for all rows) or a header
        line; None when not declared."""
        if self.has(name):
            vals = {v for v in self.text(name) if v}
            if not vals:
                return None
            assert len(vals) == 1, (self.path.name, name, sorted(vals)[:5])
            return float(vals.pop())
        if name.lower() in self.meta:
            return self.meta_number(name)
        return None

    def positions(self, axes) -> dict:
        return {a: self.number(a) for a in axes}

    def probe(self) -> np.ndarray:
        return np.column_stack([self.number(c, 0.0) for c in ("Xp", "Yp", "Zp")])

    def labels(self, name) -> np.ndarray:
        return np.array(self.text(name), dtype=object)

    def write_filled(self, path: Path, values: dict, fmt="{:.6f}") -> Path:
        """This file with the reading columns ``values`` (name -> (N,) numbers) filled."""
        lines = list(self.lines)
        idx = {c: self.columns.index(c) for c in values}
        for i, (li, row) in enumerate(zip(self.data_lines, self.cells)):
            row = list(row)
            for c, j in idx.items():
                row[j] = fmt.format(float(values[c][i]))
            buf = io.StringIO()
            csv.writer(buf, lineterminator="").writerow(row)
            lines[li] = buf.getvalue()
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("\n".join(lines) + "\n")
        return path


_META = re.compile(r"^#\s*([A-Za-z_][\w]*)\s*:\s*(.*?)\s*$")


def read_plan_file(path, kind: str) -> PlanFile:
    """Read a plan file: ``#`` lines are header / comment lines (``# key: value`` kept in
    ``meta``, keys lower case), the first other non-empty line the column row."""
    path = Path(path)
    lines = path.read_text().splitlines()
    meta, column_line, data_lines, cells = {}, None, [], []
    for i, line in enumerate(lines):
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            m = _META.match(s)
            if m:
                meta[m.group(1).lower()] = m.group(2)
            continue
        row = next(csv.reader([line]))
        if column_line is None:
            column_line, columns = i, [c.strip() for c in row]
        else:
            data_lines.append(i)
            cells.append(row)
    assert column_line is not None, f"{path}: no column row"
    for r in cells:
        assert len(r) == len(columns), (path.name, r)
    return PlanFile(path, kind, lines, column_line, columns, data_lines, cells, meta)


# ---- planted parameters --------------------------------------------------------------------
@dataclass
class View:
    """What a planted term needs: positions (mm / deg), the sign of each axis' motion that
    brought it to the reading (+1 / -1; for reversals) and their number."""

    pos: dict
    vel: dict = field(default_factory=dict)

    @property
    def n(self):
        return len(next(iter(self.pos.values())))


def along(machine: S.Machine, axis: str) -> str:
    """The positioning error of a linear axis (``EXX`` for X along x)."""
    d = np.abs(np.asarray(machine.layout.axes[axis].direction, float))
    return f"E{'XYZ'[int(np.argmax(d))]}{axis}"


def known_to_machine(machine: S.Machine, name: str) -> bool:
    """The ISO name (before ``@``) is an error the exact chain models for this layout (or
    ``RV_<axis>``, the reversal of a linear axis)."""
    lay = machine.layout
    if name.startswith("RV_"):
        return name[3:] in machine.axes and name[3:] not in machine.rotary
    base = name.split("@")[0]
    if base in lay.squareness:
        return True
    if any(base in lay.axes[a].location_errors for a in machine.rotary):
        return True
    return (len(base) == 3 and base[0] == "E" and base[1] in "XYZABC"
            and base[2] in machine.axes)


def _fourier(comp: str, kind: str, k: int) -> S.Term:
    axis, s = comp[2], (1e-6 if S.is_angular(comp) else 1e-3)
    f = np.cos if kind == "cos" else np.sin
    return S.Term(f"{comp}@{kind}{k}", comp, lambda b: s * f(k * np.deg2rad(b.pos[axis])))


def planted_terms(machine: S.Machine, names, ranges: dict) -> list:
    """Simulator terms of the report names ``names`` (constants, ``NAME@offset``,
    ``@slope``, ``@Pk`` over the measured range ``ranges[axis] = (lo, hi)``, ``@cosk`` /
    ``@sink`` of a periodic rotary axis, angle in rad; ``RV_<axis>``: the reversal value of
    ISO 230-2, half of it added to the axis' positioning error with the sign of the motion
    that brought the axis to the reading)."""
    out = []
    for name in names:
        assert known_to_machine(machine, name), f"{machine.name}: no error {name!r}"
        if name.startswith("RV_"):
            t = S.reversal(along(machine, name[3:]), name[3:])
            out.append(S.Term(name, t.target, t.basis))
            continue
        base, _, term = name.partition("@")
        if not term:
            out.append(S.constant(base))
            continue
        m = re.fullmatch(r"(cos|sin)(\d+)", term)
        if m:
            out.append(_fourier(base, m.group(1), int(m.group(2))))
            continue
        k = {"offset": 0, "slope": 1}.get(term)
        k = int(term[1:]) if k is None else k
        lo, hi = ranges[base[2]]
        out.append(S.series(base, k, lo, hi))
    return out


def _between(rng, lo, hi) -> float:
    return float(rng.choice((-1.0, 1.0)) * rng.uniform(lo, hi))


def planted_value(machine: S.Machine, name: str, rng) -> float:
    """A realistic value in the report unit: squareness 10-30 urad, location errors 5-30 um /
    10-50 urad, scales and straightness slopes 5-20 um/m, angular slopes 10-40 urad/m,
    slopes over a rotary axis 0.005-0.02 um/deg (0.02-0.1 urad/deg), offsets 5-20, Legendre
    and Fourier terms 1-5 (um / urad), reversals 1-4 um."""
    if name.startswith("RV_"):
        return _between(rng, 1, 4)
    base, _, term = name.partition("@")
    angular = S.is_angular(base)
    if not term:
        if base in machine.layout.squareness:
            return _between(rng, 10, 30)
        return _between(rng, 10, 50) if angular else _between(rng, 5, 30)
    if term == "slope":
        if base[2] in machine.rotary:
            return _between(rng, 0.02, 0.1) if angular else _between(rng, 0.005, 0.02)
        return _between(rng, 0.01, 0.04) if angular else _between(rng, 0.005, 0.02)
    if term == "offset":
        return _between(rng, 5, 20)
    return _between(rng, 1, 5)


# ---- execution -----------------------------------------------------------------------------
def measured_ranges(machine: S.Machine, files) -> dict:
    """Axis -> (min, max) of the commanded positions over every file of the campaign."""
    out = {}
    for a in machine.axes:
        vals = np.concatenate([f.number(a) for f in files])
        out[a] = (float(vals.min()), float(vals.max()))
    return out


def _errors(machine, terms, values, pos, vel=None) -> dict:
    vel = vel or {a: np.zeros(len(pos[a])) for a in machine.axes}
    return S.errors_at(View(pos, vel), terms, values)


def motion_signs(machine, f: PlanFile, traces) -> dict:
    """Axis -> (N,) sign of the motion that brought the axis to each reading: the file's
    ``dir_<axis>`` column, else from the order of the readings within each trace (``traces``
    (N,) labels): the sign of the step from the previous reading (the first reading: of the
    step to the second), standing still keeps the last sign; 0 for an axis that does not
    move in a trace (its state is constant there)."""
    out = {}
    for a in machine.axes:
        if f.has(f"dir_{a}"):
            out[a] = f.number(f"dir_{a}")
            continue
        q, s = f.number(a), np.zeros(f.n)
        for t in _groups(traces):
            idx = np.flatnonzero(traces == t)
            step = np.sign(np.diff(q[idx]))
            if len(idx) < 2 or not step.any():
                continue
            sign = np.concatenate([[step[0]], step])
            for i in range(len(sign)):
                if sign[i] == 0:
                    sign[i] = sign[i - 1] if i else next(v for v in step if v)
            s[idx] = sign
        out[a] = s
    return out


#: the standard uncertainty of one reading calibrate assumes when a file declares none (um;
#: docs/formats.md; distances: 0.3 um + 0.3 um/m times the distance)
DEFAULT_U_UM = {"ballbar": 0.5, "sphere": 1.0}


def reading_u(f: PlanFile, distance_mm=None) -> np.ndarray:
    """(N,) standard uncertainty of each reading, um: the file's ``u_um`` column or header
    line, else the documented default of its kind."""
    if f.has("u_um") or "u_um" in f.meta:
        return f.number("u_um")
    if f.kind == "distances":
        return 0.3 + 0.3e-3 * np.asarray(distance_mm, float)
    return np.full(f.n, DEFAULT_U_UM[f.kind])


def _groups(labels) -> list:
    return list(dict.fromkeys(labels.tolist()))


def ballbar_placements(f: PlanFile) -> np.ndarray:
    """The placement of every row: the ``placement`` column, else one per distinct (pivot,
    length) (docs/formats.md)."""
    if f.has("placement"):
        return f.labels("placement")
    key = np.column_stack([f.number(c) for c in ("pivot_x", "pivot_y", "pivot_z",
                                                 "length_mm")])
    return np.array([",".join(f"{v:.6f}" for v in r) for r in key], dtype=object)


def fill_ballbar(machine, f: PlanFile, terms, values, rng, setup: dict) -> dict:
    pos, probe = f.positions(machine.axes), f.probe()
    placement = ballbar_placements(f)
    sense = np.sign(f.number("direction", 1.0))
    traces = np.array([f"{p}|{d}" for p, d in zip(placement, sense)], dtype=object)
    vel = motion_signs(machine, f, traces)
    t = machine.tool_point(pos, _errors(machine, terms, values, pos, vel), probe)
    pivot = np.column_stack([f.number(c) for c in ("pivot_x", "pivot_y", "pivot_z")])
    length = f.number("length_mm")
    length_u = f.declared("length_u_um")
    dp, dl = np.zeros((f.n, 3)), np.zeros(f.n)
    for p in _groups(placement):
        m = placement == p
        key = f"{f.path.name}#{p}"
        setup[key + ":pivot"] = rng.normal(0.0, 30.0, 3)
        setup[key + ":length"] = float(rng.normal(0.0, length_u if length_u else 8.0))
        dp[m] = setup[key + ":pivot"] * 1e-3
        dl[m] = setup[key + ":length"]
    exact = 1e3 * (np.linalg.norm(t - pivot - dp, axis=1) - length) + dl
    return {"dr_um": exact + rng.normal(0.0, 1.0, f.n) * reading_u(f)}


def fill_sphere(machine, f: PlanFile, terms, values, rng, setup: dict) -> dict:
    pos, probe = f.positions(machine.axes), f.probe()
    tool_u = f.declared("tool_u_um")
    dz = float(rng.normal(0.0, tool_u if tool_u is not None else 20.0))
    setup[f"{f.path.name}:tool_dz"] = dz
    probe = probe + np.array([0.0, 0.0, 1.0]) * dz * 1e-3
    t = machine.tool_point(pos, _errors(machine, terms, values, pos), probe)
    centre = np.column_stack([f.number(c) for c in ("sphere_x", "sphere_y", "sphere_z")])
    placement = f.labels("placement")
    dc = np.zeros((f.n, 3))
    for p in _groups(placement):
        key = f"{f.path.name}#{p}:centre"
        setup[key] = rng.normal(0.0, 40.0, 3)
        dc[placement == p] = setup[key] * 1e-3
    v = t - centre - dc
    frame = f.labels("frame") if f.has("frame") else np.full(f.n, "work", dtype=object)
    mach = np.array([str(s).strip().lower() == "machine" for s in frame])
    if mach.any():
        R = machine.work_orientation({a: pos[a][mach] for a in machine.axes})
        v[mach] = np.einsum("nij,nj->ni", R, v[mach])
    d = 1e3 * v + rng.normal(0.0, 1.0, v.shape) * reading_u(f)[:, None]
    return {"dx_um": d[:, 0], "dy_um": d[:, 1], "dz_um": d[:, 2]}


def fill_distances(machine, f: PlanFile, terms, values, rng, setup: dict) -> dict:
    pos, probe = f.positions(machine.axes), f.probe()
    t = machine.tool_point(pos, _errors(machine, terms, values, pos), probe)
    for c in ("station_x", "station_y", "station_z"):
        assert f.has(c) or c in f.meta, (
            f"{f.path.name}: the plan does not say where the stations go ({c})")
    s = np.column_stack([f.number(c) for c in ("station_x", "station_y", "station_z")])
    station = f.labels("station")
    dd = np.zeros(f.n)
    for k in _groups(station):
        m = station == k
        key = f"{f.path.name}#{k}"
        setup[key + ":station"] = rng.normal(0.0, 50.0, 3)
        setup[key + ":dead_path"] = float(rng.normal(0.0, 30.0))
        s[m] = s[m] + setup[key + ":station"] * 1e-3
        dd[m] = setup[key + ":dead_path"] * 1e-3
    d = np.linalg.norm(t - s, axis=1) + dd
    d = d + rng.normal(0.0, 1.0, f.n) * reading_u(f, d) * 1e-3
    if f.has("dd_mm"):
        first = {k: d[np.flatnonzero(station == k)[0]] for k in _groups(station)}
        return {"dd_mm": d - np.array([first[k] for k in station])}
    return {"d_mm": d}


FILL = {"ballbar": fill_ballbar, "sphere": fill_sphere, "distances": fill_distances}


def execute(machine: S.Machine, files, values: dict, out_dir: Path, rng, root: Path):
    """Fill every plan file (``files`` list of :class:`PlanFile`, paths under ``root``) with
    the readings of the planted ``values`` (report name -> value, report units); write them
    under ``out_dir`` at the same relative paths.  Returns (written paths, planted set-ups)."""
    ranges = measured_ranges(machine, files)
    terms = planted_terms(machine, values, ranges)
    setup, paths = {}, []
    for f in files:
        cols = FILL[f.kind](machine, f, terms, values, rng, setup)
        fmt = "{:.9f}" if f.kind == "distances" else "{:.6f}"
        paths.append(f.write_filled(out_dir / f.path.relative_to(root), cols, fmt))
    return paths, setup


# ---- NC programs ---------------------------------------------------------------------------
_WORD = re.compile(r"([A-Za-z])[ \t]*([+-]?(?:\d+\.?\d*|\.\d+))")


@dataclass
class Block:
    """One NC block with words: its line number, ``end`` (axis -> value after the block, the
    axes commanded so far) when it moves, ``dwell`` seconds when it is a ``G4``."""

    line: int
    end: dict | None = None
    dwell: float | None = None
    errors: list = field(default_factory=list)


def _codes(words, letter) -> list:
    return [float(v) for k, v in words if k == letter]


def nc_blocks(text: str, axes) -> list:
    """The blocks of an ISO program that carry words (modal ``G0-G3``, ``G90/G91``, ``G20/21``;
    a ``G4`` block is a dwell whose ``P`` / ``X`` word is its time, not a move; ``G28``/``G30``
    blocks are skipped).  A move's ``errors`` name what the contract forbids (incremental,
    inch, an axis word the layout does not have)."""
    state = {"motion": None, "absolute": True, "mm": True}
    where: dict = {}
    out = []
    for no, raw in enumerate(text.splitlines(), 1):
        line = re.sub(r"\([^)]*\)", " ", raw).split(";", 1)[0].strip()
        if not line or line.startswith("%") or re.match(r"^[Oo]\d", line):
            continue
        words = [(k.upper(), v) for k, v in _WORD.findall(line)]
        words = [(k, v) for k, v in words if k != "N"]
        if not words:
            continue
        g = _codes(words, "G")
        if any(math.isclose(c, 4.0) for c in g):
            p = _codes(words, "P") or _codes(words, "X") or [0.0]
            out.append(Block(no, dwell=p[0]))
            continue
        for c in g:
            if c in (0, 1, 2, 3):
                state["motion"] = int(c)
            elif c == 90:
                state["absolute"] = True
            elif c == 91:
                state["absolute"] = False
            elif c == 20:
                state["mm"] = False
            elif c == 21:
                state["mm"] = True
        if any(c in (28, 30) for c in g):
            out.append(Block(no))
            continue
        moved = {k: float(v) for k, v in words if k in axes}
        foreign = sorted({k for k, _ in words if k in "XYZABCUVW" and k not in axes})
        if (not moved and not foreign) or state["motion"] is None:
            out.append(Block(no))
            continue
        errs = ([] if state["absolute"] else ["G91"]) + ([] if state["mm"] else ["G20"])
        errs += [f"axis {k} not in the layout" for k in foreign]
        where.update(moved)
        out.append(Block(no, end=dict(where), errors=errs))
    return out


def match_rows(blocks, rows: list, tol: float = 1.5e-3):
    """Greedy subsequence match of the file's rows (dicts axis -> value) to the end points of
    the motion blocks, in order.  Returns the block index of every row (None from the first
    row that cannot be matched on)."""
    out, start = [], 0
    for row in rows:
        hit = None
        for i in range(start, len(blocks)):
            e = blocks[i].end
            if e is not None and all(a in e and abs(e[a] - v) <= tol for a, v in row.items()):
                hit = i
                break
        out.append(hit)
        if hit is None:
            break
        start = hit + 1
    return out
