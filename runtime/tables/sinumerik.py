"""SINUMERIK compensation tables: LEC (measuring system error compensation, ``$AA_ENC_COMP``)
and CEC (sag / cross-axis compensation, ``$AN_CEC``).

Source: SINUMERIK 840D sl Function Manual Extended Functions, K3 Compensations, sec.
"Interpolatory compensation" (6FC5397-1BP40-3BA1, 03/2013, pp. 240-264) and the SINUMERIK
808D / 802D sl function manuals (same chapter).  Both are part programs of system variables
(values and positions in mm, deg for a rotary axis):

LEC (``sinumerik-lec``), one table per machine axis, the axis' own positioning error::

    %_N_AX_EEC_INI
    CHANDATA(1)
    $AA_ENC_COMP[0,0,X1]=0.0012        ; value at interpolation point 0 (mm)
    ...
    $AA_ENC_COMP_STEP[0,X1]=20.0       ; distance between points
    $AA_ENC_COMP_MIN[0,X1]=-250.0      ; position of point 0
    $AA_ENC_COMP_MAX[0,X1]=250.0       ; position of the last point
    $AA_ENC_COMP_IS_MODULO[0,X1]=0     ; 1: a rotary axis' table over the turn
    M17

CEC (``sinumerik-cec``), tables ``t`` = 0, 1, ... of a base (input) axis and a compensation
(output) axis: the straightness errors ``E<B><A>`` of the linear axes; with a reversal column
also the positioning error split by approach direction (``$AN_CEC_DIRECTION`` 1 / -1, the
manual's "direction-dependent compensation")::

    %_N_NC_CEC_INI
    CHANDATA(1)
    $AN_CEC[0,0]=0.0004
    ...
    $AN_CEC_INPUT_AXIS[0]=(AX1)
    $AN_CEC_OUTPUT_AXIS[0]=(AX2)
    $AN_CEC_STEP[0]=20.0
    $AN_CEC_MIN[0]=-250.0
    $AN_CEC_MAX[0]=250.0
    $AN_CEC_DIRECTION[0]=0
    $AN_CEC_MULT_BY_TABLE[0]=0
    $AN_CEC_IS_MODULO[0]=0
    M17

Conventions and limits (as documented there): "a positive compensation value causes the
machine axis to move in the negative direction": the values are the errors (actual minus
nominal, tool relative to workpiece).  Interpolation points equally spaced, linear
interpolation between them, the first and last values held beyond the table (not for a
modulo table).  Points per table: MD38000 ``$MA_MM_ENC_COMP_MAX_POINTS`` (LEC) and MD18342
``$MN_MM_CEC_MAX_POINTS`` (CEC) -- the 808D / 828D have 200 points per table, the 828D eight
CEC tables; volerr writes at most :data:`MAX_POINTS` points and :data:`MAX_CEC_TABLES`
tables.  Values written with 4 decimals (0.1 um, :data:`INCREMENT`).  The compensation value
at the reference point should be 0 to avoid a jump when the function is switched on after
referencing: volerr writes the errors as they are (the tables' own zero).  Machine axes are
named ``<axis>1`` (``X1``; ``AX1``... in CEC as ``(AX<n>)`` by their order in the layout);
rename them to the machine's names.
"""

from __future__ import annotations

import re

import numpy as np

from ..errors import InputError, require
from . import comp_tables as ct

MAX_POINTS = 200
MAX_CEC_TABLES = 8
INCREMENT = 1e-4
_NUM = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"


def _fmt(v: float) -> str:
    s = f"{v:.4f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _pos(v: float) -> str:
    """A position or step (mm / deg): multiples of 0.001, written exactly."""
    s = f"{v:.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def axis_name(a: str) -> str:
    return f"{a}1"


def build_lec(funcs, max_points: int = MAX_POINTS) -> list:
    """LEC tables: the positioning error of every axis that has one."""
    require(max_points <= MAX_POINTS, f"--points: the LEC tables hold at most {MAX_POINTS}")
    return ct.positioning_tables(funcs, max_points, INCREMENT)


