"""The words of a plan's NC program in each controller's dialect (``volerr plan --dialect``).

:mod:`volerr.plan._nc` builds a program as a list of operations (:class:`Op`: a rapid, a
straight feed move, an arc, a probing move, a dwell, a comment, a program stop); a
:class:`Dialect` writes them as its controller reads them.  Positions are the layout's machine
axes (mm, deg), 4 decimals.

What differs between the dialects (sources: the LinuxCNC G-code manual, ``docs/src/gcode/
g-code.adoc`` of LinuxCNC 2.9 -- G4 "dwell for P seconds", G38.2 "probe toward workpiece, stop
on contact, signal error if failure", G53, G54, G43/G49, G61, comments in parentheses and after
``;``, a line at most 256 characters (its interpreter refuses longer ones as "Command too
long"); Fanuc Series 0i/30i operator's manuals -- G04 X<s> or P<ms> (P without a decimal
point), G31 skip function (the move Renishaw's Inspection Plus macros probe with); SINUMERIK
840D sl programming manual -- G4 F<s>, MEAS=1 (measurement with deletion of distance to go),
comments after ``;``, G60 exact stop; Heidenhain TNC 640 user's manuals -- plain language
``L``, ``CC``/``C`` circles, ``CYCL DEF 9 DWELL TIME``, touch probe cycle 0 ``TCH PROBE 0.0
REF. PLANE`` (probing along one axis from the current pre-position), ``M91`` machine-based
positions, ``;`` comments):

===========  ==============  ===============  =================  ===========================
dialect      comment         dwell (s = 2)    probing move       machine-coordinate retract
===========  ==============  ===============  =================  ===========================
iso          ``( )``         ``G4 P2``        ``G38.2``          ``G53 G0 Z..``
linuxcnc     ``( )``         ``G4 P2``        ``G38.2``          ``G53 G0 Z..``
fanuc        ``( )``         ``G4 P2000``     ``G31``            ``G53 G0 Z..``
sinumerik    ``;``           ``G4 F2``        ``MEAS=1 G1``      ``G53 G0 Z..``
heidenhain   ``;``           ``CYCL DEF 9``   ``TCH PROBE 0``    ``L Z+.. R0 FMAX M91``
===========  ==============  ===============  =================  ===========================

``iso`` is ISO 6983 / NIST RS274NGC (the language LinuxCNC's interpreter implements): the
programs are the LinuxCNC ones.  Every line is at most :data:`LINE_MAX` characters (long
comments are split over several lines).
"""

from __future__ import annotations

from dataclasses import dataclass, field

#: the dialects ``--dialect`` takes (the first the default)
NAMES = ("iso", "linuxcnc", "fanuc", "sinumerik", "heidenhain")
#: longest line written (LinuxCNC reads at most 256 characters, refusing 254 and more)
LINE_MAX = 200
#: arc plane of a circle about the axis named (G17 XY about Z, G18 ZX about Y, G19 YZ about X)
PLANE_CODE = {"Z": "G17", "Y": "G18", "X": "G19"}
#: centre words of each arc plane, the plane's axes in their right-handed order about the
#: normal (G17 X, Y; G18 Z, X; G19 Y, Z: counter-clockwise seen from the normal's positive
#: end turns the first towards the second)
CENTRE_WORDS = {"Z": ("X", "I", "Y", "J"), "Y": ("Z", "K", "X", "I"), "X": ("Y", "J", "Z", "K")}


@dataclass
class Op:
    """One operation of a program: ``kind`` one of ``comment stop rapid line arc probe dwell
    start end``; ``to`` {axis: value} (mm, deg); ``feed`` mm/min; an arc's ``normal`` (the
    machine axis it turns about), ``ccw`` (counter-clockwise seen from the axis' positive end)
    and ``centre`` {axis: value} (absolute, machine axes); a probing move's ``axis`` and
    ``sign`` (the machine axis and sense it probes along); ``text`` a comment or a stop's
    reason; ``seconds`` a dwell."""

    kind: str
    to: dict = field(default_factory=dict)
    feed: float = 0.0
    text: str = ""
    seconds: float = 0.0
    normal: str = ""
    ccw: bool = True
    centre: dict = field(default_factory=dict)
    axis: str = ""
    sign: int = 1


def number(value: float, sign: bool = False) -> str:
    """``value`` with at most 4 decimals, no trailing zeros, no negative zero; ``sign``: an
    explicit ``+`` (Heidenhain)."""
    text = f"{value:.4f}".rstrip("0").rstrip(".")
    if text in ("", "-0"):
        text = "0"
    return ("+" + text) if sign and not text.startswith("-") else text


