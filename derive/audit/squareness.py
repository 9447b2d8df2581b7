"""Audit of the squareness chain of Ellingsdalen (2021): the signed reference-line angles of
Listing 3.1, their sum in Listing 3.2 (against the difference of eq. 2.39) and their use in
Listing 3.4 (``Y * S_YX``, ``(-Z) * S_ZX``, ``(-Z) * S_ZY`` against the ``+y E_C(0X)Y``,
``+z E_B(0X)Z``, ``+z E_A(0Y)Z`` of eq. 3.17-3.18); numpy only, no file I/O.

The printed code (``data/printed_squareness.toml``) is RUN on straightness data of
known slopes.  With E_ij = k_ij q_j (the deviation along i while axis j moves, slope k_ij):

* eq. 2.39 (ISO 230-1): the squareness is the difference of the two lines' inclinations
  measured in one rotational sense, which is +-(k_ab + k_ba) in slopes (the sign names which
  axis is the reference);
* eq. 3.16-3.18 with the X axis as datum: the HTMs replace the linear parts the fit removed
  (Listing 3.1 subtracts each reference line) only if the entry of axis a along b is
  q_a (k_ba + k_ab): the removed field minus the put-back one must be a rigid rotation.

Listing 3.1 gives each angle the sign of ``ref[-1] - ref[0]`` (the change along the travel), so
the result depends on the direction each axis travels.  The text fixes only X (0 .. 500 mm:
appendix C.1 ``x = np.linspace(0, 500, 11)``); the audit tries both directions of Y and Z.
A Listing 3.4 entry ``E_<i><q> + (+-q) * S`` is judged as a whole under each: its squareness
term, and its lookup ``cf(...)[3][round(pos_q)]``, which reads the mirrored position when q
travels negative (negative index, see :mod:`volerr.derive.audit.listings`).  An entry right for some
directions only is ``undecidable`` (the direction is an unstated set-up fact, not a
convention); an entry wrong for every direction is ``printing_error``.
"""

from __future__ import annotations

import itertools

import numpy as np

from .framework import Verdict

DATA_FILE = "printed_squareness.toml"
LAYOUTS = ("DMU50",)
SOURCE = "Ellingsdalen 2021"
LAYOUT = "DMU50"

#: slopes of the test machine, rad (um per mm / 1000), all different so that k_ab + k_ba and
#: k_ab - k_ba differ for every pair
SLOPES = {"XY": 12e-6, "YX": 7e-6, "XZ": 9e-6, "ZX": -5e-6, "YZ": 4e-6, "ZY": 11e-6}
TRAVEL = {"X": 500.0, "Y": 450.0, "Z": 400.0}


def angle_of(code: str, error: str, sign: dict) -> float:
    """Run Listing 3.1's angle code on E_<i><j> with slope SLOPES[ij] and a symmetric bow (the
    axis j travels from 0 to sign[j] * TRAVEL[j] mm in 11 steps)."""
    i, j = error[-2], error[-1]
    axis = sign[j] * np.linspace(0.0, TRAVEL[j], 11)
    u = np.linspace(0.0, 1.0, 11)
    values = SLOPES[i + j] * 1e3 * axis + 0.5 * np.sin(np.pi * u)       # um
    ns = {"np": np, "error": error, "Axis": axis, "error_parameter": values}
    exec(compile(code, "<printed Listing 3.1>", "exec"), ns)  # noqa: S102
    return float(ns["angle"])


def squareness(code: str, axis1: str, axis2: str, sign: dict) -> float:
    """Listing 3.2: angle of E_<axis2><axis1> plus angle of E_<axis1><axis2>."""
    return angle_of(code, f"E_{axis2}{axis1}", sign) + angle_of(code, f"E_{axis1}{axis2}", sign)


def _v(eq, comp, category, erratum, evidence, printed, derived, tried, used, **f) -> Verdict:
    same = category == "identical"
    return Verdict(SOURCE, eq, LAYOUT, "identical" if same else "differs",
                   "" if same else erratum, evidence, printed, derived, comp,
                   category=category, readings_tried=list(tried), readings_used=list(used), **f)


def _signs():
    for sy, sz in itertools.product((1, -1), (1, -1)):
        yield {"X": 1, "Y": sy, "Z": sz}


def _label(sign) -> str:
    return ", ".join(f"{a} travels {'+' if sign[a] > 0 else '-'}" for a in "YZ")


