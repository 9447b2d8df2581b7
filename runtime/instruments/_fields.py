"""Column rules shared by the instruments' readers: axis positions inside the layout's travel,
probe / tool offsets, readings with a unit suffix, per-reading uncertainties, placement labels
and covariates (every other numeric column).  Each check fails with one line naming the file,
the column and, where it helps, the row."""

from __future__ import annotations

import re

import numpy as np

from ..errors import InputError, require
from ..units import MIN_READING_SPREAD_UM, check_reading_spread_um

AXIS_NAMES = "XYZUVWABC"


def drop_nonfinite(cols: dict, text: dict, where: str) -> tuple[dict, dict]:
    """Numeric columns holding NaN or infinity become text columns with a message naming the
    first bad row (an error if the column is needed, else left out with a warning)."""
    from ..fileio import MAX_ABS

    cols, text = dict(cols), dict(text or {})
    for h in list(cols):
        v = np.asarray(cols[h], dtype=float)
        if not np.all(np.isfinite(v)):
            k = int(np.flatnonzero(~np.isfinite(v))[0])
            text[h] = f"{where}: column {h} row {k + 2} is NaN or infinite"
            del cols[h]
        elif np.any(np.abs(v) > MAX_ABS):   # squares would overflow: never a reading
            k = int(np.flatnonzero(np.abs(v) > MAX_ABS)[0])
            text[h] = (f"{where}: column {h} row {k + 2} = {v[k]:g} is implausibly large "
                       f"(more than {MAX_ABS:g} in the file's unit)")
            del cols[h]
    return cols, text


def require_finite(values, column: str, where: str) -> None:
    """Refuse (one line naming the column and row) NaN, infinity and magnitudes above
    :data:`volerr.fileio.MAX_ABS` in a column the reader computes with (before any
    computation: squares of 1e300 overflow)."""
    from ..fileio import MAX_ABS

    v = np.asarray(values, dtype=float)
    bad = np.flatnonzero(~np.isfinite(v))
    require(len(bad) == 0, f"{where}: column {column} row {bad[0] + 2 if len(bad) else 0} is "
                           f"NaN or infinite")
    big = np.flatnonzero(np.abs(v) > MAX_ABS)
    require(len(big) == 0, f"{where}: column {column} row {big[0] + 2 if len(big) else 0} = "
            f"{v[big[0]] if len(big) else 0:g} is implausibly large (more than {MAX_ABS:g} in "
            f"the file's unit)")


def refuse_duplicate_rows(columns, where: str) -> None:
    """Refuse a file in which a row repeats an earlier one in every cell (a file or a block
    pasted twice: real readings never agree to the last digit in every column, and a copied
    reading would count twice in the fit).  ``columns``: a
    :class:`volerr.instruments._csv.Columns` (numbers and label columns).  Where a column is
    empty in every row (a plan's file not filled in), that column is named instead: its
    missing readings are why the rows repeat."""
    from ._csv import EMPTY_COLUMN

    cells = [np.asarray(v, dtype=float) for v in columns.numbers.values()]
    for v in columns.labels.values():       # labels as codes in order of appearance
        codes: dict = {}
        cells.append(np.array([codes.setdefault(str(x), len(codes)) for x in v], dtype=float))
    if not cells or len(cells[0]) < 2:
        return
    rows = np.ascontiguousarray(np.column_stack(cells).astype(float) + 0.0)   # -0.0 == 0.0
    # a 64-bit hash of every row's bits (sorting 1-D keys: 100 000 rows in milliseconds),
    # then the rows of equal hash compared cell by cell
    bits = rows.view(np.uint64)
    mult = np.random.default_rng(0).integers(1, 2 ** 63, bits.shape[1], dtype=np.uint64) | 1
    with np.errstate(over="ignore"):
        key = (bits * mult).sum(axis=1)
    order = np.argsort(key, kind="stable")
    same = np.flatnonzero(key[order][1:] == key[order][:-1])
    for k in same:
        i, j = sorted((int(order[k]), int(order[k + 1])))
        if np.array_equal(rows[i], rows[j]):
            empty = [m for m in columns.text.values() if m and m.endswith(EMPTY_COLUMN)]
            raise InputError(empty[0] if empty else
                             f"{where}: row {j + 2} repeats row {i + 2} in every column (a "
                             f"file or a block pasted twice?)")


