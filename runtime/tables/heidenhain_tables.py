"""Heidenhain TNC nonlinear axis error compensation: compensation-value tables (``.COM``) and
their assignment table (``.CMA``).

Sources: HEIDENHAIN Technical Manual MANUALplus 620 (the chapter on nonlinear axis error
compensation: the ``*.COM`` columns ``AXISPOS``, the axis columns and ``BACKLASH``; the
``*.CMA`` assignment "[axis in column of the .COM] = F(axis in column of the .CMA in which the
.COM is entered)", the active line marked ``*`` in ``ACTIVE``), HEIDENHAIN TNC 407 / 415 /
425 Technical Manual (module 9095: "Compensation value table (.COM) has more than 256
entries"; "with an axis of rotation, the system only recognizes corrections of entries from 0
to 360"), iTNC 530 HSCI Technical Manual (KinematicsComp: ``.COM`` columns by ISO 230-1
error, e.g. positioning ``EXX``, straightness ``EYX``, ``EZX`` of the X axis).

Files (TNC table syntax: ``BEGIN <name> MM``, a header line of column names, one row per
point, ``[END]``)::

    comp.cma                             comp_X.com
    BEGIN comp.cma                       BEGIN comp_X.com MM
    NR ACTIVE X          Y               NR AXISPOS    X        Y        Z        BACKLASH
    0  *      comp_X.com comp_Y.com       0  -250.0000  +0.0012  -0.0004  +0.0002  +0.0009
    [END]                                 ...
                                         [END]

A ``.COM`` table belongs to the axis of the ``.CMA`` column it is entered in (its positions
are ``AXISPOS``, with respect to the machine datum); its columns named after axes hold the
values for those axes: the table's own axis its positioning error ``E<A><A>``, the other
linear axes the straightness ``E<B><A>``; with a reversal (``RV_<axis>``), the own column the
values approaching in the positive direction and ``BACKLASH`` those in the negative
direction.  Values are the errors (actual minus nominal, tool relative to workpiece), mm with
4 decimals (0.1 um, :data:`INCREMENT`); a rotary axis' table spans 0 .. 360 deg (deg).
Points equally spaced, at most :data:`MAX_POINTS` per table.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import InputError, require
from . import comp_tables as ct

MAX_POINTS = 256
INCREMENT = 1e-4


def build(funcs, max_points: int = MAX_POINTS) -> list:
    """Per axis with a table: its positioning error and (linear axes) its straightness in the
    other linear axes, on one grid; by approach direction where there is a reversal."""
    require(max_points <= MAX_POINTS, f"--points: a .COM table holds at most {MAX_POINTS}")
    model = funcs.model
    out = []
    for a in model.axes:
        if a not in funcs.tables:
            continue
        mod = ct.endless(model, a)
        start, step, n = ct.grid_for(funcs, a, max_points, mod)
        pos = start + step * np.arange(n)
        names = [f"E{a}{a}"] + ([f"E{b}{a}" for b in model.axes
                                 if b != a and not ct.rotary(b)] if not ct.rotary(a) else [])
        own = []
        for p in names:
            if not (ct.has_positioning(funcs, a) if p == f"E{a}{a}" else
                    p in funcs.functions):
                continue
            out_axis = p[1]
            t = ct.CompTable(p, a, out_axis, start, step,
                             ct.quantize(ct.error_values(funcs, p, a, np.mod(pos, 360.0)
                                                         if mod else pos), INCREMENT), mod)
            own.append(t)
        out += ct.reversal_tables(funcs, own, INCREMENT)
    return out


def _num(v: float) -> str:
    return f"{round(float(v), 4) + 0.0:+.4f}"


def _table(rows: list) -> list:
    """Rows of cells as fixed-width lines (each column as wide as its widest cell + 2)."""
    widths = [max(len(r[j]) for r in rows) + 2 for j in range(len(rows[0]))]
    return ["".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]


def write(stem: str, model_name: str, tables: list) -> dict:
    """{file name: text} of the ``.CMA`` (``<stem>.cma``) and its ``.COM`` tables
    (``<stem>_<axis>.com``) of layout ``model_name`` (TNC tables carry no comment: the
    layout is not named in them)."""
    by_axis: dict = {}
    for t in tables:
        by_axis.setdefault(t.input, []).append(t)
    files = {}
    cma_cols = []
    for a, ts in by_axis.items():
        name = f"{stem}_{a}.com"
        cma_cols.append((a, name))
        cols, backlash = [], None
        for t in ts:
            if t.direction == -1:
                backlash = t
            else:
                cols.append(t)
        header = ["NR", "AXISPOS"] + [t.output for t in cols] + (["BACKLASH"] if backlash
                                                                 else [])
        cells = [header]
        pos = ts[0].positions
        for k, p in enumerate(pos):
            row = [str(k), _num(p)] + [_num(t.values[k]) for t in cols]
            if backlash is not None:
                row.append(_num(backlash.values[k]))
            cells.append(row)
        files[name] = "\n".join([f"BEGIN {name} MM", *_table(cells), "[END]"]) + "\n"
    cma = [f"BEGIN {stem}.cma",
           *_table([["NR", "ACTIVE"] + [a for a, _ in cma_cols],
                    ["0", "*"] + [n for _, n in cma_cols]]), "[END]"]
    files[f"{stem}.cma"] = "\n".join(cma) + "\n"
    return files


def _rows(text: str, where: str) -> tuple:
    """(header, [(line number, cells)]) of a TNC table."""
    lines = [(n, s.strip()) for n, s in enumerate(text.splitlines(), start=1)]
    lines = [(n, s) for n, s in lines if s and not s.startswith(";")]
    require(lines and lines[0][1].upper().startswith("BEGIN"),
            f"{where}: a TNC table starts with BEGIN <name>")
    require(lines[-1][1].upper() == "[END]", f"{where}: a TNC table ends with [END]")
    require(len(lines) >= 3, f"{where}: no header line")
    header = lines[1][1].split()
    body = []
    for n, s in lines[2:-1]:
        cells = s.split()
        require(len(cells) == len(header), f"{where} line {n}: {len(cells)} cells for "
                                           f"{len(header)} columns")
        body.append((n, cells))
    return [h.upper() for h in header], body


def _float(c: str, where: str) -> float:
    if not re.fullmatch(r"[+-]?(?:\d+\.?\d*|\.\d+)", c):
        raise InputError(f"{where}: {c!r} is not a number")
    return float(c)


def read(cma_path, axes) -> list:
    """The tables of a ``.CMA`` file's active line and its ``.COM`` files (next to it)."""
    cma_path = Path(cma_path)
    require(cma_path.is_file(), f"controller file not found: {cma_path}")
    header, body = _rows(cma_path.read_text(encoding="latin-1"), str(cma_path))
    require("ACTIVE" in header, f"{cma_path}: no ACTIVE column")
    act = [cells for _, cells in body if cells[header.index("ACTIVE")] == "*"]
    require(len(act) == 1, f"{cma_path}: exactly one line must be active (*), found "
                           f"{len(act)}")
    out = []
    for j, h in enumerate(header):
        if h in ("NR", "ACTIVE"):
            continue
        require(h in axes, f"{cma_path}: column {h} is not an axis of the layout "
                           f"({' '.join(axes)})")
        out += _read_com(cma_path.parent / act[0][j], h, axes)
    require(out, f"{cma_path}: no compensation tables")
    return out


