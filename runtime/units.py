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
    import numpy as np  # here, not at import: every --help imports this module

    data = np.asarray(data, dtype=float) + 0.0      # + 0.0: -0 becomes 0
    row = ",".join([f"%.{digits}g"] * data.shape[1]) + "\n"
    return "".join((row * len(b)) % tuple(b.ravel().tolist())
                   for b in (data[i:i + block] for i in range(0, len(data), block)))


# -- quantities: a number with its unit, as options take them ("22 um", "5 urad") ------------
#: units of the options: unit -> (kind, factor to the kind's base unit).  Lengths in um;
#: angles in urad (``um/m``, ``mm/m`` are the small angles of a squareness or a slope:
#: 1 um/m = 1 urad).  Spelled as written (``µm``, ``μrad`` are read as ``um``, ``urad``).
QUANTITY_UNITS = {
    "nm": ("length", 1e-3), "um": ("length", 1.0), "mm": ("length", UM_PER_MM),
    "m": ("length", UM_PER_MM * MM_PER_M),
    "urad": ("angle", 1.0), "mrad": ("angle", 1e3), "rad": ("angle", URAD_PER_RAD),
    "arcsec": ("angle", math.pi / 180 / 3600 * URAD_PER_RAD),
    "deg": ("angle", math.pi / 180 * URAD_PER_RAD),
    "um/m": ("angle", 1.0), "mm/m": ("angle", 1e3),
}
_QUANTITY = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S*?)\s*")


def unit_name(text: str) -> str:
    """A unit as volerr spells it: ``µm``/``μm`` -> ``um``, ``µrad`` -> ``urad``, ``"`` ->
    ``arcsec``, ``°`` -> ``deg``; anything else unchanged."""
    t = str(text).strip().replace("µ", "u").replace("μ", "u")
    return {'"': "arcsec", "″": "arcsec", "°": "deg"}.get(t, t)


def parse_quantity(text, where: str, *, default_unit: str | None = None,
                   kinds=("length", "angle"), positive: bool = True,
                   any_unit: bool = False) -> tuple:
    """``"22 um"`` -> ``(22.0, "um")``: one finite number and its unit (:data:`QUANTITY_UNITS`
    of one of ``kinds``, or ``default_unit`` itself, whatever it is).  A bare number takes
    ``default_unit`` when the option documents one (an ISO 230-2 tolerance in um, a check's
    tolerance in its parameter's unit), else it is refused:
    ``"<where>: the value needs its unit, e.g. 22 um or 5 urad"``.  ``positive``: the value
    must be > 0.  ``any_unit``: a unit not in the table (``um/mm``, ``urad/deg`` of a slope)
    is returned as written, for the caller to compare with the unit of what it limits (a
    unit is still required).  Every refusal is one :class:`~volerr.errors.InputError` line
    starting with ``where`` (e.g. ``"--tolerance EX0C=22"``)."""
    m = _QUANTITY.fullmatch(str(text))
    if m is None:
        raise InputError(f"{where}: write a number and its unit, e.g. 22 um or 5 urad")
    value = float(m.group(1))
    unit = unit_name(m.group(2))
    if not math.isfinite(value) or abs(value) > 1e15:
        raise InputError(f"{where}: {m.group(1)} is not a finite number")
    if not unit:
        if default_unit is None:
            raise InputError(f"{where}: the value needs its unit, e.g. {value:g} um or "
                             f"5 urad")
        unit = default_unit
    known = " ".join(u for u, (k, _) in QUANTITY_UNITS.items() if k in kinds)
    if any_unit and unit not in QUANTITY_UNITS:
        if not re.fullmatch(r"[A-Za-z/^0-9]+", unit):
            raise InputError(f"{where}: unit {unit!r} unknown; one of {known} (or the "
                             f"parameter's own unit, e.g. um/mm)")
    elif unit != default_unit and unit not in QUANTITY_UNITS:
        raise InputError(f"{where}: unit {unit!r} unknown; one of {known}")
    if unit in QUANTITY_UNITS and unit != default_unit and \
            QUANTITY_UNITS[unit][0] not in kinds:
        raise InputError(f"{where}: {unit} is a unit of {QUANTITY_UNITS[unit][0]}, not of "
                         f"{' or '.join(kinds)}: one of {known}")
    if positive and not value > 0:
        raise InputError(f"{where}: a positive value expected")
    return value, unit


