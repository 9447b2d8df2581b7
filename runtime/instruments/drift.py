"""The ``drift`` instrument: a thermal drift test (ISO 230-3) -- a logger's run at one machine
position while the machine warms and cools (a spindle test with displacement sensors round a
test mandrel, an environmental temperature variation test, a lathe's tool-point drift).

File (``volerr formats drift``): a time column ``t_s``, ``t_min`` or ``t_h`` (read in seconds);
displacement channels ``d_<label>_um``; every other numeric column a logged input (temperatures
``T_<label>`` degC, spindle speed ``S_rpm``, feed, power ...); optional position columns
``X, Y, Z[, B, C]`` (constant in a run: the test position; axes not given stand at the middle of
their travel, rotary axes at 0), optional ``run`` (a label: a file is one run unless it says
otherwise; lags start afresh in every run), optional ``environment`` (a label per run, one
value within a run: the room behaviour or programme the run was logged in, e.g.
``constant``, ``varying``; the drift loop's folds then hold out whole environments).  Header lines ``# channel d_<label>: DIR [at
z=<mm>]`` give a channel's direction, ``DIR`` one of ``X Y Z -X -Y -Z`` (machine axes of the
workpiece frame) or ``?`` (not known, the default), and the sensor's height ``z`` on the
mandrel.  A logger's file as saved (``Time(min)``, ``ch1(um)``, ``t1(°C)``) is read by the
mapping of :mod:`volerr.instruments._drift_logger` (``volerr drift convert`` writes it out).

Reading and sign: a channel reads the displacement of the tool side relative to the workpiece
side along its direction, as the sensor reads it (positive when the mandrel moves towards +DIR
relative to the sensor's stand on the table), with any zero: ``d = dir . e(q, p) + z_c`` in um,
``e`` the volumetric error (tool point relative to the workpiece, workpiece frame) at the test
position ``q`` and the point ``p = (0, 0, z)`` of the tool frame (the sensor's height, mm, as
the probe offset ``Zp``; 0 when not given), ``z_c`` the channel's zero in that run (a set-up
unknown, um).  Two sensors of one direction at two heights read the spindle's tilt:
``(d(z2) - d(z1)) / (z2 - z1)`` (urad = um / mm).  A ``?`` channel is no row of the layout's
model (projection zero): its only model term is its zero; the loop models it on its own.

Observations: one point per reading of one channel (one row), channels after each other
within a run, runs in file order; ``info`` holds ``channel`` (label), ``run`` (label), ``t_s``
(s) per point; ``covariates`` every logged input and ``t_s`` (so lags run over seconds); each
run is its own entry of ``files`` (``file`` indexes it: lags restart in each run).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, require
from . import _drift_logger as logger
from . import _fields as f
from ._csv import Columns, read_columns, read_header
from .observations import FileInfo, Observations, Setup

KIND = "drift"
#: channel directions of the header lines, as unit vectors of the workpiece frame
DIRECTIONS = {"X": (1, 0, 0), "Y": (0, 1, 0), "Z": (0, 0, 1), "-X": (-1, 0, 0),
              "-Y": (0, -1, 0), "-Z": (0, 0, -1), "?": None}
TIME_COLUMNS = ("t_s", "t_min", "t_h")
#: the largest drift reading accepted, um (10 mm: beyond the range of the displacement
#: sensors of a thermal test -- capacitive and inductive probes read a few mm at most)
MAX_CHANNEL_UM = 10000.0
#: the least span of a channel over a file, um (10 nm): the noise of the displacement sensors
#: of a thermal test (capacitive: a few nm, inductive: tens of nm) and a machine's drift over
#: a test (a micrometre or more) give more; a drift of micrometres in mm under ``_um`` less
MIN_CHANNEL_SPAN_UM = 0.01
#: a channel column in a unit the reader does not convert (``d_<label>_nm``, ``_in`` ...)
_OTHER_UNIT = re.compile(r"d_\w+_(nm|m|cm|in|inch|mil|thou|mu|micron)", re.IGNORECASE)
POSITION_AXES = "XYZUVWABC"
#: a channel header line: ``# channel d_ch1: X at z=120`` (``d_`` and ``_um`` optional)
_CHANNEL_LINE = re.compile(r"^#\s*channel\s+(\S+?)\s*:\s*(.*?)\s*$", re.IGNORECASE)
_AT = re.compile(r"^(\S+)(?:\s+at\s+z\s*=\s*(\S+?)\s*(?:mm)?)?$", re.IGNORECASE)


@dataclass
class DriftRun:
    """One run of a drift file.

    ``file`` the file name; ``run`` its label (``"1"`` for a file of one run); ``t_s`` (N,)
    seconds from the file's time origin, strictly increasing; ``channels`` label -> (N,) um,
    the tool side relative to the workpiece side along the channel's direction, any zero;
    ``directions`` label -> ``X Y Z -X -Y -Z`` or ``?``; ``heights`` label -> the sensor's
    height ``z`` on the mandrel (mm, tool frame) or None; ``inputs`` name -> (N,) every other
    logged column (``T_*`` degC, ``S_rpm`` rpm, ...); ``position`` axis -> the test position
    (mm | deg) of the axes the file gives; ``rows`` (N,) the readings' data rows in the file
    (0-based)."""

    file: str
    run: str
    t_s: np.ndarray
    channels: dict
    directions: dict
    heights: dict
    inputs: dict
    position: dict = field(default_factory=dict)
    rows: np.ndarray | None = None
    #: columns left out (text columns such as a date), one line each
    notes: list = field(default_factory=list)
    #: the run's ``environment`` label ("" when the file has no such column)
    environment: str = ""
    #: the timestamp subtracted from the file's time column, s (its first reading, where
    #: that holds timestamps: ``_time``; 0 otherwise)
    time_origin_s: float = 0.0
    #: the run's label in the file's ``run`` column, also where the file holds one run
    #: ("" when the file has no such column; ``run`` is "" for a file of one run)
    label: str = ""

    @property
    def n(self) -> int:
        return len(self.t_s)

    @property
    def name(self) -> str:
        """The run as reported: the file name, ``FILE[run]`` when the file holds several."""
        return self.file if self.run == "" else f"{self.file}[{self.run}]"

    def __repr__(self) -> str:
        return (f"DriftRun({self.name!r}: {self.n} readings over {self.t_s[-1] - self.t_s[0]:g} s, "
                f"channels {', '.join(self.channels)}, {len(self.inputs)} inputs)")


def detect(names) -> bool:
    """A drift file has a time column and at least one displacement channel: by their drift
    names, or a logger's bracketed ones (``Time(min)``, ``ch1(um)``; the underscore forms of
    the mapping, ``ch1_um``, are other instruments' names: ``dx_um``, ``dr_um``)."""
    mapped = []
    for h in names:
        try:
            word = h.strip().lower()
            if word in logger.CLOCK_WORDS:              # Time, Timestamp: a time column
                mapped.append("t_s")
                continue
            bracketed = logger.BRACKET.match(h.strip())
            mapped.append(logger.drift_name(h, "file", "s") if bracketed else h.strip())
        except InputError:
            mapped.append(h)
    return (any(n in TIME_COLUMNS for n in mapped)
            and any(re.fullmatch(r"d_\w+_(um|mm)", n) for n in mapped))


