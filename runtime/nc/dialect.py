"""Which language a program is written in: ISO G-code or Heidenhain plain language.

:func:`detect` looks at the first lines that decide: a line of ISO words (``G1 X10``, ``N10``,
``%``, ``O1234``, Siemens ``TRAORI``) makes it ISO, a plain-language statement (``BEGIN PGM``,
``0 L X+10 FMAX``, ``TOOL CALL``) Heidenhain; comments and blank lines decide nothing.  A line
that is neither is "an unknown dialect" (APT / CL data ``GOTO/``, a binary file, another
controller's conversational language): the program is refused naming that line.
"""

from __future__ import annotations

import bisect
import itertools
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


#: how an axis or arc word's number without a decimal point is read: "auto" (refused in a
#: Fanuc-style program, :func:`fanuc_style`; mm elsewhere) or "mm"
DECIMAL_LESS = ("auto", "mm")
#: a program-number line (``O1234``, ``O0042 (NAME)``): Fanuc, Haas, Mitsubishi, Okuma EIA
_PROGRAM_NUMBER = re.compile(r"[ \t]*[Oo]\d+[ \t]*(\(.*)?$")
#: an axis or arc word whose number is not zero and has no decimal point (comments removed)
_DECIMAL_LESS = re.compile(r"(?<![A-Za-z])([XYZABCUVWIJKRxyzabcuvwijkr])[ \t]*([+-]?0*[1-9]\d*)"
                           r"(?![\d.,])")
_COMMENT = re.compile(r"\([^)\r\n]*\)|;[^\r\n]*")


def fanuc_style(lines) -> bool:
    """True when one of the first lines is a program number (``O1234``), as Fanuc and the
    controllers that read its programs (Haas, Mitsubishi) write it."""
    return any(_PROGRAM_NUMBER.match(seg.rstrip("\r\n")) for seg in lines[:LOOK])


def refuse_decimal_less(lines, first: int = 1) -> None:
    """Raise :class:`InputError` naming the first axis or arc word (``X Y Z A B C U V W I J K
    R``) whose number is not zero and has no decimal point (``X300``).  A Fanuc reads it as
    300 mm or as 300 least input increments (0.300 mm) by parameter 3401#0 DPI (FANUC Series
    0i / 30i "Decimal point programming"; Mitsubishi M700V programming manual 5.3 "Decimal
    Point Input", parameter #1078 Decpt2: X1 = X0.001 in type I), which the program does not
    say; the compensated copy writes a decimal point, a factor 1000 where it meant the
    increment.  ``--decimal-less mm`` states the reading."""
    text = _COMMENT.sub("", "".join(lines))
    m = _DECIMAL_LESS.search(text)
    if m is None:
        return
    # the match's line by the lines' lengths without comments (a comment ends on its line), so
    # any line ending counts: LF, CR LF or CR
    ends = itertools.accumulate(len(_COMMENT.sub("", seg)) for seg in lines)
    number = first + bisect.bisect_right(list(ends), m.start())
    word = f"{m.group(1).upper()}{m.group(2)}"
    raise InputError(f"line {number}: {word} has no decimal point in a Fanuc-style program "
                     f"(O number): {word}. mm or {word} x 0.001 mm by the controller's "
                     "parameter 3401#0 DPI; write the decimal point, or give --decimal-less mm")


def parser(name: str):
    """The line parser of a dialect for :func:`volerr.nc.interpret.interpret`: None for
    ISO, :class:`volerr.nc.heidenhain.Dialect` for Heidenhain."""
    if name == "heidenhain":
        from .heidenhain import Dialect
        return Dialect()
    return None
