"""Units of volerr, stated once, and the one number parser / formatter for text input/output.

API positions are mm (linear axes) and deg (rotary axes); errors are mm (translational) and
rad (angular).  Files carry unit suffixes (``_um``, ``_mm``, ``_urad``, ``_rad``); reports
show um and urad.  Convert with the factors below, never with bare ``1e3`` / ``1e6``::

    value_um = value_mm * UM_PER_MM
    value_rad = value_urad / URAD_PER_RAD
"""

from __future__ import annotations

import math
import re

import numpy as np

from .errors import InputError

#: micrometres per millimetre
UM_PER_MM = 1e3
#: microradians per radian
URAD_PER_RAD = 1e6
#: millimetres per micrometre (multiply: bit-identical to ``* 1e-3``)
MM_PER_UM = 1e-3
#: radians per microradian
RAD_PER_URAD = 1e-6
#: millimetres per metre
MM_PER_M = 1e3


def report_scale(is_angle: bool) -> float:
    """Factor from model units (mm or rad) to report units (um or urad)."""
    return URAD_PER_RAD if is_angle else UM_PER_MM


def parse_number(text, where: str = "", what: str = "") -> float:
    """One finite number from a text cell (surrounding blanks ignored).

    ``where`` locates the cell (``"path:line"``), ``what`` names it (a column).  Raises
    :class:`volerr.errors.InputError` with one line: ``"<where>: <what> = '...' is not a
    number"`` (with a hint for a decimal comma), ``"... empty value ..."`` or ``"... (NaN or
    infinite)"``."""
    prefix = f"{where}: " if where else ""
    label = f"{what} = " if what else ""
    cell = str(text).strip()
    if cell == "":
        raise InputError(f"{prefix}empty value{f' in column {what}' if what else ''}")
    try:
        value = float(cell)
    except ValueError:
        if re.fullmatch(r"[+-]?\d*,\d+([eE][+-]?\d+)?", cell):
            raise InputError(f"{prefix}{label}{cell!r} has a decimal comma; write numbers with "
                             f"a decimal point") from None
        raise InputError(f"{prefix}{label}{cell!r} is not a number") from None
    if not math.isfinite(value):
        raise InputError(f"{prefix}{label}{cell} (NaN or infinite)")
    return value


def num(value, spec: str) -> str:
    """``format(value, spec)`` without negative zero: a value that prints as zero (-0.0 or a
    tiny negative rounded away) prints with the sign of +0, e.g. ``+0.000`` or ``0.00``, never
    ``-0.00`` (every report, page and printed line of volerr formats numbers with it)."""
    s = format(float(value), spec)
    try:
        zero = float(s) == 0.0
    except ValueError:
        return s
    return format(0.0, spec) if zero else s


def format_number(value: float, digits: int = 12) -> str:
    """A number for a text file: ``digits`` significant digits (``%g``), ``-0`` written ``0``."""
    text = f"{float(value):.{digits}g}"
    return "0" if text == "-0" else text


def format_rows(data, digits: int = 12, block: int = 20000) -> str:
    """CSV rows (``\n``-terminated) of the (n, k) numbers ``data``, each cell as
    :func:`format_number`; one %-format per block of rows instead of a call per number."""
    data = np.asarray(data, dtype=float) + 0.0      # + 0.0: -0 becomes 0
    row = ",".join([f"%.{digits}g"] * data.shape[1]) + "\n"
    return "".join((row * len(b)) % tuple(b.ravel().tolist())
                   for b in (data[i:i + block] for i in range(0, len(data), block)))
