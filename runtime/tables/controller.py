"""Error parameters for controllers with built-in volumetric compensation: ISG CSV and Etalon.

Both formats are read by the ISG kernel's volumetric compensation (and by controllers built
on it); volerr writes and reads them so that the same error directory can feed a controller
instead of (or as well as) ``volerr compensate``.

Units (both formats): error values in mm (translational) and rad (angular); arguments (axis
positions) in mm for linear axes and deg for rotary axes.  Names follow ISO 230-1: component
errors keep their names (``EXX`` ... ``ECC``); position errors (squareness and location errors
of the rotary axes, volerr ``EC0Y``, ``EX0C`` ...) are written without the leading ``E``
(``C0Y``, ``X0C``), as the ISG parameter list names them.  Values are the layout's errors as
volerr defines them (tool relative to workpiece, ISO 230-1; for a table axis minus the
table's own error motion); ``--negate`` writes (reads) compensation values, the errors with
reversed sign, for a controller that expects those.

ISG CSV (columns separated by blanks or tabs)
    ``//`` starts a comment, a line ``#`` separates blocks, each block starts with a header::

        // volerr export: layout DMU50 (position errors, mm / rad)
        C0Y B0Z A0Z X0B ...
        2e-05 -1.5e-05 1e-05 0.02 ...
        #
        // component errors of axis X (argument mm, values mm / rad)
        X EXX EYX EZX EAX EBX ECX
        -250 0.0012 ...

    One block for the position errors (a single row), then one block per axis with a table:
    the argument column (the axis) and its component errors at the grid points of the table.
    Blocks with more than one argument column (e.g. ``Z X EXX``) are refused on import.

Etalon exchange format ("Vendor" variant, INI-like)
    One section per parameter: ``[C0Y]`` with ``VALUE = 2.0e-05`` for a position error,
    ``[EXY]`` with ``Gridpoints = {`` then one ``argument value`` pair per line and ``}``
    for a component error (the argument is the position of the axis named last, ``Y`` here).
    ``//`` starts a comment.

Standard deviations and u95 columns of the error tables are not exported (neither format has
them).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, require, require_file
from ..fileio import check_header, check_magnitude
from ..machine import iso_names
from .table import ErrorTable, axis_unit
from ..units import format_number

FORMATS = ("isg", "etalon")
_COMPONENT = re.compile(r"^E([XYZABC])([XYZABC])$")
_POSITION = re.compile(r"^([XYZABC])0([XYZABC])$")


def iso_to_controller(name: str) -> str:
    """``EC0Y`` -> ``C0Y``; component errors unchanged."""
    return name[1:] if re.fullmatch(r"E[XYZABC]0[XYZABC]", name) else name


def controller_to_iso(name: str) -> str:
    """``C0Y`` -> ``EC0Y``; component errors unchanged; anything else raises."""
    if _POSITION.match(name):
        return "E" + name
    if _COMPONENT.match(name):
        return name
    raise InputError(f"{name!r} is not an ISO 230-1 error parameter name")


def _num(v: float) -> str:
    return format_number(v, 12)


# ------------------------------------------------------------------------------------------
# ISG CSV
def write_isg(model_name: str, tables: dict, constants: dict) -> str:
    """ISG CSV text of an error directory's content (tables: axis -> ErrorTable; constants
    name -> mm | rad)."""
    blocks = []
    if constants:
        names = list(constants)
        blocks.append("\n".join([
            f"// volerr export: layout {model_name}; position errors (mm, rad)",
            " ".join(iso_to_controller(n) for n in names),
            " ".join(_num(constants[n]) for n in names)]))
    for ax in sorted(tables):
        t = tables[ax]
        names = list(t.values)
        unit = axis_unit(ax)
        rows = [f"// component errors of axis {ax} (argument {ax} in {unit}; values mm, rad)",
                " ".join([ax] + names)]
        for i, p in enumerate(t.positions):
            rows.append(" ".join([_num(p)] + [_num(t.values[n][i]) for n in names]))
        blocks.append("\n".join(rows))
    return "\n#\n".join(blocks) + "\n"


def _strip_comment(line: str) -> str:
    return line.split("//", 1)[0].strip()


def read_isg(text: str, where: str = "ISG CSV") -> tuple[dict, dict]:
    """Parse ISG CSV text -> (tables axis -> ErrorTable, constants name -> mm | rad), ISO names."""
    tables, constants = {}, {}
    header, rows, start = None, [], 0

    def flush():
        if header is None:
            return
        _isg_block(header, rows, tables, constants, f"{where} line {start}")

    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = _strip_comment(raw)
        if not line:
            continue
        if line == "#" or line.startswith("#"):
            flush()
            header, rows = None, []
            continue
        cells = line.replace(",", " ").replace(";", " ").split()
        if header is None:
            check_header(cells, f"{where} line {lineno}")
            header, start = cells, lineno
            continue
        require(len(cells) == len(header), f"{where} line {lineno}: {len(cells)} values for "
                                            f"{len(header)} columns")
        vals = _numbers(cells, f"{where} line {lineno}", line)
        for v in vals:
            check_magnitude(v, f"{where} line {lineno}: value")
        rows.append((lineno, vals))
    flush()
    require(tables or constants, f"{where}: no error parameters found")
    return tables, constants


def _isg_block(header, rows, tables, constants, where):
    require(rows, f"{where}: header without data rows")
    args = [h for h in header if re.fullmatch(r"[XYZABC]", h)]
    if not args:
        require(len(rows) == 1, f"{where}: position errors need exactly one data row")
        for h, v in zip(header, rows[0][1]):
            name = controller_to_iso(h)
            require(_POSITION.match(h) is not None,
                    f"{where}: {h} is a component error but the block has no argument column")
            require(name not in constants, f"{where}: {h} given twice")
            constants[name] = v
        return
    require(len(args) == 1, f"{where}: more than one argument column ({' '.join(args)}): "
                            "multi-dimensional error tables are not supported")
    ax = args[0]
    require(header[0] == ax, f"{where}: the argument column {ax} must come first")
    require(ax not in tables, f"{where}: a second block for axis {ax}")
    values = {}
    data = np.array([r[1] for r in rows])
    for j, h in enumerate(header[1:], start=1):
        m = _COMPONENT.match(h)
        require(m is not None, f"{where}: {h} is not a component error name (EXX ... ECC)")
        require(m.group(2) == ax, f"{where}: {h} is an error of axis {m.group(2)}, but the "
                                  f"argument is {ax}")
        values[h] = data[:, j]
    order = np.argsort(data[:, 0], kind="stable")
    try:
        tables[ax] = ErrorTable(ax, data[order, 0], {k: v[order] for k, v in values.items()})
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


# ------------------------------------------------------------------------------------------
# Etalon exchange format
def write_etalon(model_name: str, tables: dict, constants: dict) -> str:
    out = [f"// volerr export: layout {model_name}; Etalon exchange format (Vendor variant)",
           "// position errors: VALUE in mm or rad; component errors: Gridpoints = {argument "
           "value}, argument mm or deg, value mm or rad"]
    for n, v in constants.items():
        out += [f"[{iso_to_controller(n)}]", f"VALUE = {_num(v)}"]
    for ax in sorted(tables):
        t = tables[ax]
        for n, vals in t.values.items():
            out += [f"[{n}]", "Gridpoints = {"]
            out += [f"    {_num(p)} {_num(v)}" for p, v in zip(t.positions, vals)]
            out += [f"}}  // end of {n}"]
    return "\n".join(out) + "\n"


@dataclass
class _EtalonReader:
    """The state of reading an Etalon file line by line: the current ``[section]``, the open
    ``Gridpoints`` list (None outside one) and what has been read so far."""

    where: str
    constants: dict = field(default_factory=dict)
    columns: dict = field(default_factory=dict)
    section: str | None = None
    grid: list | None = None
    seen: set = field(default_factory=set)

    def line(self, lineno: int, line: str) -> None:
        """Read one non-blank line (comments stripped)."""
        if self.grid is not None:
            self._grid_line(lineno, line)
            return
        m = re.fullmatch(r"\[\s*([A-Za-z0-9]+)\s*\]", line)
        if m:
            self._section(lineno, m.group(1).upper())
            return
        require(self.section is not None,
                f"{self.where} line {lineno}: data before the first [section]")
        key, _, val = line.partition("=")
        self._key(lineno, key.strip().upper(), val.strip())

    def _section(self, lineno: int, section: str) -> None:
        require(section not in self.seen, f"{self.where} line {lineno}: [{section}] given twice")
        self.seen.add(section)
        controller_to_iso(section)
        self.section = section

    def _grid_line(self, lineno: int, line: str) -> None:
        at = f"{self.where} line {lineno}"
        if line.startswith("}"):
            require(self.grid, f"{at}: empty Gridpoints of {self.section}")
            self.columns[self.section] = self.grid
            self.grid = None
            return
        cells = line.split()
        require(len(cells) == 2, f"{at}: expected 'argument value'")
        a, v = _numbers(cells, at, line)
        check_magnitude(a, f"{at}: argument")
        check_magnitude(v, f"{at}: value")
        self.grid.append((a, v))

    def _key(self, lineno: int, key: str, val: str) -> None:
        at, section = f"{self.where} line {lineno}", self.section
        if key == "VALUE":
            require(_POSITION.match(section) is not None,
                    f"{at}: [{section}] is a component error; expected Gridpoints")
            try:
                self.constants["E" + section] = float(val)
            except ValueError:
                raise InputError(f"{at}: VALUE is not a number") from None
            check_magnitude(self.constants["E" + section], f"{at}: VALUE")
        elif key == "GRIDPOINTS":
            require(_COMPONENT.match(section) is not None,
                    f"{at}: [{section}] is a position error; expected VALUE")
            require(val.startswith("{"), f"{at}: Gridpoints must open with '{{'")
            self.grid = []
        else:
            raise InputError(f"{at}: unknown key {key!r} (VALUE or Gridpoints)")


def _numbers(cells, at: str, line: str) -> list[float]:
    try:
        return [float(c) for c in cells]
    except ValueError:
        raise InputError(f"{at}: not a number in {line!r}") from None


def _grid_tables(columns: dict, where: str) -> dict:
    """{axis: ErrorTable} from {component name: [(argument, value), ...]}: the columns of one
    axis must share their grid points (in any order)."""
    by_axis: dict = {}
    for name, pts in columns.items():
        by_axis.setdefault(iso_names.parse(name).axis, {})[name] = np.array(pts)
    tables = {}
    for ax, cols in by_axis.items():
        ref = None
        values = {}
        for name, pts in cols.items():
            order = np.argsort(pts[:, 0], kind="stable")
            pos = pts[order, 0]
            if ref is None:
                ref = pos
            require(pos.shape == ref.shape and np.allclose(pos, ref, atol=1e-9),
                    f"{where}: the grid points of {name} differ from those of "
                    f"{next(iter(cols))} (one grid per axis is needed)")
            values[name] = pts[order, 1]
        try:
            tables[ax] = ErrorTable(ax, ref, values)
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None
    return tables


def read_etalon(text: str, where: str = "Etalon file") -> tuple[dict, dict]:
    """Parse Etalon exchange text.

    Returns
    -------
    tables : dict
        Axis letter -> :class:`volerr.tables.ErrorTable` (ISO names, values mm or rad,
        positions mm or deg).
    constants : dict
        ISO name (``EC0Y`` ...) -> position error, mm or rad.
    """
    reader = _EtalonReader(where)
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = _strip_comment(raw)
        if line:
            reader.line(lineno, line)
    require(reader.grid is None, f"{where}: Gridpoints of [{reader.section}] not closed with '}}'")
    require(reader.constants or reader.columns, f"{where}: no error parameters found")
    return _grid_tables(reader.columns, where), reader.constants


def negated(tables: dict, constants: dict) -> tuple[dict, dict]:
    """Errors -> compensation values (or back): every value with reversed sign (ISO/TR 16907:
    reversing the sign of an error table gives the compensation table)."""
    return ({a: ErrorTable(a, t.positions, {k: -v for k, v in t.values.items()})
             for a, t in tables.items()}, {k: -v for k, v in constants.items()})


def detect_format(text: str) -> str:
    body = "\n".join(_strip_comment(x) for x in text.splitlines())
    return "etalon" if re.search(r"^\s*\[[A-Za-z0-9]+\]\s*$", body, re.M) else "isg"


def check_against_model(model, tables: dict, constants: dict, where: str) -> None:
    """Every parameter must exist in the layout's model, on the right axis."""
    params, paxis = set(model.parameters), model.parameter_axis
    for ax, t in tables.items():
        require(ax in model.axes, f"{where}: axis {ax} is not an axis of {model.name} "
                                  f"({' '.join(model.axes)})")
        for n in t.values:
            require(n in params and paxis[n] == ax, f"{where}: {model.name} has no parameter {n}")
    for n in constants:
        require(n in params and paxis[n] is None,
                f"{where}: {model.name} has no position error {iso_to_controller(n)} ({n})")


def read_controller_file(path, model, fmt: str = "auto") -> tuple[dict, dict]:
    p = Path(path)
    require_file(p, f"controller file not found: {path}")
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        text = p.read_text(encoding="latin-1")
    fmt = detect_format(text) if fmt == "auto" else fmt
    require(fmt in FORMATS, f"unknown format {fmt!r} (isg, etalon)")
    tables, constants = (read_isg if fmt == "isg" else read_etalon)(text, str(p))
    check_against_model(model, tables, constants, str(p))
    return tables, constants
