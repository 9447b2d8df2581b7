"""Audit of result numbers (numpy only, no file I/O): the compensated NC data of Ellingsdalen
(2021) Figure 3.11 (reproduced from Listing 3.4's model), the result values of ch. 4 and of the
project report that their plots carry (consistency only: the data are not in the text), and
the parameter counts and band / repeatability pairs of Pahk (1995) sec. 4.

The printed material is the parsed ``data/printed_results.toml``.  A printed value with
k decimals (or k significant digits, as numpy prints) stands for its rounding interval.

* Figure 3.11: Listing 3.4 compensates by ``NC + (T(X) - T_e(X)) [0 0 0 1]``; on a pure X move
  (Y = Z = 0) the squareness terms vanish and the Y and Z curves read at 0 give 0 (the model
  arrays drop their constant, see the Listing 3.1 + 3.4 verdict), so the compensated row is
  (X - E_XX(X), -E_YX(X), -E_ZX(X), 1) in mm: the printed X column gives E_XX(X).
* a number that no printed input reproduces is ``undecidable``; its evidence lists the
  consistency checks against the other printed material and what is missing.
* Pahk's band (range of the averaged curve over the positions) and repeatability R (largest
  2 sigma of single readings): averaging n runs leaves noise of sigma / sqrt(n) in the curve,
  whose range over m positions exceeds q05(m) sigma / sqrt(n) in 95 % of cases (q05: the 5 %
  quantile of the range of m normal values, simulated here; 1.86 for m = 10); a band below
  that needs at least n runs.  Neither the number of runs nor that of the positions is
  printed: m is taken from a 100 mm and a 50 mm pitch over the travel, and a pair consistent
  with the two runs the text implies ("repeated measurements") is identical.
"""

from __future__ import annotations

import math

import numpy as np

from .framework import Verdict
from .numbers import interval

DATA_FILE = "printed_results.toml"
LAYOUT = "-"




def _v(source, eq, comp, category, erratum, evidence, printed, derived, tried=(), used=(),
       verdict="differs", **f) -> Verdict:
    same = category == "identical"
    return Verdict(source, eq, LAYOUT, "identical" if same else verdict,
                   "" if same else erratum, evidence, printed, derived, comp,
                   category=category, readings_tried=list(tried), readings_used=list(used), **f)


