"""Arithmetic consistency of printed numbers in both seed documents (no file I/O).

The printed numbers come as the parsed ``data/printed_numbers.toml`` (values kept with
their printed digits).  A printed value ``v`` with ``k`` decimals stands for the interval
``v +- 0.5 * 10^-k`` (its rounding interval); two quotes of one quantity agree when their
intervals meet; a derived quantity (a percentage, a count) agrees when the printed value's
interval meets the interval the printed inputs give.  A value printed "approximately" has no
interval: a check that needs one is ``undecidable`` and says which value is missing.
"""

from __future__ import annotations

import math
from decimal import Decimal

import sympy as sp

from .framework import Verdict

DATA_FILE = "printed_numbers.toml"
LAYOUT = "-"


def interval(text: str) -> tuple[float, float]:
    """Rounding interval of a printed number (``"20.6"`` -> (20.55, 20.65))."""
    d = Decimal(text)
    half = Decimal(5) * Decimal(10) ** (d.as_tuple().exponent - 1)
    return float(d - half), float(d + half)


def _v(c, comp, category, erratum, evidence, printed, derived) -> Verdict:
    same = category == "identical"
    return Verdict(c["source"], c["id"], LAYOUT, "identical" if same else "differs",
                   "" if same else erratum, evidence, printed, derived, comp, category=category)


def check_reduction(c) -> list[Verdict]:
    p_lo, p_hi = interval(c["percent"])
    b_lo, b_hi = interval(c["before"])
    b, a = float(c["before"]), float(c["after"])
    exact = 100 * (1 - a / b)
    quote = c["quote"]
    if not c.get("after_approx"):
        a_lo, a_hi = interval(c["after"])
        lo, hi = 100 * (1 - a_hi / b_lo), 100 * (1 - a_lo / b_hi)
        ok = lo <= p_hi and p_lo <= hi
        ev = (f"(before - after) / before = ({c['before']} - {c['after']}) / {c['before']} = "
              f"{exact:.2f} %; with the rounding intervals of the printed values "
              f"{lo:.2f} .. {hi:.2f} %, the printed {c['percent']} % stands for "
              f"{p_lo:g} .. {p_hi:g} %: " + ("consistent" if ok else "inconsistent"))
        return [_v(c, "percent", "identical" if ok else "printing_error",
                   f"{c['percent']} % printed for {exact:.1f} %", ev, quote, f"{exact:.2f} %")]
    need_after = b * (1 - float(c["percent"]) / 100)
    need_before = a / (1 - float(c["percent"]) / 100)
    ev = (f"with the printed before {c['before']} um and 'approximately {c['after']} um' after, "
          f"the reduction is {exact:.1f} %, not {c['percent']} %; {c['percent']} % needs "
          f"{need_after:.2f} um after (or {need_before:.1f} um before with {c['after']} um "
          f"after)")
    if "other_before" in c:
        ob = float(c["other_before"])
        ev += (f"; with the peak {c['other_before']} um quoted elsewhere for the same error it "
               f"would be {100 * (1 - a / ob):.1f} %")
    ev += (f". Explanations: (1) no defect -- the peak after compensation was about "
           f"{need_after:.1f} um and the text rounds it to 'approximately {c['after']}'; (2) the "
           f"percentage computed from other values than the quoted ones (e.g. another peak "
           f"before compensation) or misprinted. Category undecidable: 'approximately' does "
           f"not bound the after-value; missing: the post-compensation peak itself (the "
           f"plotted data are not in the text)")
    v = _v(c, "percent", "undecidable", f"{c['percent']} % against {exact:.1f} % from the "
           "printed values", ev, quote, f"{exact:.1f} % (after = {c['after']} um)")
    v.readings_tried = [f"before {c['before']} um, after 'approximately {c['after']}' um taken "
                        f"as {c['after']}: {exact:.1f} %",
                        f"the after-value the printed percentage needs: {need_after:.2f} um "
                        f"(within 'approximately {c['after']}')"]
    v.readings_used = [f"missing:{c['id']} post-compensation peak"]
    return [v]