def channel_lines(path) -> dict:
    """``# channel d_<label>: DIR [at z=<mm>]`` header lines -> {label: (DIR, z or None)}
    (InputError for an unknown direction word, a bad height or a channel given twice)."""
    where = Path(path).name
    out: dict = {}
    with open(Path(path), encoding="utf-8-sig") as fh:
        for line in fh:
            s = line.strip()
            if s and not s.startswith("#"):
                break
            m = _CHANNEL_LINE.match(s)
            if not m:
                continue
            label = re.sub(r"_um$", "", re.sub(r"^d_", "", m.group(1)))
            at = _AT.match(m.group(2))
            require(at is not None, f"{where}: header 'channel {m.group(1)}: {m.group(2)}' is "
                    f"not 'DIR [at z=<mm>]'")
            word = at.group(1).upper()
            require(word in DIRECTIONS, f"{where}: channel d_{label}: direction {at.group(1)!r}"
                    f" is not one of X Y Z -X -Y -Z ?")
            z = None
            if at.group(2) is not None:
                try:
                    z = float(at.group(2))
                except ValueError:
                    z = float("nan")
                require(np.isfinite(z), f"{where}: channel d_{label}: height "
                                        f"{at.group(2)!r} is not a number (mm)")
            require(label not in out, f"{where}: channel d_{label} has two header lines")
            out[label] = (word, z)
    return out


