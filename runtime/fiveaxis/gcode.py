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
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError

_LINE = re.compile(r"[^\r\n]*(?:\r\n|\n|\r|$)")
_WORD = re.compile(r"([A-Za-z])([ \t]*)([+-]?(?:\d+\.?\d*|\.\d+))")
_SPACE = re.compile(r"[ \t]+")
_COMMENT_PAREN = re.compile(r"\([^)]*\)")
#: a line of address words and blanks only, and its words with the blanks before them
_SIMPLE = re.compile(r"(?:[ \t]*[A-Za-z][ \t]*[+-]?(?:\d+\.?\d*|\.\d+))+[ \t]*")
_PARTS = re.compile(r"([ \t]*)([A-Za-z])([ \t]*)([+-]?(?:\d+\.?\d*|\.\d+))")

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
#: M functions the interpreter acts on (a line with one of them is interpreted line by line)
SPECIAL_M = frozenset({98, 128, 129})


@dataclass
class Token:
    kind: str            # "word", "comment", "space", "other"
    text: str
    start: int
    letter: str = ""     # upper case, words only
    value: float = 0.0
    num_start: int = 0   # span of the number inside the line
    num_end: int = 0


class Line:
    """One line: its body (without the line ending), the ending, and its tokens.

    A line of address words and blanks only (``X1.5 Y-2 Z30``, the bulk of a program) keeps
    its words as ``parts`` (leading blanks, letter, blanks, number text) and tokenizes only
    when :attr:`tokens` is asked for; any other line is tokenized (and checked) at once."""

    __slots__ = ("number", "body", "ending", "_tokens", "parts", "_items")

    def __init__(self, number: int, body: str, ending: str, tokens=None, parts=None):
        self.number = number      # 1-based line number in the file
        self.body = body
        self.ending = ending
        self._tokens = tokens
        self.parts = parts
        self._items = None

    @classmethod
    def parse(cls, number: int, body: str, ending: str) -> "Line":
        if _SIMPLE.fullmatch(body):
            return cls(number, body, ending, parts=_PARTS.findall(body))
        return cls(number, body, ending, tokens=tokenize(body, number))

    @property
    def tokens(self) -> list:
        if self._tokens is None:
            self._tokens = tokenize(self.body, self.number)
        return self._tokens

    def words(self) -> list[Token]:
        return [t for t in self.tokens if t.kind == "word"]

    def items(self) -> list[tuple[str, float, str]]:
        """(upper-case letter, value, number text) of every word, in order."""
        if self._items is None:
            if self.parts is not None:
                self._items = [(p[1].upper(), float(p[3]), p[3]) for p in self.parts]
            else:
                b = self.body
                self._items = [(t.letter, t.value, b[t.num_start:t.num_end])
                               for t in self.tokens if t.kind == "word"]
        return self._items

    @property
    def text(self) -> str:
        return self.body + self.ending

    def __repr__(self) -> str:
        return f"Line({self.number}, {self.body!r}, {self.ending!r})"


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
    return [Line.parse(n, body, end) for n, (body, end) in enumerate(split_lines(text), start=1)]


def iter_lines(source, first: int = 1):
    """Parsed lines of a program, one at a time: ``source`` is the program text or an open
    text file (latin-1, ``newline=""`` so that every line keeps its own ending)."""
    import io

    fh = io.StringIO(source, newline="") if isinstance(source, str) else source
    for n, seg in enumerate(fh, start=first):
        body = seg.rstrip("\r\n")
        yield Line.parse(n, body, seg[len(body):])


@dataclass
class Step:
    """What one line does to the controller: ``kind`` "motion" (a motion block), "reference"
    (G28 / G30: the named axes go to an unknown position) or "none" (dwell, or no axis
    words); ``axis_words`` the (axis, value) pairs as written; ``incremental`` the distance
    mode in force."""

    kind: str
    axis_words: list
    incremental: bool


class ControllerState:
    """Axis positions a controller holds (mm / deg; None where unknown) and the one rule that
    moves them: :meth:`apply`.  The interpreter follows the program as read with one; the
    writer of a compensated program follows the program as written with another."""

    __slots__ = ("position",)

    def __init__(self, axes, initial: dict | None = None):
        self.position = {a: None for a in axes}
        self.position.update({a: float(v) for a, v in (initial or {}).items()})

    def apply(self, step: Step) -> None:
        pos = self.position
        if step.kind == "motion":
            if step.incremental:
                for a, v in step.axis_words:
                    prev = pos[a]
                    pos[a] = None if prev is None else prev + v
            else:
                for a, v in step.axis_words:
                    pos[a] = v
        elif step.kind == "reference":
            for a, _ in step.axis_words:
                pos[a] = None   # via an intermediate point to a reference