def check_same(c) -> list[Verdict]:
    quotes = c["quotes"]
    exact = [q for q in quotes if not q.get("approx")]
    out = []
    values = sorted({q["value"] for q in exact}, key=float)
    # the majority value of the exactly printed quotes is the reference
    ref = max(values, key=lambda v: (sum(q["value"] == v for q in exact), -float(v)))
    r_lo, r_hi = interval(ref)
    ratio = c.get("ratio")
    for q in quotes:
        lo, hi = interval(q["value"])
        meets = lo <= r_hi and r_lo <= hi
        if q["value"] == ref:
            continue
        comp = f"{q['where']}: {q['value']}"
        if meets:
            ev = (f"{q['value']} ({q['where']}, rounding interval {lo:g} .. {hi:g}) and {ref} "
                  f"({r_lo:g} .. {r_hi:g}) meet at the boundary"
                  + (", and the first is printed 'approximately'" if q.get("approx") else "")
                  + ": consistent")
            out.append(_v(c, comp, "identical", "", ev, q["text"], ref))
            continue
        ev = (f"{c['quantity']}: {q['value']} ({q['where']}) against {ref} quoted "
              f"{sum(x['value'] == ref for x in exact)} times "
              f"({', '.join(x['where'] for x in exact if x['value'] == ref)}); the rounding "
              f"intervals {lo:g} .. {hi:g} and {r_lo:g} .. {r_hi:g} do not meet")
        if ratio is not None:
            implied = float(ratio["of"]) * ratio["factor"]
            ev += (f"; the same sentence says '{ratio['text']}' ({ratio['of']} um): "
                   f"{ratio['factor']:g} x {ratio['of']} = {implied:g} um, which {ref} "
                   f"({float(ref) / float(ratio['of']):.2f} x) fits as 'almost' double and "
                   f"{q['value']} ({float(q['value']) / float(ratio['of']):.2f} x, more than "
                   f"double) does not")
        lost = _lost_glyphs(ref, q["value"])
        if lost:
            ev += (f". The sentence's own comparison and the two other quotes agree on {ref}; "
                   f"'{q['value']}' is '{ref}' with the glyphs '{lost}' lost, which the print "
                   f"(a typo) and the text extraction explain equally. Category undecidable; "
                   f"what would decide: the page of the original PDF")
            cat = "undecidable"
            used = [f"glyph:{c['id']} {q['where']}"]
        else:
            ev += (". Category printing_error: the sentence's own comparison and the two "
                   "other quotes agree on " + ref if ratio is not None else
                   ". Category printing_error")
            cat = "printing_error"
            used = [f"inconsistent:{c['id']} {q['where']}"]
        v = _v(c, comp, cat, f"{q['value']} printed for {ref}", ev, q["text"], ref)
        v.readings_tried = [f"the quote as printed, {q['value']}: its rounding interval does not "
                            f"meet {ref}'s"] + ([f"'{ref}' with '{lost}' lost by the print or "
                                                 f"the extraction: {ref} exactly"] if lost else [])
        v.readings_used = used
        out.append(v)
    return out


def _lost_glyphs(full: str, short: str) -> str:
    """The characters of ``full`` that ``short`` lacks when ``short`` is ``full`` with a run of
    adjacent characters removed ("48" from "40.8" lacks "0."), else ""."""
    for i in range(len(full)):
        for j in range(i + 1, len(full) + 1):
            if full[:i] + full[j:] == short:
                return full[i:j]
    return ""


def check_count(c) -> list[Verdict]:
    terms = [sp.sympify(t) for t in c["terms"]]
    total = sum(terms)
    ok = total == sp.Integer(c["value"])
    ev = " + ".join(f"{t} = {sp.sympify(t)}" if not sp.sympify(t).is_Integer
                    or str(sp.sympify(t)) != t else t for t in c["terms"]) + f" = {total}"
    if "also" in c:
        got = sp.sympify(c["also"]["circles"])
        ok = ok and got == sp.Integer(c["also"]["circles_printed"])
        ev += (f"; latitude circles at 18 .. 90 deg in 18 deg steps: {c['also']['circles']} = "
               f"{got} (printed {c['also']['circles_printed']})")
    return [_v(c, "count", "identical" if ok else "printing_error",
               f"{c['value']} printed, the plan gives {total}", ev, c["quote"], str(total))]


