"""Heidenhain plain-language (Klartext) programs: lines read into the tokens of
:mod:`volerr.nc.gcode`, so that the same interpreter and writer serve them.

What is read (TNC conversational format, one block per line, block number first)::

    0 BEGIN PGM PART MM
    1 BLK FORM 0.1 Z X+0 Y+0 Z-40
    2 TOOL CALL 5 Z S12000
    3 L Z+100 R0 FMAX M3
    4 M128
    5 L X+10.5 Y-3 Z+2 B+30 C+45 F800
    6 L IX+0.5 IY-0.25
    7 M129
    8 END PGM PART MM

* ``L`` straight moves: axis words ``X Y Z A B C`` with explicit signs (``IX`` ... incremental
  for that word), ``R0`` (no radius compensation), ``F``/``FMAX``/``FAUTO``, ``M`` words.
* ``TOOL CALL n`` (the tool number; ``DL`` adds to the tool length), ``M128`` / ``M129`` and
  ``FUNCTION TCPM ...`` / ``FUNCTION RESET TCPM``: TCPM on / off (rotary angles).
* Passed through (no motion): ``BEGIN PGM`` / ``END PGM`` (``MM``; ``INCH`` is refused),
  ``BLK FORM``, ``TOOL DEF``, ``PLANE RESET STAY``, ``STOP``, ``M`` lines, comments (``;``
  to the end of the line, lines starting with ``*``).
* Refused with the line number (a compensated copy could not be guaranteed): circles
  ``CC C CR CT``, ``RND CHF``, ``APPR DEP``, ``LN`` (3-D correction), radius compensation
  ``RL RR``, cycles ``CYCL``, labels and calls ``LBL CALL``, parameters ``FN Q``, ``PLANE``
  other than ``PLANE RESET STAY``, ``M140``, ``M92`` (the block's coordinates are relative
  to a position the machine builder defines), and anything else.  ``M91`` (coordinates
  relative to the machine datum) passes: the program's numbers are taken as machine axis
  positions anyway (the work-offset rule of :mod:`volerr.nc.gcode`).

Writing: only the numbers of the axis words change; a word the block needs is added after
its last axis word (or after ``L``), with an explicit sign, as the TNC writes them.
"""

from __future__ import annotations

import re

from ..errors import InputError
from .gcode import Line, Token

_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)"
_BLOCK = re.compile(r"[ \t]*\d+[ \t]*")
_AXIS_WORD = re.compile(rf"(I?)([XYZABCxyzabc])[ \t]*({_NUMBER})")
_F_WORD = re.compile(rf"(F)({_NUMBER})|(FMAX|FAUTO|F[ \t]+AUTO)\b", re.IGNORECASE)
_M_WORD = re.compile(rf"(M)({_NUMBER})", re.IGNORECASE)
_R_WORD = re.compile(r"(R0|RL|RR)\b", re.IGNORECASE)
_S_WORD = re.compile(rf"(S)({_NUMBER})", re.IGNORECASE)
_DL_WORD = re.compile(rf"(D[LR])[ \t]*({_NUMBER})", re.IGNORECASE)
_SPACE = re.compile(r"[ \t]+")

#: statements that move the machine in ways the compensation does not follow, with a reason
REFUSED = {
    "CC": "circle centre (CC/C arcs)", "C": "circular arc", "CR": "circular arc",
    "CT": "tangential arc", "RND": "rounding", "CHF": "chamfer", "APPR": "approach contour",
    "DEP": "departure contour", "LN": "3-D tool correction (LN)", "CYCL": "cycle",
    "LBL": "label (program section repeat)", "CALL": "program / label call",
    "FN": "Q parameter function", "PLANE": "tilted working plane",
}


class Dialect:
    """The Heidenhain plain-language dialect: :meth:`parse_line` for the interpreter."""

    name = "heidenhain"
    #: added words carry an explicit sign
    signed = True

def parse_line(number: int, body: str, ending: str) -> Line:
    """One plain-language line as a :class:`volerr.nc.gcode.Line`: axis, ``F M S T``
    words as word tokens (``IX``: the letter in the line's ``incremental`` set), statement
    keywords (``L``, ``TCPM``, ``TCPM_OFF``) as keyword tokens, everything else kept as
    ``other`` text.  Raises :class:`InputError` for a statement that cannot be compensated."""
    where = f"line {number}"
    tokens: list = []
    incremental, anchor = set(), None
    i = 0
    m = _BLOCK.match(body)
    if m and m.end() > 0 and body[:m.end()].strip():
        tokens.append(Token("other", m.group(0), 0))
        i = m.end()
    rest = body[i:]
    text = rest.split(";", 1)[0]
    head = text.strip().upper()
    word0 = head.split(" ", 1)[0] if head else ""
    if not head or head.startswith("*"):
        if rest:
            tokens.append(Token("comment" if head else "space", rest, i))
        return _line(number, body, ending, tokens, incremental, anchor)
    if _statement(head, text, i, tokens, where):
        pass
    elif head.startswith("TOOL CALL"):
        return _tool_call(number, body, ending, tokens, i, text, rest)
    elif word0 in REFUSED:
        raise InputError(f"{where}: {word0} ({REFUSED[word0]}) is not supported")
    elif word0 == "L" or word0.startswith("M"):
        incremental, anchor = _block_words(body, i, i + len(text), word0, tokens, where)
    else:
        raise InputError(f"{where}: cannot interpret {head[:30]!r} (plain-language statement "
                         "not supported)")
    k = rest.find(";")
    if k >= 0:
        tokens.append(Token("comment", rest[k:], i + k))
    return _line(number, body, ending, tokens, incremental, anchor)


