"""How large an error value a machine of a given size can have: the one rule of volerr.

Every error table and constant read (:func:`volerr.tables.table.read_error_dir`, hence
:meth:`volerr.tables.ErrorFunctions.from_dir` and every command reading ``--errors DIR``) or
written (:func:`volerr.tables.table.write_error_dir`: identified or calibrated tables), and
every error motion ``volerr identify`` identifies, is held against the limits below.  A value
beyond them is not a machine error but a unit mistake (``EXX_mm`` over values in um, ``_rad``
over urad, a squareness in urad declared ``rad``) or a failed identification; it is refused
with one line naming the file, the column and the likely unit, unless the caller accepts it
(``accept_implausible=True``, the option ``--accept-implausible`` "for a machine that really
is that bad").

The machine's size ``L`` (mm) is the largest travel of its linear axes in the layout (without a
layout: the largest measured span of the linear-axis tables read, else 1000 mm).

* **Translational** errors (``EXX`` ... ``EZZ``, location errors ``EX0C`` ..., the reversal
  ``RV_X``, their uncertainties): at most ``500 um + 500 ppm x L`` (1000 um for a 1 m
  machine).  500 ppm is the thermal growth of a steel scale 40 K away from 20 degC
  (11.5 ppm/K x 40 K = 460 ppm), the largest length-proportional error a machine can
  plausibly carry uncompensated; 500 um bounds the length-independent part (a worn guideway's
  straightness, backlash), some ten times the worst found on machines in use.
* **Angular** errors (``EAX`` ... ``ECC``, squareness ``EC0Y`` ..., location errors ``EA0C``
  ...): at most ``min(1 mrad, sqrt(2 x 0.5 um / L))``.  The models are first order in the
  error angles (sin e = e, cos e = 1, products of two angles dropped): the term they drop over
  the machine's size is ``e^2 L / 2``, and the limit keeps it below 0.5 um (1 mrad for
  L = 1000 mm, 0.45 mrad for L = 5000 mm).  1 mrad (206 arcsec, 1 mm per metre) is beyond
  any machine axis in use whatever its size.

Sign: the limits bound the magnitude ``abs(value)``; both signs are alike.

**Positions** of a table read from a file, against the axis' travel in the layout
(:func:`check_positions`): an error table is measured over the travel of its axis (ISO 230-2
measures over the axis' travel, a rotary axis over its range or a full turn).  A table that
covers less than :data:`POSITION_COVERAGE_MIN` (a tenth) of the travel while its positions read
in the other usual unit (radians x 180/pi for a rotary axis, inches x 25.4 for a linear one)
lie inside the travel and cover at least :data:`POSITION_COVERAGE_UNIT` (half) of it was
written in that unit: refused naming it (``C`` 0 .. 6.28 of a C axis of -360 .. 360 deg is 0 ..
360 deg in radians; ``X`` 0 .. 35.4 of a 900 mm axis is 0 .. 900 mm in inches).  The travel of
an endless rotary axis counts as one turn.  A real partial table whose span happens to be a
radian or an inch measure of the travel is the exception ``--accept-implausible`` is for.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..units import MM_PER_UM, RAD_PER_URAD, UM_PER_MM, URAD_PER_RAD

#: translational limit: length-independent part, um
TRANSLATION_BASE_UM = 500.0
#: translational limit: part proportional to the machine's size, ppm (um per m)
TRANSLATION_PPM = 500.0
#: angular limit: the largest second-order term e^2 L / 2 of the small-angle model, um
SMALL_ANGLE_DEFECT_UM = 0.5
#: angular limit: never more than this, urad
ANGLE_CAP_URAD = 1000.0
#: the machine's size without a layout and without linear-axis tables, mm
DEFAULT_SIZE_MM = 1000.0
#: the option that accepts values beyond the limits (named in every refusal)
OPTION = "--accept-implausible"

#: a table covering less than this fraction of its axis' travel is judged by
#: :func:`check_positions` (a tenth: the measuring travel of ISO 230-2 is the axis' travel)
POSITION_COVERAGE_MIN = 0.1
#: ... and refused when its positions read in the other unit cover at least this fraction
POSITION_COVERAGE_UNIT = 0.5
#: the other usual unit of an axis' positions: kind -> (unit, factor to the file's unit, file
#: unit)
POSITION_UNITS = {"rotary": ("radians", 180.0 / math.pi, "deg"),
                  "linear": ("inches", 25.4, "mm")}

#: units a value may really have been written in: name -> (kind, mm or rad per unit); in the
#: order they are suggested
_CANDIDATES = {"length": (("um", MM_PER_UM), ("nm", MM_PER_UM ** 2), ("mm", 1.0)),
               "angle": (("urad", RAD_PER_URAD), ("arcsec", math.pi / 648000.0),
                         ("deg", math.pi / 180.0), ("mrad", 1e-3), ("rad", 1.0))}
#: the units an error file accepts (a suggestion outside them says "convert to ...")
_FILE_UNITS = {"length": "um", "angle": "urad"}


@dataclass(frozen=True)
class Limits:
    """Magnitude limits of one machine (module docstring).

    ``size_mm``: the machine's size L, mm; ``basis``: where L comes from (messages)."""

    size_mm: float
    basis: str

    @property
    def length_mm(self) -> float:
        """Largest translational error, mm."""
        return (TRANSLATION_BASE_UM + TRANSLATION_PPM * MM_PER_UM * self.size_mm) * MM_PER_UM

    @property
    def angle_rad(self) -> float:
        """Largest angular error, rad."""
        defect_mm = SMALL_ANGLE_DEFECT_UM * MM_PER_UM
        return min(ANGLE_CAP_URAD * RAD_PER_URAD, math.sqrt(2.0 * defect_mm / max(self.size_mm, 1e-9)))

    def of(self, kind: str) -> float:
        """The limit of ``kind`` ("length": mm, "angle": rad)."""
        return self.length_mm if kind == "length" else self.angle_rad

    def rule(self, kind: str) -> str:
        """The limit of ``kind`` with its reason, for a message."""
        if kind == "length":
            return (f"{self.length_mm * UM_PER_MM:.0f} um = {TRANSLATION_BASE_UM:g} um + "
                    f"{TRANSLATION_PPM:g} ppm of {self.basis}")
        return (f"{self.angle_rad * URAD_PER_RAD:.0f} urad, where the small-angle model stops being "
                f"exact over {self.basis}")


