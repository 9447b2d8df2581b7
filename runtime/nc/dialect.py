"""Which language a program is written in: ISO G-code or Heidenhain plain language.

:func:`detect` looks at the first lines that decide: a line of ISO words (``G1 X10``, ``N10``,
``%``, ``O1234``, Siemens ``TRAORI``) makes it ISO, a plain-language statement (``BEGIN PGM``,
``0 L X+10 FMAX``, ``TOOL CALL``) Heidenhain; comments and blank lines decide nothing.  A line
that is neither is "an unknown dialect" (APT / CL data ``GOTO/``, a binary file, another
controller's conversational language): the program is refused naming that line.
"""

from __future__ import annotations

import re

from ..errors import InputError
from . import gcode

DIALECTS = ("auto", "iso", "heidenhain")

_HEIDENHAIN = re.compile(
    r"[ \t]*(\d+[ \t]+)?(BEGIN[ \t]+PGM|END[ \t]+PGM|BLK[ \t]+FORM|TOOL[ \t]+(CALL|DEF)|"
    r"L[ \t]+(I?[XYZABC][ \t]*[+-]|R0|FMAX|M\d)|L[ \t]*$|CC[ \t]|CYCL[ \t]|LBL[ \t]|"
    r"FUNCTION[ \t]|PLANE[ \t])|[ \t]*\d+[ \t]+M\d", re.IGNORECASE)
_NEUTRAL = re.compile(r"[ \t]*(;.*|\*.*|\([^)]*\)[ \t]*)?$")
#: lines looked at at most
LOOK = 200


def detect(lines, first: int = 1) -> str:
    """``"iso"`` or ``"heidenhain"`` from the first lines (with or without their endings);
    raises :class:`InputError` naming the first line that is neither.  A program of comments
    and blank lines only is ISO."""
    for n, seg in enumerate(lines[:LOOK], start=first):
        body = seg.rstrip("\r\n")
        if _NEUTRAL.fullmatch(body):
            continue
        if _HEIDENHAIN.match(body):
            return "heidenhain"
        try:
            toks = gcode.tokenize(body, n)
        except InputError:
            toks = None
        if toks is not None and any(t.kind in ("word", "keyword") for t in toks):
            return "iso"
        if toks is not None and body.strip().startswith("%"):
            continue
        if toks is not None and re.fullmatch(r"[ \t]*O\w*.*", body):
            return "iso"
        raise InputError(f"line {n}: unknown program dialect (neither ISO G-code nor "
                         f"Heidenhain plain language): {body.strip()[:40]!r}")
    return "iso"


def parser(name: str):
    """The line parser of a dialect for :func:`volerr.nc.interpret.interpret`: None for
    ISO, :class:`volerr.nc.heidenhain.Dialect` for Heidenhain."""
    if name == "heidenhain":
        from .heidenhain import Dialect
        return Dialect()
    return None