def refuse_repeated_block(numbers: dict, labels: dict, minimum: int, where: str) -> None:
    """Refuse a file in which ``minimum`` or more consecutive rows repeat, row for row and in
    every cell (``numbers`` name -> values, ``labels`` name -> text cells), consecutive rows
    met earlier in the file: a file or a trace pasted twice, whose readings would count twice.
    A single row equal to an earlier one is kept (a ballbar's overrun at a quantised reading
    can repeat one); a whole block of them is never a new measurement."""
    cells = [np.asarray(v, dtype=float) + 0.0 for v in numbers.values()]   # -0.0 == 0.0
    for v in labels.values():
        codes: dict = {}
        cells.append(np.array([codes.setdefault(str(x), len(codes)) for x in v], dtype=float))
    if not cells or len(cells[0]) < 2 * minimum:
        return
    rows = np.ascontiguousarray(np.column_stack(cells))
    first: dict = {}
    run, start, prev = 0, 0, -1
    for i, r in enumerate(rows):
        j = first.setdefault(r.tobytes(), i)
        run = run + 1 if j < i and run and j == prev + 1 else (1 if j < i else 0)
        if run == 1:
            start = i
        prev = j
        require(run < minimum, f"{where}: rows {start + 2} .. {i + 2} repeat rows "
                               f"{j - run + 3} .. {j + 2} in every column (a file or a trace "
                               f"pasted twice: its readings would count twice)")


def check_groups(labels, what: str, where: str, minimum: int, why: str) -> None:
    """Refuse an empty label and a group (placement, station) of fewer than ``minimum`` rows
    (a label mistyped on one row makes a group of its own that carries nothing)."""
    names = np.asarray(labels).astype(str)
    blank = np.flatnonzero(np.char.strip(names) == "")
    require(len(blank) == 0, f"{where}: row {blank[0] + 2 if len(blank) else 0}: empty "
                             f"{what} label")
    found, counts = np.unique(names, return_counts=True)
    few = [(g, int(c)) for g, c in zip(found, counts) if c < minimum]
    require(not few, f"{where}: {what} {few[0][0] if few else ''!r} has "
                     f"{few[0][1] if few else 0} row{'s' if few and few[0][1] > 1 else ''}; a "
                     f"{what} needs at least {minimum} ({why}; a mistyped label?)")


def text_columns(text: dict, needed, where: str, labels=()) -> list:
    """Refuse a needed column that is not numeric; one warning for each other such column
    (``labels``: text columns the instrument reads itself, e.g. ``placement``)."""
    from ._csv import EMPTY_COLUMN

    needed = {h.lower() for h in needed}
    labels = {h.lower() for h in labels}
    warnings = []
    for h, msg in text.items():
        if h.lower() in labels and msg is None:
            continue
        require(h.lower() not in needed, msg or f"{where}: column {h} is not numeric")
        warnings.append(f"column {h} is not numeric: left out of the candidates" if msg is None
                        else f"column {h} is empty in every row: left out of the candidates"
                        if msg.endswith(EMPTY_COLUMN)
                        else f"column {h} has a value that is not a finite number: left out "
                             f"of the candidates")
    return warnings