def audit(printed: dict, layouts=None) -> list[Verdict]:
    if layouts is not None and "DMU50" not in layouts:
        return []
    if "angle" not in printed:
        return []
    code = printed["angle"]["code"]
    repairs = "; ".join(printed["angle"]["repairs"])
    out = []
    # Listing 3.2 against eq. 2.39, every travel reading
    pairs = {"XY": ("Y", "X"), "XZ": ("Z", "X"), "YZ": ("Z", "Y")}
    table, ok_all = [], []
    for sign in _signs():
        res = {}
        for p, (a1, a2) in pairs.items():
            s = squareness(code, a1, a2, sign)
            want = SLOPES[a1 + a2] + SLOPES[a2 + a1]
            res[p] = abs(abs(s) - abs(want)) < 1e-3 * abs(want)   # arccos: ~1e-11 rad
        table.append((sign, res))
        ok_all.append(all(res.values()))
    tried = [f"{_label(sign)}: " + ", ".join(f"{p} {'= eq. 2.39' if ok else 'not eq. 2.39'}"
                                              for p, ok in res.items()) for sign, res in table]
    s = printed["sum"]
    if not any(ok_all):
        out.append(_v(s["id"], "sum of the two angles", "printing_error",
                      "for every travel direction one pair's sum is not the squareness",
                      "run on straightness lines of known slopes (E_ij = k_ij q_j, k_XY 12, "
                      "k_YX 7, k_XZ 9, k_ZX -5, k_YZ 4, k_ZY 11 urad, plus a symmetric bow): "
                      "eq. 2.39's difference of the two inclinations in one rotational sense is "
                      "+-(k_ab + k_ba) in slopes. Listing 3.1 signs each angle by the change of "
                      "its reference line along the travel (negative for E_YX falling, E_ZX "
                      "rising, E_XY rising, E_ZY falling, E_XZ rising, E_YZ falling), so the "
                      "sum of Listing 3.2 is +-(k_ab + k_ba) -- the difference of eq. 2.39 -- "
                      "only where the two rules give opposite senses for the directions the "
                      "axes travel: XY needs Y travelling negative, XZ needs Z positive, YZ "
                      "needs Y and Z in the same direction (" + X_POSITIVE + "). No choice satisfies all three: " + "; ".join(tried)
                      + ". Elsewhere the sum is +-(k_ab - k_ba), the squareness plus twice a "
                      "rotation of the measuring frame. Category printing_error: a defect of "
                      "the printed code (its sign rules), for every travel direction the text "
                      f"leaves open. Extraction repairs: {repairs}", s["text"],
                      "+-(k_ab + k_ba) for every pair (eq. 2.39)", tried,
                      ["inconsistent:Listing 3.1 sign rules of the six angles"]))
    else:
        right = [sign for sign, ok in zip(_signs(), ok_all) if ok]
        everywhere = len(right) == len(ok_all)
        out.append(_v(s["id"], "sum of the two angles",
                      "identical" if everywhere else "undecidable",
                      "the sum of signed angles is eq. 2.39's difference only for "
                      + "; ".join(_label(sg) for sg in right),
                      "the sum of the signed angles is eq. 2.39's difference for "
                      + "; ".join(_label(sg) for sg in right) + ("" if everywhere else
                      ". Category undecidable; missing: the travel directions of Y and Z"),
                      s["text"], "eq. 2.39", tried,
                      [] if everywhere else ["missing:DMU50 travel directions of Y and Z"]))
    # Listing 3.4's use of S against eq. 3.17-3.18: each entry judged as a whole (its
    # squareness term and its E_<i><q> lookup) under every travel direction the text leaves open
    for u in printed.get("use", []):
        out.append(_use_verdict(code, u))
    return out


#: why X is taken as travelling positive (the one direction the text gives)
X_POSITIVE = ("X travels + (the one direction the text gives: appendix C.1 defines the X "
              "displacements as 'x = np.array(np.linspace(0, 500, num = 11))', 0 .. 500 mm, and the "
              "NC data of Figure 3.11, extracted as a table, run X = 0, 50, .., 500 mm)")

#: the lines 47-51 of Listing 3.4 that define E_XZ, E_YZ, E_ZZ are blank in the extraction
LOST_LOOKUP = ("lines 47-51 of Listing 3.4, which define E_XZ, E_YZ and E_ZZ, are blank in the "
               "extraction; the text says lines 40-50 define the translational errors 'by "
               "reading the value of the fitted polynomial at the desired positio[n]', and every "
               "visible line 40-46 does so as cf('E_<i><q>_avg.', n)[3][round(pos_<q>)], so "
               "the lost lines are read as the same lookup at round(pos_Z)")


def _negative_index(u) -> str:
    """Why the lookup of the entry's E_<i><q> is wrong when q travels negative."""
    q = u["position"]
    e = u["term"].split(" + ")[0]
    shown = (f"line {u['lookup_line']} '{u['lookup']}'" if u.get("lookup")
             else f"the lost line (47-51) that reads {e} (see 'Reading' below)")
    return (f"{e} is read by {shown} at round(pos_{q}) < 0 (the NC positions are the measured "
            f"Axis values, Listing 3.4 lines 76-87, so an axis travelling negative has negative "
            f"positions), a negative index that reads the curve at the mirrored position "
            f"-(n - |round(pos_{q})|) mm (the verdict 'Listing 3.1 + 3.4 / negative "
            f"positions', printing_error)")