def _mapped_columns(path, mapping=None, time_unit=None) -> Columns:
    """The file's columns under their drift names (:mod:`._drift_logger`)."""
    c = read_columns(path)
    raw = [h.strip() for h in read_header(path)]
    found = logger.clock_time(raw, c.labels)
    if found is not None and found[0] not in (mapping or {}):   # clock times -> t_s
        name, secs, date = found
        c.numbers[name] = np.asarray(secs, dtype=float)
        mapping = {**(mapping or {}), name: "t_s"}
        for gone in (name, date):
            c.text.pop(gone, None)
            c.labels.pop(gone, None)
        if date is not None:
            raw = [h for h in raw if h != date]
    for h in raw:
        if h in c.labels and logger.split_unit(h)[0].lower() in logger.CLOCK_WORDS \
                and h not in (mapping or {}):
            cell = next((x for x in c.labels[h] if logger.clock_seconds([x]) is None),
                        c.labels[h][0])
            raise InputError(f"{c.name}: time column {h}: {cell!r} is neither a number nor a "
                             f"clock time (14:05:30, 2024-03-01 14:05:30, 01.03.2024 14:05:30; "
                             f"see volerr formats drift)")
    names = logger.map_header(raw, c.name, mapping, time_unit)
    rename = dict(zip(raw, names))
    for k, n in rename.items():             # a channel in mm is read in um
        if re.fullmatch(r"d_\w+_mm", n):
            rename[k] = n[:-3] + "_um"
            require(rename[k] not in names, f"{c.name}: both {n} and {rename[k]} given")
            if k in c.numbers:
                c.numbers[k] = c.numbers[k] * 1000.0
    return Columns({rename[k]: v for k, v in c.numbers.items()},
                   {rename[k]: v for k, v in c.text.items()},
                   {rename[k]: v for k, v in c.labels.items()}, c.name)


def _column_defects(c: Columns, needed) -> None:
    """A needed column that is empty, holds text, a blank cell or NaN: one line."""
    where = c.name
    for h in needed:
        if h in c.text:
            cells = c.labels.get(h, [])
            require(any(s.strip() for s in cells), f"{where}: column {h} is empty (no reading "
                                                   f"in any row)")
            blank = next((i for i, s in enumerate(cells) if not s.strip()), None)
            require(blank is None, f"{where}: column {h} row {(blank or 0) + 2} is empty")
            raise InputError(c.text[h] or f"{where}: column {h} is not numeric")
        f.require_finite(c.numbers[h], h, where)


#: a time column whose first reading lies beyond this (s, about 3 years) holds timestamps
#: (epoch seconds: 1.7e9 in 2024), not a time since the start of a test
TIMESTAMP_S = 1e8