def open_columns(cols: dict, text: dict, model, where: str, needed=(), labels=()):
    """The first step of every instrument reader: columns holding NaN or infinity set aside
    (:func:`drop_nonfinite`), then the columns the reader needs -- the layout's axes (bare,
    ``_mm``, ``_deg``), the instrument's ``needed`` and the layout's covariates -- refused
    when not numeric, other text columns warned about (:func:`text_columns`; ``labels``: the
    instrument's own text columns).  Returns ``(find, warnings)``: a :class:`Finder` over the
    numeric columns (``find.cols``) and the warnings."""
    cols, text = drop_nonfinite(cols, text, where)
    needed = ({a + u for a in model.axes for u in ("", "_mm", "_deg")} | set(needed)
              | set(model.covariates))
    return Finder(cols, where), text_columns(text, needed, where, labels)


def read_file(path, model, columns_to_observations, unique_rows: bool = True, **options):
    """Read an instrument's CSV into :class:`Observations` with the instrument's
    ``columns_to_observations(numbers, text, labels, model, name, **options)``; a row given
    twice refused first (``unique_rows``).  InputError, one line, on a defect."""
    from ._csv import read_columns

    c = read_columns(path)
    if unique_rows:
        refuse_duplicate_rows(c, c.name)
    return columns_to_observations(c.numbers, c.text, c.labels, model, c.name, **options)


class Finder:
    """Finds a column under one of its unit spellings (names case-insensitive); remembers the
    columns used."""

    def __init__(self, cols: dict, where: str):
        self.cols, self.where, self.used = cols, where, set()
        self._lower = {}
        for h in cols:
            self._lower.setdefault(h.lower(), h)

    def name(self, text: str) -> str | None:
        return self._lower.get(text.lower())

    def __call__(self, name, units, what):
        hits = [h for h in (self.name(f"{name}{u}") for u in units) if h is not None]
        require(len(hits) <= 1, f"{self.where}: both {' and '.join(hits)} given for {what}")
        if hits:
            self.used.add(hits[0])
            return hits[0]
        return None


def positions(find: Finder, model, where: str, min_points: int = 1,
              needs: str = "the fit", check_travel: bool = True) -> dict:
    """Axis columns (mm | deg): every axis of the layout, no other, inside the travel (unless
    ``check_travel`` is False: a generic layout standing in for an unknown machine)."""
    cols, out = find.cols, {}
    for a in model.axes:
        unit = ("", "_deg") if a in model.rotary_axes else ("", "_mm")
        c = find(a, unit, f"axis {a}")
        require(c is not None, f"{where}: missing axis column {a} (layout {model.name} has "
                f"axes {' '.join(model.axes)})")
        out[a] = cols[c]
    extra_axes = [h for h in cols if re.fullmatch(rf"[{AXIS_NAMES}](_mm|_deg)?", h)
                  and h[0] not in model.axes]
    require(not extra_axes, f"{where}: axis column {extra_axes[0] if extra_axes else ''} is "
            f"not an axis of layout {model.name} ({' '.join(model.axes)}): layout mismatch")
    n = len(next(iter(out.values())))
    require(n >= min_points, f"{where}: too few points ({n}); {needs} needs at least "
                             f"{min_points}")
    for a, v in out.items() if check_travel else ():
        lo, hi = model.travel[a]
        margin = 0.05 * (hi - lo)
        bad = np.flatnonzero((v < lo - margin) | (v > hi + margin))
        if len(bad):
            from .geometry_check import travel_cause

            cause = travel_cause(model, out)
            require(False, f"{where}: {a} = {v[bad[0]]:g} lies outside the travel "
                    f"[{lo:g}, {hi:g}] of layout {model.name}: "
                    + (f"likely {cause}" if cause else "layout mismatch"))
    return out


def probe(find: Finder, n: int, where: str) -> np.ndarray:
    """Probe / tool offsets (n, 3) mm: all of Xp, Yp, Zp or none (zero)."""
    pc = [find(c, ("", "_mm"), f"probe offset {c}") for c in ("Xp", "Yp", "Zp")]
    require(all(c is None for c in pc) or all(c is not None for c in pc),
            f"{where}: give all of Xp, Yp, Zp or none")
    if pc[0] is None:
        return np.zeros((n, 3))
    return np.column_stack([find.cols[c] for c in pc])