def convert(value: float, unit: str, to: str, where: str = "") -> float:
    """``value`` in ``unit`` expressed in ``to`` (both in :data:`QUANTITY_UNITS`, of one kind;
    equal units pass unchanged whatever they are).  Else :class:`InputError`: ``"<where>:
    given in <unit>, which is not a unit of <to>"``."""
    unit, to = unit_name(unit), unit_name(to)
    if unit == to:
        return float(value)
    a, b = QUANTITY_UNITS.get(unit), QUANTITY_UNITS.get(to)
    if a is None or b is None or a[0] != b[0]:
        raise InputError(f"{where + ': ' if where else ''}given in {unit}, which is not a "
                         f"unit of {to}")
    return float(value) * a[1] / b[1]


def parse_assignments(text, option: str, example: str = "EX0C=20 um, EA0C=5 urad",
                      keywords_for=None, **quantity) -> list:
    """``"EX0C=20 um, EA0C=5 urad"`` -> ``[(name, (value, unit)), ...]`` in the order given:
    pairs split at ``,`` ``;`` ``|``, each ``NAME=VALUE UNIT`` read by :func:`parse_quantity`
    (``quantity``: its keywords; the unit may follow the number directly, ``5um``).  A bare
    number takes ``default_unit`` where the option states one (``volerr iso230-2
    --tolerance``: every quantity a length in um), else it is refused (``volerr history show
    --tolerance``, ``volerr check --tolerance``: parameters in different units).  Names as
    written (stripped); a name given twice, an empty list or a pair without ``=`` is refused,
    naming ``option`` and the pair (``example``: the option's own, for that message).
    ``keywords_for``: ``name -> dict`` of further :func:`parse_quantity` keywords for that
    name's value (``volerr check``: a slope parameter takes its own unit); it may refuse an
    unknown name before its value is read."""
    out, seen = [], set()
    for part in filter(None, (p.strip() for p in re.split(r"[,;|]", str(text or "")))):
        name, eq, rest = part.partition("=")
        name = name.strip()
        if not (eq and name):
            raise InputError(f"{option} {part!r}: NAME=VALUE UNIT expected (e.g. {example})")
        if name in seen:
            raise InputError(f"{option}: {name} given twice")
        seen.add(name)
        extra = keywords_for(name) if keywords_for is not None else {}
        out.append((name, parse_quantity(rest, f"{option} {part}", **{**quantity, **extra})))
    if not out:
        raise InputError(f"{option}: no value given (NAME=VALUE UNIT, e.g. "
                         f"{example.split(',')[0]})")
    return out


def match_name(name: str, known, option: str) -> str | None:
    """The one of ``known`` that ``name`` (of a ``NAME=VALUE`` pair of ``option``) names, or
    None: written exactly, else the only one equal to it ignoring case (``ex0c`` is ``EX0C``,
    ``map`` is ``MAP``, ``a`` is ``A``).  Two known names equal ignoring case and neither
    written exactly are refused in one line naming both: a name is never assigned by a guess.
    The rule of every ``--tolerance`` of volerr (``iso230-2``, ``check``, ``history show``)."""
    known = list(known)
    if name in known:
        return name
    hits = [k for k in known if k.casefold() == name.casefold()]
    if len(hits) > 1:
        raise InputError(f"{option}: {name!r} is any of {', '.join(hits)} ignoring case; "
                         f"write the name exactly")
    return hits[0] if hits else None


