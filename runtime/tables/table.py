"""Error tables: the per-axis tables and constants of an error directory, read and written
(unit-suffixed CSV).

File formats (INTERFACE.md)
---------------------------
*Error table* (one per axis), CSV::

    X,EXX_um,EYX_um,EZX_um,EAX_urad,EBX_urad,ECX_urad,EXX_std_um
    0,0.0,0.0,0.0,0.0,0.0,0.0,0.4
    100,1.2,...

* first column: the axis position, named by the axis (``X`` in mm, ``C`` in deg; ``X_mm`` and
  ``C_deg`` are accepted too).  Positions must be finite and strictly increasing.
* parameter columns ``<ISO name>_<unit>``; translational errors (``EX? EY? EZ?``) in ``um`` or
  ``mm``, angular errors (``EA? EB? EC?``) in ``urad`` or ``rad``.  A table holds only the
  component errors of its own axis (``E??X`` in ``X.csv``).
* optional uncertainty columns for a parameter present in the table, one meaning each:

  - ``EXX_std_um``: the *standard uncertainty of the tabulated value* (k = 1), e.g. of a mean
    of n rounds: s / sqrt(n).  A Monte Carlo perturbs the error function by it once per
    simulated machine (it is systematic for every later measurement).
  - ``EXX_s_um``: the *repeatability of one reading* (experimental standard deviation s of a
    single reading, ddof = 1): the scatter of the machine (and instrument) from one reading
    to the next.
  - ``EXX_u95_um``: an expanded uncertainty (k = 2) of the tabulated value; without a
    ``_std`` column it counts as ``_std = u95 / 2``.

  ``volerr identify`` with n rounds writes ``_s`` = s and ``_std`` = s / sqrt(n); ``volerr
  iso230-2 --errors-out`` writes ``_s`` = S_i and ``_std`` = S_i / sqrt(2 n).  The unit stays
  the last suffix, like every other column; ``EXX_um_std`` / ``EXX_um_s`` / ``EXX_um_u95`` are
  accepted on read.
* optional reversal column ``RV_<axis>_um`` (or ``_mm``; linear axes): the ISO 230-2 reversal
  value B_i at each position = mean positional deviation approaching in the positive direction
  minus approaching in the negative direction (the sign of the loop's ``RV_<axis>`` effect):
  forward EXX + RV/2, backward EXX - RV/2 when EXX is the bidirectional mean.  Read into
  :attr:`ErrorTable.reversal` (``volerr iso230-2`` and ``volerr calibrate`` write it); the error functions apply it by
  approach direction (:meth:`volerr.tables.functions.ErrorFunctions.reversal`: ``compensate``
  block by block, ``map`` / ``tcpmap --approach``).
* blank lines and lines starting with ``#`` are ignored; every other cell must be a finite number.
* columns separated by ``,`` or, as spreadsheets export them, by ``;`` or tabs (with a decimal
  point; the rule of every CSV reader of volerr: :func:`volerr.fileio.sniff_delimiter`).
* lenient spelling: names and units in any case (``exx_UM`` = ``EXX_um``; ``µm``/``µrad`` =
  ``um``/``urad``); the axis column may stand anywhere (it is moved first); columns that are
  neither parameter names nor unit-suffixed (``comment``, ``T_C``) are ignored.  A column named
  like a parameter without a valid unit is refused, and so is a table without error columns.

*Constants* (squareness, rotary-axis location errors), CSV ``name,value,unit`` with unit one of
``um mm urad rad``; optional columns ``std`` and ``u95`` in the same unit as ``value``.  Columns
in any order and case; other columns (comments) are ignored.

*Error directory* (``--errors DIR``): ``<AXIS>.csv`` for each measured axis of the layout and
optionally ``constants.csv``.  A missing table means zero errors for that axis; any other CSV
file in the directory is refused (it is almost always a misnamed table).

In memory everything is mm / rad (translational / angular) and mm / deg (positions).

Error functions of position (built from these tables): :mod:`volerr.tables.functions`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..machine import iso_names
from ..units import (MIN_ANGLE_SPREAD_URAD, MIN_READING_SPREAD_UM, MM_PER_UM, RAD_PER_URAD,
                     UM_PER_MM, URAD_PER_RAD, check_reading_spread_um, format_number,
                     format_rows, parse_number)
from ..errors import InputError, require
from ..fileio import check_magnitude, read_csv_rows, write_text
from . import plausible

#: unit suffix -> (kind, factor to mm or rad)
UNITS = {"um": ("length", MM_PER_UM), "mm": ("length", 1.0), "urad": ("angle", RAD_PER_URAD),
         "rad": ("angle", 1.0)}
_DIVISOR = {"um": UM_PER_MM, "mm": 1.0, "urad": URAD_PER_RAD, "rad": 1.0}  # value_in_unit / divisor -> mm|rad
ROTARY_LETTERS = ("A", "B", "C")
_TABLE_NAME = re.compile(r"^E([XYZABC])([A-Z])$")
_CONST_NAME = re.compile(r"^E([XYZABC])0([A-Z])$")
_COL = re.compile(r"^(?P<name>[A-Za-z0-9]+?)"
                  r"(?:_(?P<kind1>std|u95|s))?_(?P<unit>[A-Za-z]+)(?:_(?P<kind2>std|u95|s))?$",
                  re.IGNORECASE)
#: uncertainty column kinds: suffix -> meaning (docs, reports)
UNCERTAINTY_COLUMNS = {
    "std": "standard uncertainty of the tabulated value (k = 1)",
    "s": "repeatability of one reading (experimental standard deviation, k = 1)",
    "u95": "expanded uncertainty of the tabulated value (k = 2)"}
#: a column that names an error parameter (any case): it must carry a unit suffix
_PARAM_LIKE = re.compile(r"^E[XYZABC]0?[A-Z](?:_|$)", re.IGNORECASE)
_AXIS_COL = re.compile(r"([A-Za-z])(?:_(mm|deg))?", re.IGNORECASE)
_REVERSAL_COL = re.compile(r"RV_([A-Z])_(um|mm)", re.IGNORECASE)


def _unit_text(text: str) -> str:
    """Column or unit spelling -> canonical: micro sign as ``u``, case-insensitive."""
    return text.replace("\u00b5", "u").replace("\u03bc", "u")


def _ignored_column(col: str) -> bool:
    """An extra column (comment, temperature ...): neither a parameter name nor unit-suffixed."""
    if _PARAM_LIKE.match(col):
        return False
    m = _COL.match(_unit_text(col))
    return m is None or m.group("unit").lower() not in UNITS


def parameter_kind(name: str) -> str:
    """``"length"`` for translational (EX?, EY?, EZ?, EX0?, ...), ``"angle"`` for angular."""
    return "length" if iso_names.is_length(name) else "angle"


def axis_unit(axis: str) -> str:
    """Position unit of an axis: ``deg`` for rotary letters A B C, else ``mm``."""
    return "deg" if axis in ROTARY_LETTERS else "mm"


def range_cause(axis: str, lo: float, hi: float, x: float, source: str = "") -> str:
    """Why a position ``x`` lies outside the measured range ``lo .. hi`` of table ``axis``,
    when a unit explains it: a rotary table whose positions all lie within +-2 pi and
    whose range read as radians (x 180/pi) covers ``x`` was tabulated in radians.  Returns
    ``"<source>/<axis>.csv: column <axis>: ... likely radians, not degrees; "`` or ``""``."""
    import math

    if axis not in ROTARY_LETTERS or not (-2 * math.pi - 1e-9 <= lo < hi <= 2 * math.pi + 1e-9):
        return ""
    dlo, dhi = math.degrees(lo), math.degrees(hi)
    if not dlo - 1e-6 <= x <= dhi + 1e-6:
        return ""
    name = f"{source.rstrip('/')}/{axis}.csv" if source else f"{axis}.csv"
    return (f"{name}: column {axis}: the table's positions {lo:g} .. {hi:g} are likely "
            f"radians, not degrees (x 180/pi: {dlo:g} .. {dhi:g} deg); ")


def _to_internal(values, unit: str):
    return np.asarray(values, dtype=float) / _DIVISOR[unit]


def _from_internal(values, unit: str):
    return np.asarray(values, dtype=float) * _DIVISOR[unit]


@dataclass
class ErrorTable:
    """Component errors of one axis at measured positions (one ``<AXIS>.csv``).

    ``axis``: the axis letter.  ``positions``: shape (n,), mm or deg, strictly increasing.
    ``values``, ``std``, ``u95``, ``s``: ISO name -> shape (n,) arrays in mm (translational) or
    rad (angular); ``std`` is the standard uncertainty of the tabulated value (k = 1), ``u95``
    its expanded uncertainty (k = 2), ``s`` the repeatability of one reading (module
    docstring); each may be empty.  ``reversal``: shape (n,) mm or None, the ISO 230-2 reversal
    B_i (positive-direction minus negative-direction approach) at each position."""

    axis: str
    positions: np.ndarray
    values: dict
    std: dict = field(default_factory=dict)
    u95: dict = field(default_factory=dict)
    reversal: np.ndarray | None = None
    s: dict = field(default_factory=dict)

    def __post_init__(self):
        self.positions = np.asarray(self.positions, dtype=float)
        self.values = {k: np.asarray(v, dtype=float) for k, v in self.values.items()}
        self.std = {k: np.asarray(v, dtype=float) for k, v in (self.std or {}).items()}
        self.u95 = {k: np.asarray(v, dtype=float) for k, v in (self.u95 or {}).items()}
        self.s = {k: np.asarray(v, dtype=float) for k, v in (self.s or {}).items()}
        if self.reversal is not None:
            self.reversal = np.asarray(self.reversal, dtype=float)
        self.validate()

    def check_magnitudes(self, machine=None, accept_implausible: bool = False) -> None:
        """Refuse values beyond what ``machine`` (Model or Layout; default: this table's span)
        can have (:func:`check_magnitudes`, :mod:`volerr.tables.plausible`)."""
        check_magnitudes({self.axis: self}, machine=machine,
                         accept_implausible=accept_implausible)

    def validate(self, where: str = "") -> None:
        """Check shapes, names, finiteness and increasing positions; raise InputError."""
        w = where or f"table {self.axis}"
        require(re.fullmatch(r"[A-Z]", self.axis or "") is not None,
                f"{w}: axis name must be one capital letter, got {self.axis!r}")
        p = self.positions
        require(p.ndim == 1 and p.size >= 2, f"{w}: needs at least two positions, got {p.size}")
        require(np.all(np.isfinite(p)), f"{w}: positions contain NaN or infinite values")
        d = np.diff(p)
        if np.any(d <= 0):
            i = int(np.argmax(d <= 0))
            what = "duplicate" if d[i] == 0 else "decreasing"
            raise InputError(f"{w}: positions must be strictly increasing ({what} position "
                             f"{p[i + 1]:g} after {p[i]:g})")
        for label, dct in (("", self.values), ("std ", self.std), ("u95 ", self.u95),
                           ("s ", self.s)):
            for k, v in dct.items():
                m = _TABLE_NAME.match(k)
                require(m is not None and m.group(2) == self.axis,
                        f"{w}: {k!r} is not a component error of axis {self.axis} "
                        f"(expected EX{self.axis} ... EC{self.axis})")
                require(v.shape == p.shape, f"{w}: {label}{k} has {v.size} values for {p.size} positions")
                require(np.all(np.isfinite(v)), f"{w}: {label}{k} contains NaN or infinite values")
                if label:
                    require(k in self.values, f"{w}: {label.strip()} column for {k} without a {k} column")
                    require(np.all(v >= 0), f"{w}: {label}{k} has negative values")
        if self.reversal is not None:
            require(self.reversal.shape == p.shape and np.all(np.isfinite(self.reversal)),
                    f"{w}: reversal needs {p.size} finite values")


# ---------------------------------------------------------------------------------------------
# CSV reading
def _read_rows(path: Path) -> tuple[list[str], list[tuple[int, list[str]]]]:
    """Header and (line number, cells) of a CSV file; blank and '#' lines skipped."""
    rows = read_csv_rows(path, empty=f"{path}: empty file (no header)")
    (_, header), body = rows[0], rows[1:]
    require(all(header), f"{path}: empty column name in header")
    dup = sorted({h for h in header if header.count(h) > 1})
    if dup:
        raise InputError(f"{path}: duplicate column {dup[0]!r}")
    for lineno, cells in body:
        require(len(cells) == len(header),
                f"{path}:{lineno}: {len(cells)} fields, header has {len(header)}")
    return header, body


def _number(path, lineno, column, text) -> float:
    where = f"{path}:{lineno}"
    return check_magnitude(parse_number(text, where, column), f"{where}: {column}")


def _parse_column(path, col: str, axis: str):
    """-> (name, unit, kind) with kind '', 'std', 's' or 'u95'."""
    m = _COL.match(_unit_text(col))
    if m is None or (m.group("kind1") and m.group("kind2")):
        raise InputError(f"{path}: column {col!r} has no unit suffix (wrong units): "
                         f"write it as <name>_um, _mm, _urad or _rad")
    name, unit = m.group("name").upper(), m.group("unit").lower()
    kind = (m.group("kind1") or m.group("kind2") or "").lower()
    require(unit in UNITS, f"{path}: column {col!r}: unknown unit {unit!r} (wrong units); "
                           f"use um, mm, urad or rad")
    mt = _TABLE_NAME.match(name)
    require(mt is not None and mt.group(2) == axis,
            f"{path}: column {col!r}: {name} is not a component error of axis {axis} "
            f"(expected EX{axis} EY{axis} EZ{axis} EA{axis} EB{axis} EC{axis})")
    need = parameter_kind(name)
    require(UNITS[unit][0] == need,
            f"{path}: column {col!r}: wrong units, {name} is {'an angle' if need == 'angle' else 'a length'}"
            f" (use {'urad or rad' if need == 'angle' else 'um or mm'})")
    return name, unit, kind


def _read_error_table(path, axis: str | None = None) -> ErrorTable:
    """:func:`read_error_table` without the magnitude check."""
    path = Path(path)
    header, body = _read_rows(path)
    # the axis column comes first (INTERFACE.md); one found elsewhere is moved there, and extra
    # columns that are neither parameters nor unit-suffixed (comments, temperatures) are ignored
    if _AXIS_COL.fullmatch(header[0]) is None:
        at = [j for j, h in enumerate(header) if _AXIS_COL.fullmatch(h)
              and (axis is None or h[0].upper() == axis)]
        if len(at) == 1:
            order = at + [j for j in range(len(header)) if j != at[0]]
            header = [header[j] for j in order]
            body = [(ln, [cells[j] for j in order]) for ln, cells in body]
    rv = [j for j, h in enumerate(header) if _REVERSAL_COL.fullmatch(_unit_text(h))]
    require(len(rv) <= 1, f"{path}: more than one reversal column (RV_<axis>_um)")
    rv_col = (header[rv[0]], [cells[rv[0]] for _, cells in body]) if rv else None
    keep = [0] + [j for j in range(1, len(header)) if not _ignored_column(header[j])]
    if len(keep) < len(header):
        header = [header[j] for j in keep]
        body = [(ln, [cells[j] for j in keep]) for ln, cells in body]
    first = header[0]
    m = _AXIS_COL.fullmatch(first)
    require(m is not None, f"{path}: first column must be the axis position named by the axis "
                           f"(e.g. X or C), got {first!r}")
    tax = m.group(1).upper()
    if m.group(2):
        require(m.group(2).lower() == axis_unit(tax), f"{path}: axis {tax} positions are in "
                                                      f"{axis_unit(tax)}, not {m.group(2)}")
    if axis is not None:
        require(tax == axis, f"{path}: header names axis {tax!r}, expected {axis!r} (header mismatch)")
    require(len(header) >= 2, f"{path}: no error columns")
    require(body, f"{path}: no data rows")
    cols = [_parse_column(path, c, tax) for c in header[1:]]
    seen = {}
    for (name, unit, kind), col in zip(cols, header[1:]):
        require((name, kind) not in seen, f"{path}: columns {seen.get((name, kind))!r} and "
                                          f"{col!r} both give {name} {kind}".rstrip())
        seen[(name, kind)] = col
    data = np.array([[_number(path, ln, h, c) for h, c in zip(header, cells)] for ln, cells in body])
    values, std, u95, rep = {}, {}, {}, {}
    for j, (name, unit, kind) in enumerate(cols, start=1):
        {"": values, "std": std, "u95": u95, "s": rep}[kind][name] = _to_internal(data[:, j],
                                                                                 unit)
    for name in list(std) + list(u95) + list(rep):
        require(name in values, f"{path}: uncertainty column for {name} without a {name} column")
    reversal = None
    if rv_col is not None:
        rm = _REVERSAL_COL.fullmatch(_unit_text(rv_col[0]))
        require(rm.group(1).upper() == tax, f"{path}: reversal column {rv_col[0]!r} names axis "
                                            f"{rm.group(1).upper()}, the table is for {tax}")
        reversal = _to_internal([_number(path, ln, rv_col[0], c)
                                 for (ln, _), c in zip(body, rv_col[1])], rm.group(2).lower())
    try:
        table = ErrorTable(tax, data[:, 0], values, std, u95, reversal, rep)
    except InputError as exc:
        msg = str(exc).split(": ", 1)[-1]
        raise InputError(f"{path}: {msg}") from None
    # where each value came from, for the magnitude check's message (check_magnitudes)
    table._source = str(path)
    table._columns = {(name, kind): (col, unit) for (name, unit, kind), col in zip(cols, header[1:])}
    if rv_col is not None:
        table._columns[("RV", "")] = (rv_col[0], rm.group(2).lower())
    return table


def read_error_table(path, axis: str | None = None, *, machine=None,
                     accept_implausible: bool = False) -> ErrorTable:
    """Read one error table (format in the module docstring) -> :class:`ErrorTable` in mm / rad.

    ``axis``: the expected axis (e.g. from the file name); the first column must name it.
    ``machine``: the Model or Layout whose size limits the values (:mod:`.plausible`; one
    table alone does not tell the machine's size: without ``machine`` nothing is checked,
    :func:`read_error_dir` always checks); ``accept_implausible``: skip that check."""
    table = _read_error_table(path, axis)
    check_magnitudes({table.axis: table}, machine=machine,
                     accept_implausible=accept_implausible or machine is None)
    return table


def _fmt(v: float) -> str:
    return format_number(v, 12)


def table_to_csv(table: ErrorTable) -> str:
    """CSV text of a table: lengths in um, angles in urad, uncertainty as ``_std_um``,
    ``_s_um``, ``_u95_um`` (module docstring)."""
    table.validate()
    names = list(table.values)
    header, columns = [table.axis], [table.positions]
    for n in names:
        unit = "um" if parameter_kind(n) == "length" else "urad"
        header.append(f"{n}_{unit}")
        columns.append(_from_internal(table.values[n], unit))
    for kind, dct in (("std", table.std), ("s", table.s), ("u95", table.u95)):
        for n in names:
            if n in dct:
                unit = "um" if parameter_kind(n) == "length" else "urad"
                header.append(f"{n}_{kind}_{unit}")
                columns.append(_from_internal(dct[n], unit))
    if table.reversal is not None:
        header.append(f"RV_{table.axis}_um")
        columns.append(_from_internal(table.reversal, "um"))
    return ",".join(header) + "\n" + format_rows(
        np.column_stack([np.asarray(c, dtype=float) for c in columns]), 12)


def _comment_lines(comments) -> str:
    """``# ...`` lines before a CSV header (every reader skips them: :func:`read_csv_rows`)."""
    return "".join(f"# {' '.join(str(c).split())}\n" for c in comments)


def write_error_table(path, table: ErrorTable, inputs=(), comments=(), *, machine=None,
                      accept_implausible: bool = False) -> Path:
    """Write ``table`` as CSV (um / urad), ``comments`` as ``#`` lines above the header;
    refuses to overwrite any file in ``inputs``, and values beyond what ``machine`` (Model or
    Layout) can have unless ``accept_implausible`` (:func:`check_magnitudes`; without
    ``machine`` nothing is checked, :func:`write_error_dir` always checks)."""
    check_magnitudes({table.axis: _unread(table)}, machine=machine, where=str(Path(path).parent),
                     cause=WRITE_CAUSE, accept_implausible=accept_implausible or machine is None)
    return write_text(path, _comment_lines(comments) + table_to_csv(table), inputs=inputs)


# ---------------------------------------------------------------------------------------------
# magnitudes (the limits: volerr.tables.plausible)
#: what the writer's refusal says is likely
WRITE_CAUSE = "not written: an input in the wrong unit, or a fit that went wrong?"


def _column_name(name: str, label: str) -> str:
    """The column :func:`table_to_csv` writes for parameter ``name`` (``label``: "", "std" ...)."""
    unit = "um" if parameter_kind(name) == "length" else "urad"
    return f"{name}_{label}_{unit}" if label else f"{name}_{unit}"


def check_magnitudes(tables: dict, constants=None, constants_std=None, constants_u95=None, *,
                     machine=None, where: str = "", cause: str = "", constants_origin=None,
                     accept_implausible: bool = False) -> None:
    """Refuse error values beyond what a machine of this size can have (:mod:`.plausible`).

    Checks every value, uncertainty and reversal of ``tables`` (axis -> :class:`ErrorTable`)
    and every constant (name -> value, ``constants_std``, ``constants_u95``), mm / rad.  A
    table read from a file names its file, column and the likely unit (the column's declared
    unit is known); other values name ``where`` (the folder they come from or go to) and
    ``cause``.  ``constants_origin``: name -> ("path:line", declared unit).  ``machine``: a
    Model or Layout (its travel sets the limits); without it, the tables' span.  Raises
    :class:`InputError`; does nothing with ``accept_implausible``."""
    if accept_implausible:
        return
    limits = plausible.limits_for(machine, tables)
    for ax, t in tables.items():
        cols = getattr(t, "_columns", {})
        src = getattr(t, "_source", "") or (str(Path(where) / f"{ax}.csv") if where
                                            else f"table {ax}")
        for label, dct in (("", t.values), ("std", t.std), ("s", t.s), ("u95", t.u95)):
            for name, v in dct.items():
                col, unit = cols.get((name, label), (_column_name(name, label), None))
                plausible.check(v, parameter_kind(name), limits, src, f"column {col}", unit,
                                cause)
        if t.reversal is not None:
            col, unit = cols.get(("RV", ""), (f"RV_{ax}_um", None))
            plausible.check(t.reversal, "length", limits, src, f"column {col}", unit, cause)
        _check_spread(t, src)
        if machine is not None and getattr(t, "_source", ""):
            plausible.check_positions(ax, t.positions, machine, src)
    origin = constants_origin or {}
    csrc = str(Path(where) / "constants.csv") if where else "constants"
    for label, dct in (("", constants), ("std", constants_std), ("u95", constants_u95)):
        for name, v in (dct or {}).items():
            src, unit = origin.get(name, (csrc, None))
            plausible.check([v], parameter_kind(name), limits, src,
                            f"{name} {label}".strip(), unit, cause)


def _check_spread(table: ErrorTable, src: str) -> None:
    """The lower bound of a table read from a file: its error columns headed ``_um`` (and,
    apart, those headed ``_urad``) must span, the widest of them, at least what any machine
    and instrument show (:func:`volerr.units.check_reading_spread_um`,
    :data:`~volerr.units.MIN_READING_SPREAD_UM` 0.05 um,
    :data:`~volerr.units.MIN_ANGLE_SPREAD_URAD` 0.05 urad): a table in mm under ``_um``
    (mrad or rad under ``_urad``) spans a thousandth of the real error or less.  Columns without spread (zeros,
    a constant) say nothing and pass; uncertainty and reversal columns are not judged (a
    constant backlash or uncertainty is real).  Tables not read from a file (computed, to be
    written) are not judged: a simulated perfect machine identifies to round-off."""
    cols = getattr(table, "_columns", None)
    if not cols:
        return
    for unit, scale, minimum in (("um", UM_PER_MM, MIN_READING_SPREAD_UM),
                                 ("urad", URAD_PER_RAD, MIN_ANGLE_SPREAD_URAD)):
        heads = {col: table.values[name] * scale for (name, kind), (col, u) in cols.items()
                 if kind == "" and u == unit and name in table.values}
        check_reading_spread_um(heads, src, minimum, unit)


# ---------------------------------------------------------------------------------------------
# constants
def read_constants_full(path, *, machine=None,
                        accept_implausible: bool = False) -> tuple[dict, dict, dict]:
    """Read a constants CSV -> (values, std, u95), each name -> float in mm / rad; values
    beyond what ``machine`` (Model or Layout) can have are refused unless
    ``accept_implausible`` (:mod:`.plausible`; without ``machine`` nothing is checked,
    :func:`read_error_dir` always checks)."""
    values, std, u95, origin = _read_constants(path)
    check_magnitudes({}, values, std, u95, machine=machine, constants_origin=origin,
                     accept_implausible=accept_implausible or machine is None)
    return values, std, u95


def _read_constants(path) -> tuple[dict, dict, dict, dict]:
    """(values, std, u95, origin) of a constants CSV; origin: name -> ("path:line", unit)."""
    path = Path(path)
    header, body = _read_rows(path)
    low = [h.lower() for h in header]
    require(all(k in low for k in ("name", "value", "unit")),
            f"{path}: header must have the columns name,value,unit, got {','.join(header)}")
    # columns in any order, any case; columns other than std / u95 (comments ...) are ignored
    order = [low.index(k) for k in ("name", "value", "unit")]
    order += [j for j, h in enumerate(low) if h in ("std", "u95")]
    header = [low[j] for j in order]
    body = [(ln, [cells[j] for j in order]) for ln, cells in body]
    extra = header[3:]
    values, std, u95, origin = {}, {}, {}, {}
    for lineno, cells in body:
        name, unit = cells[0].upper(), _unit_text(cells[2]).lower()
        require(_CONST_NAME.match(name) is not None,
                f"{path}:{lineno}: {name!r} is not a constant error name "
                f"(squareness EC0Y EB0Z EA0Z or location errors such as EX0C)")
        require(name not in values, f"{path}:{lineno}: duplicate constant {name}")
        require(unit in UNITS, f"{path}:{lineno}: unknown unit {unit!r} for {name} (wrong units); "
                               f"use um, mm, urad or rad")
        need = parameter_kind(name)
        require(UNITS[unit][0] == need, f"{path}:{lineno}: wrong units {unit!r} for {name} "
                                        f"({'urad or rad' if need == 'angle' else 'um or mm'})")
        values[name] = float(_to_internal(_number(path, lineno, "value", cells[1]), unit))
        origin[name] = (f"{path}:{lineno}", unit)
        for h in extra:
            dct = std if h == "std" else u95
            if cells[header.index(h)] == "":
                continue
            v = _number(path, lineno, h, cells[header.index(h)])
            require(v >= 0, f"{path}:{lineno}: negative {h} for {name}")
            dct[name] = float(_to_internal(v, unit))
    return values, std, u95, origin


def read_constants(path, *, machine=None, accept_implausible: bool = False) -> dict:
    """Read a constants CSV ``name,value,unit`` -> name -> float in mm (translational) / rad
    (magnitudes checked as :func:`read_constants_full`)."""
    return read_constants_full(path, machine=machine, accept_implausible=accept_implausible)[0]


def write_constants(path, values: dict, inputs=(), std: dict | None = None,
                    u95: dict | None = None, comments=(), *, machine=None,
                    accept_implausible: bool = False) -> Path:
    """Write constants (mm / rad) as ``name,value,unit[,std][,u95]`` in um / urad,
    ``comments`` as ``#`` lines above the header; values beyond what ``machine`` (Model or
    Layout) can have are refused unless ``accept_implausible`` (:func:`check_magnitudes`;
    without ``machine`` nothing is checked, :func:`write_error_dir` always checks)."""
    std, u95 = dict(std or {}), dict(u95 or {})
    check_magnitudes({}, {k: float(v) for k, v in values.items()}, std, u95, machine=machine,
                     where=str(Path(path).parent), cause=WRITE_CAUSE,
                     accept_implausible=accept_implausible or machine is None)
    header = ["name", "value", "unit"] + (["std"] if std else []) + (["u95"] if u95 else [])
    lines = [_comment_lines(comments) + ",".join(header)]
    for name, v in values.items():
        require(_CONST_NAME.match(name) is not None, f"{name!r} is not a constant error name")
        require(math.isfinite(float(v)), f"constant {name} is NaN or infinite")
        unit = "um" if parameter_kind(name) == "length" else "urad"
        row = [name, _fmt(_from_internal(v, unit)), unit]
        if std:
            row.append(_fmt(_from_internal(std[name], unit)) if name in std else "")
        if u95:
            row.append(_fmt(_from_internal(u95[name], unit)) if name in u95 else "")
        lines.append(",".join(row))
    return write_text(path, "\n".join(lines) + "\n", inputs=inputs)


# ---------------------------------------------------------------------------------------------
# error directories
def read_error_dir(directory, axes=None, *, machine=None,
                   accept_implausible: bool = False) -> tuple[dict, tuple[dict, dict, dict]]:
    """Read an error directory (``<AXIS>.csv`` per measured axis, optional ``constants.csv``).

    Parameters
    ----------
    directory : path
        The error directory; a missing table means zero errors for that axis.
    axes : sequence of str, optional
        The axes the machine has; a table for any other axis, or any other CSV file, is
        refused (default: the axes of ``machine``, else X Y Z tables).
    machine : Model or Layout, optional
        The machine whose travel limits the values (:mod:`volerr.tables.plausible`; without
        it the span of the linear-axis tables read).
    accept_implausible : bool
        Accept values beyond those limits (a machine that really is that bad); by default they
        are refused naming the file, the column and the likely unit.

    Returns
    -------
    tables : dict
        Axis -> :class:`ErrorTable` (positions mm / deg, values mm / rad).
    (constants, std, u95) : tuple of dict
        ISO name (``EC0Y`` ...) -> value, its standard deviation and its expanded uncertainty
        (k = 2), mm or rad; ``std`` and ``u95`` hold only the names that carry them.
    """
    d = Path(directory)
    require(not d.is_file(), f"{d} is a file, not an error directory (give the folder that "
                             f"holds X.csv, Y.csv ... and constants.csv)")
    require(d.is_dir(), f"error directory {d} does not exist")
    tables, consts, origin = {}, ({}, {}, {}), {}
    if axes is None and machine is not None:
        axes = getattr(machine, "layout", machine).axis_names
    allowed = None if axes is None else set(axes)
    for f in sorted(d.iterdir()):
        if f.suffix.lower() != ".csv" or f.name.startswith("."):
            continue
        stem = f.stem
        if stem.lower() == "constants":
            *consts, origin = _read_constants(f)
            continue
        if len(stem) == 1 and stem.isalpha():
            ax = stem.upper()
            require(allowed is None or ax in allowed,
                    f"{f}: table for axis {ax}, but the machine's axes are {' '.join(sorted(allowed or ()))}")
            require(ax not in tables, f"{d}: two tables for axis {ax}")
            tables[ax] = _read_error_table(f, axis=ax)
            continue
        raise InputError(f"{f}: unknown file in error directory (expected "
                         f"{', '.join(a + '.csv' for a in (axes or ['X', 'Y', 'Z']))} or constants.csv)")
    _refuse_a_folder_of_other_things(d, tables)
    check_magnitudes(tables, *consts, machine=machine, constants_origin=origin,
                     accept_implausible=accept_implausible)
    return tables, tuple(consts)


def _refuse_a_folder_of_other_things(d: Path, tables: dict) -> None:
    """An empty folder is a machine without errors (a missing table means zero errors); a
    folder that holds other things (sub-folders, programs, plots) but no table and no
    ``constants.csv`` is refused: it is the wrong folder (``--errors dmu50`` for
    ``dmu50/errors``), and read as zero errors it would give a confident wrong answer."""
    if tables or any(f.suffix.lower() == ".csv" for f in d.iterdir()):
        return                          # tables, or a constants.csv (other CSVs are refused)
    others = sorted(f.name + ("/" if f.is_dir() else "") for f in d.iterdir()
                    if not f.name.startswith("."))
    sub = next((o for o in others if o.endswith("/")), None)
    require(not others, f"{d}: no error table (X.csv ...) and no constants.csv in this folder, "
            f"only {', '.join(others[:3])}{' ...' if len(others) > 3 else ''}"
            + (f": is the error directory {d / sub.rstrip('/')}?" if sub else
               ": not an error directory"))


def error_dir_names(axes) -> list:
    """The files of an error directory a fit writes (:func:`write_error_dir`): ``<axis>.csv``
    of each of ``axes``, ``constants.csv``."""
    return [f"{a}.csv" for a in axes] + ["constants.csv"]


def write_error_dir(directory, tables: dict, constants: dict | None = None,
                    constants_std: dict | None = None, inputs=(), comments=None, *,
                    machine=None, accept_implausible: bool = False, shown=None) -> Path:
    """Write ``<AXIS>.csv`` for each table and ``constants.csv`` (when given) into ``directory``;
    ``comments``: {axis or "constants": [line ...]} written as ``#`` lines above the header
    (what a value written under a name stands for).  Values beyond what ``machine`` (Model or
    Layout; default: the tables' span) can have are refused before anything is written,
    unless ``accept_implausible`` (:func:`check_magnitudes`; a refusal names the folder
    ``shown``, default ``directory``: the folder the user named when ``directory`` is a
    staging folder)."""
    d = Path(directory)
    comments = comments or {}
    for ax, t in tables.items():
        require(ax == t.axis, f"table for {t.axis} stored under {ax}")
    check_magnitudes({ax: _unread(t) for ax, t in tables.items()}, constants, constants_std,
                     machine=machine, where=str(shown or d), cause=WRITE_CAUSE,
                     accept_implausible=accept_implausible)
    for ax, t in tables.items():
        write_error_table(d / f"{ax}.csv", t, inputs=inputs, comments=comments.get(ax, ()),
                          accept_implausible=True)
    if constants:
        write_constants(d / "constants.csv", constants, inputs=inputs, std=constants_std,
                        comments=comments.get("constants", ()), accept_implausible=True)
    return d


def _unread(table: ErrorTable) -> ErrorTable:
    """``table`` as values to be written: a refusal names the column written (um / urad), not
    the file it may once have been read from."""
    if getattr(table, "_columns", None) is None:
        return table
    copy = ErrorTable(table.axis, table.positions, table.values, table.std, table.u95,
                      table.reversal, table.s)
    return copy