def _time(c: Columns) -> tuple[str, np.ndarray, float]:
    """(the time column, its readings in s, the origin subtracted): timestamps
    (:data:`TIMESTAMP_S`) are read as seconds since the file's first reading, as clock
    times are (the origin, in the column's seconds, is returned; else 0)."""
    where = c.name
    present = [h for h in TIME_COLUMNS if h in c.numbers or h in c.text]
    require(len(present) == 1, f"{where}: " + (
        f"several time columns ({', '.join(present)})" if present else
        "no time column (t_s, t_min or t_h; see volerr formats drift)"))
    h, origin = present[0], 0.0
    v = np.asarray(c.numbers.get(h, []), dtype=float) * logger.SECONDS[h]
    if len(v) and np.all(np.isfinite(v)) and v[0] > TIMESTAMP_S:
        origin = float(v[0])
        c.numbers[h] = (v - origin) / logger.SECONDS[h]
    _column_defects(c, present)
    return h, c.numbers[h] * logger.SECONDS[h], origin


def _runs(c: Columns, n: int) -> tuple[list, np.ndarray]:
    """Run labels in order of appearance and each row's run index."""
    if "run" not in c.numbers and "run" not in c.labels:
        return [""], np.zeros(n, int)
    raw = (c.labels["run"] if "run" in c.labels else [f"{x:g}" for x in c.numbers["run"]])
    blank = next((i for i, s in enumerate(raw) if not str(s).strip()), None)
    require(blank is None, f"{c.name}: column run row {(blank or 0) + 2} is empty")
    labels: dict = {}
    idx = np.array([labels.setdefault(str(s).strip(), len(labels)) for s in raw])
    return list(labels), idx


def _check_time(t: np.ndarray, rows: np.ndarray, where: str, tcol: str) -> None:
    """Strictly increasing time within a run: a step back or a repeated time is one line."""
    step = np.diff(t)
    k = np.flatnonzero(step <= 0)
    if len(k):
        i, j = int(rows[k[0]]) + 2, int(rows[k[0] + 1]) + 2
        require(step[k[0]] != 0, f"{where}: row {j} repeats the time of row {i} ({tcol}; "
                                 f"duplicated timestamps)")
        raise InputError(f"{where}: time goes back at row {j} ({tcol}; the time must increase "
                         f"within a run)")


def _channels(c: Columns, heads: dict) -> list:
    """The channel columns, in file order; header lines of absent channels and a file without
    a channel refused."""
    where = c.name
    for h in read_order(c):
        m = _OTHER_UNIT.fullmatch(h)
        require(m is None, f"{where}: column {h}: a displacement channel's unit is um or mm, "
                           f"not {m and m.group(1)!r}; convert it to um (d_<label>_um)")
    names = [h for h in list(c.numbers) + list(c.text) if re.fullmatch(r"d_\w+_um", h)]
    order = {h: i for i, h in enumerate(read_order(c))}
    names.sort(key=lambda h: order.get(h, 0))
    require(bool(names), f"{where}: no displacement channel d_<label>_um (see volerr formats "
                         f"drift)")
    labels = [h[2:-3] for h in names]
    extra = [k for k in heads if k not in labels]
    require(not extra, f"{where}: header line for channel d_{extra[0] if extra else ''} but "
                       f"no column d_{extra[0] if extra else ''}_um")
    _column_defects(c, names)
    for h in names:
        big = np.flatnonzero(np.abs(c.numbers[h]) > MAX_CHANNEL_UM)
        require(len(big) == 0, f"{where}: column {h} row {big[0] + 2 if len(big) else 0} = "
                f"{c.numbers[h][big[0]] if len(big) else 0:g} um is beyond what a displacement "
                f"sensor reads ({MAX_CHANNEL_UM / 1000:g} mm): likely nm headed um, or a wrong "
                f"unit")
    return names


