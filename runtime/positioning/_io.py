"""Reading an ISO 230-2 positioning run (laser interferometer, one axis) from CSV.

Two formats are read; both are comma-separated (a header without commas but with ``;`` or tabs
is read with that separator, as interferometer software often exports), blank lines and lines
starting with ``#`` are ignored, names are case-insensitive.

*Long format*, one row per reading::

    target_mm,cycle,direction,deviation_um[,T_C]
    0,1,+1,0.0
    0,1,-1,1.8
    ...

* ``target_mm``: target position P_i, mm; also ``target``, ``target_position``, ``position``
  with or without a unit ``_mm``, `` mm``, ``(mm)``, ``[mm]`` (or um: ``_um``, ``(µm)`` ...);
  no unit means mm (``Target (mm)``, ``Target [mm]``, ``position_mm``).
* ``cycle`` (or ``run``): the cycle j = 1..n, an integer (``1`` and ``1.0`` are the same
  cycle; ``1.5`` is refused) or a text label.
* ``direction`` (or ``dir``): ``+1`` forward (approach in the positive direction, the
  standard's up arrow) or ``-1`` backward (down arrow); ``+``/``-``, ``fwd``/``bwd``,
  ``forward``/``backward``, ``up``/``down`` are accepted too.
* ``deviation_um`` (or ``deviation_mm``; the unit spellings of the target, no unit: um):
  positional deviation x_ij = actual minus target
  position, the interferometer reading after the usual environmental (air) compensation, in
  the axis' NC coordinate (ISO 841: tool relative to workpiece).
* optional material temperature ``T_C`` (or ``material_T_C``, ``T_material_C``), degC, used by
  the correction to 20 degC; any other column ending in ``_C`` (e.g. ``air_T_C``) is reported
  as a condition of the run; further columns (comments, time stamps) are ignored.

*Wide format*, one row per target, one column per cycle and direction (what interferometer
software exports)::

    target_mm,fwd_1_um,bwd_1_um,fwd_2_um,bwd_2_um,...[,T_C]

* the canonical column name is ``fwd_<j>_um`` / ``bwd_<j>_um``; accepted variants: direction
  ``fwd forward fw f up pos plus + ↑`` / ``bwd backward bw b back down neg minus rev reverse
  - ↓`` before or after the cycle number, optionally with ``run``/``cycle``/``c``/``r``
  (``fwd1``, ``Fwd 1``, ``run1_fwd``, ``1+``, ``cycle_2_bwd``), and a unit suffix ``_um``,
  ``_mm``, ``(um)``, ``(mm)``, ``[um]``, ``[mm]``; a column without a unit is in um.
* the target column as in the long format (``target_mm``, ``Target (mm)`` ...).
* ``T_C``: the material temperature at that target (all its cycles).

In both formats every target must be measured in both directions in every cycle, exactly once;
at least 2 targets and 2 cycles (the standard test asks for 5 of each; fewer gives a note).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, require
from ..fileio import TARGET_KEY_MM, read_csv_rows, refuse_repeated_readings
from ..units import (MATERIAL_TEMPERATURE_RANGE_C, MM_PER_UM, UM_PER_MM,
                     check_reading_spread_um, check_temperature_C, parse_number)

FWD, BWD = 0, 1
DIRECTION_NAMES = ("forward", "backward")
LINEAR_AXES = "XYZUVW"

_CYCLE = ("cycle", "run")
_DIRECTION = ("direction", "dir")
_TEMP = ("t_c", "material_t_c", "t_material_c")
_DIR_WORDS = {**{w: +1 for w in ("+1", "1", "+1.0", "1.0", "+", "fwd", "forward", "up", "pos",
                                 "plus", "\u2191")},
              **{w: -1 for w in ("-1", "-1.0", "-", "bwd", "backward", "back", "down", "neg",
                                 "minus", "rev", "reverse", "\u2193")}}
_F = r"fwd|forward|fw|f|up|pos|plus|\+|\u2191"
_B = r"bwd|backward|bw|back|b|down|neg|minus|reverse|rev|-|\u2193"
_UNIT = r"(?:[ _]?[(\[]?(?P<u>um|\u00b5m|\u03bcm|mm)[)\]]?)?"
#: target column: name (target, target_position, position) and an optional unit, default mm
_TARGET_RX = re.compile(rf"^(?P<n>target(?:[ _]?position)?|position){_UNIT}$", re.IGNORECASE)
#: deviation column of the long format, optional unit, default um
_DEVIATION_RX = re.compile(rf"^deviation{_UNIT}$", re.IGNORECASE)
_RUN = r"(?:run|cycle|cyc|c|r)?"
_WIDE = (re.compile(rf"^(?P<d>{_F}|{_B})[ _.-]?{_RUN}[ _.-]?(?P<k>\d+){_UNIT}$", re.IGNORECASE),
         re.compile(rf"^{_RUN}[ _.-]?(?P<k>\d+)[ _.-]?(?P<d>{_F}|{_B}){_UNIT}$", re.IGNORECASE))


@dataclass
class PositioningRun:
    """One ISO 230-2 run of one axis, complete: m targets x 2 directions x n cycles.

    ``targets``: shape (m,), mm, strictly increasing.  ``deviation``: shape (m, 2, n), mm,
    actual minus target; index 1 is the direction (0 forward/up arrow, 1 backward/down
    arrow), index 2 the cycle in the order of ``cycles``.  ``temperature``: material
    temperature, degC, shape (m, 2, n), or None.  ``conditions``: other ``*_C`` columns ->
    (min, mean, max) degC."""

    axis: str
    targets: np.ndarray
    cycles: tuple
    deviation: np.ndarray
    temperature: np.ndarray | None = None
    conditions: dict = field(default_factory=dict)
    source: str = ""
    format: str = ""
    ignored_columns: tuple = ()

    def __post_init__(self):
        self.targets = np.asarray(self.targets, dtype=float)
        self.deviation = np.asarray(self.deviation, dtype=float)
        if self.temperature is not None:
            self.temperature = np.asarray(self.temperature, dtype=float)
        self.validate()

    @property
    def n_targets(self) -> int:
        return int(self.targets.size)

    @property
    def n_cycles(self) -> int:
        return int(self.deviation.shape[2])

    def validate(self) -> None:
        """Shapes, counts, finiteness, increasing targets; InputError on any defect."""
        w = self.source or "positioning run"
        require(isinstance(self.axis, str) and len(self.axis) == 1
                and self.axis in LINEAR_AXES,
                f"{w}: axis must be a linear axis letter ({' '.join(LINEAR_AXES)}), got "
                f"{self.axis!r} (rotary axes are not supported)")
        t, d = self.targets, self.deviation
        require(t.ndim == 1 and t.size >= 2, f"{w}: needs at least 2 target positions, got "
                                             f"{t.size}")
        require(d.ndim == 3 and d.shape[:2] == (t.size, 2),
                f"{w}: deviation must have shape (targets, 2, cycles), got {d.shape}")
        require(d.shape[2] >= 2, f"{w}: needs at least 2 cycles per direction, got "
                                 f"{d.shape[2]}")
        require(len(self.cycles) == d.shape[2], f"{w}: {len(self.cycles)} cycle labels for "
                                                f"{d.shape[2]} cycles")
        require(np.all(np.isfinite(t)) and np.all(np.diff(t) > 0),
                f"{w}: targets must be finite and strictly increasing")
        require(np.all(np.isfinite(d)), f"{w}: deviations contain NaN or infinite values")
        if self.temperature is not None:
            require(self.temperature.shape == d.shape,
                    f"{w}: temperature shape {self.temperature.shape} != {d.shape}")
            require(np.all(np.isfinite(self.temperature)),
                    f"{w}: temperatures contain NaN or infinite values")


# ---------------------------------------------------------------------------------------------
def _rows(path: Path) -> tuple[list[str], list[tuple[int, list[str]]]]:
    rows = read_csv_rows(path, empty=f"{path}: empty file (no header)")
    (_, header), body = rows[0], rows[1:]
    require(all(header), f"{path}: empty column name in header")
    low = [h.lower() for h in header]
    dup = sorted({h for h in low if low.count(h) > 1})
    require(not dup, f"{path}: duplicate column {dup[0] if dup else ''!r}")
    require(body, f"{path}: no data rows")
    for lineno, cells in body:
        require(len(cells) == len(header),
                f"{path}:{lineno}: {len(cells)} fields, header has {len(header)}")
    return header, body


def _number(path, lineno, column, text) -> float:
    return parse_number(text, f"{path}:{lineno}", column)


def _find(low: list[str], names) -> int | None:
    hits = [low.index(n) for n in names if n in low]
    return hits[0] if hits else None


def _unit_column(path, header, rx, what: str, default: str):
    """-> (index, factor to mm) of the one column whose name matches ``rx`` (a name and an
    optional unit um / mm in any spelling of ``_UNIT``; ``default`` unit when none), or
    (None, None).  Two matching columns are refused."""
    hits = []
    for j, h in enumerate(header):
        m = rx.match(h.strip())
        if m:  # 'target...' is preferred to a bare 'position' when both are present
            rank = 1 if (m.groupdict().get("n") or "").lower() == "position" else 0
            hits.append((rank, j, m))
    if not hits:
        return None, None
    hits.sort(key=lambda h: h[:2])
    if len(hits) > 1 and hits[1][0] == hits[0][0]:
        raise InputError(f"{path}: columns {header[hits[0][1]]!r} and {header[hits[1][1]]!r} "
                         f"both give the {what}")
    _, j, m = hits[0]
    unit = (m.group("u") or default).lower()
    return j, (1.0 if unit == "mm" else MM_PER_UM)


def _cycle_label(path, lineno, column, text: str) -> str:
    """Cycle label: an integer (``1`` and ``1.0`` are the same cycle) or a text label; a
    number that is not an integer (``1.5``) is refused."""
    try:
        v = float(text)
    except ValueError:
        return text
    if not (math.isfinite(v) and v == int(v)):
        raise InputError(f"{path}:{lineno}: {column} = {text!r}: cycle must be an integer")
    return str(int(v))


def _conditions(path, header, body, columns) -> dict:
    out = {}
    for j in columns:
        vals = [_number(path, ln, header[j], cells[j]) for ln, cells in body]
        out[header[j]] = (min(vals), sum(vals) / len(vals), max(vals))
    return out


def _assemble(path, axis, entries, temps, fmt, conditions, ignored) -> PositioningRun:
    """``entries``: {(target_key, dir_index, cycle): (deviation_mm, target_mm, line)}."""
    tkeys = sorted({k[0] for k in entries})
    cycles = []
    for k in entries:  # cycles in order of first appearance, numeric labels sorted
        if k[2] not in cycles:
            cycles.append(k[2])
    if all(re.fullmatch(r"-?\d+", c) for c in cycles):
        cycles.sort(key=int)
    require(len(cycles) >= 2, f"{path}: needs at least 2 cycles per direction, got "
                              f"{len(cycles)}")
    require(len(tkeys) >= 2, f"{path}: needs at least 2 target positions, got {len(tkeys)}")
    require(len(tkeys) < len(entries) or len(entries) < 4,
            f"{path}: every reading has a target position of its own ({len(entries)} readings, "
            f"{len(tkeys)} targets): not the target list of a run, whose every target is read "
            f"in both directions in every cycle -- the target and deviation columns swapped?")
    targets = {}
    for (tk, _, _), (_, t, _) in entries.items():
        targets.setdefault(tk, t)
    dirs = {}
    for (k, d, _) in entries:
        dirs.setdefault(k, set()).add(d)
    for tk in tkeys:
        have = dirs[tk]
        if len(have) == 1:
            only = DIRECTION_NAMES[have.pop()]
            raise InputError(f"{path}: target {targets[tk]:g} mm is measured in the {only} "
                             f"direction only (ISO 230-2 needs both directions at every target)")
        for d in (FWD, BWD):
            for c in cycles:
                require((tk, d, c) in entries,
                        f"{path}: cycle {c} missing at target {targets[tk]:g} mm "
                        f"({DIRECTION_NAMES[d]})")
    m, n = len(tkeys), len(cycles)
    dev = np.empty((m, 2, n))
    tem = np.empty((m, 2, n)) if temps else None
    for i, tk in enumerate(tkeys):
        for d in (FWD, BWD):
            for j, c in enumerate(cycles):
                dev[i, d, j] = entries[(tk, d, c)][0]
                if tem is not None:
                    tem[i, d, j] = temps[(tk, d, c)]
    return PositioningRun(axis, [targets[tk] for tk in tkeys], tuple(cycles), dev, tem,
                          conditions, str(path), fmt, tuple(ignored))


def _read_long(path, axis, header, body, low) -> PositioningRun:
    jt, tscale = _unit_column(path, header, _TARGET_RX, "target position", "mm")
    jc, jd = _find(low, _CYCLE), _find(low, _DIRECTION)
    jv, scale = _unit_column(path, header, _DEVIATION_RX, "deviation", "um")
    for j, what in ((jt, "target_mm"), (jc, "cycle"), (jd, "direction"),
                    (jv, "deviation_um")):
        require(j is not None, f"{path}: missing column {what} (long format: target_mm,cycle,"
                               f"direction,deviation_um; see volerr iso230-2 --help)")
    jT = _find(low, _TEMP)
    used = {jt, jc, jd, jv, jT}
    cond = [j for j in range(len(header)) if j not in used and low[j].endswith("_c")]
    ignored = [header[j] for j in range(len(header)) if j not in used and j not in cond]
    rows = []               # (target mm, FWD | BWD, cycle, deviation mm, line, T or None)
    for ln, cells in body:
        t = _number(path, ln, header[jt], cells[jt]) * tscale
        dtext = cells[jd].lower()
        require(dtext in _DIR_WORDS, f"{path}:{ln}: direction = {cells[jd]!r}: use +1 (forward) "
                                     f"or -1 (backward)")
        d = FWD if _DIR_WORDS[dtext] > 0 else BWD
        require(cells[jc] != "", f"{path}:{ln}: empty value in column {header[jc]}")
        c = _cycle_label(path, ln, header[jc], cells[jc])
        v = _number(path, ln, header[jv], cells[jv]) * scale
        rows.append((t, d, c, v, ln,
                     None if jT is None else _number(path, ln, header[jT], cells[jT])))
    refuse_repeated_readings([r[0] for r in rows], [1 if r[1] == FWD else -1 for r in rows],
                             [r[2] for r in rows], str(path), lines=[r[4] for r in rows])
    entries, temps = {}, {}
    for t, d, c, v, ln, T in rows:
        key = (round(t / TARGET_KEY_MM), d, c)
        entries[key] = (v, t, ln)
        if T is not None:
            temps[key] = T
    return _assemble(path, axis, entries, temps, "long", _conditions(path, header, body, cond),
                     ignored)


def wide_column(name: str):
    """``(direction index, cycle label, factor to mm)`` of a wide-format column, or None."""
    for rx in _WIDE:
        m = rx.match(name.strip())
        if m:
            d = FWD if _DIR_WORDS.get(_canon_dir(m.group("d"))) == 1 else BWD
            unit = (m.group("u") or "um").lower()
            return d, str(int(m.group("k"))), (1.0 if unit == "mm" else MM_PER_UM)
    return None


def _canon_dir(word: str) -> str:
    w = word.lower()
    return {"fw": "fwd", "f": "fwd", "bw": "bwd", "b": "bwd"}.get(w, w)


def _read_wide(path, axis, header, body, low) -> PositioningRun:
    jt, tscale = _unit_column(path, header, _TARGET_RX, "target position", "mm")
    require(jt is not None, f"{path}: missing column target_mm (wide format: target_mm,fwd_1_um,"
                            f"bwd_1_um,...; see volerr iso230-2 --help)")
    jT = _find(low, _TEMP)
    cols, seen = {}, {}
    for j, h in enumerate(header):
        if j in (jt, jT):
            continue
        spec = wide_column(h)
        if spec is None:
            continue
        d, c, f = spec
        if (d, c) in seen:
            raise InputError(f"{path}: columns {seen[(d, c)]!r} and {h!r} both give cycle {c} "
                             f"{DIRECTION_NAMES[d]} (duplicate readings)")
        seen[(d, c)] = h
        cols[j] = spec
    require(cols, f"{path}: no reading columns (long format needs target_mm,cycle,direction,"
                  f"deviation_um; wide format target_mm,fwd_1_um,bwd_1_um,...)")
    used = set(cols) | {jt, jT}
    cond = [j for j in range(len(header)) if j not in used and low[j].endswith("_c")]
    ignored = [header[j] for j in range(len(header)) if j not in used and j not in cond]
    entries, temps, rows_of = {}, {}, {}
    for ln, cells in body:
        t = _number(path, ln, header[jt], cells[jt]) * tscale
        tk = round(t / TARGET_KEY_MM)
        if tk in rows_of:
            raise InputError(f"{path}:{ln}: duplicate target {t:g} mm (already on line "
                             f"{rows_of[tk]})")
        rows_of[tk] = ln
        T = _number(path, ln, header[jT], cells[jT]) if jT is not None else None
        for j, (d, c, f) in cols.items():
            if cells[j] == "":
                continue  # reported as a missing cycle below
            entries[(tk, d, c)] = (_number(path, ln, header[j], cells[j]) * f, t, ln)
            if T is not None:
                temps[(tk, d, c)] = T
    return _assemble(path, axis, entries, temps, "wide", _conditions(path, header, body, cond),
                     ignored)


def check_material_temperature(values, where: str) -> None:
    """Refuse a material temperature column (degC, ISO 1: the scale's or part's temperature)
    with a value outside :data:`volerr.units.MATERIAL_TEMPERATURE_RANGE_C` (-10 .. 50 degC):
    one line naming ``where`` (file and column) and the likely unit (68 degF = 20 degC; 293 is
    K).  The correction to 20 degC would otherwise move every deviation by
    cte x (T - 20) x P: 48 K too warm on 800 mm of steel is 445 um."""
    v = np.asarray(values, dtype=float).ravel()
    v = v[np.isfinite(v)]
    if not v.size:
        return
    lo, hi = MATERIAL_TEMPERATURE_RANGE_C
    worst = float(v.max()) if v.max() - hi >= lo - v.min() else float(v.min())
    check_temperature_C(worst, where, MATERIAL_TEMPERATURE_RANGE_C)


def read_run(path, axis: str = "X") -> PositioningRun:
    """Read a positioning run (long or wide format, module docstring) -> :class:`PositioningRun`.

    ``axis``: the axis letter the run belongs to (a linear axis, X Y Z U V W)."""
    path = Path(path)
    require(isinstance(axis, str) and len(axis) == 1 and axis.upper() in LINEAR_AXES,
            f"--axis must be a linear axis letter ({' '.join(LINEAR_AXES)}), got {axis!r}")
    header, body = _rows(path)
    low = [h.lower() for h in header]
    if _find(low, _DIRECTION) is not None:
        run = _read_long(path, axis.upper(), header, body, low)
    else:
        run = _read_wide(path, axis.upper(), header, body, low)
    if run.temperature is not None:
        check_material_temperature(run.temperature, f"{path}: column {header[_find(low, _TEMP)]}")
    cols = [h.strip() for h in header
            if _DEVIATION_RX.match(h.strip()) or wide_column(h) is not None]
    check_plausible_deviations(run, cols[0] if len(cols) == 1 else
                               (f"{cols[0]} .. {cols[-1]}" if cols else None))
    return run


#: the largest positional deviation accepted, mm: ISO 230-2 deviations of a machine axis are
#: micrometres to tens of micrometres; 1 mm or more is a unit error (um under a _mm header)
MAX_DEVIATION_MM = 1.0


def check_plausible_deviations(run: PositioningRun, column: str | None = None) -> None:
    """Refuse deviations a positioning run cannot hold: |x_ij| of :data:`MAX_DEVIATION_MM` or
    more, or more than half the smallest target spacing (the machine would then stand nearer
    the next target than its own), or every deviation exactly equal (a constant column: no
    axis repeats to the nanometre; the instrument recorded nothing).  Such values are a unit
    mistake (nm under a ``_um`` header, um under a ``_mm`` header) or a target column in the
    wrong unit.  Deviations read in um (a column not headed mm) that all span less than
    :data:`volerr.units.MIN_READING_SPREAD_UM` (0.05 um; the best axes span 0.1 um or more)
    are mm written under ``_um`` (:func:`volerr.units.check_reading_spread_um`).
    ``column``: the reading column(s) as headed, for the line (one line)."""
    col = f"column {column}" if column else "the deviation column"
    headed_mm = bool(column) and re.search(r"mm\b|\(mm\)|_mm", column.lower()) is not None
    d = run.deviation
    if d.size and float(np.ptp(d)) == 0.0:
        raise InputError(f"{run.source}: every deviation in {col} is {1e3 * float(d.flat[0]):g} "
                         f"um, a constant column: no axis repeats exactly (the instrument "
                         f"recorded nothing? a zero-filled export?)")
    worst = float(np.max(np.abs(d)))
    spacing = float(np.min(np.diff(run.targets)))
    limit = min(MAX_DEVIATION_MM, 0.5 * spacing)
    if worst >= limit:
        i = np.unravel_index(int(np.argmax(np.abs(d))), d.shape)
        why = (f"{MAX_DEVIATION_MM:g} mm or more" if limit == MAX_DEVIATION_MM else
               f"more than half the smallest target spacing ({spacing:g} mm)")
        if headed_mm:
            cause = "values in um under a _mm header? the target column in the wrong unit?"
        elif worst * 1e-3 < limit:
            cause = (f"values in nm under a um header? ({1e3 * worst:g} nm = {worst:g} um); "
                     f"give um")
        else:
            cause = "a wrong unit? the target column in the wrong unit?"
        raise InputError(
            f"{run.source}: {col}: deviation {1e3 * worst:g} um at target "
            f"{run.targets[i[0]]:g} mm is {why}: not a positioning deviation ({cause})")
    if not headed_mm:
        check_reading_spread_um({column or "deviation": UM_PER_MM * d}, str(run.source))