def wrap(text: str, width: int) -> list:
    """``text`` split at spaces into pieces of at most ``width`` characters (a word longer
    than that cut after its last comma that fits, else at the width)."""
    out, line = [], ""
    for word in str(text).split():
        while len(word) > width:
            if line:
                out.append(line)
                line = ""
            cut = word.rfind(",", 0, width) + 1 or width     # after a comma where one is
            out.append(word[:cut])
            word = word[cut:]
        if not line:
            line = word
        elif len(line) + 1 + len(word) <= width:
            line += " " + word
        else:
            out.append(line)
            line = word
    if line or not out:
        out.append(line)
    return out


def _linear(to: dict) -> dict:
    """The linear axis words of ``to`` (a probing move names only them: the rotary axes
    stand still)."""
    return {a: v for a, v in to.items() if a in "XYZ"}


class Iso:
    """ISO 6983 / RS274NGC (the module docstring's table)."""

    name = "iso"
    suffix = ".nc"

    def __init__(self, axes):
        self.axes = tuple(axes)

    # -- words ----------------------------------------------------------------------------
    def words(self, to: dict) -> str:
        return " ".join(f"{a}{self.position(to[a])}" for a in self.axes if a in to)

    def position(self, value: float) -> str:
        """An axis position or arc-centre offset (mm / deg) as a word's number."""
        return number(value)

    def comment(self, text: str) -> list:
        clean = str(text).replace("(", "[").replace(")", "]")
        return [f"({piece})" for piece in wrap(clean, LINE_MAX - 2)]

    def begin(self, name: str) -> list:
        return ["%"]

    def start(self, z_top: float) -> list:
        return ["G21 G90 G94 G17 G40 G49 G80",
                f"G53 G0 Z{self.position(z_top)}",
                "G54 G61",
                *self.comment("metric, absolute, feed per minute; first the retract along Z "
                              "alone in machine coordinates to the top of the Z travel; "
                              "work offset G54 with zero offsets: the positions are the "
                              "layout's machine axes; tool length compensation off [G49]: "
                              "the positions already carry the probe / tool offset of the "
                              "plan; G61 exact path")]

    def rapid(self, op: Op) -> list:
        return [f"G0 {self.words(op.to)}"]

    def line(self, op: Op) -> list:
        return [f"G1 {self.words(op.to)} F{number(op.feed)}"]

    def arc(self, op: Op, start: dict) -> list:
        a, i, b, j = CENTRE_WORDS[op.normal]
        code = "G3" if op.ccw else "G2"
        off = " ".join(sorted([f"{i}{self.position(op.centre[a] - start[a])}",
                               f"{j}{self.position(op.centre[b] - start[b])}"]))    # I J K
        return [f"{PLANE_CODE[op.normal]} {code} {self.words(op.to)} {off} F{number(op.feed)}"]

    def probe(self, op: Op) -> list:
        return [f"G38.2 {self.words(_linear(op.to))} F{number(op.feed)}"]

    def dwell(self, op: Op) -> list:
        return [f"G4 P{number(op.seconds)}"]

    def stop(self, op: Op) -> list:
        return ["M0", *self.comment(op.text)]

    def end(self) -> list:
        return ["M30", "%"]

    # -- the program ----------------------------------------------------------------------
    def render(self, ops: list, name: str) -> str:
        """The program text of ``ops`` (one line each, ``\\n`` endings)."""
        lines = self.begin(name)
        where: dict = {}
        for op in ops:
            if op.kind == "comment":
                lines += self.comment(op.text)
            elif op.kind == "start":
                lines += self.start(op.to["Z"])
                where["Z"] = op.to["Z"]
            elif op.kind == "arc":
                lines += self.arc(op, {**where})
            elif op.kind == "end":
                lines += self.end()
            else:
                lines += getattr(self, op.kind)(op)
            where.update(op.to)
        return self.finish(lines, name)

    def finish(self, lines: list, name: str) -> str:
        return "\n".join(lines) + "\n"


class LinuxCNC(Iso):
    """LinuxCNC 2.9 (the same words as :class:`Iso`)."""

    name = "linuxcnc"


class Fanuc(Iso):
    """Fanuc Series 0i / 30i: ``O`` number, ``G4 P`` in milliseconds, ``G31`` skip moves."""

    name = "fanuc"

    def begin(self, name: str) -> list:
        return ["%", "O1000"]

    def position(self, value: float) -> str:
        """Always with a decimal point (``Z400.``): without one a Fanuc reads 400 least input
        increments (0.400 mm) when parameter 3401#0 DPI is 0 (FANUC 0i / 30i "decimal point
        programming"; ``volerr compensate`` refuses such words in an O-number program)."""
        text = number(value)
        return text if "." in text else text + "."

    def dwell(self, op: Op) -> list:
        return [f"G4 P{int(round(op.seconds * 1000))}"]

    def probe(self, op: Op) -> list:
        return [f"G31 {self.words(_linear(op.to))} F{number(op.feed)}"]


