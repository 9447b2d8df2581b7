"""G-code programs in machine axis coordinates: a byte-keeping tokenizer and a modal interpreter.

What is read
------------
A program is read as bytes and decoded as latin-1, so that writing it back gives the same bytes
(any encoding of comments survives).  Lines end in LF, CRLF or CR; every line keeps its own
ending.  A line is split into tokens that together are the line exactly:

* ``word``: an address letter and a number, e.g. ``X-12.5``, ``G01``, ``N0010`` (the letter may be
  lower case; blanks between letter and number are allowed and kept);
* ``comment``: ``( ... )`` or ``;`` up to the end of the line;
* ``space`` and ``other``: ``%`` and the program name line are kept as they are.

Anything else (variables ``#1``, expressions ``[..]``, ``=``, conversational syntax) is refused
with the line number: the program cannot be interpreted safely.

Interpretation (modal state, one block per line)
------------------------------------------------
* Motion: ``G0`` and ``G1`` (straight moves in axis space).  A block with axis words and no
  other non-modal function is a *motion block*.  ``G2``/``G3`` (arcs), canned cycles
  ``G73 G74 G76 G81``-``G89``, ``G92 G52 G10`` (offset changes), ``G68 G51`` (rotation,
  scaling), ``G41 G42`` (cutter radius compensation), ``G43.4 G43.5 M128 TRAORI`` (TCPM: the
  program would be in workpiece, not axis, coordinates), ``G20`` (inch), ``/`` (block delete)
  and ``M98`` (subprogram call) are refused: a compensated copy could not be guaranteed.
  Arcs are refused rather than linearised, so that the output's geometry stays the program's.
* ``G90``/``G91``: both handled; in ``G91`` an axis word is the increment from the position
  the controller holds.
* ``G53`` moves and work offsets (``G54`` ...) are kept as written: the program's numbers are
  taken to be the axis positions the error tables refer to.
* ``G28``/``G30`` (reference return) and ``G4`` (dwell, its ``X``/``P`` is time) are passed
  through untouched; after ``G28``/``G30`` the axes they name are at an unknown position until
  programmed again.
* Axis words are the model's axes (e.g. ``X Y Z B C``); a letter that is an axis of another
  machine (``A`` ``U`` ... on a DMU 50) is refused.  All other words (``N F S T M H D``, ...)
  are kept and ignored.
* An axis that has never been programmed is unknown; a motion block that needs it is reported
  as not compensated (its bytes are kept), unless an initial position is given.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from volerr.errors import InputError

_LINE = re.compile(r"[^\r\n]*(?:\r\n|\n|\r|$)")
_WORD = re.compile(r"([A-Za-z])([ \t]*)([+-]?(?:\d+\.?\d*|\.\d+))")
_SPACE = re.compile(r"[ \t]+")
_COMMENT_PAREN = re.compile(r"\([^)]*\)")

REFUSED_G = {
    2: "G2 circular arc", 3: "G3 circular arc", 10: "G10 offset setting",
    20: "G20 inch units", 41: "G41 cutter radius compensation",
    42: "G42 cutter radius compensation", 51: "G51 scaling", 52: "G52 local coordinate shift",
    68: "G68 coordinate rotation", 73: "G73 canned cycle", 74: "G74 canned cycle",
    76: "G76 canned cycle", 92: "G92 coordinate shift", 43.4: "G43.4 TCPM (tool centre point "
    "control: program not in axis coordinates)", 43.5: "G43.5 TCPM (tool centre point control)",
    12.1: "G12.1 polar interpolation", 7.1: "G7.1 cylindrical interpolation",
}
REFUSED_G.update({g: f"G{g} canned cycle" for g in range(81, 90)})
REFUSED_M = {98: "M98 subprogram call", 128: "M128 TCPM (tool centre point control)"}


@dataclass
class Token:
    kind: str            # "word", "comment", "space", "other"
    text: str
    start: int
    letter: str = ""     # upper case, words only
    value: float = 0.0
    num_start: int = 0   # span of the number inside the line
    num_end: int = 0


@dataclass
class Line:
    """One line: its body (without the line ending), the ending, and its tokens."""

    number: int          # 1-based line number in the file
    body: str
    ending: str
    tokens: list = field(default_factory=list)

    def words(self) -> list[Token]:
        return [t for t in self.tokens if t.kind == "word"]

    @property
    def text(self) -> str:
        return self.body + self.ending


@dataclass
class Block:
    """A motion block after interpretation: target axis positions (mm / deg, absolute) of every
    axis (None where unknown), which axes the line programs, and the distance mode."""

    line: Line
    target: dict
    programmed: tuple
    incremental: bool


def read_program(path) -> str:
    p = Path(path)
    if not p.is_file():
        raise InputError(f"program not found: {path}")
    return p.read_bytes().decode("latin-1")


def split_lines(text: str) -> list[tuple[str, str]]:
    """(body, ending) of every line; joining body + ending gives ``text`` back exactly."""
    out = []
    pos = 0
    while pos < len(text):
        m = _LINE.match(text, pos)
        seg = m.group(0)
        body = seg.rstrip("\r\n")
        out.append((body, seg[len(body):]))
        pos = m.end()
    return out


def tokenize(body: str, number: int = 0) -> list[Token]:
    """Tokens of one line body; raises :class:`InputError` on text it cannot interpret."""
    tokens = []
    i = 0
    stripped = body.strip()
    if stripped.startswith("%") or stripped == "":
        return [Token("other", body, 0)] if body else []
    while i < len(body):
        c = body[i]
        if c in " \t":
            m = _SPACE.match(body, i)
            tokens.append(Token("space", m.group(0), i))
            i = m.end()
        elif c == "(":
            m = _COMMENT_PAREN.match(body, i)
            if not m:
                raise InputError(f"line {number}: unclosed comment '(' ")
            tokens.append(Token("comment", m.group(0), i))
            i = m.end()
        elif c == ";":
            tokens.append(Token("comment", body[i:], i))
            i = len(body)
        elif c == "/" and not any(t.kind == "word" for t in tokens):
            raise InputError(f"line {number}: block delete '/' is not supported (the block may "
                             "or may not run)")
        else:
            m = _WORD.match(body, i)
            if not m:
                raise InputError(f"line {number}: cannot interpret {body[i:i + 12]!r} (only "
                                 "address words, comments and blanks are supported)")
            tokens.append(Token("word", m.group(0), i, m.group(1).upper(), float(m.group(3)),
                                m.start(3), m.end(3)))
            i = m.end()
    return tokens


def parse(text: str) -> list[Line]:
    """All lines of a program with their tokens."""
    return [Line(n, body, end, tokenize(body, n))
            for n, (body, end) in enumerate(split_lines(text), start=1)]


class Interpreter:
    """Modal interpretation of a tokenized program for a machine with axes ``axes``.

    ``initial``: axis -> known position at program start (mm / deg)."""

    FOREIGN_AXES = set("XYZABCUVW")

    def __init__(self, axes, initial: dict | None = None):
        self.axes = tuple(axes)
        self.position = {a: None for a in self.axes}
        self.position.update({a: float(v) for a, v in (initial or {}).items()})
        self.incremental = False

    def block(self, line: Line) -> Block | None:
        """Update the modal state with one line; return a :class:`Block` for a motion block."""
        words = line.words()
        if not words:
            return None
        gs = [w.value for w in words if w.letter == "G"]
        ms = [w.value for w in words if w.letter == "M"]
        where = f"line {line.number}"
        for g in gs:
            g = round(g, 1)
            if g in REFUSED_G:
                raise InputError(f"{where}: {REFUSED_G[g]} is not supported")
        for m in ms:
            if round(m) in REFUSED_M:
                raise InputError(f"{where}: {REFUSED_M[round(m)]} is not supported")
        if "TRAORI" in line.body.upper():
            raise InputError(f"{where}: TRAORI (TCPM) is not supported")
        for g in gs:
            if g == 90:
                self.incremental = False
            elif g == 91:
                self.incremental = True
        axis_words = [w for w in words if w.letter in self.FOREIGN_AXES]
        for w in axis_words:
            if w.letter not in self.axes:
                raise InputError(f"{where}: axis {w.letter} is not an axis of this machine "
                                 f"(axes {' '.join(self.axes)})")
        seen = set()
        for w in axis_words:
            if w.letter in seen:
                raise InputError(f"{where}: axis {w.letter} programmed twice")
            seen.add(w.letter)
        if not axis_words:
            return None
        if any(round(g, 1) == 4 for g in gs):
            return None  # dwell: X / P are times
        if any(round(g, 1) in (28, 30) for g in gs):
            for w in axis_words:
                self.position[w.letter] = None  # via an intermediate point to a reference
            return None
        for w in axis_words:
            if self.incremental:
                prev = self.position[w.letter]
                self.position[w.letter] = None if prev is None else prev + w.value
            else:
                self.position[w.letter] = w.value
        return Block(line, dict(self.position), tuple(w.letter for w in axis_words),
                     self.incremental)


def blocks(lines: list[Line], axes, initial: dict | None = None) -> list[Block]:
    """The motion blocks of a parsed program (raises on unsupported constructs)."""
    interp = Interpreter(axes, initial)
    out = []
    for line in lines:
        b = interp.block(line)
        if b is not None:
            out.append(b)
    return out


def decimals(text: str) -> int:
    """Number of decimals written in a number's text (``"10."`` -> 0, ``"1.250"`` -> 3)."""
    return len(text.split(".", 1)[1]) if "." in text else 0