def _read_com(path: Path, axis: str, axes) -> list:
    require(path.is_file(), f"compensation table not found: {path}")
    header, body = _rows(path.read_text(encoding="latin-1"), str(path))
    require("AXISPOS" in header, f"{path}: no AXISPOS column")
    require(len(body) <= MAX_POINTS, f"{path}: {len(body)} points, a .COM table holds at "
                                     f"most {MAX_POINTS}")
    data = np.array([[_float(c, f"{path} line {n}") for c in cells] for n, cells in body])
    pos = data[:, header.index("AXISPOS")]
    require(len(pos) >= 2 and np.all(np.diff(pos) > 0), f"{path}: AXISPOS must increase")
    step = float(np.mean(np.diff(pos)))
    require(np.allclose(np.diff(pos), step, atol=1e-6),
            f"{path}: points not equally spaced")
    out = []
    has_backlash = "BACKLASH" in header
    for j, h in enumerate(header):
        if h in ("NR", "AXISPOS", "BACKLASH"):
            continue
        require(h in axes, f"{path}: column {h} is not an axis of the layout")
        name = f"E{h}{axis}"
        mod = ct.rotary(axis) and abs(pos[-1] - pos[0] - 360.0) < 1e-6
        if has_backlash and h == axis:
            out.append(ct.CompTable(name, axis, h, pos[0], step, data[:, j], mod, 1))
            out.append(ct.CompTable(name, axis, h, pos[0], step,
                                    data[:, header.index("BACKLASH")], mod, -1))
        else:
            out.append(ct.CompTable(name, axis, h, pos[0], step, data[:, j], mod))
    return out