def machine_size(machine) -> float | None:
    """The largest travel of the linear axes of ``machine`` (a :class:`volerr.Model` or a
    :class:`volerr.machine.layout.Layout`), mm; None without linear axes."""
    layout = getattr(machine, "layout", machine)
    spans = [float(ax.travel[1] - ax.travel[0]) for ax in layout.axes.values()
             if ax.kind == "linear"]
    return max(spans) if spans else None


def limits_for(machine=None, tables=None) -> Limits:
    """The limits of ``machine`` (Model or Layout, its travel), or without one, of the linear
    axes measured in ``tables`` (axis -> :class:`volerr.tables.ErrorTable`)."""
    if machine is not None:
        size = machine_size(machine)
        layout = getattr(machine, "layout", machine)
        if size is not None:
            return Limits(size, f"the {size:g} mm travel of {layout.name}")
    spans = [float(t.positions[-1] - t.positions[0]) for ax, t in (tables or {}).items()
             if ax not in ("A", "B", "C")]
    if spans:
        return Limits(max(spans), f"the {max(spans):g} mm the tables span")
    return Limits(DEFAULT_SIZE_MM, f"a {DEFAULT_SIZE_MM:g} mm machine")


def likely_units(peak: float, declared: str, kind: str, limit: float) -> list[str]:
    """Units in which ``peak`` (the largest magnitude, in the ``declared`` unit) is a plausible
    error: within the limit and at least a thousandth of it."""
    factor = dict(_CANDIDATES[kind]).get(declared, 1.0)
    return [u for u, f in _CANDIDATES[kind] if f < factor and limit * 1e-3 <= peak * f <= limit]


def _shown(value_internal: float, kind: str) -> str:
    return f"{value_internal * UM_PER_MM:.4g} um" if kind == "length" else \
        f"{value_internal * URAD_PER_RAD:.4g} urad"


