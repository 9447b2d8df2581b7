"""A thermal logger's file as saved, read as a ``drift`` file: the header mapping and the
conversion (``volerr drift convert``).

Loggers name their columns as their software likes (``Time``, ``時間(s)``, ``ch1(um)``,
``t1(°C)``, ``spindle(RPM)``).  The default mapping (:func:`drift_name`), applied to every
header cell that is not already a ``drift`` name, one rule per cell, the first that fits:

1. a time column -- a name ``time``, ``t``, ``zeit``, ``時間``, ``时间`` (any case) with its
   unit in brackets or after an underscore: ``(s)`` ``(sec)`` -> ``t_s``, ``(min)`` ->
   ``t_min``, ``(h)`` ``(hr)`` -> ``t_h``.  Without a unit the time is refused (say the unit:
   ``volerr drift convert --time-unit min``);
2. a displacement, unit ``um`` / ``µm`` / ``μm``: ``ch1(um)`` -> ``d_ch1_um``; unit ``mm``:
   ``d_<label>_mm`` (converted to um by ``drift convert``, refused by the reader);
3. a temperature, unit ``°C`` / ``degC`` / ``C`` / ``℃``: ``t1(°C)`` -> ``T_1`` (a name that is
   ``t`` or ``T`` followed by digits keeps the digits), ``motor(°C)`` -> ``T_motor``;
4. a speed, unit ``rpm`` / ``1/min``: ``spindle(RPM)``, ``S(rpm)``, ``speed(rpm)`` -> ``S_rpm``
   (the spindle speed); another name ``NAME(rpm)`` -> ``NAME_rpm``;
5. any other ``NAME(unit)`` -> ``NAME_unit``; a name without a unit is kept.

**Clock times.**  A time column (a time word above, or ``datetime``, ``timestamp``) whose cells
are clock times or dates with times -- ``14:05:30``, ``14:05:30.250``, ``14:05``,
``2024-03-01 14:05:30`` (or with ``T``), ``2024/03/01 14:05:30``, ``01.03.2024 14:05:30`` --
becomes ``t_s``, seconds from its first cell (:func:`clock_seconds`: the first of these forms
that reads every cell; day-first and month-first slashed dates such as ``03/01/2024`` are
ambiguous and refused).  A clock without a date that goes back by more than 12 h has passed
midnight (a day added).  A separate date column (``date``, ``datum``, ``日付``) beside a clock
column is joined to it (and not kept as an input).

Labels are made identifiers: every run of characters other than letters, digits and ``_``
becomes one ``_``.  ``--map "RAW=NAME,..."`` overrides the rule of any column.
"""

from __future__ import annotations

import re

from datetime import datetime

from ..errors import require, require_file

#: names of a time column (lower case), in the loggers' languages
TIME_WORDS = ("time", "t", "zeit", "時間", "时间", "temps", "tiempo", "tempo")
#: time units (lower case) -> the drift time column
TIME_UNITS = {"s": "t_s", "sec": "t_s", "secs": "t_s", "second": "t_s", "seconds": "t_s",
              "min": "t_min", "mins": "t_min", "minute": "t_min", "minutes": "t_min",
              "h": "t_h", "hr": "t_h", "hrs": "t_h", "hour": "t_h", "hours": "t_h"}
#: seconds per unit of each drift time column
SECONDS = {"t_s": 1.0, "t_min": 60.0, "t_h": 3600.0}
_UM = ("um", "µm", "μm", "micron", "microns")
_DEGC = ("°c", "degc", "c", "℃", "deg c", "° c")
_RPM = ("rpm", "1/min", "min-1", "u/min")
_SPINDLE = ("spindle", "s", "speed", "n", "spindle speed", "spindle_speed", "sp")
#: ``NAME(unit)``, ``NAME [unit]``, ``NAME_unit`` (the last only for known units)
BRACKET = re.compile(r"^(.*?)\s*[(\[]\s*([^)\]]*)\s*[)\]]\s*$")


def _ident(text: str) -> str:
    out = re.sub(r"[^0-9A-Za-z_]+", "_", text.strip()).strip("_")
    return out