# -- dates -----------------------------------------------------------------------------------
def today_utc() -> str:
    """Today's date (UTC), ``YYYY-MM-DD``."""
    import datetime as _dt

    return _dt.datetime.now(_dt.timezone.utc).date().isoformat()


def parse_date(text, where: str = "--date", future: bool = False) -> str:
    """``text`` as a date ``YYYY-MM-DD`` (exactly: ``2025-2-1``, ``01.02.2025`` refused) not
    after today (UTC: a measurement is not from the future); returns it as written.  One-line
    :class:`InputError`: ``"--date 2099-01-01 is in the future (today is ... UTC)"``,
    ``"--date '2025-13-01': a date YYYY-MM-DD expected (year-month-day)"``; ``future``:
    a date after today is taken (a calibration's due date)."""
    import datetime as _dt

    t = str(text).strip()
    try:
        if not re.fullmatch(r"\d{4}-\d{2}-\d{2}", t):
            raise ValueError(t)
        d = _dt.date.fromisoformat(t)
    except ValueError:
        raise InputError(f"{where} {str(text)!r}: a date YYYY-MM-DD expected "
                         f"(year-month-day, e.g. 2025-03-31)") from None
    now = today_utc()
    if not future and d.isoformat() > now:
        raise InputError(f"{where} {t} is in the future (today is {now} UTC); a result is "
                         f"dated when it was measured")
    return d.isoformat()


# -- plausibility of option values typed in the wrong unit ----------------------------------
#: a temperature read in degC (a room, a structure, a motor, a part) lies in this range; a
#: value beyond it is not degC (degF: 68 degF = 20 degC)
TEMPERATURE_RANGE_C = (-10.0, 80.0)
#: the material temperature of a measured scale or part (ISO 230-2, ISO 1): degC
MATERIAL_TEMPERATURE_RANGE_C = (-10.0, 50.0)
#: no material's expansion coefficient reaches this, ppm/K (Zerodur class 0: 0.02 ppm/K)
CTE_FLOOR_PPM_PER_K = 1e-3
#: no solid's expansion coefficient reaches this, ppm/K (polymers: about 200 ppm/K)
CTE_CEILING_PPM_PER_K = 1e3


def check_temperature_C(value: float, where: str,
                        low_high: tuple = TEMPERATURE_RANGE_C) -> float:
    """``value`` (degC) returned when finite and in ``low_high``; else one-line
    :class:`InputError` naming ``where``, with ``"degF?"`` when the value read as degF
    (``(F - 32) x 5/9``) falls in the range (68 -> 20 degC)."""
    lo, hi = low_high
    if not math.isfinite(value):
        raise InputError(f"{where}: {value} is not a finite temperature")
    if lo <= value <= hi:
        return float(value)
    as_c = (value - 32.0) * 5.0 / 9.0
    hint = (f"likely in degF (Fahrenheit: {value:g} degF = {as_c:.1f} degC); give degC"
            if lo <= as_c <= hi else "not a temperature in degC (in K? a wrong column?)")
    raise InputError(f"{where} = {value:g} is outside {lo:g} .. {hi:g} degC: {hint}")


