"""Audit of the squareness chain of Ellingsdalen (2021): the signed reference-line angles of
Listing 3.1, their sum in Listing 3.2 (against the difference of eq. 2.39) and their use in
Listing 3.4 (``Y * S_YX``, ``(-Z) * S_ZX``, ``(-Z) * S_ZY`` against the ``+y E_C(0X)Y``,
``+z E_B(0X)Z``, ``+z E_A(0Y)Z`` of eq. 3.17-3.18); numpy only, no file I/O.

The printed code (``volerr/data/printed_squareness.toml``) is RUN on straightness data of
known slopes.  With E_ij = k_ij q_j (the deviation along i while axis j moves, slope k_ij):

* eq. 2.39 (ISO 230-1): the squareness is the difference of the two lines' inclinations
  measured in one rotational sense, which is +-(k_ab + k_ba) in slopes (the sign names which
  axis is the reference);
* eq. 3.16-3.18 with the X axis as datum: the HTMs replace the linear parts the fit removed
  (Listing 3.1 subtracts each reference line) only if the entry of axis a along b is
  q_a (k_ba + k_ab): the removed field minus the put-back one must be a rigid rotation.

Listing 3.1 gives each angle the sign of ``ref[-1] - ref[0]`` (the change along the travel), so
the result depends on the direction each axis travels.  The text fixes only X (0 .. 500 mm:
appendix C.1 ``x = np.linspace(0, 500, 11)``, Figure 3.11); the audit tries both directions of
Y and Z (``travel:`` readings).
"""

from __future__ import annotations

import itertools

import numpy as np

from .audit import Verdict, category_of

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


def _keys(sign, axes="YZ") -> list[str]:
    return [f"travel:DMU50 {a} {'positive' if sign[a] > 0 else 'negative'}" for a in axes]


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
                      "needs Y and Z in the same direction (X travels positive: appendix C.1, "
                      "Figure 3.11). No choice satisfies all three: " + "; ".join(tried)
                      + ". Elsewhere the sum is +-(k_ab - k_ba), the squareness plus twice a "
                      "rotation of the measuring frame. Category printing_error: a defect of "
                      "the printed code (its sign rules), for every travel direction the text "
                      f"leaves open. Extraction repairs: {repairs}", s["text"],
                      "+-(k_ab + k_ba) for every pair (eq. 2.39)", tried,
                      ["inconsistent:Listing 3.1 sign rules of the six angles"]))
    else:
        best = next(sign for sign, ok in zip(_signs(), ok_all) if ok)
        keys = _keys(best)
        out.append(_v(s["id"], "sum of the two angles", category_of(keys), "sum of signed "
                      "angles", "the sum of the signed angles is eq. 2.39's difference for "
                      f"{_label(best)}", s["text"], "eq. 2.39", tried, keys))
    # Listing 3.4's use of S against eq. 3.17-3.18
    uses = printed.get("use", [])
    results = []
    for sign in _signs():
        row = {}
        for u in uses:
            a1, a2 = u["call"]
            coef = u["sign"] * squareness(code, a1, a2, sign)
            want = SLOPES[u["pair"]] + SLOPES[u["pair"][::-1]]
            row[u["id"]] = abs(coef - want) < 1e-3 * abs(want)
        results.append((sign, row))
    best_n = max(sum(r.values()) for _, r in results)
    best = [(sign, r) for sign, r in results if sum(r.values()) == best_n]
    for u in uses:
        tried = [f"{_label(sign)}: {u['term']} " + ("= " if r[u['id']] else "!= ") + u["eq"]
                 for sign, r in results]
        right = [sign for sign, r in best if r[u["id"]]]
        raw = u.get("raw", u["term"])
        shown = (f"'{u['term']}'" + (f" (extraction text of the line: '{raw}')"
                                     if raw != u["term"] else ""))
        base = (f"the entry {u['entry']} of Listing 3.4, {shown}, run with the angles of "
                f"Listing 3.1 and the sum of Listing 3.2 on lines of known slopes, against "
                f"{u['eq']} with the X axis as datum (the entry must put back q (k_ab + k_ba), "
                f"the slope-signed squareness eq. 3.11/3.13 define). Travel directions that "
                f"make the most of the three squareness entries right ({best_n} of 3): "
                + "; ".join(_label(sg) for sg, _ in best) + ".")
        if len(right) == len(best):
            axes = "Y" if u["pair"] == "XY" else "YZ"
            keys = _keys(right[0], axes) if len({tuple(_keys(sg, axes)) for sg in right}) == 1 \
                else []
            extra = (" With Z travelling positive, S_ZX is eq. 2.39's E_B(0Z)X = "
                     "-E_B(0X)Z, so (-Z) * S_ZX = +z E_B(0X)Z: the minus converts the "
                     "squareness of X to Z into the Z to X of eq. 3.18." if u["pair"] == "XZ"
                     else "")
            keys = keys + (["notation:S_ZX is E_B(0Z)X = -E_B(0X)Z"] if u["pair"] == "XZ"
                           else [])
            out.append(_v(u["id"], u["entry"], category_of(keys), f"equals {u['eq']} for "
                          + "; ".join(_label(sg) for sg in right), base + " Under every one "
                          f"of them the entry equals {u['eq']}." + extra + " The travel "
                          "direction is a reading: the text does not give it.", u["text"],
                          u["eq"], tried, keys,
                          statement="the travel direction(s) " + "; ".join(
                              _label(sg) for sg in right) + " (not printed)"))
        elif not right:
            out.append(_v(u["id"], u["entry"], "printing_error", f"{u['term']} != {u['eq']}",
                          base + f" Under none of them does the entry equal {u['eq']}. "
                          "Category printing_error: a defect of the printed code", u["text"],
                          u["eq"], tried, [f"inconsistent:{u['id']} sign"]))
        else:
            extra = (" With Z travelling positive S_ZX is eq. 2.39's E_B(0Z)X = -E_B(0X)Z, "
                     "so (-Z) * S_ZX = +z E_B(0X)Z: the minus converts the squareness of X to "
                     "Z into the Z to X of eq. 3.18." if u["pair"] == "XZ" else "")
            out.append(_v(u["id"], u["entry"], "undecidable", f"{u['term']} equals {u['eq']} "
                          "only for one travel direction of Z", base + " Among these the "
                          "entry is right for " + "; ".join(_label(sg) for sg in right)
                          + " and wrong for the other." + extra + " The other Z entry of "
                          "Listing 3.4 is wrong exactly "
                          "where this one is right: one of the two Z entries is a printing "
                          "error whatever the direction. Category undecidable; missing: the "
                          "travel direction of Z (the sign of the positions in the E_XZ and "
                          "E_YZ data)", u["text"], u["eq"], tried,
                          ["missing:DMU50 travel direction of Z"]))
    return out