class Interpreter:
    """Modal interpretation of a tokenized program for a machine with axes ``axes``.

    ``initial``: axis -> known position at program start (mm / deg)."""

    FOREIGN_AXES = set("XYZABCUVW")

    def __init__(self, axes, initial: dict | None = None):
        self.axes = tuple(axes)
        self.state = ControllerState(self.axes, initial)
        self.incremental = False
        #: the :class:`Step` of the last line read (None for a line without words)
        self.last_step: Step | None = None

    @property
    def position(self) -> dict:
        return self.state.position

    def step(self, line: Line) -> Step | None:
        """Check one line and update the distance mode; return what it does (None without
        words).  Raises :class:`InputError` on unsupported constructs."""
        items = line.items()
        if not items:
            return None
        where = f"line {line.number}"
        foreign = self.FOREIGN_AXES
        gs, axis_words = [], []
        for letter, value, _ in items:
            if letter in foreign:
                axis_words.append((letter, value))
            elif letter == "G":
                g = round(value, 1)
                if g in REFUSED_G:
                    raise InputError(f"{where}: {REFUSED_G[g]} is not supported")
                gs.append(g)
            elif letter == "M" and round(value) in REFUSED_M:
                raise InputError(f"{where}: {REFUSED_M[round(value)]} is not supported")
        if line.parts is None and "TRAORI" in line.body.upper():
            raise InputError(f"{where}: TRAORI (TCPM) is not supported")
        for g in gs:
            if g == 90:
                self.incremental = False
            elif g == 91:
                self.incremental = True
        if axis_words:
            axes = self.axes
            for a, _ in axis_words:
                if a not in axes:
                    raise InputError(f"{where}: axis {a} is not an axis of this machine "
                                     f"(axes {' '.join(axes)})")
            seen = set()
            for a, _ in axis_words:
                if a in seen:
                    raise InputError(f"{where}: axis {a} programmed twice")
                seen.add(a)
        kind = "none"
        if axis_words and 4 not in gs:      # dwell: X / P are times
            kind = "reference" if (28 in gs or 30 in gs) else "motion"
        return Step(kind, axis_words, self.incremental)

    def block(self, line: Line) -> Block | None:
        """Update the modal state with one line; return a :class:`Block` for a motion block."""
        step = self.last_step = self.step(line)
        if step is None:
            return None
        self.state.apply(step)
        if step.kind != "motion":
            return None
        return Block(line, dict(self.state.position), tuple(a for a, _ in step.axis_words),
                     step.incremental)


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
    if ndigits:
        dot = template.find(".")
        keep = len(template) - dot - 1 if dot >= 0 else 0
        if keep == 0 and dot >= 0:
            keep = 1
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


def _kinds(line: Line) -> list[str]:
    if line.parts is not None:
        kinds = []
        for p in line.parts:
            if p[0]:
                kinds.append("space")
            kinds.append("word")
        return kinds
    return [t.kind for t in line.tokens]


def _spaced(kinds: list[str]) -> bool | None:
    for a, b, c in zip(kinds, kinds[1:], kinds[2:]):
        if a == "word" and c == "word":
            return b == "space"
    for a, b in zip(kinds, kinds[1:]):
        if a == "word" and b == "word":
            return False
    return None


def spaced_style(lines) -> bool:
    """True when the program separates words by blanks (``G1 X1 Y2``), False when it writes
    them together (``G1X1Y2``): decides how an added word is separated."""
    for line in lines:
        own = _spaced(_kinds(line))
        if own is not None:
            return own
    return True


def rewrite_line(line: Line, new_values: dict, added: dict, spaced: bool | None = None) -> str:
    """The line with the numbers of axis words in ``new_values`` (letter -> text) replaced and
    the words of ``added`` (letter -> text) appended after the last word; every other byte kept.
    ``spaced``: separate added words by a blank (default: as the line does, else yes)."""
    body = line.body
    if line.parts is not None:
        parts = line.parts
        get = new_values.get
        head = "".join([f"{p[0]}{p[1]}{p[2]}{get(p[1].upper(), p[3])}" for p in parts])
        tail = body[len(body.rstrip(" \t")):]   # a simple line ends in a number, then blanks
        if not added:
            return head + tail + line.ending
        own = _spaced(_kinds(line)) if len(parts) > 1 else None
        lower = all(p[1].islower() for p in parts)
    else:
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
        if not added:
            return out + line.ending
        # the insertion point moves with the length change of the replaced numbers before it
        shift = len(out) - len(body)
        at = (last_word_end if last_word_end is not None else len(body)) + shift
        head, tail = out[:at], out[at:]
        words = line.words()
        own = _spaced(_kinds(line)) if len(words) > 1 else None
        if len(words) > 1 and own is None:
            own = True
        lower = all(t.text[0].islower() for t in words) and words
    sep = " " if (own if own is not None else (spaced if spaced is not None else True)) else ""
    ins = "".join(f"{sep}{(a.lower() if lower else a)}{v}" for a, v in added.items())
    return head + ins + tail + line.ending