def build_cec(funcs, max_points: int = MAX_POINTS) -> list:
    """CEC tables: straightness of the linear axes, and the positioning by approach
    direction where the tables carry a reversal."""
    require(max_points <= MAX_POINTS, f"--points: the CEC tables hold at most {MAX_POINTS}")
    tables = ct.straightness_tables(funcs, max_points, INCREMENT)
    if funcs.has_reversal:
        pos = [t for t in ct.positioning_tables(funcs, max_points, INCREMENT,
                                                axes=list(funcs.reversal_functions))]
        tables += [t for t in ct.reversal_tables(funcs, pos, INCREMENT) if t.direction]
    require(len(tables) <= MAX_CEC_TABLES,
            f"{len(tables)} CEC tables, the controller holds {MAX_CEC_TABLES}")
    return tables


def write_lec(model_name: str, tables: list) -> str:
    out = [f"; volerr export: layout {model_name}; SINUMERIK LEC (measuring system error "
           "compensation), values = errors in mm (deg for rotary axes)",
           "%_N_AX_EEC_INI", "CHANDATA(1)"]
    for t in tables:
        ax = axis_name(t.input)
        out += [f"$AA_ENC_COMP[0,{k},{ax}]={_fmt(v)}" for k, v in enumerate(t.values)]
        out += [f"$AA_ENC_COMP_STEP[0,{ax}]={_pos(t.step)}",
                f"$AA_ENC_COMP_MIN[0,{ax}]={_pos(t.start)}",
                f"$AA_ENC_COMP_MAX[0,{ax}]={_pos(t.end)}",
                f"$AA_ENC_COMP_IS_MODULO[0,{ax}]={int(t.modulo)}"]
    out.append("M17")
    return "\n".join(out) + "\n"


def write_cec(model_name: str, tables: list, axes) -> str:
    out = [f"; volerr export: layout {model_name}; SINUMERIK CEC (sag / cross-axis "
           "compensation), values = errors in mm",
           "%_N_NC_CEC_INI", "CHANDATA(1)"]
    index = {a: i + 1 for i, a in enumerate(axes)}
    for n, t in enumerate(tables):
        out.append(f"; table {n}: {t.parameter} ({t.output} = f({t.input})"
                   + (f", approaching {'+' if t.direction > 0 else '-'}" if t.direction else "")
                   + ")")
        out += [f"$AN_CEC[{n},{k}]={_fmt(v)}" for k, v in enumerate(t.values)]
        out += [f"$AN_CEC_INPUT_AXIS[{n}]=(AX{index[t.input]})",
                f"$AN_CEC_OUTPUT_AXIS[{n}]=(AX{index[t.output]})",
                f"$AN_CEC_STEP[{n}]={_pos(t.step)}", f"$AN_CEC_MIN[{n}]={_pos(t.start)}",
                f"$AN_CEC_MAX[{n}]={_pos(t.end)}", f"$AN_CEC_DIRECTION[{n}]={t.direction}",
                f"$AN_CEC_MULT_BY_TABLE[{n}]=0", f"$AN_CEC_IS_MODULO[{n}]=0"]
    out.append("M17")
    return "\n".join(out) + "\n"


def _assignments(text: str, where: str):
    """(line number, name, indices, value text) of every ``$NAME[i,j]=value`` line."""
    for n, raw in enumerate(text.splitlines(), start=1):
        line = raw.split(";", 1)[0].strip()
        if not line or line.upper() in ("CHANDATA(1)", "M17", "M30") or line.startswith("%"):
            continue
        m = re.fullmatch(r"\$(\w+)\[([^\]]*)\]\s*=\s*(.+)", line)
        if m is None:
            raise InputError(f"{where} line {n}: cannot interpret {line[:40]!r}")
        yield n, m.group(1).upper(), [s.strip() for s in m.group(2).split(",")], m.group(3)


def _number(text: str, where: str) -> float:
    if not re.fullmatch(_NUM, text.strip()):
        raise InputError(f"{where}: {text.strip()!r} is not a number")
    return float(text)