def _channel_span(v: np.ndarray, h: str, where: str, run: str) -> None:
    """A channel's span over a run (um) that no thermal drift has: 1 mm or more (nm under
    ``_um``; :data:`volerr.instruments._drift_logger.MAX_DRIFT_RANGE_MM`, the rule of a
    ``(mm)`` header in ``drift convert``) or less than :data:`MIN_CHANNEL_SPAN_UM` (mm under
    ``_um``); one line.  A constant channel is :func:`_constant_sensor`'s."""
    span, inside = float(np.ptp(v)), f" in run {run}" if run else " over the run"
    require(span < 1000.0 * logger.MAX_DRIFT_RANGE_MM,
            f"{where}: column {h} drifts by {span:g} um{inside}, beyond any thermal drift "
            f"({logger.MAX_DRIFT_RANGE_MM:g} mm): likely readings in nm under the _um header; "
            f"give um")
    require(not 0 < span < MIN_CHANNEL_SPAN_UM,
            f"{where}: column {h} spans {span:.3g} um{inside}, below what a displacement "
            f"sensor's noise and a machine's drift give ({MIN_CHANNEL_SPAN_UM:g} um): likely "
            f"readings in mm under the _um header; give um")


#: a channel whose every reading lies in this range (um) reads like a room's temperatures
#: (degC) ...
ROOM_LIKE = (10.0, 40.0)
#: ... and a temperature whose first reading is within this of 0 (degC) like a zeroed channel
ZERO_LIKE_C = 0.5


def _refuse_swapped(c: Columns, names, temps: dict, where: str) -> None:
    """One line when a temperature column starts at a channel's zero (:data:`ZERO_LIKE_C`)
    while a channel reads a room's temperatures (:data:`ROOM_LIKE`): the temperature and
    drift columns swapped in the header (no machine sensor reads 0 degC in a drift test)."""
    cold = next((h for h, v in temps.items() if abs(v[0]) <= ZERO_LIKE_C), None)
    room = next((h for h in names if ROOM_LIKE[0] <= np.min(c.numbers[h])
                 and np.max(c.numbers[h]) <= ROOM_LIKE[1]), None)
    if cold is None or room is None:
        return
    v = c.numbers[room]
    raise InputError(f"{where}: column {cold} starts at {temps[cold][0]:g} degC like a zeroed "
                     f"channel, and {room} reads {np.min(v):.4g} .. {np.max(v):.4g} um like a "
                     f"room's temperatures: temperature and drift columns swapped? check the "
                     f"header")


#: an input whose correlation with a channel is this close to 1 (in size) is the channel
#: again: logged inputs and readings never agree so (their noises are independent), while a
#: copy rescaled (nm, mm) and printed to 6 digits or more agrees to 1e-10; judged on this
#: many readings or more (two readings always correlate 1, three may by chance)
COPY_CORRELATION = 1 - 1e-9
COPY_MIN_READINGS = 10