def format_number(value: float, ndigits: int, template: str = "") -> str:
    """``value`` with ``ndigits`` decimals, trailing zeros dropped but at least as many
    decimals as ``template`` had; a leading ``+`` kept if the template had one."""
    s = f"{value:.{ndigits}f}"
    if "." in s:
        keep = max(decimals(template), 1 if "." in template else 0)
        intpart, frac = s.split(".")
        frac = frac.rstrip("0")
        if len(frac) < keep:
            frac = frac + "0" * (keep - len(frac))
        s = intpart + ("." + frac if frac else ("." if template.endswith(".") else ""))
    if s.lstrip("+-").strip(".0") == "":
        s = s.lstrip("-")  # no "-0"
    if template.startswith("+") and not s.startswith("-"):
        s = "+" + s
    return s


def spaced_style(lines: list[Line]) -> bool:
    """True when the program separates words by blanks (``G1 X1 Y2``), False when it writes
    them together (``G1X1Y2``): decides how an added word is separated."""
    for line in lines:
        toks = line.tokens
        for a, b, c in zip(toks, toks[1:], toks[2:]):
            if a.kind == "word" and c.kind == "word":
                return b.kind == "space"
        for a, b in zip(toks, toks[1:]):
            if a.kind == "word" and b.kind == "word":
                return False
    return True