def vector(find: Finder, names, what: str, where: str, units=("", "_mm")) -> np.ndarray:
    """(n, len(names)) mm of required columns such as ``pivot_x, pivot_y, pivot_z``."""
    out = []
    for c in names:
        h = find(c, units, what)
        require(h is not None, f"{where}: missing column {c} ({what}, mm)")
        out.append(find.cols[h])
    return np.column_stack(out)


def readings(find: Finder, names, n: int, where: str, limit_mm: float = 5.0,
             what: str = "an error map", min_spread_um: float = MIN_READING_SPREAD_UM
             ) -> np.ndarray:
    """Readings (n, len(names)) mm from columns ``<name>_um`` or ``<name>_mm``,
    plausibility-checked: none of ``limit_mm`` or more (nm under ``_um``, um under ``_mm``),
    and the ``_um`` columns not all spanning less than ``min_spread_um`` (mm under
    ``_um``: :func:`volerr.units.check_reading_spread_um`)."""
    out, heads = np.zeros((n, len(names))), []
    for i, d in enumerate(names):
        require(find.name(d) is None, f"{where}: deviation column {d} has no unit suffix "
                f"(use {d}_um or {d}_mm)")
        c_um, c_mm = find(d, ("_um",), d), find(d, ("_mm",), d)
        require(not (c_um and c_mm), f"{where}: both {d}_um and {d}_mm given")
        for bad in (f"{d}_nm", f"{d}_m", f"{d}_in", f"{d}_urad", f"{d}_rad"):
            require(find.name(bad) is None, f"{where}: deviation column {bad}: unit not "
                    f"supported (use {d}_um or {d}_mm)")
        require(c_um or c_mm, f"{where}: missing deviation column {d}_um (or {d}_mm)")
        out[:, i] = find.cols[c_um] * 1e-3 if c_um else find.cols[c_mm]
        heads.append(c_um or c_mm)
    big = float(np.max(np.abs(out))) if out.size else 0.0
    if big >= limit_mm:
        col = heads[int(np.argmax(np.max(np.abs(out), axis=0)))]
        cause = ("wrong unit: likely nm under the _um header (give um), or nominal instead of "
                 "deviation values" if col.lower().endswith("_um") and big * 1e-3 < limit_mm else
                 "wrong unit (um given as mm?) or nominal instead of deviation values")
        raise InputError(f"{where}: column {col}: deviations up to {big:g} mm are implausible "
                         f"for {what}: {cause}")
    check_reading_spread_um({h: find.cols[h] for h in heads if h.lower().endswith("_um")},
                            where, min_spread_um)
    return out


def uncertainty(find: Finder, n: int, default_um: float, where: str) -> np.ndarray:
    """Standard uncertainty of each reading (n,) mm: column ``u_um`` (or ``u_mm``), else the
    instrument's default."""
    return uncertainty_named(find, "u", n, default_um, where)


def uncertainty_named(find: Finder, name: str, n: int, default_um: float,
                      where: str) -> np.ndarray:
    """Standard uncertainty of each reading (n,) mm from the column ``<name>_um`` (or
    ``<name>_mm``), else the instrument's default."""
    h_um = find(name, ("_um",), f"{name}_um")
    h_mm = find(name, ("_mm",), f"{name}_mm")
    require(not (h_um and h_mm), f"{where}: both {name}_um and {name}_mm given")
    if not (h_um or h_mm):
        return np.full(n, default_um * 1e-3)
    u = find.cols[h_um] * 1e-3 if h_um else find.cols[h_mm]
    require(np.all(u > 0), f"{where}: column {h_um or h_mm}: uncertainties must be positive")
    return u