def check_steps(c) -> list[Verdict]:
    n, step, span = int(c["points"]), float(c["step_deg"]), float(c["span_deg"])
    need = int(round(span / step)) + (0 if c.get("closed") else 1)
    ok = n == need
    how = (f"a full turn of {span:g} deg in {step:g} deg steps has {need} distinct positions "
           f"(0 .. {span - step:g})" if c.get("closed") else
           f"{span:g} deg of travel in {step:g} deg steps, both ends measured: {need} positions")
    return [_v(c, "points", "identical" if ok else "printing_error",
               f"{n} points printed, the plan gives {need}", how, c["quote"], str(need))]


def check_units(c) -> list[Verdict]:
    ball = float(c["ball_radius_mm"])
    reff = float(c["r_eff_mm"])
    vals = [float(v) for v in c["values"]]
    mean_pretravel_um = (ball - reff) * 1e3
    worst = max(abs(v) for v in vals)
    ok = worst < ball
    ev = (f"probe errors of {', '.join(c['values'])} {c['unit']} against a probe ball of "
          f"{ball:g} mm radius: a deviation of {worst:g} mm from the mean pretravel is larger "
          f"than the ball itself; R_eff = {reff} mm means a mean pretravel of "
          f"{ball:g} - {reff} = {mean_pretravel_um:.0f} um, the scale on which deviations from "
          f"that mean lie. Read in um ({', '.join(c['values'])} um) the numbers fit, the unit of "
          f"every other error in sec. 4: the printed unit mm is wrong")
    v = _v(c, "unit", "identical" if ok else "undecidable",
           f"{c['unit']} printed for um", ev + (
               ". Category undecidable: 'mm' for 'um' is the confusion of one glyph (mu read "
               "or printed as m), which the print and the text extraction explain equally; "
               "no um of this section is extracted (sec. 3.2 spells the sphere's roundness "
               "'1 마이크로미터' in words), so the page shows neither reading; what would "
               "decide: the page of the original PDF" if not ok else ""),
           c["quote"], f"{', '.join(c['values'])} um")
    if not ok:
        v.readings_tried = [f"the unit as printed, mm: a deviation of {worst:g} mm from the "
                            f"mean pretravel, larger than the ball",
                            "um (the glyph mu lost or misread): fits R_eff and every error of "
                            "sec. 4"]
        v.readings_used = [f"glyph:{c['id']} unit"]
    return [v]


def check_rms(c) -> list[Verdict]:
    mx, mn, rms, n = float(c["max"]), float(c["min"]), float(c["rms"]), int(c["n"])
    # zero-mean data in [mn, mx]: the RMS is largest with values only at the two ends
    # (fractions mx/(mx - mn) at mn and -mn/(mx - mn) at mx): RMS^2 <= -mx*mn
    bound = math.sqrt(-mx * mn)
    ok = 0 < rms <= bound
    ev = (f"Probe values are deviations from their mean (eq. 13), so their RMS is at most "
          f"sqrt(-max * min) = sqrt({mx:g} * {-mn:g}) = {bound:.2f} (zero-mean values confined "
          f"to [{mn:g}, {mx:g}]); the printed RMS {rms:g} is below it: consistent with {n} "
          f"points")
    return [_v(c, "rms", "identical" if ok else "printing_error",
               f"RMS {rms:g} exceeds sqrt(-max*min) = {bound:.2f}", ev, c["quote"],
               f"RMS <= {bound:.2f}")]


def _pairs_from_equation(eq: dict, symbols) -> dict:
    """symbol -> the axis pair it couples in a printed volumetric equation (component letter and
    the position multiplying it)."""
    loc = {n: sp.Symbol(n) for n in symbols}
    pos = {n: sp.Symbol(n) for n in "XYZ"}
    out = {}
    for comp, text in eq.items():
        clean = text
        for f in ("dx", "dy", "dz", "Ex", "Ey", "Ez"):
            for a in "XYZ":
                clean = clean.replace(f"{f}({a})", f"{f}_{a}")
        expr = sp.expand(sp.sympify(clean, locals={**loc, **pos}))
        for n in symbols:
            for a, s in pos.items():
                if expr.coeff(loc[n]).coeff(s) != 0:
                    out[n] = "".join(sorted(comp[1] + a))
    return out