class Sinumerik(Iso):
    """SINUMERIK 840D sl: ``;`` comments, ``G4 F`` seconds, ``MEAS=1`` probing moves, G71
    metric, ``D0`` no tool offset, G60 exact stop."""

    name = "sinumerik"
    suffix = ".mpf"

    def begin(self, name: str) -> list:
        return []

    def comment(self, text: str) -> list:
        return [f"; {piece}" for piece in wrap(text, LINE_MAX - 2)]

    def start(self, z_top: float) -> list:
        return ["G71 G90 G94 G17 G40 G60",
                f"G53 G0 Z{self.position(z_top)}",
                "G54 D0",
                *self.comment("metric, absolute, feed per minute; first the retract along Z "
                              "alone in machine coordinates; work offset G54 with zero "
                              "offsets: the positions are the layout's machine axes; no tool "
                              "offset [D0]: the positions carry the probe / tool offset of "
                              "the plan; G60 exact stop")]

    def probe(self, op: Op) -> list:
        return [f"MEAS=1 G1 {self.words(_linear(op.to))} F{number(op.feed)}"]

    def dwell(self, op: Op) -> list:
        return [f"G4 F{number(op.seconds)}"]

    def end(self) -> list:
        return ["M30"]


class Heidenhain(Iso):
    """Heidenhain TNC plain language (``.h``): numbered blocks, ``L`` moves with signed
    words, ``CC``/``C`` circles, ``CYCL DEF 9`` dwell, ``TCH PROBE 0`` probing."""

    name = "heidenhain"
    suffix = ".h"

    def words(self, to: dict) -> str:
        return " ".join(f"{a}{number(to[a], sign=True)}" for a in self.axes if a in to)

    def begin(self, name: str) -> list:
        return [f"BEGIN PGM {name} MM"]

    def comment(self, text: str) -> list:
        return [f"; {piece}" for piece in wrap(text, LINE_MAX - 10)]

    def start(self, z_top: float) -> list:
        return [f"L Z{number(z_top, sign=True)} R0 FMAX M91",
                "TOOL CALL 0 Z",
                *self.comment("first the retract along Z alone to the top of the Z travel "
                              "[M91: machine-based]; the datum [preset] with zero offsets: "
                              "the positions are the layout's machine axes; tool 0 [no "
                              "length]: the positions carry the probe / tool offset of the "
                              "plan")]

    def rapid(self, op: Op) -> list:
        return [f"L {self.words(op.to)} R0 FMAX"]

    def line(self, op: Op) -> list:
        return [f"L {self.words(op.to)} R0 F{number(op.feed)}"]

    def arc(self, op: Op, start: dict) -> list:
        a, _, b, _ = CENTRE_WORDS[op.normal]
        cc = f"CC {a}{number(op.centre[a], sign=True)} {b}{number(op.centre[b], sign=True)}"
        end = self.words({k: v for k, v in op.to.items() if k in (a, b)})  # the circle's plane
        return [cc, f"C {end} DR{'+' if op.ccw else '-'} R0 F{number(op.feed)}"]

    def probe(self, op: Op) -> list:
        sense = "+" if op.sign > 0 else "-"
        pre = _linear(self.last_position)       # where it stands
        return [f"TCH PROBE 0.0 REF. PLANE Q1 {op.axis}{sense}",
                f"TCH PROBE 0.1 {self.words(pre)}"]

    def dwell(self, op: Op) -> list:
        return ["CYCL DEF 9.0 DWELL TIME", f"CYCL DEF 9.1 DWELL {number(op.seconds)}"]

    def stop(self, op: Op) -> list:
        return ["STOP", *self.comment(op.text)]

    def end(self) -> list:
        return ["M30"]

    def render(self, ops: list, name: str) -> str:
        self.last_position = {}
        where: dict = {}
        lines = self.begin(name)
        for op in ops:
            self.last_position = dict(where)
            if op.kind == "comment":
                lines += self.comment(op.text)
            elif op.kind == "start":
                lines += self.start(op.to["Z"])
            elif op.kind == "arc":
                lines += self.arc(op, where)
            elif op.kind == "end":
                lines += self.end()
            else:
                lines += getattr(self, op.kind)(op)
            where.update(op.to)
        return self.finish(lines, name)

    def finish(self, lines: list, name: str) -> str:
        lines = lines + [f"END PGM {name} MM"]
        return "\n".join(f"{n} {text}" for n, text in enumerate(lines)) + "\n"


DIALECTS = {c.name: c for c in (Iso, LinuxCNC, Fanuc, Sinumerik, Heidenhain)}


def dialect(name: str, axes) -> Iso:
    """The writer of dialect ``name`` for the machine axes ``axes``."""
    return DIALECTS[name](axes)