def known_uncertainty(find: Finder, name: str, where: str) -> float | None:
    """Standard uncertainty (mm) of a set-up value the user knows (a calibrated bar length, a
    tool length from a presetter) from the one-valued column ``<name>_um``, else None (the
    set-up value is an unknown)."""
    h = find(name, ("_um",), f"{name}_um")
    if h is None:
        return None
    v = np.unique(find.cols[h])
    require(len(v) == 1 and v[0] > 0, f"{where}: {name}_um must be one positive value")
    return float(v[0]) * 1e-3


def labels(find: Finder, name: str, raw: dict, n: int) -> np.ndarray | None:
    """A label column (numbers or text, e.g. ``placement``) as strings, or None when absent."""
    h = find.name(name)
    if h is None:
        for k in raw:
            if k.lower() == name.lower():
                h = k
        if h is None:
            return None
        return np.asarray(raw[h], dtype=object)
    find.used.add(h)
    v = find.cols[h]
    return np.asarray([f"{x:g}" for x in v], dtype=object)


#: temperature columns of a room, the air, the structure or the material: degC in this range
#: (a workshop's or a structure's temperature is never above 50 degC); other ``T_*`` columns
#: (spindle, motor, coolant) in :data:`volerr.units.TEMPERATURE_RANGE_C`
_AMBIENT_RX = re.compile(r"^T(_C)?$|room|air|amb|env|hall|material|part|scale|struct|bed|base",
                         re.IGNORECASE)
AMBIENT_RANGE_C = (-10.0, 50.0)
#: the longest time axis of one file, s (30 days): a drift test or a calibration campaign lasts
#: hours to days; a longer ``t_s`` is milliseconds read as seconds
LONGEST_TIME_S = 30 * 86400.0


def is_temperature(name: str) -> bool:
    """A temperature column (degC): ``T``, ``T_C``, ``T_<label>``, ``<label>_T_C``."""
    return re.fullmatch(r"T(_\w+)?|\w+_T_C", name) is not None


def check_temperature(values, name: str, where: str) -> None:
    """Refuse a temperature column (``name``, degC) outside the range of its kind (room /
    structure / material: -10 .. 50 degC, else -10 .. 80 degC): one line naming the file and
    the column, ``degF`` when the values read as Fahrenheit fit (68 -> 20 degC)."""
    from ..units import TEMPERATURE_RANGE_C, check_temperature_C

    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if not v.size:
        return
    rng = AMBIENT_RANGE_C if _AMBIENT_RX.search(name) else TEMPERATURE_RANGE_C
    worst = float(v.max()) if v.max() - rng[1] >= rng[0] - v.min() else float(v.min())
    check_temperature_C(worst, f"{where}: column {name}", rng)


def check_temperatures_together(temps: dict, where: str) -> None:
    """Refuse a file whose temperature columns ``temps`` (name -> degC, two or more) all read
    above the room range (:data:`AMBIENT_RANGE_C`) in every reading: no sensor at a room's
    or structure's temperature (each column alone may be a hot spindle's,
    :func:`check_temperature`); one line naming the coldest, ``degF`` when it reads as
    Fahrenheit (68 degF = 20 degC)."""
    from ..units import check_temperature_C

    lows = {h: float(np.min(v)) for h, v in temps.items() if np.size(v)}
    if len(lows) < 2 or min(lows.values()) <= AMBIENT_RANGE_C[1]:
        return
    cold = min(lows, key=lambda h: lows[h])
    check_temperature_C(lows[cold], f"{where}: every temperature column reads above "
                        f"{AMBIENT_RANGE_C[1]:g} degC in every row (none a room's); the "
                        f"coldest, column {cold}", AMBIENT_RANGE_C)