def refusal(where: str, what: str, peak_internal: float, kind: str, limits: Limits,
            declared: str | None = None, cause: str = "", single: bool = False) -> InputError:
    """The one-line refusal of a value beyond the limits.

    ``where``: the file (and line); ``what``: the column or name; ``peak_internal``: the value
    of largest magnitude, mm or rad (signed); ``declared``: the unit the file gave it (then the
    likely unit is named), else ``cause``: the likely cause (e.g. of an identification);
    ``single``: one value (``name = value``, signed), not a column (its largest magnitude)."""
    if not single:
        peak_internal = abs(peak_internal)
    shown = _shown(peak_internal, kind)
    if declared:
        f = dict(_CANDIDATES[kind])[declared]
        peak = abs(peak_internal) / f
        head = (f"{what} = {peak_internal / f:.4g} {declared} ({shown}) is" if single else
                f"{what}: values up to {peak_internal / f:.4g} {declared} ({shown}) are")
        units = likely_units(peak, declared, kind, limits.of(kind))
        if units:
            fix = _FILE_UNITS[kind]
            other = [u for u in units if u != fix]
            how = f"give it in {fix}" + (f", converted if it is in {' or '.join(other)}"
                                         if other else "")
            cause = f"likely in {' or '.join(units)}, not {declared}: {how}"
        else:
            cause = (f"not a {'translational' if kind == 'length' else 'angular'} error in "
                     f"any usual unit (another quantity in this column?)")
    else:
        head = f"{what} = {shown} is" if single else f"{what}: values up to {shown} are"
        cause = cause or "an error in the wrong unit?"
    return InputError(f"{where}: {head} beyond what a machine of this size can have "
                      f"(limit {limits.rule(kind)}); {cause} ({OPTION} for a machine that "
                      f"really is that bad)")


def check(values, kind: str, limits: Limits, where: str, what: str,
          declared: str | None = None, cause: str = "") -> None:
    """Refuse (:func:`refusal`) when any of ``values`` (mm or rad) exceeds the limit."""
    v = np.asarray(values, dtype=float).ravel()
    if v.size and float(np.abs(v).max()) > limits.of(kind):
        peak = float(v[np.argmax(np.abs(v))])   # signed: as the file or table has it
        raise refusal(where, what, peak, kind, limits, declared, cause, single=v.size == 1)


def check_positions(axis: str, positions, machine, where: str) -> None:
    """Refuse table positions (``axis``'s, mm or deg, increasing) written in radians or inches
    (module docstring: :data:`POSITION_COVERAGE_MIN`, :data:`POSITION_COVERAGE_UNIT`) against
    the travel of ``axis`` in ``machine`` (Model or Layout); one-line :class:`InputError`
    naming ``where``, the column and the likely unit.  An axis the layout lacks: nothing."""
    layout = getattr(machine, "layout", machine)
    ax = getattr(layout, "axes", {}).get(axis)
    if ax is None or ax.kind not in POSITION_UNITS or len(positions) < 2:
        return
    t0, t1 = float(ax.travel[0]), float(ax.travel[1])
    travel = min(t1 - t0, 360.0) if ax.kind == "rotary" else t1 - t0
    lo, hi = float(positions[0]), float(positions[-1])
    if not (travel > 0 and 0 < hi - lo < POSITION_COVERAGE_MIN * travel):
        return
    unit, factor, given = POSITION_UNITS[ax.kind]
    lo2, hi2 = lo * factor, hi * factor
    slack = 0.05 * travel                 # a table may reach a little past the nominal travel
    if not (t0 - slack <= lo2 and hi2 <= t1 + slack
            and hi2 - lo2 >= POSITION_COVERAGE_UNIT * travel):
        return
    raise InputError(f"{where}: column {axis}: positions {lo:g} .. {hi:g} {given} cover "
                     f"{(hi - lo) / travel:.1%} of the {t0:g} .. {t1:g} {given} travel of "
                     f"{layout.name}; read as {unit} (x {factor:.4g}: {lo2:.4g} .. {hi2:.4g} "
                     f"{given}) they cover it: likely {unit}, not {given}; give {given} "
                     f"({OPTION} for a table that really covers this little)")