def rewrite_line(line: Line, new_values: dict, added: dict, spaced: bool | None = None) -> str:
    """The line with the numbers of axis words in ``new_values`` (letter -> text) replaced and
    the words of ``added`` (letter -> text) appended after the last word; every other byte kept.
    ``spaced``: separate added words by a blank (default: as the line does, else yes)."""
    body = line.body
    pieces = []
    pos = 0
    last_word_end = None
    for t in line.tokens:
        if t.kind == "word":
            last_word_end = t.start + len(t.text)
    for t in line.tokens:
        if t.kind == "word" and t.letter in new_values:
            pieces.append(body[pos:t.num_start])
            pieces.append(new_values[t.letter])
            pos = t.num_end
    out = "".join(pieces) + body[pos:]
    if added:
        # the insertion point moves with the length change of the replaced numbers before it
        shift = len(out) - len(body)
        at = (last_word_end if last_word_end is not None else len(body)) + shift
        own = spaced_style([line]) if len(line.words()) > 1 else None
        sep = " " if (own if own is not None else (spaced if spaced is not None else True)) \
            else ""
        lower = all(t.text[0].islower() for t in line.words()) and line.words()
        ins = "".join(f"{sep}{(a.lower() if lower else a)}{v}" for a, v in added.items())
        out = out[:at] + ins + out[at:]
    return out + line.ending
