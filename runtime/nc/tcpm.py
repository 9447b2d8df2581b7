"""TCPM programs: the tool tip in the workpiece frame, the tool length, the tool table.

Under TCPM (tool centre point management: Fanuc ``G43.4`` / ``G43.5``, Heidenhain ``M128`` /
``FUNCTION TCPM``, Siemens ``TRAORI``) a motion block gives the tool tip ``X Y Z`` (mm) in
the workpiece frame and the tool orientation, either as the rotary axis angles (deg; G43.4,
M128, TRAORI with rotary words) or as a tool vector (``I J K`` of G43.5, ``A3 B3 C3`` of
TRAORI: the unit tool-axis direction, from the tip towards the spindle, in the workpiece
frame).

The tool tip lies the tool length ``L`` from the point the axes refer to, against the tool axis: a
tool offset ``(0, 0, -L)`` in the tool frame (the same offset ``volerr compensate --tool``
gives a program in axis positions).

This module holds what the program says: the frame of a row (:data:`AXES`, :data:`ANGLES`,
:data:`VECTOR`), the tool offset of a tool length, the rule that finds a block's tool length
(:func:`length_rule`) and the tool table file (:func:`read_tool_table`).  How the controller
turns the words into axis positions is the machine's: :mod:`volerr.fiveaxis.tcpm_kinematics`.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, require

#: frames of a row: axis positions, TCPM with rotary angles, TCPM with a tool vector
AXES, ANGLES, VECTOR = 0, 1, 2


def tool_offset(length) -> np.ndarray:
    """The tool offset (N, 3) of tool lengths ``length`` (N,) mm: ``(0, 0, -L)``."""
    length = np.asarray(length, dtype=float)
    out = np.zeros((len(length), 3))
    out[:, 2] = -length
    return out


def length_rule(tool_length: float | None = None, table: dict | None = None):
    """The tool length a TCPM block uses, as the interpreter asks for it: ``rule(tools,
    where)`` with ``tools`` the last ``T H D`` words (letter -> number) -> mm.  The ``table``
    (tool number -> mm) at the ``H`` word (Fanuc tool length offset), else at ``T`` (Siemens,
    Heidenhain ``TOOL CALL``), else at ``D``; a given ``tool_length`` for every tool the table
    does not hold (or without a table).  Given both, a tool the table holds with another
    length is refused (which one is right cannot be told).  Plus a Heidenhain ``DL`` (delta
    length).  None when neither is given."""
    if tool_length is None and not table:
        return None

    def rule(tools: dict, where: str) -> float:
        delta = float(tools.get("DL", 0.0))
        found = _table_entry(table or {}, tools, where, must=tool_length is None)
        if found is None:
            return float(tool_length) + delta
        word, length = found
        if tool_length is not None and abs(length - float(tool_length)) > 1e-9:
            raise InputError(f"{where}: --tool-length {float(tool_length):g} mm and the tool "
                             f"table's {length:g} mm for tool {word} disagree (give one of "
                             "them)")
        return length + delta
    return rule


def _table_entry(table: dict, tools: dict, where: str, must: bool):
    """(word, length mm) of the tool the ``H``, else ``T``, else ``D`` word names in
    ``table``; None when there is none and not ``must`` (else :class:`InputError`)."""
    for letter in ("H", "T", "D"):
        if letter in tools:
            number = tools[letter]
            key = int(number) if float(number).is_integer() else number
            if key in table:
                return f"{letter}{key:g}", float(table[key])
            if not must:
                return None
            raise InputError(f"{where}: tool {letter}{key:g} is not in the tool table "
                             f"(tools {' '.join(f'{k:g}' for k in sorted(table))})")
    if not must:
        return None
    raise InputError(f"{where}: TCPM with no T / H / D word before it: the tool length "
                     "is unknown (give --tool-length)")


def read_tool_table(path) -> dict:
    """A tool table CSV ``tool,length_mm`` (tool number, tool length in mm; other columns
    ignored) -> {tool number: mm}."""
    from ..fileio import read_csv_rows
    from ..units import parse_number

    rows = read_csv_rows(path, missing=f"tool table not found: {path}",
                         empty=f"{path}: empty tool table")
    header = [h.lower() for h in rows[0][1]]
    require("tool" in header and "length_mm" in header,
            f"{path}: a tool table needs the columns tool,length_mm (got {','.join(header)})")
    it, il = header.index("tool"), header.index("length_mm")
    out = {}
    for lineno, cells in rows[1:]:
        require(len(cells) == len(header), f"{path}:{lineno}: {len(cells)} fields, header "
                                           f"has {len(header)}")
        t = parse_number(cells[it], f"{path}:{lineno}", "tool")
        key = int(t) if float(t).is_integer() else t
        require(key not in out, f"{path}:{lineno}: tool {key:g} given twice")
        length = parse_number(cells[il], f"{path}:{lineno}", "length_mm")
        require(0 <= length <= 2000, f"{path}:{lineno}: tool length {length:g} mm is not "
                                     "plausible (0 .. 2000 mm)")
        out[key] = length
    require(out, f"{path}: no tools in the tool table")
    return out