def check_time(t, name: str, where: str) -> None:
    """Refuse a time column (s) spanning more than :data:`LONGEST_TIME_S` (one line naming
    the file and the column: likely milliseconds read as seconds)."""
    t = np.asarray(t, dtype=float)
    t = t[np.isfinite(t)]
    span = float(t.max() - t.min()) if t.size else 0.0
    require(span <= LONGEST_TIME_S,
            f"{where}: column {name} spans {span:g} s ({span / 86400:.0f} days) in one file, "
            f"longer than a drift test or a calibration lasts: likely in ms, not s "
            f"({span / 1000:g} s = {span / 3.6e6:.3g} h); give seconds")


def covariates(find: Finder, model, where: str, skip=()) -> dict:
    """Every numeric column not used by the reader (temperatures, times, directions ...);
    temperatures (:func:`check_temperature`) and ``t_s`` (:func:`check_time`) checked."""
    skip = {s.lower() for s in skip}
    covs = {c: v for c, v in find.cols.items() if c not in find.used and c.lower() not in skip}
    for c, v in covs.items():
        if is_temperature(c):
            check_temperature(v, c, where)
        elif c == "t_s":
            check_time(v, c, where)
    missing = [c for c in model.covariates if c not in covs]
    require(not missing, f"{where}: layout {model.name} needs covariate column "
            f"{missing[0] if missing else ''}")
    return covs


# --- faulty sensors: a reading frozen, an offset step (the logger's own noise as the scale) ---
#
# The scale of a sensor is its own reading-to-reading scatter, estimated robustly from the
# second differences d2_i = v_{i+1} - 2 v_i + v_{i-1} (a smooth drift contributes almost
# nothing to them): for white noise of std sigma, std(d2) = sqrt(6) sigma and the std of a
# first difference about the local trend is sqrt(2) sigma = std(d2) / sqrt(3); std(d2) is
# taken as 1.4826 median ``|d2|`` (the MAD of a zero-median variable, consistent for normal
# noise; Rousseeuw & Croux 1993, JASA 88 1273; the difference-based noise estimate of
# von Neumann's mean square successive difference, Ann. Math. Stat. 12 (1941) 367).  A
# logger that loses its sensor holds the last value (a frozen stretch); a re-plugged or
# re-seated sensor jumps (an offset step): the two faults of a data logger's quality checks
# (e.g. WMO-No. 8 (2018) Vol. V 1.3.3 "step test" and "persistence test").

#: a frozen stretch: at least this many equal readings in a row ...
FROZEN_MIN_READINGS = 10
#: ... and less likely than this under the sensor's own rate of equal consecutive readings
#: elsewhere in the run (n p^L, p that rate, L the equal steps of the stretch)
FROZEN_CHANCE = 1e-6
#: an offset step: a reading-to-reading change beyond STEP_K robust stds of the sensor's own
#: changes about its local trend (the median change over STEP_WINDOW readings each side) ...
STEP_K = 12.0
STEP_WINDOW = 10
#: ... while no other logged input changes by more than SHARED_K of its own std (and half
#: the step's own score) at that reading (then the change is an event of
#: the machine, not of the sensor)
SHARED_K = 4.0


def _longest_equal(v: np.ndarray) -> tuple[int, int]:
    """(start, number of equal steps) of the longest stretch of equal consecutive readings."""
    same = np.concatenate([[False], np.diff(v) == 0, [False]])
    edges = np.flatnonzero(np.diff(same.astype(int)))
    if not len(edges):
        return 0, 0
    starts, ends = edges[::2], edges[1::2]
    k = int(np.argmax(ends - starts))
    return int(starts[k]), int(ends[k] - starts[k])