Dialect.parse_line = staticmethod(parse_line)


def _statement(head: str, text: str, i: int, tokens: list, where: str) -> bool:
    """A statement kept as it is (program begin / end, blank form, tool definition, stop,
    plane reset) or a TCPM switch: its token appended; False for any other line."""
    if head.startswith("BEGIN PGM") or head.startswith("END PGM"):
        if re.search(r"\bINCH\b", head):
            raise InputError(f"{where}: a program in inch (INCH) is not supported")
        tokens.append(Token("other", text, i))
    elif head.startswith(("BLK FORM", "TOOL DEF", "STOP")) or \
            re.fullmatch(r"PLANE RESET( STAY)?", head):
        tokens.append(Token("other", text, i))
    elif head.startswith("FUNCTION"):
        if re.fullmatch(r"FUNCTION\s+RESET\s+TCPM", head):
            tokens.append(Token("keyword", text, i, "TCPM_OFF"))
        elif re.match(r"FUNCTION\s+TCPM\b", head):
            tokens.append(Token("keyword", text, i, "TCPM"))
        else:
            raise InputError(f"{where}: {head[:30]!r} is not supported")
    else:
        return False
    return True


def _block_words(body: str, i: int, end: int, word0: str, tokens: list, where: str):
    """The words of a straight block ``L ...`` (or of a line of M functions) from ``i`` to
    ``end`` appended to ``tokens`` -> (letters written incrementally ``IX``, index of the token
    after which added words go)."""
    incremental, anchor = set(), None
    j = i
    if word0 == "L":
        k = body.index("L", i) if "L" in body[i:] else body.index("l", i)
        tokens.append(Token("keyword", body[i:k + 1], i, "L"))
        j = k + 1
        anchor = len(tokens) - 1
    while j < end:
        if body[j] in " \t":
            s = _SPACE.match(body, j)
            tokens.append(Token("space", s.group(0), j))
            j = s.end()
            continue
        for rx, kind in ((_AXIS_WORD, "axis"), (_R_WORD, "r"), (_F_WORD, "f"),
                         (_M_WORD, "m"), (_S_WORD, "s")):
            mm = rx.match(body, j)
            if mm:
                break
        else:
            raise InputError(f"{where}: cannot interpret {body[j:j + 12]!r} in a "
                             "plain-language block")
        if kind == "axis":
            letter = mm.group(2).upper()
            if mm.group(1):
                incremental.add(letter)
            tokens.append(Token("word", mm.group(0), j, letter, float(mm.group(3)),
                                mm.start(3), mm.end(3)))
            anchor = len(tokens) - 1
        elif kind == "r":
            if mm.group(1).upper() != "R0":
                raise InputError(f"{where}: radius compensation {mm.group(1).upper()} "
                                 "is not supported (the path would be offset by the "
                                 "controller)")
            tokens.append(Token("other", mm.group(0), j))
        elif kind == "m" and float(mm.group(2)) == 92:
            raise InputError(f"{where}: M92 (coordinates relative to a position the machine "
                             "builder defines, not the machine datum) is not supported")
        elif kind == "f" and not mm.group(2):
            tokens.append(Token("other", mm.group(0), j))
        else:
            letter = "F" if kind == "f" else kind.upper()
            tokens.append(Token("word", mm.group(0), j, letter, float(mm.group(2)),
                                mm.start(2), mm.end(2)))
        j = mm.end()
    if word0 != "L" and any(t.kind == "word" and t.letter in "XYZABC" for t in tokens):
        raise InputError(f"{where}: axis words outside an L block")
    return incremental, anchor


def _tool_call(number, body, ending, tokens, i, text, rest) -> Line:
    where = f"line {number}"
    m = re.match(r"([ \t]*TOOL[ \t]+CALL[ \t]+)", body[i:], re.IGNORECASE)
    j = i + m.end()
    tokens.append(Token("other", m.group(0), i))
    t = re.match(r"\d+(?:\.\d+)?", body[j:])
    if t is None:
        raise InputError(f"{where}: TOOL CALL with a tool name: give --tool-length (the tool "
                         "table is keyed by tool numbers)")
    tokens.append(Token("word", t.group(0), j, "T", float(t.group(0)), j, j + t.end()))
    j += t.end()
    end = i + len(text)
    while j < end:
        dl = _DL_WORD.match(body, j)
        if dl:
            letter = dl.group(1).upper()
            tokens.append(Token("word" if letter == "DL" else "other", dl.group(0), j,
                                letter if letter == "DL" else "", float(dl.group(2)),
                                dl.start(2), dl.end(2)))
            j = dl.end()
            continue
        s = re.match(r"[^ \t]+|[ \t]+", body[j:end])
        tokens.append(Token("other", s.group(0), j))
        j += s.end()
    k = rest.find(";")
    if k >= 0:
        tokens.append(Token("comment", rest[k:], i + k))
    return _line(number, body, ending, tokens, set(), None)


def _line(number, body, ending, tokens, incremental, anchor) -> Line:
    line = Line(number, body, ending, tokens=tokens)
    line.incremental = frozenset(incremental)
    line.anchor = anchor
    return line