# -------------------------------------------------------------------------- Figure 3.11
def audit_nc(item: dict) -> list[Verdict]:
    src, eq = item["source"], item["id"]
    xs = [float(x) for x in item["ideal_x"]]
    rows = [(x, r) for x, r in zip(xs, item["comp"]) if r[0]]
    exx = []                                             # implied E_XX (um) with its interval
    for x, r in rows:
        lo, hi = interval(r[0])
        exx.append((x, (x - hi) * 1e3, (x - lo) * 1e3, (x - float(r[0])) * 1e3))
    positive = all(lo > 0 for _, lo, _, _ in exx)
    x_pk, pk_lo, pk_hi, pk = max(exx, key=lambda t: t[3])
    quotes = item["peak_quotes"]
    meets = {q["value"]: interval(q["value"])[0] <= pk_hi and pk_lo <= interval(q["value"])[1]
             for q in quotes}
    ys = [abs(float(r[1])) * 1e3 for _, r in rows]
    zs = [abs(float(r[2])) * 1e3 for _, r in rows]
    out = []
    ok = positive and all(meets.values())
    listing = ", ".join(f"{x:g}: {v:.1f}" for x, _, _, v in exx)
    out.append(_v(src, eq, "X column", "identical" if ok else "printing_error",
                  "implied E_XX inconsistent with the quoted peak",
                  "Listing 3.4 on the NC data of pure X moves (Y = Z = 0) gives the row (X - "
                  "E_XX(X), -E_YX(X), -E_ZX(X), 1) mm (the squareness terms multiply Y and Z, "
                  "and the Y and Z curves read at 0 give 0: the model arrays drop their "
                  f"constant); the printed X column therefore implies E_XX (um) = {listing}: "
                  f"{'positive everywhere' if positive else 'not positive everywhere'}, rising "
                  f"to a peak of {pk:.1f} um (printed digits: {pk_lo:.2f} .. {pk_hi:.2f}) at "
                  f"{x_pk:g} mm; the peak quoted for the measured E_XX, "
                  + ", ".join(f"{q['value']} um ({q['where']})" for q in quotes)
                  + f", {'meets' if all(meets.values()) else 'does not meet'} that interval "
                  "(the compensated curve is the degree-4 fit of the averaged data, whose peak "
                  "may differ from the data's by the fit residual)", item["text"],
                  f"E_XX implied: {listing}",
                  [f"row = X - E_XX(X) with E_XX from the printed X column: {listing}",
                   f"peak {pk:.1f} um against the quoted " + ", ".join(q["value"] for q in quotes)
                   + " um: " + ("consistent" if all(meets.values()) else "inconsistent")]))
    out.append(_v(src, eq, "Y and Z columns", "identical", "",
                  f"the Y and Z columns are -E_YX(X) and -E_ZX(X) of the fitted curves after "
                  f"Listing 3.1 removed their reference lines: at most {max(ys):.2f} um and "
                  f"{max(zs):.2f} um, the size of the residual straightness (sec. 4.1.1: E_YX "
                  f"and E_ZX 'much lower' than E_XX); the squareness terms Y * S_YX, -Z * S_ZX, "
                  f"-Z * S_ZY of Listing 3.4 are zero on these X moves", item["text"],
                  "(-E_YX, -E_ZX) of the fitted residual curves"))
    out.append(_v(src, eq, "homogeneous column", "undecidable", "the right array lacks the "
                  "homogeneous 1 (and row 0)",
                  "Listing 3.4 sets NC_data_comp[0] = [0., 0., 0., 1] and adds the compensation "
                  "(deviation with the homogeneous 0) to rows holding 1, so every row of the "
                  "right array ends in 1, as the caption says ('Both arrays are expressed in "
                  "homogeneous coordinates'); the printed right array has that column and row 0 "
                  f"blank ({item['comp_columns']}). The left array shows its 1s but also leaves "
                  "its zeros blank except one '0' in row 10: a table whose cells the "
                  "extraction drops. Category undecidable: lost cells of a table, which the "
                  "print (a cropped screenshot) and the extraction explain equally; what "
                  "would decide: the figure itself", item["comp_columns"],
                  "column 3 = 1 in every row, row 0 = [0, 0, 0, 1]",
                  ["the array as printed: no homogeneous column",
                   "cells lost by the print or by the extraction: the code's output"],
                  ["glyph:Figure 3.11 right array column 3"]))
    return out


def audit_eyx(item: dict, nc: dict | None) -> list[Verdict]:
    src, eq = item["source"], item["id"]
    out = [_v(src, eq, "values", "undecidable", f"{item['before']} -> {item['after']} um: "
              "not checkable (the plotted data are not printed)", f"the peaks "
              f"{item['before']} um (before) and {item['after']} um (after) of E_YX are read "
              "from the plots of Figures 4.1 and 4.11, which the text does not carry; nothing "
              "printed gives either value or contradicts it (no discrepancy is shown: the "
              "verdict 'unchecked' says only that the values could not be compared): the values "
              "as read from the plots, or ones misread from them or misprinted -- nothing "
              "printed tells them apart. Category "
              "undecidable; missing: the E_YX data before and after compensation",
              item["text"], f"{item['before']} -> {item['after']} um",
              ["no printed input reproduces or contradicts the values"], [f"missing:{eq} data"],
              verdict="unchecked")]
    if nc is not None:
        ys = [abs(float(r[1])) * 1e3 for r in nc["comp"] if r[1]]
        out.append(_v(src, eq, "attribution", "printing_error",
                      "reduction attributed to the squareness compensation, which does not act "
                      "on X moves",
                      f"the text attributes the reduction of E_YX ({item['before']} -> "
                      f"{item['after']} um, {float(item['before']) - float(item['after']):.1f} "
                      f"um) to the squareness compensation. But the compensated NC data of the "
                      f"X axis (Figure 3.11) move Y by at most {max(ys):.2f} um along the whole "
                      f"travel: Listing 3.4 puts the squareness into T_e_Y and T_e_Z only, as "
                      f"Y * S_YX and -Z * S_ZY, which vanish on X moves (Y = Z = 0), with X the "
                      f"datum axis (sec. 3.3.2). A {float(item['before']) - float(item['after']):.1f}"
                      f" um reduction cannot come from that compensation; the text itself names "
                      f"the cause that fits: the re-measured motion was aligned anew 'to the "
                      f"compensated motion of the X- and Z-axis' (sec. 5.1.2), which removes the "
                      f"slope of E_YX by construction. Category printing_error: the printed "
                      f"statement contradicts the printed code and data (no reading reconciles "
                      f"them; not extraction damage)", item["text"],
                      f"Y compensation along X <= {max(ys):.2f} um (Figure 3.11)",
                      [f"the squareness compensation on X moves: Y * S_YX = 0 at Y = 0, Y column "
                       f"of Figure 3.11 <= {max(ys):.2f} um", "the new frame alignment of sec. "
                       "5.1.2: removes the slope, fits the reduction"],
                      [f"inconsistent:{eq} attribution"]))
    return out