def _axis(text: str, axes, where: str) -> str:
    t = text.strip().strip("()").upper()
    m = re.fullmatch(r"AX(\d+)", t)
    if m:
        k = int(m.group(1))
        require(1 <= k <= len(axes), f"{where}: machine axis AX{k} (the layout has "
                                     f"{len(axes)} axes)")
        return axes[k - 1]
    # the layout's letter alone or with the index 1 (X, X1: the names volerr writes and the
    # default machine axis names of MD10000 $MN_AXCONF_MACHAX_NAME_TAB); any other index
    # (X2, X9) is another machine axis, never read as X
    m = re.fullmatch(r"([XYZABC])(1?)", t)
    require(m is not None and m.group(1) in axes,
            f"{where}: unknown axis {text.strip()!r} (read: the layout's axes "
            f"{' '.join(axes)} as {axes[0]} or {axes[0]}1, or AX1..AX{len(axes)} in their "
            f"order; rename the machine's axes)")
    return m.group(1)


def _check_grid(start, step, end, n, where):
    require(step > 0, f"{where}: the distance between points must be positive")
    require(n >= 2, f"{where}: fewer than two points")
    require(abs(start + step * (n - 1) - end) <= 1e-6 * max(1.0, abs(end)),
            f"{where}: MIN + (points - 1) x STEP = {start + step * (n - 1):g} is not MAX "
            f"{end:g} (equally spaced points)")


def read_lec(text: str, axes, where: str = "LEC file") -> list:
    vals, par = {}, {}
    for n, name, idx, value in _assignments(text, where):
        at = f"{where} line {n}"
        if name == "AA_ENC_COMP":
            require(len(idx) == 3, f"{at}: $AA_ENC_COMP[e,N,axis] expected")
            a = _axis(idx[2], axes, at)
            vals.setdefault(a, {})[int(idx[1])] = _number(value, at)
        elif name.startswith("AA_ENC_COMP_"):
            a = _axis(idx[-1], axes, at)
            par.setdefault(a, {})[name[len("AA_ENC_COMP_"):]] = _number(value, at)
        else:
            raise InputError(f"{at}: ${name} is not a LEC variable")
    require(vals, f"{where}: no $AA_ENC_COMP values")
    out = []
    for a, v in vals.items():
        p = par.get(a, {})
        for key in ("STEP", "MIN", "MAX"):
            require(key in p, f"{where}: $AA_ENC_COMP_{key} of axis {a} missing")
        n = max(v) + 1
        require(sorted(v) == list(range(n)), f"{where}: axis {a}: interpolation points "
                                             f"missing (0 .. {n - 1})")
        _check_grid(p["MIN"], p["STEP"], p["MAX"], n, f"{where} axis {a}")
        out.append(ct.CompTable(f"E{a}{a}", a, a, p["MIN"], p["STEP"],
                                np.array([v[k] for k in range(n)]),
                                bool(p.get("IS_MODULO", 0))))
    return out


def read_cec(text: str, axes, where: str = "CEC file") -> list:
    vals, par = {}, {}
    for n, name, idx, value in _assignments(text, where):
        at = f"{where} line {n}"
        if name == "AN_CEC":
            require(len(idx) == 2, f"{at}: $AN_CEC[t,N] expected")
            vals.setdefault(int(idx[0]), {})[int(idx[1])] = _number(value, at)
        elif name.startswith("AN_CEC_"):
            key = name[len("AN_CEC_"):]
            t = int(idx[0])
            par.setdefault(t, {})[key] = _axis(value, axes, at) if key.endswith("AXIS") \
                else _number(value, at)
        else:
            raise InputError(f"{at}: ${name} is not a CEC variable")
    require(vals, f"{where}: no $AN_CEC values")
    out = []
    for t, v in sorted(vals.items()):
        p = par.get(t, {})
        for key in ("INPUT_AXIS", "OUTPUT_AXIS", "STEP", "MIN", "MAX"):
            require(key in p, f"{where}: $AN_CEC_{key}[{t}] missing")
        require(not p.get("MULT_BY_TABLE", 0), f"{where}: table {t} is multiplied by "
                                               "another table (not read)")
        n = max(v) + 1
        require(sorted(v) == list(range(n)), f"{where}: table {t}: points missing")
        _check_grid(p["MIN"], p["STEP"], p["MAX"], n, f"{where} table {t}")
        a, b = p["INPUT_AXIS"], p["OUTPUT_AXIS"]
        out.append(ct.CompTable(f"E{b}{a}", a, b, p["MIN"], p["STEP"],
                                np.array([v[k] for k in range(n)]),
                                bool(p.get("IS_MODULO", 0)), int(p.get("DIRECTION", 0))))
    return out
