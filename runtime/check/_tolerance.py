"""``--tolerance``: does the machine still meet its tolerances after the check?  ISO 14253-1
decision rule, as the certificates (:mod:`volerr.conformance`): each quantity against its
limit with the expanded uncertainty ``U = 2 u`` (k = 2) from the covariance after the check.

Grammar: ``NAME=VALUE UNIT`` pairs separated by ``,`` ``;`` or ``|`` (the reading of every
``--tolerance``, :func:`volerr.units.parse_assignments`; ``22 um`` or ``22um``), ``NAME`` as
written or in any case when that names one (:func:`volerr.units.match_name`): a parameter of
the reference (its ``|value|`` against ``VALUE UNIT``: the unit is required and must be of
its kind, it is converted, :func:`volerr.units.parse_quantity`; a limit beyond
:mod:`volerr.tables.plausible` is refused, and a length limit below any machine's tolerance,
:func:`volerr.units.check_tolerance_um`) or ``map`` (the largest length of the volumetric
error over the working volume, um).  Example:
``"EX0C=20 um,EA0B=40 urad,map=30 um"``.
"""

from __future__ import annotations

import math

from .. import conformance
from ..errors import InputError, require
from ..units import (QUANTITY_UNITS, check_tolerance_um, convert, match_name,
                     parse_assignments)
from . import _volume


def parse(text: str, ref, model=None) -> dict:
    """``{NAME: limit}`` (the parameter's unit; ``map``: um); one-line InputError.

    The pairs as every ``--tolerance`` is read (:func:`volerr.units.parse_assignments`: split
    at ``,`` ``;`` ``|``, ``22 um`` or ``22um``); a name as written or in any case when that
    names one (:func:`volerr.units.match_name`: ``ex0c`` is ``EX0C``, ``MAP`` is ``map``).
    Every VALUE needs its unit (issue 43: ``EX0C=22`` is refused, as ``history show`` does).
    A limit beyond what any machine of ``model``'s size can have
    (:mod:`volerr.tables.plausible`: ``EX0C=22 mm``, um typed as mm) is refused naming the
    likely unit."""
    from ..tables import plausible

    limits = plausible.limits_for(model)
    units = {**dict(zip(ref.names, ref.units)), "map": "um"}
    out = {}
    pairs = parse_assignments(
        text, "--tolerance", "EX0C=20 um,EA0B=40 urad,map=30 um",
        keywords_for=lambda name: {"any_unit": given_unit_any(units[_key(name, ref)])},
        positive=False)
    for name, (v, given) in pairs:
        key = _key(name, ref)
        part = f"{name}={v:g}" + (f" {given}" if given else "")
        v = convert(v, given, units[key], f"--tolerance {name}")
        _plausible(v, units[key], given, part, limits)
        if QUANTITY_UNITS.get(units[key], (None,))[0] == "length":
            check_tolerance_um(convert(v, units[key], "um"), f"--tolerance {part}", given,
                               name, ceiling=False)
        require(math.isfinite(v) and v > 0, f"--tolerance: {name} = {part.partition('=')[2]!r} "
                                            f"must be a positive number")
        require(key not in out, f"--tolerance: {name} given twice")
        out[key] = v
    return out


def _key(name: str, ref) -> str:
    """``map`` or the reference's parameter ``name`` names (:func:`volerr.units.match_name`);
    else one line naming the first known ones."""
    key = match_name(name, ["map", *ref.names], "--tolerance")
    require(key is not None, f"--tolerance: {name!r} is neither 'map' nor a parameter of the "
                             f"reference ({', '.join(ref.names[:8])} ...)")
    return key


def given_unit_any(unit: str) -> bool:
    """A parameter unit outside :data:`volerr.units.QUANTITY_UNITS` (a slope, ``um/mm``) is
    given as written."""
    return unit not in QUANTITY_UNITS


def _plausible(v: float, unit: str, given: str, part: str, limits) -> None:
    """Refuse a limit beyond the magnitude rule (:mod:`volerr.tables.plausible`)."""
    kind = QUANTITY_UNITS.get(unit, (None,))[0]
    if kind is None:
        return
    internal = convert(v, unit, "mm" if kind == "length" else "rad")
    if internal > limits.of(kind):
        small = "um" if kind == "length" else "urad"
        raise InputError(f"--tolerance {part}: {kind} limit {v:g} {unit} is beyond what any "
                         f"machine of this size can have ({limits.rule(kind)}); likely meant "
                         f"in {small}, not {given}")


def decide(limits: dict, result) -> dict:
    """``{"rule", "verdict", "items": [{"quantity", "value", "unit", "U", "limit",
    "verdict"}]}`` of the values after the check."""
    ref = result.reference
    values, cov = result.after()
    items = []
    for key, limit in limits.items():
        if key == "map":
            v, u = _volume.map_max(result.J, values, cov)
            unit = "um"
        else:
            j = ref.names.index(key)
            v, u, unit = abs(float(values[j])), math.sqrt(max(cov[j, j], 0.0)), ref.units[j]
        U = 2.0 * u
        items.append({"quantity": key, "value": round(v, 6), "unit": unit, "U": round(U, 6),
                      "limit": limit, "verdict": conformance.verdict(v, limit, U)})
    return {"rule": conformance.RULE, "verdict": conformance.overall(i["verdict"] for i in items),
            "items": items}