def check_cte(value: float, where: str, unit: str = "ppm/K") -> float:
    """An expansion coefficient in ``unit`` (``"ppm/K"`` or ``"1/K"``) returned when finite and
    0 or of a material's size (|alpha| between 1e-3 and 1e3 ppm/K); else one-line
    :class:`InputError` naming ``where`` and the likely unit (11.5e-6 typed for ppm/K is
    1/K; 11.5 typed for 1/K is ppm/K).  Sign: any (a negative coefficient exists)."""
    if not math.isfinite(value):
        raise InputError(f"{where}: {value} is not a finite number")
    ppm = abs(value) * (1e6 if unit == "1/K" else 1.0)
    if value == 0 or CTE_FLOOR_PPM_PER_K <= ppm <= CTE_CEILING_PPM_PER_K:
        return float(value)
    if unit == "1/K":
        raise InputError(f"{where} = {value:g} 1/K is {ppm:g} ppm/K, beyond any material: "
                         f"likely given in ppm/K; give 1/K ({value:g} ppm/K = "
                         f"{value * 1e-6:g} 1/K)")
    hint = (f"likely given in 1/K; give ppm/K ({value:g} 1/K = {value * 1e6:g} ppm/K)"
            if ppm < CTE_FLOOR_PPM_PER_K else "no material expands this much (a wrong unit?)")
    raise InputError(f"{where} = {value:g} ppm/K is beyond any material's expansion "
                     f"coefficient ({CTE_FLOOR_PPM_PER_K:g} .. {CTE_CEILING_PPM_PER_K:g} "
                     f"ppm/K): {hint}")


def check_offset_mm(vector, where: str, limit_mm: float, what: str = "offset") -> tuple:
    """An offset vector (mm) returned as a tuple of floats when finite and no longer than
    ``limit_mm`` (the machine's size: a stylus or a tool cannot be longer than the machine);
    else one-line :class:`InputError` naming ``where`` and the likely unit (um typed for
    mm, when the length / 1000 fits)."""
    v = tuple(float(x) for x in vector)
    if not all(math.isfinite(x) for x in v):
        raise InputError(f"{where}: the {what} must be finite numbers (mm)")
    n = math.sqrt(sum(x * x for x in v))
    if n <= limit_mm:
        return v
    hint = ("likely given in um; give mm" if n * MM_PER_UM <= limit_mm
            else "a wrong unit?")
    raise InputError(f"{where} {' '.join(f'{x:g}' for x in v)}: an {what} {n:g} mm long, "
                     f"longer than the machine ({limit_mm:g} mm): {hint}")


#: no tolerance or MPE of a machine tool or CMM is below this, um (the best CMMs: MPE
#: 0.3 um + L/1000; an ISO 230-2 tolerance is a micrometre or more)
TOLERANCE_FLOOR_UM = 0.1
#: no tolerance or MPE of a machine tool or CMM is above this, um (1 mm): the positioning
#: tolerances of the longest axes in the machine-tool standards (ISO 10791-2, ISO 3070-2:
#: A of axes of several metres) are a few tenths of a millimetre, a CMM's MPE constant a few
#: micrometres; a tolerance of millimetres is a value in um typed with ``mm`` (``A=12 mm``)
#: or one in nm typed as um (``E=25000``)
TOLERANCE_CEILING_UM = 1000.0


def check_tolerance_um(value_um: float, where: str, unit: str = "um", name: str = "",
                       ceiling: bool = True) -> float:
    """A tolerance (um) returned when at least :data:`TOLERANCE_FLOOR_UM` and at most
    :data:`TOLERANCE_CEILING_UM`; else one-line :class:`InputError` naming ``where``: below
    any machine's tolerance, likely given in mm; above it, likely given in um with ``mm`` or
    in nm (``unit``: as the user wrote it; bare numbers are um; ``name``: the quantity, for
    the suggested spelling ``A=0.012 mm``).  Zero and negative values are returned for the
    caller's own one line.  ``ceiling=False``: the floor only (a limit on a parameter of a
    layout, bounded by the machine's size instead: :mod:`volerr.tables.plausible`)."""
    label = name + "=" if name else ""
    if ceiling and value_um > TOLERANCE_CEILING_UM:
        hint = (f"likely meant in um: write {label}{value_um / UM_PER_MM:g} um" if unit == "mm"
                else f"likely given in nm: write {label}{value_um * 1e-3:g} um"
                if unit in ("um", "nm") else "a wrong unit?")
        raise InputError(f"{where}: {value_um:g} um is above any machine's tolerance "
                         f"({TOLERANCE_CEILING_UM:g} um): {hint}")
    if value_um >= TOLERANCE_FLOOR_UM or value_um <= 0:
        return value_um
    hint = (f"likely meant in mm: write {name + '=' if name else ''}{value_um:g} mm"
            if unit == "um"
            else "a wrong unit?")
    raise InputError(f"{where}: {value_um:g} um is below any machine's tolerance "
                     f"({TOLERANCE_FLOOR_UM:g} um): {hint}")