def _use_verdict(code: str, u: dict) -> Verdict:
    """One entry of Listing 3.4 (E_<i><q> + (+-q) * S) under the travel directions of Y, Z."""
    q = u["position"]
    a1, a2 = u["call"]
    want = SLOPES[u["pair"]] + SLOPES[u["pair"][::-1]]
    axes = sorted({q, a1, a2} - {"X"})             # the directions the entry depends on
    rows = []
    for signs in itertools.product((1, -1), repeat=len(axes)):
        sign = {"X": 1, "Y": 1, "Z": 1, **dict(zip(axes, signs))}
        coef = u["sign"] * squareness(code, a1, a2, sign)
        rows.append((sign, abs(coef - want) < 1e-3 * abs(want), sign[q] > 0))
    label = (lambda sg: ", ".join(f"{a} travels {'+' if sg[a] > 0 else '-'}" for a in axes))
    tried = [f"{label(sg)}: squareness term {u['term'].split(' + ')[1]} "
             + ("= " if sq else "!= ") + f"the one of {u['eq']}; {u['term'].split(' + ')[0]} "
             + ("read at its own position" if look else
                "read at a negative index (mirrored position)") for sg, sq, look in rows]
    right = [sg for sg, sq, look in rows if sq and look]
    raw = u.get("raw", u["term"])
    shown = (f"'{u['term']}'" + (f" (extraction text of the line: '{raw}')"
                                 if raw != u["term"] else ""))
    base = (f"the entry {u['entry']} of Listing 3.4, {shown}, judged as a whole: its "
            f"squareness term run with the angles of Listing 3.1 and the sum of Listing 3.2 on "
            f"lines of known slopes, against {u['eq']} with the X axis as datum (the entry "
            f"must put back q (k_ab + k_ba), the slope-signed squareness eq. 3.11/3.13 "
            f"define), and its lookup of {u['term'].split(' + ')[0]} at round(pos_{q}). "
            f"{X_POSITIVE}; the text gives no direction for "
            + " or ".join(axes) + ", so every one is tried. By direction:")
    per = []
    for sg, sq, look in rows:
        bad = []
        if not sq:
            bad.append(f"the squareness term is not the one of {u['eq']} (the sign rules of "
                       f"Listing 3.1, the verdict 'Listing 3.2', printing_error)")
        if not look:
            bad.append(_negative_index(u))
        per.append(f"{label(sg)}: " + ("right" if not bad else "; and ".join(bad)))
    lost = "" if u.get("lookup") else f" Reading: {LOST_LOOKUP}."
    extra = (" With Z travelling positive S_ZX is eq. 2.39's E_B(0Z)X = -E_B(0X)Z, so "
             "(-Z) * S_ZX = +z E_B(0X)Z: the minus converts the squareness of X to Z into the "
             "Z to X of eq. 3.18. The other Z entry, T_e_Z (2,4), is wrong for every "
             "direction (its own verdict)." if u["pair"] == "XZ" else "")
    ocr = [] if u.get("lookup") else ["ocr:Listing 3.4 lines 47-51 read as lines 40-46"]
    only_lost = [label(sg) for sg, sq, look in rows if sq and not look]
    if ocr and only_lost:
        lost += (" Only for " + "; ".join(only_lost) + " does the verdict rest on the lost "
                 "lines (there the squareness term is right and the entry is wrong by the "
                 "lookup alone); for every other direction the visible line decides.")
    if not right:
        return _v(u["id"], u["entry"], "printing_error",
                  f"{u['term']} != {u['eq']} for every travel direction (for different "
                  "reasons)", base + " " + "; ".join(per) + "." + lost + " Category "
                  "printing_error: the entry is wrong for either direction, each time by a "
                  "defect of the printed code another verdict decides (no reading makes the "
                  "whole entry right)", u["text"], u["eq"], tried,
                  [f"inconsistent:{u['id']} for every travel direction"] + ocr)
    if len(right) == len(rows):
        return _v(u["id"], u["entry"], "identical", "", base + " Right for every direction.",
                  u["text"], u["eq"], tried, [])
    return _v(u["id"], u["entry"], "undecidable",
              f"{u['term']} equals {u['eq']} only for " + "; ".join(label(sg) for sg in right),
              base + " " + "; ".join(per) + "." + extra + lost + " The entry is right for "
              + "; ".join(label(sg) for sg in right) + " and wrong otherwise; whether it is "
              "right depends on a set-up fact the text does not give (an unstated set-up fact "
              "is no convention). Category undecidable; missing: the travel direction of "
              + " and ".join(sorted({q} | ({a for sg in right for a in axes}))) + " (the sign "
              "of the positions in the " + ", ".join(sorted({f"E_{a}{q}" for a in "XYZ" if a != q}))
              + " data)", u["text"], u["eq"], tried,
              [f"missing:DMU50 travel direction of {q}"] + ocr)
