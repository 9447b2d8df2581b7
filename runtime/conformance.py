"""Decisions on conformance with a tolerance, ISO 14253-1 (default rule: guard bands of U).

ISO 14253-1:2017 ("Decision rules for verifying conformity or nonconformity with
specifications"), the rule for a supplier proving conformance and a customer proving
nonconformance with the same measurement: the *conformance zone* is the specification zone
reduced on each specified side by the expanded uncertainty U (k = 2); the *nonconformance
zone* lies outside the specification zone widened by U.

* ``pass``: the measured value lies in the conformance zone (value <= T - U for an upper
  limit T), conformance is proven;
* ``fail``: it lies in the nonconformance zone (value > T + U), nonconformance is proven;
* ``undecided``: in between (the uncertainty range straddles the limit): neither is proven.

Every volerr verdict comes from :func:`verdict`; a set of verdicts from :func:`overall` (any
fail -> fail, else any undecided -> undecided, else pass).  Values and U in one unit.
"""

from __future__ import annotations

import math

from .errors import InputError, require

PASS, FAIL, UNDECIDED = "pass", "fail", "undecided"
#: the decision rule as stated on every certificate
RULE = ("ISO 14253-1: pass when the measured value lies inside the tolerance reduced by the "
        "expanded uncertainty U (k = 2); fail when it lies outside the tolerance widened by U; "
        "undecided in between")


def verdict(value: float, upper: float, U: float, lower: float | None = None) -> str:
    """ISO 14253-1 verdict of ``value`` against the limits ``upper`` (and ``lower``) with the
    expanded uncertainty ``U`` >= 0 (module docstring)."""
    require(U >= 0 and math.isfinite(U), f"expanded uncertainty must be >= 0, got {U}")
    if value > upper + U or (lower is not None and value < lower - U):
        return FAIL
    if value <= upper - U and (lower is None or value >= lower + U):
        return PASS
    return UNDECIDED


def overall(verdicts) -> str | None:
    """One verdict from several: any fail -> fail, else any undecided -> undecided, else pass
    (None when there is none)."""
    v = list(verdicts)
    if not v:
        return None
    if FAIL in v:
        return FAIL
    return UNDECIDED if UNDECIDED in v else PASS


def parse_tolerances(text: str, names, option: str = "--tolerance") -> dict:
    """``"A=10,E=8 um,R=0.004 mm"`` -> ``{"A": 10.0, "E": 8.0, "R": 4.0}`` (um): the pairs
    as every ``--tolerance`` is read (:func:`volerr.units.parse_assignments`: split at ``,``
    ``;`` ``|``, ``NAME=VALUE UNIT``, ``5um`` or ``5 um``), names from ``names`` (as written, or
    in any case when that names one, :func:`volerr.units.match_name`; an optional ``_um``
    suffix), each at most once, values positive finite lengths; a bare
    number is um (every quantity here is a length reported in um)."""
    from .units import check_tolerance_um, convert, match_name, parse_assignments

    names = list(names)
    example = ",".join(f"{n}=10 um" for n in list(names)[:3])
    out = {}
    for name, (v, unit) in parse_assignments(text, option, example, default_unit="um",
                                             kinds=("length",), positive=False):
        bare = name[:-3] if name.upper().endswith("_UM") else name
        key = match_name(bare, names, option)
        require(key is not None, f"{option}: unknown quantity {bare.upper()!r}; one of "
                                 f"{' '.join(names)}")
        require(key not in out, f"{option}: {key} given twice")
        given = f"{option} {key}={v:g}" + ("" if unit == "um" else f" {unit}")
        v = convert(v, unit, "um")
        check_tolerance_um(v, given, unit, key)
        require(math.isfinite(v) and 0 < v <= 1e6,
                f"{given}: a tolerance must be a positive number of um (at most 1e6)")
        out[key] = v
    return out