#: the smallest spread (largest minus smallest value) the readings of one error column of a
#: real machine show, um.  A very good machine's positioning error over a short axis still
#: spans about 0.1 um (its repeatability alone: ISO 230-2 R of the best axes 0.2-0.5 um), an
#: R-test over a rotary sweep or a ballbar circle micrometres; the instruments resolve
#: 0.001-0.01 um (laser interferometer, probe), so no real column spans less than half that
#: 0.1 um.  Readings in mm written under an ``_um`` header span a thousandth of the real
#: spread: every machine whose real spread is below 50 um is caught (one-sided evidence: a
#: column in mm of a worse machine passes).
MIN_READING_SPREAD_UM = 0.05
#: a spread at or below this, um, is no reading at all (1 pm, a thousandth of the finest
#: instrument's resolution): a constant or zero-filled column, or the round-off of a
#: simulated perfect machine (1e-9 um), left to the readers' own checks
NO_SPREAD_UM = 1e-6


#: the smallest spread of one angular error column of a real machine, urad (an error table's
#: ``EAX_urad`` ... over an axis' travel).  The pitch, yaw and roll of the best linear axes
#: and the wobble of the best rotary axes over their travel span 0.5 urad and more (ISO 230-2
#: angular runs of precision CMMs: 0.5-2 urad); angular optics resolve 0.01-0.05 urad, so no
#: real column spans less than a tenth of that 0.5 urad.  Angles in mrad (or rad) written under
#: ``_urad`` span a thousandth (a millionth) of the real spread: every machine whose real
#: spread is below 50 urad is caught.
MIN_ANGLE_SPREAD_URAD = 0.05


#: the smallest spread of the readings of a cycle over a rotary axis' travel (R-test, touch
#: probe on a sphere) or of a ballbar circle, um: they read the axes' location and squareness
#: errors times a radius of 100 mm or more and the set-up's offsets (the sphere off its
#: nominal centre, the circle's centre), micrometres on the best five-axis machines
#: (ISO 230-4 G of the best circles 1-2 um); a tenth of a micrometre spread is no such cycle
MIN_CYCLE_SPREAD_UM = 0.5


def check_reading_spread_um(columns: dict, where: str,
                            minimum_um: float = MIN_READING_SPREAD_UM, unit: str = "um") -> None:
    """Refuse readings that look like mm written under ``_um`` (x1000): ``columns``
    ``{header: values}`` of one file's error readings headed ``_um`` (values as written, um);
    one-line :class:`InputError` naming ``where`` and the column when the largest spread
    ``max - min`` of the columns is above :data:`NO_SPREAD_UM` and below ``minimum_um``
    (:data:`MIN_READING_SPREAD_UM`; :data:`MIN_CYCLE_SPREAD_UM` for the readings of a
    rotary cycle or a ballbar circle).  ``unit="urad"``: angular columns headed ``_urad``
    (values in urad, ``minimum_um`` then a spread in urad, :data:`MIN_ANGLE_SPREAD_URAD`):
    the refusal names mrad or rad written under ``_urad``."""
    import numpy as np

    vals = {h: np.asarray(v, dtype=float) for h, v in columns.items()}
    vals = {h: v[np.isfinite(v)] for h, v in vals.items()}
    vals = {h: v for h, v in vals.items() if v.size}
    spread = {h: float(np.ptp(v)) for h, v in vals.items()}
    col = max(spread, key=spread.get, default=None)      # the widest column (first on ties)
    if col is None or not NO_SPREAD_UM < spread[col] < minimum_um:
        return
    big = float(np.max(np.abs(vals[col])))
    likely = ("mm written under _um (x1000); give um, or head the column _mm" if unit == "um"
              else "mrad or rad written under _urad (x1000 or x1e6); give urad, or head the "
                   "column _rad")
    raise InputError(f"{where}: column {col}: the readings span {spread[col]:.3g} {unit} "
                     f"(largest {big:.3g} {unit}), less than any machine and instrument show "
                     f"({minimum_um:g} {unit}): looks like {likely}")