def _collinear(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether ``a`` and ``b`` agree up to scale and offset (correlation ``COPY_CORRELATION``
    or closer to 1 in size; never for a constant)."""
    x, y = a - np.mean(a), b - np.mean(b)
    den = float(np.sqrt(np.dot(x, x) * np.dot(y, y)))
    return den > 0 and abs(float(np.dot(x, y))) >= COPY_CORRELATION * den


def _refuse_channel_copy(c: Columns, names, inputs, where: str, t=None) -> None:
    """One line when a logged input is a channel again (up to scale and offset: the channel
    exported twice, or in another unit under another name): a model would fit the measurand
    with itself.  A channel that is itself a straight line in time ``t`` (s; a noise-free
    ramp, as a simulated or a hand-written test file has it) is not judged: any other ramp,
    a temperature rising steadily, agrees with it as closely without being a copy."""
    if c.n < COPY_MIN_READINGS:
        return
    for ch in names:
        if t is not None and _collinear(c.numbers[ch], t):
            continue
        for h in inputs:
            require(not _collinear(c.numbers[h], c.numbers[ch]),
                    f"{where}: column {h} is channel {ch} again (correlation 1: a copy up to "
                    f"scale and offset): the channel exported twice? an input must be logged "
                    f"beside the channel, not be it")


def read_order(c: Columns) -> list:
    """Column names of ``c`` in one stable order (numbers first as read, then text)."""
    return list(c.numbers) + [h for h in c.text if h not in c.numbers]


def _constant_sensor(v: np.ndarray, h: str, where: str, run: str) -> None:
    require(np.ptp(v) > 0, f"{where}: {h} is constant{' in run ' + run if run else ''} "
                           f"(= {v[0]:g}): a sensor disconnected or stuck?")


def _position(c: Columns, idx: np.ndarray, where: str, run: str) -> dict:
    out = {}
    for h, v in c.numbers.items():
        m = re.fullmatch(r"([XYZUVWABC])(_mm|_deg)?", h)
        if not m:
            continue
        vals = np.unique(v[idx])
        require(len(vals) == 1, f"{where}: position {h} changes{' in run ' + run if run else ''}"
                                f" ({vals[0]:g} .. {vals[-1]:g}); a drift run holds one position")
        out[m.group(1)] = float(vals[0])
    return out


#: the largest drift file read, bytes (100 MB: a week at one reading a second with ten
#: columns is about 50 MB; reading holds some 25 bytes of memory per byte of the file, the
#: loop more, so a week at 0.01 s -- 3 GB -- would exhaust the memory, not be refused)
MAX_FILE_BYTES = 100 * 2 ** 20


def refuse_huge(path) -> None:
    """One line for a drift file larger than :data:`MAX_FILE_BYTES`, before it is read
    (nothing for a missing file: the reader names it)."""
    p = Path(path)
    size = p.stat().st_size if p.is_file() else 0
    require(size <= MAX_FILE_BYTES,
            f"{p.name}: {size / 2 ** 20:.0f} MB is more than a drift file holds "
            f"({MAX_FILE_BYTES / 2 ** 20:.0f} MB: a week at one reading a second is about 50 "
            f"MB); readings every 0.01 s? a thermal drift changes over minutes: resample to "
            f"1 s or coarser")


def read_runs(path, mapping: dict | None = None, time_unit: str | None = None,
              keep_constant: bool = False) -> list:
    """Read a drift file into its :class:`DriftRun` (one per run label, in order of
    appearance); InputError (one line) on every defect of the module docstring's list.
    ``keep_constant``: a ``T_*`` input constant over a run is kept (the drift loop leaves it
    out and names it, :func:`faults`), not refused."""
    path = Path(path)
    refuse_huge(path)
    c = _mapped_columns(path, mapping, time_unit)
    where, n = c.name, c.n
    tcol, t, origin = _time(c)
    heads = channel_lines(path)
    names = _channels(c, heads)
    labels, run_of = _runs(c, n)
    skip = set(names) | {tcol, "run", ENVIRONMENT} | {h for h in c.numbers
                                         if re.fullmatch(r"[XYZUVWABC](_mm|_deg)?", h)}
    inputs = [h for h in c.numbers if h not in skip]
    _column_defects(c, inputs)
    f.check_time(t, tcol, where)
    temps = {h: c.numbers[h] for h in inputs if f.is_temperature(h)}
    for h, v in temps.items():
        f.check_temperature(v, h, where)
    f.check_temperatures_together(temps, where)
    _refuse_swapped(c, names, temps, where)
    _refuse_channel_copy(c, names, inputs, where, t)
    notes = _text_inputs(c, skip)
    out = []
    for r, label in enumerate(labels):
        idx = np.flatnonzero(run_of == r)
        shown = label if len(labels) > 1 else ""
        _check_time(t[idx], idx, where, tcol)
        require(len(idx) >= 2, f"{where}: run {label} has one reading; a drift run needs two "
                               f"or more")
        chans = {h[2:-3]: c.numbers[h][idx] for h in names}
        for h in names:
            _constant_sensor(c.numbers[h][idx], h, where, shown)
            _channel_span(c.numbers[h][idx], h, where, shown)
        for h in inputs:
            if h.startswith("T_") and not keep_constant:
                _constant_sensor(c.numbers[h][idx], h, where, shown)
        out.append(DriftRun(
            where, shown or ("" if len(labels) == 1 else label), t[idx], chans,
            {k: heads.get(k, ("?", None))[0] for k in chans},
            {k: heads.get(k, ("?", None))[1] for k in chans},
            {h: c.numbers[h][idx] for h in inputs}, _position(c, idx, where, shown), idx,
            notes, _environment(c, idx, where, shown), origin, label))
    return out


#: the optional column naming the environment (room behaviour, programme) of each run
ENVIRONMENT = "environment"


def _environment(c: Columns, idx: np.ndarray, where: str, run: str) -> str:
    """The run's ``environment`` label ("" without the column); one line refuses a blank
    cell or a label that changes within the run."""
    if ENVIRONMENT not in c.numbers and ENVIRONMENT not in c.labels:
        return ""
    raw = (c.labels[ENVIRONMENT] if ENVIRONMENT in c.labels
           else [f"{x:g}" for x in c.numbers[ENVIRONMENT]])
    cells = [str(raw[i]).strip() for i in idx]
    blank = next((i for i, s in zip(idx, cells) if not s), None)
    require(blank is None, f"{where}: column {ENVIRONMENT} row {(blank or 0) + 2} is empty "
                           f"(one label per run: e.g. constant, varying)")
    found = list(dict.fromkeys(cells))
    require(len(found) == 1, f"{where}: column {ENVIRONMENT} changes within "
            f"{'run ' + run if run else 'the run'} ({found[0]}, {found[-1]}); one environment "
            f"per run (a run column splits the file into runs)")
    return found[0]


def _text_inputs(c: Columns, skip) -> list:
    """Text columns besides the run label: a temperature or speed, or a column numeric but
    for a cell, is refused (one line); a column of labels (a date, a comment) is left out with
    a note."""
    notes = []
    for h, msg in c.text.items():
        if h in skip:
            continue
        require(msg is None and not h.startswith(("T_", "S_")),
                msg or f"{c.name}: column {h} is not numeric")
        notes.append(f"column {h} is not numeric: left out of the inputs")
    return notes


def faults(run: DriftRun) -> list:
    """The faulty sensors of a run (:func:`volerr.instruments._fields.sensor_faults`: a
    temperature frozen or stepped against its own reading-to-reading scatter; a channel
    frozen), each {"input", "fault", ..., "file", "run"}; a channel's fault is marked
    ``"channel": True``.  A step of a channel is not judged: a machine's displacement jumps
    when a spindle starts or stops (FL_THERMAL's channels do, unlogged in their speed)."""
    temps = {h: v for h, v in run.inputs.items() if f.is_temperature(h)}
    out = f.sensor_faults(run.t_s, temps, run.inputs)
    for label, v in run.channels.items():
        span = f.frozen_stretch(v)
        if span is not None:
            out.append({"input": f"d_{label}_um", "fault": "frozen", "channel": True,
                        "from_s": float(run.t_s[span[0]]), "to_s": float(run.t_s[span[1]]),
                        "readings": int(span[1] - span[0] + 1)})
    for e in out:
        e.update(file=run.file, run=run.run)
    return out


def fault_where(e: dict) -> str:
    """Where a fault of :func:`faults` is: its file, and ``[run]`` for a run of a file of
    several."""
    return e["file"] if not e.get("run") else f"{e['file']}[{e['run']}]"


def fault_text(e: dict) -> str:
    """One fault of :func:`faults` in words (times in s of the run's file)."""
    where = fault_where(e)
    if e["fault"] == "constant":
        return (f"{e['input']} constant in {where} (= {e['value']:g} in all {e['readings']} "
                f"readings: disconnected, stuck, or steadier than its resolution)")
    if e["fault"] == "frozen":
        return (f"{e['input']} frozen in {where} from t = {e['from_s']:.0f} s to "
                f"{e['to_s']:.0f} s ({e['readings']} equal readings)")
    return (f"{e['input']} steps by {e['step']:+.3g} at t = {e['at_s']:.0f} s in {where} "
            f"({abs(e['step']) / e['noise']:.0f}x its reading-to-reading scatter "
            f"{e['noise']:.2g})")


def test_position(run: DriftRun, model) -> dict:
    """Every axis of ``model`` at the run's position (absent axes: middle of the travel,
    rotary axes 0 when inside it), inside the travel."""
    where = run.name
    extra = [a for a in run.position if a not in model.axes]
    require(not extra, f"{where}: position column {extra[0] if extra else ''} is not an axis of "
                       f"layout {model.name} ({' '.join(model.axes)}): layout mismatch")
    out = {}
    for a in model.axes:
        lo, hi = model.travel[a]
        default = 0.0 if a in model.rotary_axes and lo <= 0 <= hi else 0.5 * (lo + hi)
        v = run.position.get(a, default)
        require(lo - 1e-9 <= v <= hi + 1e-9, f"{where}: {a} = {v:g} lies outside the travel "
                                              f"[{lo:g}, {hi:g}] of layout {model.name}")
        out[a] = v
    return out


def run_observations(run: DriftRun, model) -> Observations:
    """One run -> :class:`Observations` (module docstring): one point per reading of each
    channel; each channel's zero its own set-up group."""
    labels = list(run.channels)
    n, k = run.n, len(labels)
    total = n * k
    pos = test_position(run, model)
    probe = np.zeros((total, 3))
    proj = np.zeros((total, 3, 3))
    dev = np.zeros((total, 3))
    group = np.repeat(np.arange(k), n)
    local = np.zeros((total, 3, k))
    local[np.arange(total), 0, group] = 1.0          # the channel's zero, mm per mm
    for j, lab in enumerate(labels):
        sl = slice(j * n, (j + 1) * n)
        dev[sl, 0] = run.channels[lab] * 1e-3
        probe[sl, 2] = run.heights[lab] or 0.0
        vec = DIRECTIONS[run.directions[lab]]
        if vec is not None:
            proj[sl, 0, :] = vec
    covs = {h: np.tile(v, k) for h, v in run.inputs.items()}
    covs["t_s"] = np.tile(run.t_s, k)
    names = [f"{run.name}:{lab}" for lab in labels]
    setup = Setup(group[:, None], local, names, [("zero",)] * k,
                  [("local", j) for j in range(k)], [("um",)] * k)
    info = {"channel": np.repeat(np.array(labels, dtype=object), n),
            "run": np.full(total, run.run, dtype=object), "t_s": np.tile(run.t_s, k)}
    rows = np.tile(run.rows if run.rows is not None else np.arange(n), k)
    return Observations({a: np.full(total, v) for a, v in pos.items()}, probe, dev, covs,
                        list(run.notes),
                        proj, np.ones(total, int), None, setup, np.zeros(total, int), rows,
                        (FileInfo(run.name, KIND, "um", 1),), None, info)


def read(path, model) -> Observations:
    """Read a drift file into :class:`Observations` for ``model`` (InputError, one line); a
    file of several runs is their stack (each run its own ``files`` entry)."""
    from .observations import stack

    runs = read_runs(path)
    return stack([run_observations(r, model) for r in runs])


def convert(path, mapping: dict | None = None, time_unit: str | None = None,
            channels: dict | None = None) -> tuple[str, list]:
    """A logger's file -> (the text of its ``drift`` file, its :class:`DriftRun`): the header
    mapping of :mod:`volerr.instruments._drift_logger` (``mapping`` {raw: name} over its
    rules), the time in seconds (``time_unit`` ``s|min|h`` for a time column without a unit),
    ``channels`` {label: ``DIR [at z=<mm>]``} written as header lines.  The text is read back
    by :func:`read_runs`, so a file that converts is a file that reads (InputError, one line,
    naming the raw file, otherwise)."""
    import tempfile

    require(time_unit in (None, "s", "min", "h"), f"--time-unit: {time_unit!r} is not one of "
                                                  f"s, min, h")
    refuse_huge(path)
    text = logger.convert(path, mapping, time_unit, channels)
    with tempfile.TemporaryDirectory() as tmp:
        probe = Path(tmp) / Path(path).name
        probe.write_text(text, encoding="utf-8")
        runs = read_runs(probe)
    return text, runs