def split_unit(cell: str) -> tuple[str, str | None]:
    """``'ch1(um)'`` -> (``'ch1'``, ``'um'``); ``'Time'`` -> (``'Time'``, None)."""
    m = BRACKET.match(cell.strip())
    if m:
        return m.group(1).strip(), m.group(2).strip()
    head, sep, tail = cell.strip().rpartition("_")
    known = set(TIME_UNITS) | set(_UM) | {"mm"} | set(_DEGC) | set(_RPM)
    if sep and head and tail.lower() in known:
        return head, tail
    return cell.strip(), None


def is_drift_name(name: str) -> bool:
    """Already a ``drift`` column name (time, channel, temperature, speed, position, run)."""
    return bool(re.fullmatch(r"t_(s|min|h)|d_\w+_um|T_\w+|S_rpm|run", name)
                or re.fullmatch(r"[XYZABCUVW](_mm|_deg)?", name))


def drift_name(cell: str, where: str, time_unit: str | None = None) -> str:
    """The ``drift`` name of one header cell by the module's rules (InputError for a time
    column without a unit when ``time_unit`` is not given)."""
    cell = cell.strip()
    if is_drift_name(cell):
        return cell
    name, unit = split_unit(cell)
    low, ulow = name.lower(), (unit or "").lower()
    if low in TIME_WORDS:
        if unit is None:
            require(time_unit is not None, f"{where}: time column {cell!r} has no unit; "
                    f"convert the file with 'volerr drift convert {where} --out drift.csv "
                    f"--time-unit s|min|h' (see volerr formats drift)")
            ulow = time_unit
        require(ulow in TIME_UNITS, f"{where}: time column {cell!r}: unit {unit!r} is not "
                                    f"one of s, min, h")
        return TIME_UNITS[ulow]
    label = _ident(name)
    if ulow in _UM + ("mm",):
        label = re.sub(r"^d_(?=.)", "", label)
    if ulow in _UM:
        return f"d_{label}_um"
    if ulow == "mm" and not re.fullmatch(r"[XYZABCUVW]", name):
        return f"d_{label}_mm"
    if ulow in _DEGC:
        m = re.fullmatch(r"[tT]_?(\d+)", label)
        return f"T_{m.group(1) if m else label}"
    if ulow in _RPM:
        return "S_rpm" if low in _SPINDLE else f"{label}_rpm"
    if unit:
        return f"{label}_{_ident(unit)}"
    return label or cell


def parse_map(text: str | None) -> dict:
    """``--map "RAW=NAME,RAW2=NAME2"`` -> {RAW: NAME} (InputError for a malformed entry)."""
    out: dict = {}
    for part in [p for p in re.split(r",(?![^()\[\]]*[)\]])", text or "") if p.strip()]:
        raw, sep, new = part.rpartition("=")
        require(bool(sep and raw.strip() and new.strip()),
                f"--map: {part.strip()!r} is not RAW=NAME")
        require(raw.strip() not in out, f"--map: column {raw.strip()!r} given twice")
        out[raw.strip()] = new.strip()
    return out


def map_header(header, where: str, mapping: dict | None = None,
               time_unit: str | None = None) -> list:
    """Every header cell's ``drift`` name: ``mapping`` first, else :func:`drift_name`;
    InputError when two cells get the same name or a mapped column is not in the file."""
    mapping = dict(mapping or {})
    cells = [h.strip() for h in header]
    missing = [k for k in mapping if k not in cells]
    require(not missing, f"{where}: --map names column {missing[0] if missing else ''!r}, "
                         f"which the file does not have")
    out = [mapping[h] if h in mapping else drift_name(h, where, time_unit) for h in cells]
    seen: dict = {}
    for h, n in zip(cells, out):
        first = seen.setdefault(n, h)
        require(first == h, f"{where}: columns {first!r} and {h!r} both become {n!r}; "
                            f"name one with --map")
    return out


def parse_channels(items) -> dict:
    """``--channel "ch1=X at z=120"`` (repeatable) -> {label: "X at z=120"}."""
    out: dict = {}
    for item in items or ():
        label, sep, spec = str(item).partition("=")
        label = re.sub(r"_um$", "", re.sub(r"^d_", "", label.strip()))
        require(bool(sep and label and spec.strip()),
                f"--channel: {item!r} is not LABEL=DIR [at z=<mm>]")
        require(label not in out, f"--channel: channel {label} given twice")
        out[label] = spec.strip()
    return out