def audit_unreproducible(item: dict) -> Verdict:
    return _v(item["source"], item["id"], "", "undecidable",
              f"{item['value']} {item['unit']}: not checkable (its data are not printed); no "
              f"inconsistency found",
              f"{item['quantity']}: no printed input reproduces it. Consistency with the rest "
              f"of the text: " + "; ".join(item["consistent"]) + f". No discrepancy is shown "
              f"(the verdict 'unchecked' says only that the value could not be compared): the "
              f"value as read from the plot, or one misread from it or misprinted -- nothing "
              f"printed tells them apart. "
              f"Category undecidable; missing: {item['missing']}", item["text"],
              f"{item['value']} {item['unit']}",
              [f"checked: {c}" for c in item["consistent"]],
              [f"missing:{item['id']} data"], verdict="unchecked")


def audit_count(item: dict) -> Verdict:
    total = sum(int(p) for p in item["parts"])
    ok = total == int(item["total"])
    return _v(item["source"], item["id"], "count", "identical" if ok else "printing_error",
              f"{item['total']} printed, the parts add to {total}",
              " + ".join(f"{p} {n}" for p, n in zip(item["parts"], item["names"]))
              + f" = {total} (printed {item['total']})", item["text"], str(total))


_Q05: dict = {}

#: the number of measuring positions along the travel is not printed: from a 100 mm to a 50 mm
#: pitch of a laser calibration (10 to 19 positions over CMM A's 900 mm X travel)
PITCHES_MM = (100, 50)


