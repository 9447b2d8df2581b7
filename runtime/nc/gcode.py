"""G-code programs (ISO dialect: Fanuc, Siemens, Heidenhain ISO): a byte-keeping tokenizer and a
modal interpreter.

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

Siemens extended addresses ``A3=``, ``B3=``, ``C3=`` (the tool vector under ``TRAORI``) are
words (read as the vector components ``I J K``), and ``TRAORI`` / ``TRAFOOF`` are keywords.

Interpretation (modal state, one block per line)
------------------------------------------------
* Motion: ``G0`` and ``G1`` (straight moves in axis space) and ``G2``/``G3`` (arcs in the
  plane of ``G17``/``G18``/``G19``, centre ``I J K`` relative to the start or radius ``R``;
  see :mod:`volerr.nc.arcs`), modal.  A block with axis words and no other non-modal
  function is a *motion block*.  Canned cycles ``G73 G74 G76 G81``-``G89``, ``G92 G52 G10``
  (offset changes), ``G68 G51`` (rotation, scaling), ``G41 G42`` (cutter radius
  compensation, also ``G41.1 G42.1`` ... ``G41.6 G42.6``), ``G20`` (inch), ``/`` (block
  delete) and ``M98`` (subprogram call) are refused: a compensated copy could not be guaranteed; so are what other controllers' posts
  write that changes what axis words mean (:data:`REFUSED_G`, :data:`REFUSED_M`: ``G7``
  diameter mode, ``G16`` polar, ``G51.1`` mirror, ``G65 G66`` macro calls, ``G68.2`` tilted
  plane, ``G70 G700`` SINUMERIK inch, ``G90.1`` absolute arc centres, ``G12 G13 G75``
  cycles, ``M97 M198`` subprogram calls), an arc under ``G93`` inverse-time feed
  (linearised, the block's ``F`` -- its time -- would apply to every segment), and
  LinuxCNC's spline moves ``G5 G5.1 G5.2`` (:data:`SPLINE_G`) on a line that moves, and
  probing moves (``G38.2``-``G38.5``, ``G31``, SINUMERIK ``MEAS=`` / ``MEAW=``: they end
  where the probe touches, unknown to the program).
* TCPM (tool centre point management): ``G43.4`` (rotary angles) / ``G43.5`` (tool vector
  ``I J K``) until ``G49``; ``M128`` until ``M129``; ``TRAORI`` until ``TRAFOOF`` (rotary
  angles, or the vector ``A3 B3 C3``).  In TCPM the linear words are the tool tip in the
  workpiece frame (see :mod:`volerr.nc.tcpm`); the tool length comes from the
  interpreter's ``tool_length`` rule (an ``H``, ``D`` or ``T`` word, or a given length).
  At a switch into or out of TCPM the linear positions become unknown until programmed.
* ``G90``/``G91``: both handled; in ``G91`` an axis word is the increment from the position
  the controller holds.
* ``G53`` moves and work offsets (``G54``-``G59``, ``G59.1``-``G59.3``, Fanuc ``G54.1 P`` /
  ``G54 P``) are kept as written: the program's numbers are taken to be the machine axis
  positions the error tables refer to (every work offset zero, as in LinuxCNC with its default
  parameters), so a ``G53`` word and a work-offset word mean the same position.  What makes a
  word mean another position than written is refused (``G10 G52 G92 G92.3``); ``G92.1`` /
  ``G92.2`` (cancel / suspend G92 offsets) pass.
* ``G28``/``G30`` (reference return) and ``G4`` (dwell, its ``X``/``P`` is time) are passed
  through untouched; after ``G28``/``G30`` the axes they name (without axis words: every
  axis, as LinuxCNC and Haas go to the reference with all) are at an unknown position until
  programmed again.
* Axis words are the model's axes (e.g. ``X Y Z B C``); a letter that is an axis of another
  machine (``A`` ``U`` ... on a DMU 50) is refused.  ``T H D`` words are remembered (tool
  length of TCPM); all other words (``N F S M``, ...) are kept and ignored.
* An axis that has never been programmed is unknown; a motion block that needs it is reported
  as not compensated (its bytes are kept), unless an initial position is given.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import InputError

_LINE = re.compile(r"[^\r\n]*(?:\r\n|\n|\r|$)")
_WORD = re.compile(r"([A-Za-z])([ \t]*)([+-]?(?:\d+\.?\d*|\.\d+))")
_SPACE = re.compile(r"[ \t]+")
_COMMENT_PAREN = re.compile(r"\([^)]*\)")
#: a line of address words and blanks only, and its words with the blanks before them
_SIMPLE = re.compile(r"(?:[ \t]*[A-Za-z][ \t]*[+-]?(?:\d+\.?\d*|\.\d+))+[ \t]*")
_PARTS = re.compile(r"([ \t]*)([A-Za-z])([ \t]*)([+-]?(?:\d+\.?\d*|\.\d+))")

#: a number run straight into an E: exponent notation, which G-code does not have
_EXPONENT = re.compile(r"([A-Za-z])[ \t]*([+-]?(?:\d+\.?\d*|\.\d+)[eE][+-]?\d+)")


def refuse_exponent(text: str, number: int) -> None:
    """``X1e300`` is no number of G-code: read as written it is ``X1`` followed by a word
    ``E300``; refused (one line) instead of silently moving to X1."""
    m = _EXPONENT.search(text)
    if m:
        raise InputError(f"line {number}: {m.group(1)}{m.group(2)}: exponent notation is not "
                         f"G-code (it would read as {m.group(1)}{m.group(2).lower().split('e')[0]}"
                         f" followed by an E word); write the number in full, or a blank "
                         f"before an E word")


REFUSED_G = {
    10: "G10 offset setting",
    20: "G20 inch units", 41: "G41 cutter radius compensation",
    42: "G42 cutter radius compensation", 51: "G51 scaling", 52: "G52 local coordinate shift",
    68: "G68 coordinate rotation", 73: "G73 canned cycle", 74: "G74 canned cycle",
    76: "G76 canned cycle", 92: "G92 coordinate shift",
    12.1: "G12.1 polar interpolation", 7.1: "G7.1 cylindrical interpolation",
}
REFUSED_G.update({g: f"G{g} canned cycle" for g in range(81, 90)})
#: what other controllers' post-processors write that changes what the axis words mean (a
#: compensated copy would be silently wrong): lathe diameter mode, polar coordinates, mirror
#: image, macro calls with axis arguments, tilted working planes, absolute arc centres, inch
#: (SINUMERIK G70 / G700; G70 is a finishing cycle on Fanuc and LinuxCNC lathes), the Fanuc
#: lathe grooving cycle and Haas circle-milling cycles
REFUSED_G.update({
    7: "G7 lathe diameter mode", 16: "G16 polar coordinates", 51.1: "G51.1 mirror image",
    65: "G65 macro call", 66: "G66 modal macro call",
    **{g: f"G{g} tilted working plane" for g in (68.1, 68.2, 68.3, 68.4)},
    70: "G70 inch units (SINUMERIK) / finishing cycle (lathe)", 700: "G700 inch units",
    90.1: "G90.1 absolute arc centres", 75: "G75 grooving cycle",
    12: "G12 circle milling cycle", 13: "G13 circle milling cycle",
})
#: G92.3 restores the G92 offsets saved in parameters 5211-5216 before the program ran
#: (linuxcnc.org/docs/html/gcode/g-code.html#gcode:g92.3): unknown to the program, and the
#: words after it would mean other machine positions (G92.1 / G92.2 cancel / suspend G92
#: offsets: every offset stays zero, as the program's numbers are taken, and they pass)
REFUSED_G[92.3] = "G92.3 restore of saved G92 offsets"
#: cutter radius compensation in every form posts write: LinuxCNC's dynamic G41.1 / G42.1
#: (the diameter in the D word, linuxcnc.org/docs/html/gcode/g-code.html#gcode:g41.1-g42.1),
#: Fanuc's G41.2-G41.6 / G42.2-G42.6 (3-D and five-axis tool radius compensation): the
#: controller moves the tool off the written positions by its radius
REFUSED_G.update({g: f"G{g} cutter radius compensation"
                  for side in (41, 42) for g in (side + k / 10 for k in range(1, 7))})
#: probing (measuring) moves: the move ends where the probe touches, which the program does not
#: know, so every position after it (an incremental move, a modal probe line: LinuxCNC's G38.x
#: is in modal group 1) would rest on a guess, and the position the controller records at the
#: trigger is the raw axis position, which compensating the target does not correct.  LinuxCNC
#: G38.2-G38.5 (linuxcnc.org/docs/html/gcode/g-code.html#gcode:g38), Fanuc / Haas G31 skip
#: and G31.1-G31.4 multi-step skip; Siemens MEAS= / MEAW= are refused by the tokenizer
#: (:data:`PROBING_KEYWORD`)
REFUSED_G.update({
    **{g: f"G{g} probe move (ends where the probe touches: the position after it is unknown)"
       for g in (38.2, 38.3, 38.4, 38.5)},
    **{g: f"G{g:g} skip (probe) move (ends where the probe touches: the position after it is "
          "unknown)" for g in (31, 31.1, 31.2, 31.3, 31.4)},
})
#: Siemens measuring moves (``MEAS=1 G1 X..``, ``MEAW=1``): refused as G31 / G38.x are
PROBING_KEYWORD = re.compile(r"(MEAS|MEAW)[ \t]*=", re.IGNORECASE)
#: SINUMERIK frame instructions (programmable work offset, rotation, scale, mirror: the words
#: after them mean other machine positions) and SUPA (suppresses every offset: the words are
#: machine positions); refused naming the instruction, with the work-offset rule
SIEMENS_FRAMES = {"TRANS": "frame (programmable work offset)",
                  "ATRANS": "frame (additive work offset)", "ROT": "frame (rotation)",
                  "AROT": "frame (additive rotation)", "SCALE": "frame (scaling)",
                  "ASCALE": "frame (additive scaling)", "MIRROR": "frame (mirror)",
                  "AMIRROR": "frame (additive mirror)",
                  "SUPA": "machine coordinates with every offset suppressed"}
_SIEMENS_FRAME = re.compile(r"(A?TRANS|A?ROT|A?SCALE|A?MIRROR|SUPA)(?![A-Za-z0-9_])",
                            re.IGNORECASE)
#: LinuxCNC's spline motions (cubic, quadratic B-spline, NURBS): refused where the line moves
#: (axis or I J words); Fanuc writes G05 / G05.1 with P or Q alone as machining modes
SPLINE_G = frozenset({5.0, 5.1, 5.2, 5.3})
REFUSED_M = {98: "M98 subprogram call", 97: "M97 local subprogram call",
             198: "M198 subprogram call"}
#: the components of a tool vector (``I J K`` of G43.5, ``A3 B3 C3`` of TRAORI)
VECTOR = ("I", "J", "K")
#: Siemens extended address of a tool-vector component: ``A3=0.5``
_SIEMENS_VECTOR = re.compile(r"([ABCabc])3[ \t]*=[ \t]*([+-]?(?:\d+\.?\d*|\.\d+))")
_KEYWORD = re.compile(r"(TRAORI|TRAFOOF)(?:[ \t]*\([ \t]*\d*[ \t]*\))?", re.IGNORECASE)
#: M functions the interpreter acts on (a line with one of them is interpreted line by line)
SPECIAL_M = frozenset({128, 129, *REFUSED_M})


@dataclass
class Token:
    kind: str            # "word", "comment", "space", "keyword", "other"
    text: str
    start: int
    letter: str = ""     # upper case: words (I J K for A3 B3 C3) and keywords
    value: float = 0.0
    num_start: int = 0   # span of the number inside the line
    num_end: int = 0


class Line:
    """One line: its body (without the line ending), the ending, and its tokens.

    A line of address words and blanks only (``X1.5 Y-2 Z30``, the bulk of a program) keeps
    its words as ``parts`` (leading blanks, letter, blanks, number text) and tokenizes only
    when :attr:`tokens` is asked for; any other line is tokenized (and checked) at once."""

    __slots__ = ("number", "body", "ending", "_tokens", "parts", "_items", "incremental",
                 "anchor")

    def __init__(self, number: int, body: str, ending: str, tokens=None, parts=None):
        self.number = number      # 1-based line number in the file
        self.body = body
        self.ending = ending
        self._tokens = tokens
        self.parts = parts
        self._items = None
        #: letters written incrementally in an absolute block (Heidenhain ``IX``)
        self.incremental = frozenset()
        #: index of the token after which added words go (None: after the last word)
        self.anchor = None

    @classmethod
    def parse(cls, number: int, body: str, ending: str) -> "Line":
        if _SIMPLE.fullmatch(body):
            refuse_exponent(body, number)
            return cls(number, body, ending, parts=_PARTS.findall(body))
        return cls(number, body, ending, tokens=tokenize(body, number))

    @property
    def tokens(self) -> list:
        if self._tokens is None:
            self._tokens = tokenize(self.body, self.number)
        return self._tokens

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

    def keywords(self) -> list[str]:
        """The keywords of the line (``TRAORI`` ...), upper case."""
        if self.parts is not None:
            return []
        return [t.letter for t in self.tokens if t.kind == "keyword"]

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
        elif c in "ABCabc" and _SIEMENS_VECTOR.match(body, i):
            m = _SIEMENS_VECTOR.match(body, i)
            tokens.append(Token("word", m.group(0), i, VECTOR["ABC".index(c.upper())],
                                float(m.group(2)), m.start(2), m.end(2)))
            i = m.end()
        elif c in "Tt" and _KEYWORD.match(body, i):
            m = _KEYWORD.match(body, i)
            tokens.append(Token("keyword", m.group(0), i, m.group(1).upper()))
            i = m.end()
        else:
            m = _WORD.match(body, i)
            if not m and PROBING_KEYWORD.match(body, i):
                raise InputError(f"line {number}: SINUMERIK {body[i:i + 4].upper()} probe "
                                 "move is not supported (ends where the probe touches: the "
                                 "position after it is unknown)")
            if not m and c == "," and tokens and tokens[-1].kind == "word" and \
                    body[i + 1:i + 2].isdigit():
                raise InputError(f"line {number}: {tokens[-1].text.strip()}{body[i:i + 2]}...: "
                                 "a comma is no decimal point in G-code (write a point)")
            frame = None if m else _SIEMENS_FRAME.match(body, i)
            if frame:
                name = frame.group(1).upper()
                raise InputError(f"line {number}: SINUMERIK {name} {SIEMENS_FRAMES[name]} is "
                                 "not supported (the program's numbers are taken as machine "
                                 "positions with zero offsets)")
            if not m:
                raise InputError(f"line {number}: cannot interpret {body[i:i + 12]!r} (only "
                                 "address words, comments and blanks are supported)")
            refuse_exponent(body[i:m.end() + 3], number)
            tokens.append(Token("word", m.group(0), i, m.group(1).upper(), float(m.group(3)),
                                m.start(3), m.end(3)))
            i = m.end()
    return tokens


def parse(text: str) -> list[Line]:
    """All lines of a program with their tokens."""
    return [Line.parse(n, body, end) for n, (body, end) in enumerate(split_lines(text), start=1)]


@dataclass
class Arc:
    """The arc words of a ``G2``/``G3`` block: ``plane`` 17, 18 or 19, ``ccw`` (G3), the
    centre words as written (``I J K`` -> value, mm, relative to the start) or the radius
    ``R`` (mm; negative: more than half a turn)."""

    plane: int
    ccw: bool
    centre: dict
    radius: float | None


@dataclass
class Step:
    """What one line does to the controller: ``kind`` "motion" (a straight motion block),
    "arc" (a ``G2``/``G3`` block), "reference" (G28 / G30: the named axes go to an unknown
    position) or "none" (dwell, a switch, or no axis words); ``axis_words`` the (letter,
    value) pairs as written (axes, and ``I J K`` of a tool vector under TCPM);
    ``incremental`` the distance mode in force (``incremental_words``: letters written
    incrementally in an absolute block, Heidenhain ``IX``); ``arc`` the :class:`Arc`;
    ``frame`` "axes" or "tcpm" for the block; ``forget`` the letters whose positions become
    unknown before it (a switch into or out of TCPM); ``tool_length`` the tool length (mm) of
    a TCPM block; ``orientation`` "angles" or "vector" for a TCPM motion block."""

    kind: str
    axis_words: list
    incremental: bool
    arc: Arc | None = None
    frame: str = "axes"
    forget: tuple = ()
    tool_length: float | None = None
    incremental_words: frozenset = frozenset()
    orientation: str | None = None
    #: modal motion after the line (0 1 straight, 2 3 arcs) and whether the line writes it
    motion: int = 0
    motion_word: bool = False


class ControllerState:
    """Positions a controller holds (axes mm / deg, the tool vector ``I J K`` under TCPM;
    None where unknown) and the one rule that moves them: :meth:`apply`.  The interpreter
    follows the program as read with one; the writer of a compensated program follows the
    program as written with another."""

    __slots__ = ("position", "linear")

    def __init__(self, axes, initial: dict | None = None, linear=("X", "Y", "Z")):
        self.position = {a: None for a in (*axes, *VECTOR)}
        self.position.update({a: float(v) for a, v in (initial or {}).items()})
        self.linear = tuple(linear)

    def apply(self, step: Step) -> None:
        pos = self.position
        for a in step.forget:
            pos[a] = None
        if step.kind in ("motion", "arc"):
            inc = step.incremental_words
            for a, v in step.axis_words:
                if (step.incremental and a not in VECTOR) or a in inc:   # a vector: absolute
                    prev = pos[a]
                    pos[a] = None if prev is None else prev + v
                else:
                    pos[a] = v
        elif step.kind == "reference":
            for a, _ in step.axis_words:
                pos[a] = None   # via an intermediate point to a reference


#: G codes that switch TCPM on (with the orientation they read) and off
TCPM_ON = {43.4: "angles", 43.5: "vector"}
TCPM_OFF = (49,)


class Interpreter:
    """Modal interpretation of a tokenized program for a machine with axes ``axes``.

    ``initial``: axis -> known position at program start (mm / deg).  ``tool_length``: a
    callable ``(tools, where) -> mm`` giving the tool length a TCPM block uses from the last
    ``T``/``H``/``D`` words (``tools``: letter -> value); it raises :class:`InputError`
    naming ``where`` when it cannot.  Without it a TCPM program is refused."""

    FOREIGN_AXES = set("XYZABCUVW")

    def __init__(self, axes, initial: dict | None = None, tool_length=None):
        self.axes = tuple(axes)
        linear = tuple(a for a in self.axes if a in "XYZUVW")
        self.state = ControllerState(self.axes, initial, linear)
        self.incremental = False
        #: modal motion: 0, 1 (straight), 2, 3 (arcs); plane 17, 18, 19
        self.motion = 0
        self.plane = 17
        #: G93 inverse-time feed in force (G94 / G95 end it)
        self.inverse_time = False
        #: "axes", or "tcpm" with ``orientation`` "angles" / "vector" / "any" (TRAORI)
        self.frame = "axes"
        self.orientation = None
        self.tools: dict = {}
        self.tool_length = tool_length
        self._length = None
        self._last_orientation = None
        #: spelling of the tool-vector words once the program writes one (Siemens A3=)
        self.vector_words: dict | None = None
        #: rotary positions (deg) the machine holds after the last known block (TCPM vector
        #: blocks continue from them); None before one
        self.rotary_actual = None

    @property
    def position(self) -> dict:
        return self.state.position

    @property
    def plain(self) -> bool:
        """True when a line of axis words (and G0 / G1, T H D and ignored words) is a straight
        move with nothing but its words to read: absolute, straight motion mode, axis
        positions or TCPM with rotary angles (the whole-chunk path)."""
        if self.incremental or self.motion not in (0, 1):
            return False
        return self.frame == "axes" or self.orientation == "angles" or \
            (self.orientation == "any" and self._last_orientation != "vector")

    @property
    def plain_vector(self) -> bool:
        """True when a line of linear-axis and tool-vector words (and G0 / G1, T H D and
        ignored words; no rotary word) is a straight TCPM move to the tool tip with the tool
        vector: absolute, straight motion mode, TCPM with a tool vector (G43.5, or TRAORI
        after a block with one) (the whole-chunk path of tool-vector programs)."""
        if self.incremental or self.motion not in (0, 1) or self.frame != "tcpm":
            return False
        return self.vector_words is not None and (self.orientation == "vector" or (
            self.orientation == "any" and self._last_orientation == "vector"))

    @property
    def length(self) -> float | None:
        """The tool length of TCPM blocks now (mm), None outside TCPM."""
        return self._length if self.frame == "tcpm" else None

    def _switch(self, frame: str, orientation, where: str) -> tuple:
        """Switch into or out of TCPM; returns the letters whose positions become unknown:
        the linear words change their meaning (axis positions / tool tip in the workpiece
        frame), the tool vector is forgotten, and after a tool-vector section the rotary
        axes are where the controller's inverse put them (not a programmed word)."""
        if frame == "tcpm":
            if self.tool_length is None:
                raise InputError(f"{where}: a TCPM program needs the tool length "
                                 "(--tool-length, or a tool table for its T / H / D word)")
            self._length = float(self.tool_length(dict(self.tools), where))
        if frame == self.frame and orientation == self.orientation:
            return ()
        forget = ()
        if frame != self.frame:
            forget = (*self.state.linear, *VECTOR)
            if self.orientation in ("vector", "any"):
                forget += tuple(a for a in self.axes if a not in self.state.linear)
        self.frame, self.orientation = frame, orientation
        return forget

    def step(self, line: Line) -> Step | None:
        """Check one line and update the modal state; return what it does (None without
        words).  Raises :class:`InputError` on unsupported constructs."""
        items = line.items()
        keywords = line.keywords()
        if not items and not keywords:
            return None
        where = f"line {line.number}"
        gs, ms, axis_words, centre, vector, radius = self._read_words(items, where)
        spline = [g for g in gs if g in SPLINE_G]
        if spline and (axis_words or centre):
            # LinuxCNC's G5 / G5.1 / G5.2 move along a curve its words define: compensating
            # the end point only would leave the path between uncorrected (Fanuc's G05 P10000
            # and G05.1 Q1 are modes without axis words and pass)
            raise InputError(f"{where}: G{spline[0]:g} spline move is not supported (only its "
                             "end point could be compensated, not the curve between)")
        if "L" in keywords:                 # Heidenhain straight move
            gs.append(1.0)
        self._set_modes(gs)
        forget = self._tcpm_switch(gs, ms, keywords, where)
        if (28 in gs or 30 in gs) and not axis_words:
            # without axis words every axis goes to the reference (LinuxCNC, Haas)
            forget = (*forget, *self.axes)
        self._check_axes(axis_words, where)
        if vector and self.vector_words is None:
            # a line of address words only (parts) cannot hold a Siemens A3=: I J K
            siemens = line.parts is None and any(
                t.kind == "word" and t.letter in VECTOR and t.text[:1].upper() in "ABC"
                for t in line.tokens)
            self.vector_words = ({"I": "A3=", "J": "B3=", "K": "C3="} if siemens else
                                 {v: v for v in VECTOR})
        tcpm = self.frame == "tcpm"
        orientation = None
        if tcpm:
            orientation = "vector" if self.orientation == "vector" else "angles"
        if tcpm and vector:
            orientation = "vector"
            self._check_vector(axis_words, vector, where)
            axis_words = axis_words + vector
        kind = "none"
        if axis_words and 4 not in gs:      # dwell: X / P are times
            kind = "reference" if (28 in gs or 30 in gs) else \
                "arc" if self.motion in (2, 3) else "motion"
        if kind == "arc" and self.inverse_time:
            raise InputError(f"{where}: an arc (G{self.motion}) under G93 inverse-time feed is "
                             "not supported (linearised, the block's F -- its time -- would "
                             "apply to every segment)")
        arc = self._arc(axis_words, centre, radius, where) if kind == "arc" else None
        if tcpm and self.orientation == "any" and kind == "motion":
            # TRAORI: rotary words give angles, A3 B3 C3 a vector; a block with neither
            # keeps the orientation of the block before
            rot = any(a not in self.state.linear for a, _ in axis_words)
            orientation = "vector" if vector else "angles" if rot else \
                (self._last_orientation or "angles")
        if tcpm and kind == "motion":
            self._last_orientation = orientation
        return Step(kind, axis_words, self.incremental, arc, self.frame, forget,
                    self._length if tcpm else None, line.incremental, orientation,
                    self.motion, any(g in (0, 1, 2, 3) for g in gs))

    def _read_words(self, items, where: str) -> tuple:
        """The words of a line by kind -> (G numbers, M numbers, axis words, centre words,
        tool-vector words, radius); refused G / M functions raise; ``T H D DL`` are kept."""
        gs, ms, axis_words, centre, vector = [], [], [], {}, []
        radius = None
        for letter, value, _ in items:
            if letter in self.FOREIGN_AXES:
                axis_words.append((letter, value))
            elif letter == "G":
                g = round(value, 1)
                if g in REFUSED_G:
                    raise InputError(f"{where}: {REFUSED_G[g]} is not supported")
                gs.append(g)
            elif letter == "M":
                m = round(value)
                if m in REFUSED_M:
                    raise InputError(f"{where}: {REFUSED_M[m]} is not supported")
                ms.append(m)
            elif letter in VECTOR:
                centre[letter] = value
                vector.append((letter, value))
            elif letter == "R":
                radius = value
            elif letter in ("T", "H", "D", "DL"):
                self.tools[letter] = value
        if any(a == "T" for a, _, _ in items) and not any(a == "DL" for a, _, _ in items):
            self.tools.pop("DL", None)      # a new tool: no delta length unless given
        return gs, ms, axis_words, centre, vector, radius

    def _set_modes(self, gs) -> None:
        """Distance mode, motion mode and plane from the line's G numbers."""
        for g in gs:
            if g == 90:
                self.incremental = False
            elif g == 91:
                self.incremental = True
            elif g in (0, 1, 2, 3):
                self.motion = int(g)
            elif g in (17, 18, 19):
                self.plane = int(g)
            elif g in (93, 94, 95):
                self.inverse_time = g == 93

    def _tcpm_switch(self, gs, ms, keywords, where: str) -> tuple:
        """TCPM on / off by the line's G, M and keywords (the tool numbers of this line
        count) -> the letters whose positions become unknown (:meth:`_switch`)."""
        want = None
        for g in gs:
            if g in TCPM_ON:
                want = ("tcpm", TCPM_ON[g])
            elif g in TCPM_OFF:
                want = ("axes", None)
        for m in ms:
            if m == 128:
                want = ("tcpm", "angles")
            elif m == 129:
                want = ("axes", None)
        for k in keywords:
            if k in ("TRAORI", "TCPM"):
                want = ("tcpm", "any" if k == "TRAORI" else "angles")
            elif k in ("TRAFOOF", "TCPM_OFF"):
                want = ("axes", None)
        return self._switch(*want, where) if want is not None else ()

    def _check_axes(self, axis_words, where: str) -> None:
        """Every axis word an axis of the machine, none twice."""
        for a, _ in axis_words:
            if a not in self.axes:
                raise InputError(f"{where}: axis {a} is not an axis of this machine "
                                 f"(axes {' '.join(self.axes)})")
        seen = set()
        for a, _ in axis_words:
            if a in seen:
                raise InputError(f"{where}: axis {a} programmed twice")
            seen.add(a)

    def _check_vector(self, axis_words, vector, where: str) -> None:
        """A tool vector under TCPM: not with rotary angles (G43.4 / M128), not with a rotary
        axis word."""
        if self.orientation == "angles":
            raise InputError(f"{where}: a tool vector ({' '.join(a for a, _ in vector)}) "
                             "under TCPM with rotary angles (G43.4 / M128)")
        rot = [a for a, _ in axis_words if a not in self.state.linear]
        if rot:
            raise InputError(f"{where}: rotary axis {rot[0]} and a tool vector in one block")

    def _arc(self, axis_words, centre, radius, where: str) -> Arc:
        """The :class:`Arc` of an arc block (not under TCPM, no rotary axis)."""
        if self.frame == "tcpm":
            raise InputError(f"{where}: an arc (G{self.motion}) under TCPM is not supported")
        rot = [a for a, _ in axis_words if a not in self.state.linear]
        if rot:
            raise InputError(f"{where}: rotary axis {rot[0]} in an arc block (G"
                             f"{self.motion}) is not supported")
        return Arc(self.plane, self.motion == 3, centre, radius)

    def block(self, line: Line) -> Block | None:
        """Update the modal state with one line; return a :class:`Block` for a motion block
        (straight or arc)."""
        step = self.step(line)
        if step is None:
            return None
        self.state.apply(step)
        if step.kind not in ("motion", "arc"):
            return None
        pos = self.state.position
        return Block(line, {a: pos[a] for a in self.axes},
                     tuple(a for a, _ in step.axis_words), step.incremental)


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
        if line.anchor is not None:
            t = line.tokens[line.anchor]
            last_word_end = t.start + len(t.text)
        # the insertion point moves with the length change of the numbers replaced before it
        anchor = last_word_end if last_word_end is not None else len(body)
        shift = sum(len(new_values[t.letter]) - (t.num_end - t.num_start)
                    for t in line.tokens if t.kind == "word" and t.letter in new_values
                    and t.num_end <= anchor)
        at = anchor + shift
        head, tail = out[:at], out[at:]
        words = [t for t in line.tokens if t.kind == "word"]
        own = _spaced(_kinds(line)) if len(words) > 1 else None
        if len(words) > 1 and own is None:
            own = True
        lower = all(t.text[0].islower() for t in words) and words
    sep = " " if (own if own is not None else (spaced if spaced is not None else True)) else ""
    ins = "".join(f"{sep}{(a.lower() if lower else a)}{v}" for a, v in added.items())
    return head + ins + tail + line.ending