def _raw_rows(path) -> tuple[list, list]:
    """(comment lines, CSV rows) of a logger's file (UTF-8, BOM allowed; the delimiter rule of
    :func:`volerr.fileio.sniff_delimiter`)."""
    import csv
    import io
    from pathlib import Path

    from ..errors import InputError
    from ..fileio import sniff_delimiter

    p = Path(path)
    require_file(p, f"data file not found: {path}")
    try:
        text = p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise InputError(f"{p.name}: not a UTF-8 text file (save the logger's export as "
                         f"UTF-8 CSV)") from None
    comments, rows = [], []
    try:
        for cells in csv.reader(io.StringIO(text), delimiter=sniff_delimiter(text)):
            if cells and cells[0].lstrip().startswith("#"):
                comments.append(",".join(cells).strip())
            elif any(c.strip() for c in cells):
                rows.append([c.strip() for c in cells])
    except csv.Error as exc:
        raise InputError(f"{p.name}: not a readable CSV ({exc})") from None
    require(len(rows) >= 2, f"{p.name}: no data rows")
    return comments, rows


#: the largest thermal drift of a displacement channel over a test, mm: spindle and structure
#: drifts are micrometres to a few hundred micrometres; 1 mm or more is um under a (mm) header
MAX_DRIFT_RANGE_MM = 1.0


def _check_mm_drift(cells, head: str, where: str) -> None:
    """Refuse a channel headed mm whose range over the test is :data:`MAX_DRIFT_RANGE_MM` or
    more (one line naming the file and the column: likely um under a (mm) header)."""
    vals = []
    for c in cells:
        try:
            vals.append(float(c))
        except ValueError:
            continue    # the reader names a cell that is not a number
    vals = [v for v in vals if v == v and abs(v) != float("inf")]
    if len(vals) < 2:
        return
    span = max(vals) - min(vals)
    require(span < MAX_DRIFT_RANGE_MM,
            f"{where}: column {head} drifts by {span:g} mm over the test, beyond any thermal "
            f"drift ({MAX_DRIFT_RANGE_MM:g} mm): likely readings in um under a (mm) header; "
            f"head it (um)")


def _scaled(cell: str, factor: float) -> str:
    """A cell multiplied by ``factor`` (the cell as it was when ``factor`` is 1 or it is not a
    number: the reader names it)."""
    if factor == 1.0:
        return cell
    try:
        return repr(float(cell) * factor)
    except ValueError:
        return cell


def _clock_rows(rows: list, mapping: dict | None) -> list:
    """The raw rows with a clock time column as seconds (``t_s``) and its date column
    dropped (:func:`clock_time`); unchanged without one or when ``mapping`` names it."""
    header = [h.strip() for h in rows[0]]
    cols = {h: [r[j] if j < len(r) else "" for r in rows[1:]] for j, h in enumerate(header)}
    text = {h: v for h, v in cols.items() if not all(_is_number(c) for c in v)}
    found = clock_time(header, text)
    if found is None or found[0] in (mapping or {}):
        return rows
    name, secs, date = found
    j = header.index(name)
    out = [[("t_s" if k == j else c) for k, c in enumerate(rows[0])]]
    out += [[(repr(float(secs[i])) if k == j else c) for k, c in enumerate(r)]
            for i, r in enumerate(rows[1:])]
    if date is not None:
        d = header.index(date)
        out = [[c for k, c in enumerate(r) if k != d] for r in out]
    return out


def _is_number(cell: str) -> bool:
    try:
        float(cell)
        return True
    except ValueError:
        return False