def check_tool_offset(vector, where: str, limit_mm: float) -> tuple:
    """A tool offset in the tool frame (mm, from the point the axis positions refer to, the
    spindle gauge point, to the tool tip: ``0 0 -L`` for a tool L long, docs/conventions.md)
    returned when :func:`check_offset_mm` accepts it and its z is not positive; a positive z
    puts the tip inside the spindle: refused as the likely sign (one line naming ``where``)."""
    v = check_offset_mm(vector, where, limit_mm, "offset")
    if v[2] > 0:
        raise InputError(f"{where} {' '.join(f'{x:g}' for x in v)}: a tool offset with z = "
                         f"+{v[2]:g} mm puts the tip inside the spindle; the offset of a tool "
                         f"L long is 0 0 -L: likely the sign (write {v[0]:g} {v[1]:g} "
                         f"{-v[2]:g}, or --tool-length {v[2]:g})")
    return v


#: the spindle's tilt read by two displacement sensors of one direction at two heights z:
#: direction -> (the axis it turns about, the sign of the tilt per ds/dz), right hand --
#: sensors along X read the tilt about +Y (+ds/dz), along Y the tilt about +X (-ds/dz);
#: used by the ISO 230-3 evaluation and the drift loop's rows alike
SENSOR_TILT = {"X": ("Y", 1.0), "Y": ("X", -1.0)}


#: the largest coordinate accepted on the command line (mm)
MAX_COORD_MM = 1e6


def parse_vector(tokens, what: str, n: int = 3) -> tuple:
    """``["1", "2", "3"]``, ``["1,2,3"]`` or ``["1, 2", "3"]`` -> (1.0, 2.0, 3.0): both vector
    syntaxes, finite numbers of at most :data:`MAX_COORD_MM`; ``what`` (the option) names
    the value in the one-line :class:`InputError` of a bad one."""
    if isinstance(tokens, str):
        tokens = [tokens]
    parts = [c for t in tokens for c in str(t).replace(",", " ").split()]
    try:
        v = tuple(float(c) for c in parts)
    except ValueError:
        raise InputError(f"{what}: expected {'three' if n == 3 else n} numbers (X Y Z or "
                         f"X,Y,Z), got "
                         f"{' '.join(map(str, tokens))!r}") from None
    if len(v) != n:
        raise InputError(f"{what}: expected {'three' if n == 3 else n} numbers (X Y Z or "
                         f"X,Y,Z), got {len(v)}")
    if not all(math.isfinite(c) and abs(c) <= MAX_COORD_MM for c in v):
        raise InputError(f"{what}: numbers must be finite and at most {MAX_COORD_MM:g} mm, "
                         f"got {' '.join(map(str, tokens))}")
    return v


def parse_at(items, option: str = "--at") -> dict:
    """``["B=30", "C=-90"]`` (``AXIS=VALUE``, repeatable option) -> ``{"B": 30.0, "C": -90.0}``
    (rotary axes in deg, linear in mm); a malformed item: one-line :class:`InputError`."""
    out = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        if not (sep == "=" and name):
            raise InputError(f"{option} expects AXIS=VALUE, got {item!r}")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise InputError(f"{option} {item!r}: {value!r} is not a number") from None
    return out