#: :func:`rewrite_tokens`: drop the word (and the blanks before it)
REMOVE = object()


def rewrite_tokens(line: Line, edit, added: dict, spaced: bool | None = None) -> str:
    """The line with every word token passed through ``edit(token)`` -> new number text, None
    (keep) or :data:`REMOVE` (drop the word and the blanks before it), and the words of
    ``added`` (word address -> number text, e.g. ``"G"`` or ``"A3="``) appended after the last
    word; every other byte kept.  ``spaced`` as in :func:`rewrite_line`."""
    body = line.body
    toks = line.tokens
    pieces, pos = [], 0
    last_word_end = None
    kept_words = []
    for k, t in enumerate(toks):
        if t.kind != "word":
            continue
        new = edit(t)
        if new is REMOVE:
            cut = t.start
            if k and toks[k - 1].kind == "space" and toks[k - 1].start >= pos:
                cut = toks[k - 1].start
            pieces.append(body[pos:cut])
            pos = t.start + len(t.text)
            continue
        if new is not None:
            pieces.append(body[pos:t.num_start])
            pieces.append(new)
            pos = t.num_end
        kept_words.append(t)
        last_word_end = sum(len(x) for x in pieces) + (t.start + len(t.text) - pos)
    out = "".join(pieces) + body[pos:]
    if not added:
        return out + line.ending
    at = last_word_end if last_word_end is not None else len(out)
    head, tail = out[:at], out[at:]
    own = _spaced(_kinds(line)) if len(kept_words) > 1 else None
    if len(kept_words) > 1 and own is None:
        own = True
    lower = bool(kept_words) and all(t.text[0].islower() for t in kept_words)
    sep = " " if (own if own is not None else (spaced if spaced is not None else True)) else ""
    if not kept_words and head and not head[-1].isspace():
        head += sep
        sep_first = ""
    else:
        sep_first = sep
    words = [f"{(a.lower() if lower else a)}{v}" for a, v in added.items()]
    return head + sep_first + sep.join(words) + tail + line.ending

