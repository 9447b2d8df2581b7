"""``--tolerance``: does the machine still meet its tolerances after the check?  ISO 14253-1
decision rule, as the certificates (:mod:`volerr.conformance`): each quantity against its
limit with the expanded uncertainty ``U = 2 u`` (k = 2) from the covariance after the check.

Grammar: ``NAME=VALUE [UNIT],...`` with ``NAME`` a parameter of the reference (its ``|value|``
against ``VALUE`` in the parameter's unit; a unit given must be of its kind and is converted,
:func:`volerr.units.parse_quantity`) or ``map`` (the largest
length of the volumetric error over the working volume, um).  Example:
``"EX0C=20 um,EA0B=40 urad,map=30 um"``.
"""

from __future__ import annotations

import math

from .. import conformance
from ..errors import require
from ..units import convert, parse_quantity
from . import _volume


def parse(text: str, ref) -> dict:
    """``{NAME: limit}`` (the parameter's unit; ``map``: um); one-line InputError."""
    units = dict(zip(ref.names, ref.units))
    out = {}
    parts = [p.strip() for p in str(text).replace("|", ",").split(",") if p.strip()]
    require(parts, "--tolerance: no tolerance given")
    for part in parts:
        name, eq, rest = part.partition("=")
        name = name.strip()
        require(eq and name and rest.strip(),
                f"--tolerance {text!r}: write NAME=VALUE [UNIT] pairs, e.g. \"map=30 um\"")
        key = "map" if name.lower() == "map" else name
        require(key == "map" or key in units, f"--tolerance: {name!r} is neither 'map' nor a "
                                              f"parameter of the reference "
                                              f"({', '.join(ref.names[:8])} ...)")
        unit = "um" if key == "map" else units[key]
        # a bare number is in the parameter's unit (documented); a unit given is converted
        v, given = parse_quantity(rest, f"--tolerance {part}", default_unit=unit,
                                  positive=False)
        v = convert(v, given, unit, f"--tolerance {name}")
        require(math.isfinite(v) and v > 0, f"--tolerance: {name} = {rest.strip()!r} must be "
                                            f"a positive number")
        require(key not in out, f"--tolerance: {name} given twice")
        out[key] = v
    return out


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
