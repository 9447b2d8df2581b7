"""The instruments of a plan: ``--instrument SPEC`` parsed, and the time model.

``SPEC`` = ``KIND[:key=value[,value...]]...`` (``volerr formats plan``).  Every kind takes
``u_um=U`` (the standard uncertainty of one reading the plan assumes, written into the files
as the ``u_um`` column so that ``calibrate`` weighs the readings with it) and ``tool=L`` or
``tool=X,Y,Z`` (the tool / stylus offset, mm, tool frame).

Time model (minutes; planning assumptions, documented in ``volerr formats plan`` with their
sources): a set-up change (mount and centre a pivot, move the sphere, move a station) costs
``SETUP_MIN[kind]``; a reading costs ``READING_S[kind]`` seconds (a stop, the dwell and the
move to the next pose); a ballbar trace is read on the fly at ``BALLBAR_FEED_MM_MIN``, its time
is the circle's length at that feed (both directions, each with a 45 deg run-in and a 45 deg
run-out arc: runtime/plan/_nc.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import require

#: set-up change, minutes per set-up
SETUP_MIN = {"ballbar": 5.0, "sphere": 10.0, "distances": 15.0, "interferometer": 20.0,
             "artifact": 20.0}
#: time per reading, seconds (0 for the ballbar: it samples during the motion)
READING_S = {"ballbar": 0.0, "sphere": 12.0, "distances": 5.0, "interferometer": 6.0,
             "artifact": 30.0}
#: (interferometer: the move to the next target at 2000 mm/min and the dwell; a set-up change
#: is mounting and aligning the optics on a new line)
#: (artifact: move and clamp the plate, align it; a ball probed by a five-point cycle)
#: (sphere: up to the clearance height and back down, 2 x 20 mm along the tool axis at
#: 1000 mm/min, the dwell: runtime/plan/_nc.py)
#: feed of a ballbar circle (mm/min), ISO 230-4 tests at the machine's contouring feed
BALLBAR_FEED_MM_MIN = 1000.0
#: dwell at a reading (s) written into the NC program for instruments that read at a stop
DWELL_S = {"sphere": 2.0, "distances": 2.0, "interferometer": 3.0, "artifact": 2.0}
#: keys every kind takes
COMMON = ("u_um", "tool")
KEYS = {"ballbar": COMMON + ("lengths", "length_u_um"),
        "sphere": COMMON + ("places", "tool_u_um", "frame"),
        "distances": COMMON + ("stations",),
        "interferometer": COMMON + ("optics", "u_urad"),
        "artifact": COMMON + ("balls", "pitch", "cal_u_um", "places")}
#: optics of an interferometer plan (``optics=``), default all
OPTICS = ("linear", "straightness", "angular")


@dataclass
class Instrument:
    """One ``--instrument``: its kind and options (mm, um; None: the default)."""

    kind: str
    u_um: float | None = None
    tool: tuple = (0.0, 0.0, 0.0)
    lengths: tuple = (100.0, 150.0, 250.0)
    length_u_um: float | None = None
    places: int = 4
    tool_u_um: float | None = None
    frame: str = "work"
    stations: int = 4
    optics: tuple = OPTICS
    u_urad: float | None = None
    balls: tuple = (5, 5)
    pitch: float = 100.0
    cal_u_um: float = 0.5
    text: str = ""
    given: set = field(default_factory=set)


def parse(text: str) -> Instrument:
    """``KIND[:key=value[,value...]]...`` -> :class:`Instrument` (InputError, one line)."""
    parts = [p.strip() for p in str(text).split(":")]
    kind = parts[0].lower()
    require(kind in KEYS, f"--instrument {text!r}: kind must be one of {', '.join(KEYS)}")
    inst = Instrument(kind, text=str(text))
    for part in parts[1:]:
        key, eq, value = part.partition("=")
        key = key.strip().lower()
        require(eq and value.strip(), f"--instrument {text!r}: {part!r} is not key=value")
        require(key in KEYS[kind], f"--instrument {text!r}: {kind} takes "
                                   f"{', '.join(KEYS[kind])}, not {key!r}")
        require(key not in inst.given, f"--instrument {text!r}: {key} given twice")
        inst.given.add(key)
        _set(inst, key, value.strip(), text)
    return inst


def _numbers(value: str, key: str, text: str) -> list:
    out = []
    for v in value.split(","):
        try:
            x = float(v)
        except ValueError:
            x = float("nan")
        require(x == x and abs(x) < 1e6, f"--instrument {text!r}: {key}={value!r} is not a "
                                         f"number list")
        out.append(x)
    return out


def _set(inst: Instrument, key: str, value: str, text: str) -> None:
    if key == "frame":
        require(value in ("work", "machine"), f"--instrument {text!r}: frame must be work "
                                              f"or machine")
        inst.frame = value
        return
    if key == "balls":
        n = value.lower().split("x")
        ok = len(n) == 2 and all(v.strip().isdigit() for v in n)
        require(ok and all(2 <= int(v) <= 20 for v in n), f"--instrument {text!r}: balls=NxM, "
                                                         f"2..20 balls a side (a ball plate)")
        inst.balls = (int(n[0]), int(n[1]))
        return
    if key == "optics":
        words = [w.strip().lower() for w in value.split(",")]
        require(all(w in OPTICS for w in words), f"--instrument {text!r}: optics are "
                                                 f"{', '.join(OPTICS)}")
        inst.optics = tuple(dict.fromkeys(words))
        return
    vals = _numbers(value, key, text)
    if key == "lengths":
        require(all(v > 0 for v in vals), f"--instrument {text!r}: lengths must be positive")
        inst.lengths = tuple(sorted(set(vals)))
    elif key == "tool":
        require(len(vals) in (1, 3), f"--instrument {text!r}: tool=L or tool=X,Y,Z (mm)")
        inst.tool = (0.0, 0.0, vals[0]) if len(vals) == 1 else tuple(vals)
    elif key in ("places", "stations"):
        require(len(vals) == 1 and vals[0] == int(vals[0]) and 1 <= vals[0] <= 50,
                f"--instrument {text!r}: {key} must be a whole number 1..50")
        require(key != "stations" or vals[0] >= 3, f"--instrument {text!r}: multilateration "
                                                   f"needs at least 3 stations")
        setattr(inst, key, int(vals[0]))
    else:
        require(len(vals) == 1 and vals[0] > 0, f"--instrument {text!r}: {key} must be one "
                                                f"positive number")
        setattr(inst, key, vals[0])
