"""A diagnosis of ballbar traces in ISO 230-1 parameters, from the layout's observation model.

Not a table of hand rules: the traces are fitted (:func:`volerr.calibrate.calibrate`) with the
parameters a circle in a plane of two linear axes ``a``, ``b`` can show, and each is reported
with its standard uncertainty only where the traces determine it:

* the squareness of the plane (``EC0Y`` for XY, ``EB0Z`` for ZX, ``EA0Z`` for YZ);
* the scale errors (slope of the positioning errors ``Eaa``, ``Ebb``); with the bar length
  unknown (no ``length_u_um``) only their difference (scale mismatch) is determined;
* the curvature of the straightness errors ``Eba``, ``Eab`` (Legendre P2 coefficient, um);
* the reversal value of each axis (``RV_a`` = mean error approaching in the positive direction
  minus in the negative direction, ISO 230-2's B), from the axes' directions of motion, when
  both directions were run;
* for a rotary sweep: the location errors of the swept axis.

Angular errors of the axes act on a trace through the tool-ball offset (Abbe arm); they are
not separable from the positioning and straightness errors in one plane and are not reported.
"""

from __future__ import annotations

import numpy as np

from ..calibrate.budget import combination_budget
from ..calibrate.run import fit_campaign
from ..errors import require
from ..machine.iso_names import along_component

SQUARENESS_OF_PLANE = {"XY": "EC0Y", "ZX": "EB0Z", "YZ": "EA0Z"}


def _axis_along(model, k: int) -> str | None:
    for a in model.axes:
        if a in model.rotary_axes:
            continue
        if int(np.argmax(np.abs(model.layout.axes[a].direction))) == k:
            return a
    return None


def diagnose(model, obs, planes: list, swept: list = ()) -> list:
    """``[{"parameter", "value", "unit", "std"}]`` of the traces ``obs`` (stacked ballbar
    files) in ``planes`` (XY, YZ, ZX) with rotary axes ``swept``."""
    return diagnose_with_note(model, obs, planes, swept)[0]


def diagnose_with_note(model, obs, planes: list, swept: list = ()) -> tuple[list, str | None]:
    """:func:`diagnose` and, for a rotary sweep that determines none of its axis' location
    errors, the sentence saying why (:func:`why_not`; None otherwise)."""
    return diagnose_fit(model, obs, planes, swept)[:2]


def diagnose_fit(model, obs, planes: list, swept: list = ()) -> tuple:
    """:func:`diagnose_with_note` and the diagnosis fit's residual against the readings'
    declared uncertainty (:class:`volerr.fit_quality.FitQuality`, the calibration's)."""
    params, extra, report = [], [], []
    for plane in planes:
        i, j = {"XY": (0, 1), "YZ": (1, 2), "ZX": (2, 0)}[plane]
        a, b = _axis_along(model, i), _axis_along(model, j)
        require(a and b, f"{model.name}: no linear axes along the plane {plane}")
        sq = SQUARENESS_OF_PLANE[plane]
        if sq in model.parameters:
            params.append(sq)
        ea, eb = along_component(model.layout, a), along_component(model.layout, b)
        sab = "E" + "XYZ"[j] + a
        sba = "E" + "XYZ"[i] + b
        params += [p for p in (ea, eb, sab, sba) if p in model.parameters]
        for ax, comp in ((a, ea), (b, eb)):
            d = obs.covariates.get(f"dir_{ax}")
            if d is not None and len(np.unique(d)) == 2 and comp in model.parameters \
                    and not any(e[0] == f"RV_{ax}" for e in extra):
                extra.append((f"RV_{ax}", comp, f"dir_{ax}/2", (1e3, "um")))
        report.append((plane, a, b, sq, ea, eb, sab, sba))
    for r in swept:
        params += [p for p in model.parameters if model.parameter_axis.get(p) is None
                   and p[-1] == r and p[2] == "0"]
    require(params, "nothing to diagnose in these traces")
    cal = fit_campaign(model, obs, parameters=",".join(dict.fromkeys(params)), degree=2,
                       extra_terms=extra, plan=False, progress=False)
    entries = _entries(cal, report, swept, extra)
    for e in entries:   # the estimator's budget where the entry is one of its parameters
        b = (cal.data.get("budgets") or {}).get(e["parameter"])
        if b is not None and abs(b["u"] - e["std"]) <= 1e-9 * max(e["std"], 1e-300):
            e["budget"] = b
        elif "weights" in e:     # a combination: its budget from the same per-file terms
            b = combination_budget(cal, e["weights"], e["parameter"], e["factor"], e["unit"])
            if b is not None:
                e["budget"] = b
    for e in entries:
        e.pop("weights", None)
        e.pop("factor", None)
    return entries, why_not(cal, swept, entries), cal.quality