def change_scores(v) -> tuple[np.ndarray, float]:
    """(z, s): every reading-to-reading change of ``v`` about its local trend in units of the
    sensor's robust scale ``s`` (block comment above; z[i] the change from reading i to i+1;
    ``s`` = 0 (a sensor without noise, e.g. a commanded speed): any change scores inf)."""
    v = np.asarray(v, float)
    d1 = np.diff(v)
    if len(d1) < 3:
        return np.zeros(len(d1)), 0.0
    w = min(STEP_WINDOW, (len(d1) - 1) // 2)
    pad = np.pad(d1, w, mode="edge")
    win = np.lib.stride_tricks.sliding_window_view(pad, 2 * w + 1)
    # the median of an odd window is its middle element: one partition at w (np.median also
    # partitions at the end to find a NaN, and takes a mean of the one element); with a NaN
    # np.median (NaN there).  A zero's sign may differ between the two: e == 0 below sees none
    trend = (np.partition(win, w, axis=1)[:, w] if not np.isnan(d1).any()
             else np.median(win, axis=1))
    start, steps = _longest_equal(v)
    keep = np.ones(len(v), bool)
    keep[start:start + steps + 1] = steps == 0
    d2 = np.diff(v[keep], 2) if keep.sum() > 2 else np.diff(v, 2)
    s = 1.4826 * float(np.median(np.abs(d2))) / np.sqrt(3.0)
    e = d1 - trend
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(e == 0, 0.0, np.abs(e) / s) if s > 0 else np.where(e == 0, 0.0, np.inf)
    return z, s


def frozen_stretch(v) -> tuple[int, int] | None:
    """(first, last) reading index of a frozen stretch of ``v`` (the rule of
    :data:`FROZEN_MIN_READINGS` and :data:`FROZEN_CHANCE`; the sensor must change elsewhere),
    or None."""
    v = np.asarray(v, float)
    start, steps = _longest_equal(v)
    if steps + 1 < FROZEN_MIN_READINGS:
        return None
    d1 = np.diff(v)
    other = np.ones(len(d1), bool)
    other[start:start + steps] = False
    if not other.any() or not np.any(d1[other] != 0):
        return None                     # never changes: the constant-sensor check's case
    p = float(np.mean(d1[other] == 0))
    return (start, start + steps) if len(d1) * p ** steps < FROZEN_CHANCE else None


def sensor_faults(t, columns: dict, others: dict) -> list:
    """The faults of the series ``columns`` {name: (N,)} of one run logged at ``t`` (N,) s:
    [{"input", "fault": "constant", "value", "from_s", "to_s", "readings"}] (one value over
    the whole run: a sensor disconnected or stuck, or a room steadier than its resolution),
    [{"input", "fault": "frozen", "from_s", "to_s", "readings"}] and
    [{"input", "fault": "step", "at_s", "step", "noise"}] (``step`` the jump in the column's
    unit, ``noise`` the sensor's robust std of a reading-to-reading change), one per column
    at most, constant first, then frozen.  ``others`` {name: (N,)} every logged input: a step shared with
    another input (:data:`SHARED_K`) is no fault."""
    t = np.asarray(t, float)
    found = {k: change_scores(v) for k, v in others.items()}
    scores = {k: zs[0] for k, zs in found.items()}
    out = []
    for name, v in columns.items():
        # the column's own (z, s), when ``others`` holds that very array: computed once
        own = found[name] if others.get(name) is v else None
        v = np.asarray(v, float)
        if len(v) and not np.ptp(v) > 0:
            out.append({"input": name, "fault": "constant", "value": float(v[0]),
                        "from_s": float(t[0]), "to_s": float(t[-1]), "readings": len(v)})
            continue
        fz = frozen_stretch(v)
        if fz is not None:
            out.append({"input": name, "fault": "frozen", "from_s": float(t[fz[0]]),
                        "to_s": float(t[fz[1]]), "readings": int(fz[1] - fz[0] + 1)})
            continue
        step = _step(v, name, scores, own)
        if step is not None:
            i, s = step
            out.append({"input": name, "fault": "step", "at_s": float(t[i + 1]),
                        "step": float(v[i + 1] - v[i]), "noise": float(s)})
    return out


def _step(v: np.ndarray, name: str, scores: dict, own=None) -> tuple[int, float] | None:
    """(i, s): the largest lasting change i -> i+1 of ``v`` beyond :data:`STEP_K` its scale
    ``s`` that no other input shares (:data:`SHARED_K`), or None (lasting: :func:`_lasting`);
    ``own``: :func:`change_scores` of ``v`` when already computed (not changed here)."""
    z, s = change_scores(v) if own is None else own
    d1 = np.diff(v)
    if not s > 0:               # no scatter (a coarse resolution): the resolution is the scale
        nz = np.abs(d1[d1 != 0])
        if not len(nz):
            return None
        s = float(nz.min())
        z = np.abs(d1 - np.median(d1)) / s
    for i in np.argsort(-z, kind="stable"):
        if not z[i] > STEP_K:
            return None
        if not _lasting(v, int(i), s) or not _isolated(z, int(i)):
            continue
        shared = max(SHARED_K, 0.5 * float(z[i]))
        if any(zo[i] > shared for k, zo in scores.items() if k != name):
            continue
        return int(i), s
    return None


def _isolated(z: np.ndarray, i: int) -> bool:
    """The change i -> i+1 stands alone: over the 3 changes before it and the 3 after it the
    median score is within :data:`SHARED_K` (a sensor answering heat keeps moving for several
    readings -- a kink of its trend, not a jump; a re-plugged sensor jumps once)."""
    around = [z[max(i - 3, 0):i], z[i + 1:i + 4]]
    return all(not len(a) or float(np.median(a)) < SHARED_K for a in around)


def _lasting(v: np.ndarray, i: int, s: float) -> bool:
    """The change i -> i+1 moves the level: the median of the :data:`STEP_WINDOW` readings
    after it minus the median of those up to it (less the local trend over that span) has
    the change's sign, at least half its size, and is beyond :data:`STEP_K` ``s`` itself (a
    spike, a burst of noise or a change taken back soon after is no offset step)."""
    w = STEP_WINDOW
    if i + 1 - w < 0 or i + 1 + w > len(v):
        w = min(i + 1, len(v) - i - 1)
    if w < 2:
        return False
    d1 = np.diff(v)
    near = np.concatenate([d1[max(i - w, 0):i], d1[i + 1:i + 1 + w]])
    level = float(np.median(v[i + 1:i + 1 + w]) - np.median(v[i + 1 - w:i + 1])
                  - w * np.median(near))
    step = float(d1[i])
    return (level * step > 0 and abs(level) >= 0.5 * abs(step) and abs(level) > STEP_K * s
            and not _relaxes(v, i, step) and _quiet(v, i, s))


def _relaxes(v: np.ndarray, i: int, step: float) -> bool:
    """After the change the reading relaxes back (a door opened, a draught: the air is
    replaced and warms again): over the ``2 STEP_WINDOW`` readings after the change its
    least-squares slope runs against the change and undoes more than a quarter of it."""
    after = v[i + 1:i + 1 + 2 * STEP_WINDOW]
    if len(after) < 4:
        return False
    slope = np.polyfit(np.arange(len(after)), after, 1)[0]
    return slope * step < 0 and abs(slope) * len(after) > 0.25 * abs(step)


def _quiet(v: np.ndarray, i: int, s: float) -> bool:
    """The sensor reads with its usual scatter round the change (a robust scale of its second
    differences within ``STEP_WINDOW`` readings each side, the change's own left out, at most
    3 ``s``): a change inside a burst of noise is no clean offset step."""
    w = STEP_WINDOW
    d2 = np.diff(v, 2)              # d2[j] centred on reading j + 1; the step touches i, i+1
    near = np.r_[d2[max(i - w, 0):max(i - 1, 0)], d2[i + 1:i + 1 + w]]
    return len(near) < 4 or 1.4826 * np.median(np.abs(near)) / np.sqrt(3.0) <= 3.0 * s