def positions(travel_mm: float) -> tuple[int, int]:
    return tuple(int(travel_mm // p) + 1 for p in PITCHES_MM)


def _range_q05(m: int = 10) -> float:
    """5 % quantile of the range of m standard normal values (simulated, seeded)."""
    if m not in _Q05:
        rng = np.random.default_rng(1995 + m)
        x = rng.standard_normal((40000, m))
        _Q05[m] = float(np.quantile(x.max(axis=1) - x.min(axis=1), 0.05))
    return _Q05[m]


def _n_min(band: float, sigma: float, m: int) -> int:
    return max(1, math.ceil((_range_q05(m) * sigma / band) ** 2))


def audit_band(item: dict, others: list | None = None) -> Verdict:
    """Band (range of the averaged curve) against repeatability (largest 2 sigma of single
    readings): averaging n runs leaves noise sigma / sqrt(n) in the curve; its range over m
    positions exceeds q05(m) sigma / sqrt(n) in 95 % of cases.  ``others``: the other band
    items of the same document (for the pattern)."""
    band, rep = float(item["band"]), float(item["repeatability"])
    sigma = rep / 2
    u = item["unit"]
    pos = positions(float(item["travel_mm"]))
    ns = {m: _n_min(band, sigma, m) for m in pos}
    lo, hi = ns[pos[0]], ns[pos[-1]]
    ev = (f"band {band:g} {u} (range of the averaged curve), repeatability {rep:g} {u} (the "
          f"largest 2 sigma of single readings over the positions, sec. 4); if every position "
          f"scattered as much as the worst one (sigma = {sigma:g} {u}), averaging n runs would "
          f"leave noise sigma / sqrt(n) in the curve, whose range over m positions exceeds "
          + ", ".join(f"{_range_q05(m):.2f} sigma / sqrt(n) for m = {m}" for m in pos)
          + f" in 95 % of cases (the number of positions is not printed: {pos[0]} to "
          f"{pos[-1]} at the 100 or 50 mm pitch of a laser calibration over the "
          f"{item['travel_mm']:g} mm travel)")
    need = f"{lo}" if lo == hi else f"{lo} to {hi}"
    if hi == 1:
        return _v(item["source"], item["id"], "", "identical", "", ev + ": the band is "
                  "consistent with any number of runs", item["text"],
                  f"band >= {_range_q05(pos[-1]) * sigma:.3g} {u} for n = 1")
    if hi <= 2:
        return _v(item["source"], item["id"], "", "identical", "", ev + f": the band is "
                  f"consistent with {need} averaged runs, and the text says the repeatability "
                  f"comes from repeated measurements ('반복측정을 수행하여', n >= 2); assumed: "
                  f"the plotted curve is the mean of those runs (the text does not say; a "
                  f"single plotted run would need the band above "
                  f"{_range_q05(pos[0]) * sigma:.3g} .. "
                  f"{_range_q05(pos[-1]) * sigma:.3g} {u})", item["text"],
                  f"n >= {need} runs")
    pattern = [o for o in (others or []) if o["id"] != item["id"]
               and o["source"] == item["source"] and o["id"].split(":")[0][:-3] ==
               item["id"].split(":")[0][:-3]]
    pat = ("; ".join(f"{o['id'].split(': ')[0].split(' ', 2)[-1]} band {o['band']}, "
                     f"repeatability {o['repeatability']} {o['unit']}" for o in pattern))
    ev += (f": the band is consistent with at least {lo} averaged runs for {pos[0]} "
           f"positions and {hi} for {pos[-1]} (assumed: the plotted curve is the mean of the runs; fewer runs would leave the averaged curve's own noise above the "
           f"printed band in 95 % of cases; a smaller scatter at the other positions would "
           f"allow fewer). The text says the repeatability comes from repeated measurements "
           f"('반복측정을 수행하여', n >= 2) but gives neither the number of runs (ISO 230-2's "
           f"standard test has 5 per direction) nor the number of positions. Explanations: "
           f"(1) no defect -- a band below the single-reading 2 sigma is what averaging "
           f"{need} or more runs gives"
           + (f", and the same figure group shows repeatabilities of the size of the band ("
              f"{pat}), a pattern of these measurements rather than a one-off misprint"
              if pattern else "")
           + "; (2) a misprinted band or repeatability (a digit lost or exchanged), which "
             "nothing printed supports or excludes. Category undecidable; missing: the number "
             "of runs and of positions (the plots of Figure 4 are not in the text)")
    return _v(item["source"], item["id"], "", "undecidable",
              f"repeatability {rep:g} {u} above the band {band:g} {u}: consistent only with "
              f"{need} or more averaged runs (not printed)", ev, item["text"],
              f"n >= {need} runs",
              [f"n runs averaged over {pos[0]} positions: consistent for n >= {lo}",
               f"n runs averaged over {pos[-1]} positions: consistent for n >= {hi}",
               "a single run: the band would be below the noise range",
               "a misprinted band or repeatability: not decidable from the text"],
              [f"missing:{item['id']} number of runs"])


def audit(printed: dict, layouts=None) -> list[Verdict]:
    """Verdicts on the result numbers (layout-independent: skipped for named layouts)."""
    if layouts:
        return []
    out = []
    nc = printed.get("nc_data")
    if nc:
        out.extend(audit_nc(nc))
    if "eyx" in printed:
        out.extend(audit_eyx(printed["eyx"], nc))
    out.extend(audit_unreproducible(u) for u in printed.get("unreproducible", []))
    out.extend(audit_count(c) for c in printed.get("count", []))
    bands = printed.get("band", [])
    out.extend(audit_band(b, bands) for b in bands)
    return out