def check_definition(c) -> list[Verdict]:
    syms = c["symbols"]
    places = c["places"]
    ref = places[-1]
    ref_pairs = _pairs_from_equation(ref["eq4"], syms)
    norm = {n: "".join(sorted(ref_pairs[n])) for n in syms}
    out = []
    for pl in places[:-1]:
        got = {n: "".join(sorted(p)) for n, p in zip(syms, pl["pairs"])}
        bad = [n for n in syms if got[n] != norm[n]]
        same_set = sorted(got.values()) == sorted(norm.values())
        comp = pl["where"]
        if not bad:
            out.append(_v(c, comp, "identical", "", "pairs per symbol ("
                          + ", ".join(f"{n}: {got[n]}" for n in syms) + ") as in eq. 4, where "
                          + ", ".join(f"{n} multiplies the {norm[n][0]}-{norm[n][1]} coupling"
                                      for n in syms), pl["text"], str(norm)))
            continue
        ev = ("eq. 4 couples " + ", ".join(f"{n} to the {norm[n][0]}-{norm[n][1]} axes"
                                             for n in syms)
              + f" (the position multiplying it and the component it enters); the {comp} "
              f"assigns " + ", ".join(f"{n} to {pl['pairs'][syms.index(n)]}" for n in bad))
        if same_set:
            ev += (". The same three axis pairs, in another order: read 'respectively', the list "
                   "exchanges the planes of beta1 and beta2; the text after eq. 3 and every "
                   "volumetric equation (4, 7, A2, A5, A8) use the eq. 4 assignment. Read as a "
                   "plain enumeration (the three pairs, in no particular correspondence) the "
                   "list would say nothing wrong, but every other entry of the same symbol "
                   "list with several symbols pairs them respectively ('(Tx, Ty, Tz) : X, Y, Z "
                   "축을 따라서 정의되는 회전변환행렬', 'Lx, Ly, Lz : X, Y, Z 축을 따라서 ...', "
                   "'RX, RY, RZ : X, Y, Z 방향으로의 ...', 'A, B : ... 틸트각도 및 롤 각도'), "
                   "so the list's own convention is 'respectively'. The wrong pairs are no "
                   "glyph damage: 'YZ' and 'ZX' are well-formed pairs, and the extraction reads "
                   "'X축 - Z축' and 'Y축 - Z축' right after eq. 3. Sec. 4 quotes CMM A's "
                   "squareness for XY, XZ, YZ (the eq. 4 order) but CMM B's for XY, YZ, ZX (the "
                   "list's order), so which of CMM B's values is beta1 depends on the reading")
        v = _v(c, comp, "printing_error", "squareness planes of "
               + ", ".join(bad) + " exchanged", ev + ". Category printing_error: a "
               "well-formed list of other axis pairs, not extraction damage", pl["text"],
               str(norm))
        v.readings_tried = ["the list read 'respectively' against eq. 4: " + ", ".join(
            f"{n}: {pl['pairs'][syms.index(n)]}" for n in bad),
            "the order XY, YZ, ZX as a plain enumeration (not respectively): no contradiction, "
            "but not the list's convention (its other multi-symbol entries pair respectively)"]
        v.readings_used = [f"inconsistent:{c['id']} {comp}"]
        out.append(v)
    return out


KINDS = {"reduction": check_reduction, "same": check_same, "count": check_count,
         "steps": check_steps, "units": check_units, "rms": check_rms,
         "definition": check_definition}


def audit(printed: dict, layouts=None) -> list[Verdict]:
    """Verdicts on the printed numbers (layout-independent: skipped for named layouts)."""
    if layouts:
        return []
    out = []
    for c in printed.get("check", []):
        out.extend(KINDS[c["kind"]](c))
    return out