def convert(path, mapping: dict | None = None, time_unit: str | None = None,
            channels: dict | None = None) -> str:
    """A logger's file -> the text of a ``drift`` file: header cells renamed (``mapping`` over
    the module's rules), the time in seconds (``t_min``, ``t_h`` and ``--time-unit`` scaled),
    mm channels in um, every other cell as written; the file's ``#`` lines kept and a line
    ``# channel d_<label>: SPEC`` for each of ``channels``.  The result is not checked here
    (:func:`volerr.instruments.drift.read_runs` reads it)."""
    from pathlib import Path

    where = Path(path).name
    comments, rows = _raw_rows(path)
    rows = _clock_rows(rows, mapping)
    names = map_header(rows[0], where, mapping, time_unit)
    factors = []
    for j, n in enumerate(names):
        if n in SECONDS and n != "t_s":
            factors.append(SECONDS[n])
            names[j] = "t_s"
        elif re.fullmatch(r"d_\w+_mm", n):
            factors.append(1000.0)
            names[j] = n[:-3] + "_um"
        else:
            factors.append(1.0)
    for j, f in enumerate(factors):
        if f == 1000.0:
            _check_mm_drift([r[j] for r in rows[1:] if j < len(r)], rows[0][j], where)
    twice = sorted({n for n in names if names.count(n) > 1})
    require(not twice, f"{where}: two columns become the same drift column "
                       f"({', '.join(twice)}); name one with --map")
    present = {n[2:-3] for n in names if re.fullmatch(r"d_\w+_um", n)}
    for label in channels or {}:
        require(label in present, f"--channel: {where} has no channel {label} (channels: "
                                  f"{', '.join(sorted(present)) or 'none'})")
    lines = [c for c in comments if not re.match(r"#\s*channel\s", c, re.IGNORECASE)
             or re.sub(r"^#\s*channel\s+(?:d_)?(\S+?)(?:_um)?\s*:.*$", r"\1", c)
             not in (channels or {})]
    lines.append(f"# converted by volerr drift convert from {where}")
    lines += [f"# channel d_{k}: {v}" for k, v in (channels or {}).items()]
    import csv
    import io

    buf = io.StringIO()
    out = csv.writer(buf, lineterminator="\n")        # a cell with a comma stays one cell
    out.writerow(names)
    for r in rows[1:]:
        out.writerow([_scaled(cell, f) for cell, f in zip(r, factors)]
                     + [""] * (len(names) - len(r)))
    return "\n".join(lines) + "\n" + buf.getvalue()


#: names of a column of dates or timestamps (lower case)
CLOCK_WORDS = TIME_WORDS + ("datetime", "timestamp", "date_time", "zeitstempel", "日時")
DATE_WORDS = ("date", "datum", "日付", "fecha", "data")
#: the clock forms, tried in this order; a form must read every cell
CLOCK_FORMATS = ("%Y-%m-%d %H:%M:%S.%f", "%Y-%m-%d %H:%M:%S", "%Y-%m-%dT%H:%M:%S.%f",
                 "%Y-%m-%dT%H:%M:%S", "%Y/%m/%d %H:%M:%S", "%d.%m.%Y %H:%M:%S",
                 "%Y-%m-%d %H:%M", "%d.%m.%Y %H:%M", "%H:%M:%S.%f", "%H:%M:%S", "%H:%M")


def clock_seconds(cells) -> list | None:
    """Seconds from the first cell of clock / date-time cells (module docstring), or None when
    no form of :data:`CLOCK_FORMATS` reads every cell."""
    cells = [str(c).strip() for c in cells]
    for fmt in CLOCK_FORMATS:
        try:
            stamps = [datetime.strptime(c, fmt) for c in cells]
        except ValueError:
            continue
        secs = [(d - stamps[0]).total_seconds() for d in stamps]
        if "%d" not in fmt:                     # a clock alone: passing midnight adds a day
            day, out = 0.0, []
            for k, v in enumerate(secs):
                if k and v + day < out[-1] - 43200.0:
                    day += 86400.0
                out.append(v + day)
            secs = out
        return secs
    return None


def clock_time(header, text_cells: dict) -> tuple | None:
    """(the raw time column, its seconds, the raw date column joined or None) of a file whose
    time column holds clock times (``text_cells``: raw name -> cells of its text columns), or
    None."""
    names = [h.strip() for h in header]
    dates = [h for h in names if split_unit(h)[0].lower() in DATE_WORDS and h in text_cells]
    for h in names:
        if split_unit(h)[0].lower() not in CLOCK_WORDS or h not in text_cells:
            continue
        cells = text_cells[h]
        if dates and clock_seconds(cells) is not None and ":" in cells[0] \
                and "-" not in cells[0] and "." not in cells[0].split(":")[0]:
            joined = [f"{d} {c}" for d, c in zip(text_cells[dates[0]], cells)]
            secs = clock_seconds(joined)
            if secs is not None:
                return h, secs, dates[0]
        secs = clock_seconds(cells)
        if secs is not None:
            return h, secs, None
    return None