def why_not(cal, swept: list, entries: list) -> str | None:
    """One sentence: why a rotary sweep determines none of its axis' location errors (None
    when it determines some, or no axis swept): what they act like on these readings (the
    combinations the traces do determine, or the set-up unknowns -- pivot position, bar
    length), and what would separate them."""
    if not swept:
        return None
    model = cal.model
    names = [p for r in swept for p in model.parameters
             if model.parameter_axis.get(p) is None and p[-1] == r and p[2] == "0"]
    if any(e["parameter"] in names for e in entries):
        return None
    ident = cal.data["identifiability"]
    setup_only = [n for n in names if ident.get(n, {}).get("confounded_with")
                  and all(c.startswith("setup:") for c in ident[n]["confounded_with"])]
    combos = [f"{c['expression']} = {c['value']:.4g} +- {c['std']:.2g} {c['unit']}"
              for c in cal.data["combinations"]
              if any(n in c["expression"] for n in names)]
    parts = [f"the sweep of {', '.join(swept)} determines none of "
             f"{', '.join(names)} on its own"]
    if combos:
        parts.append(f"it determines only the combinations {'; '.join(combos)}")
    if setup_only:
        parts.append(f"{', '.join(setup_only)} act on the bar length exactly as the set-up "
                     f"does (the pivot's position, the bar's length)")
    parts.append("sweeps with the bar in other directions (radial, tangential, axial) and "
                 "the pivot at other heights separate them (ISO 10791-6)")
    return "; ".join(parts) + "."



def _entry(name, value_std, factor, unit, weights=None) -> dict:
    """The JSON entry; ``weights`` (of a combination) and ``factor`` kept for its budget
    until :func:`diagnose_fit` drops them."""
    v, s = value_std
    return {"parameter": name, "value": v * factor, "unit": unit, "std": s * abs(factor),
            **({"weights": weights, "factor": factor} if weights else {})}


def _entries(cal, report, swept, extra) -> list:
    out = []
    ranges = cal.ranges
    for plane, a, b, sq, ea, eb, sab, sba in report:
        if sq in cal.model.parameters:
            w = {(sq, None): 1.0}
            r = cal.combination(w)
            if r:
                out.append(_entry(sq, r, 1e6, "urad", w))
        slopes = {}
        for ax, comp in ((a, ea), (b, eb)):
            lo, hi = ranges[ax]
            slopes[comp] = 2.0 / (hi - lo)
            w = {(comp, 1): slopes[comp]}
            r = cal.combination(w)
            if r:
                out.append(_entry(f"{comp}@slope", r, 1e3, "um/mm", w))
        if not any(e["parameter"] in (f"{ea}@slope", f"{eb}@slope") for e in out):
            w = {(ea, 1): slopes[ea], (eb, 1): -slopes[eb]}
            r = cal.combination(w)
            if r:
                out.append(_entry(f"{ea}@slope-{eb}@slope", r, 1e3, "um/mm", w))
        for comp in (sab, sba):
            w = {(comp, 2): 1.0}
            r = cal.combination(w)
            if r:
                out.append(_entry(f"{comp}@P2", r, 1e3, "um", w))
    for name, *_ in extra:
        w = {(name, "extra"): 1.0}
        r = cal.combination(w)
        if r and not any(e["parameter"] == name for e in out):
            out.append(_entry(name, r, 1e3, "um", w))
    for r_axis in swept:
        for p in cal.model.parameters:
            if cal.model.parameter_axis.get(p) is None and p[-1] == r_axis and p[2] == "0":
                w = {(p, None): 1.0}
                r = cal.combination(w)
                if r:
                    f, u = (1e6, "urad") if p[1] in "ABC" else (1e3, "um")
                    out.append(_entry(p, r, f, u, w))
    return out
