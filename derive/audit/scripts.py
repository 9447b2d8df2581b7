"""Audit of the hand-pasted solved formulas of Ellingsdalen (2021): appendix C.1 (the six
errors of the X axis from three points on the spindle) and D.1 (the B axis from three points
on the table); sympy / numpy, no file I/O.

The printed material (``data/printed_scripts.toml``) keeps only what the extraction left
legible.  The authority:

* C.1: Cramer's rule on the selected system of eq. 32 (rows P x, P y, Q x, Q z, K y, K z of the
  first-order displacement d = t + e x r of a point on the carriage), :func:`volerr.derive.
  three_point.closed_form` -- every solution is sum_k c_k d_k / N with the deviations d_k
  (measured minus nominal) of the selected rows; each legible printed term sign * cofactor * d
  is compared with c_d, a term whose deviation is lost with the cofactors left over;
* D.1: the rotary model the thesis states for a table axis (eq. 3.4-3.6): the nominal point
  turns by the axis angle and the coefficient matrix holds the turned lever arms.  The printed
  formulas' legible features -- their denominators and which of cos(theta), sin(theta) their
  numerators hold -- are compared with every candidate model: the nominal point turned about
  x, y or z, with the lever arms turned or not.
"""

from __future__ import annotations

import itertools

import numpy as np
import sympy as sp

from .framework import Verdict, category_of, fmt
from ..three_point import closed_form_once as closed_form

DATA_FILE = "printed_scripts.toml"
LAYOUTS = ("DMU50",)
SOURCE = "Ellingsdalen 2021"
LAYOUT = "DMU50"
MOTIONS = {"E_XX": "EX", "E_YX": "EY", "E_ZX": "EZ", "E_AX": "EA", "E_BX": "EB", "E_CX": "EC"}
ROWS = (("P", "x"), ("P", "y"), ("Q", "x"), ("Q", "z"), ("K", "y"), ("K", "z"))


def _v(eq, comp, category, erratum, evidence, printed, derived, tried=(), used=(), **f):
    same = category == "identical"
    return Verdict(SOURCE, eq, LAYOUT, "identical" if same else "differs",
                   "" if same else erratum, evidence, printed, derived, comp,
                   category=category, readings_tried=list(tried), readings_used=list(used), **f)


def _c1_locals(tag: str) -> dict:
    """Script names (x_xP, x_actPt, x_o, x ...) -> symbols of derive.three_point (x_P ...)."""
    loc = {}
    for lab in "PQK":
        for c in "xyz":
            loc[f"{c}_{tag}{lab}"] = sp.Symbol(f"{c}_{lab}", real=True)
            loc[f"{c}_act{lab}t"] = sp.Symbol(f"{c}m_{lab}", real=True)
    for c in "xyz":
        loc[f"{c}_o"] = sp.Symbol(f"{c}_o", real=True)
    loc["x"] = sp.Symbol("x", real=True)
    return loc


def _deviations() -> dict:
    """d_<c><lab> of the X axis -> measured minus nominal in script symbols."""
    x = sp.Symbol("x", real=True)
    out = {}
    for lab, c in ROWS:
        nominal = sp.Symbol(f"{c}_{lab}", real=True) + sp.Symbol(f"{c}_o", real=True) + \
            (x if c == "x" else 0)
        out[sp.Symbol(f"d_{c}{lab}", real=True)] = sp.Symbol(f"{c}m_{lab}", real=True) - nominal
    return out


def _paren(expr: str) -> str:
    """The cofactor in parentheses when it is a sum, so a leading sign applies to all of it."""
    depth = 0
    for i, ch in enumerate(expr):
        depth += (ch == "(") - (ch == ")")
        if depth == 0 and i > 0 and ch in "+-" and expr[i - 1] == " ":
            return f"({expr})"
    return expr


def _repairs(term: dict) -> str:
    """' (read with: ...)' -- the repairs a legible term's reading needs, '' if none."""
    return f" (read with: {'; '.join(term['repairs'])})" if term["repairs"] else ""


def _line_span(terms) -> str:
    """'lines 197-220': the listing lines of a formula's legible terms."""
    nums = [int(x) for t in terms for x in str(t["line"]).split("-") if x.strip().isdigit()]
    return f"lines {min(nums)}-{max(nums)}" if nums else "its lines"


def _c1_terms(terms: list, cof: dict, devs: dict, by_dev: dict, loc: dict) -> tuple[list, list]:
    """The legible terms of one formula of appendix C.1 against the derived cofactors: the
    lines that match (checked) and those that do not (bad), each described."""
    checked, bad, used_d = [], [], set()
    for t in terms:
        pc = sp.expand(t["sign"] * sp.sympify(t["cofactor"], locals=loc))
        if t["status"] == "complete":
            dv = by_dev.get(sp.expand(sp.sympify(t["d"], locals=loc)))
            ok = dv is not None and sp.expand(pc - cof[dv]) == 0
            used_d.add(dv)
            (checked if ok else bad).append(
                f"line {t['line']}: {'+' if t['sign'] > 0 else '-'}{_paren(t['cofactor'])} * "
                f"({t['d']}) " + ("= the derived term of " + str(dv) if ok else
                                  f"!= the derived {fmt(cof.get(dv, 'none'))} of {dv}")
                + _repairs(t))
    for t in terms:
        if t["status"] != "cofactor":
            continue
        pc = sp.expand(t["sign"] * sp.sympify(t["cofactor"], locals=loc))
        hit = [d for d in devs if d not in used_d and sp.expand(pc - cof[d]) == 0]
        if hit:
            used_d.add(hit[0])
            checked.append(f"line {t['line']}: {'+' if t['sign'] > 0 else '-'}"
                           f"{_paren(t['cofactor'])} (deviation lost) = the derived cofactor of "
                           f"{hit[0]}, the one deviation left" + _repairs(t))
        else:
            bad.append(f"line {t['line']}: {t['cofactor']} matches no remaining cofactor")
    return checked, bad


def _unit_factor_verdict(c1: dict, name: str, factor: str, unit: str) -> Verdict:
    """The unit factor of E_YX in appendix C.1 ('+ 1e3' where '* 1e3' belongs): undecidable."""
    out = []
    out.append(_v(f"{c1['id']} {name}", "unit factor", "undecidable",
                  f"'{factor}' where the other translational errors have '{unit}'",
                  f"{c1['factor_text'].get(name, '')}: the mm result is converted to um "
                  f"by '{unit}' in E_XX and E_ZX (and to urad by '* 1e6' in E_AX .. "
                  f"E_CX); '{factor}' adds 1000 instead, which would make E_YX near "
                  f"1000 um and its compensation near -1 mm. The thesis' own results, "
                  f"made with this script, rule that out: sec. 4.1.1 ('The two "
                  f"straightness errors E_YX and E_ZX are much lower' than E_XX's "
                  f"20.5 um), sec. 4.2.1 (E_YX 'improved from 6.6 um before "
                  f"compensation, to 1.3 um after compensation') and the compensated "
                  f"NC-data of Figure 3.11 (ideal Y 0), whose Y coordinates all stay "
                  f"within 1 um (largest -0.000949 mm, at X 49.9956 mm); "
                  f"appendix B sec. 4 (the project's own script) agrees ('significantly "
                  f"lower' than E_XX's 23 um): the script that made the results "
                  f"multiplied. Category undecidable: the extraction demonstrably "
                  f"renders '*' as '+' in this same function -- the first monomial of "
                  f"the d_yP term, '(x_xK_{{y_xK}} + z_xP - N)' at the end of line 97, "
                  f"reads x_xK*y_xK*z_xP (see the E_YX formula verdict) -- but a '+' "
                  f"typed into a listing edited after the run explains the print as "
                  f"well; what would decide: the page of the original PDF",
                  factor, unit, [f"'{factor}' as printed: E_YX + 1000 um",
                                 f"'{unit}' (a glyph misread or misprinted): the plotted "
                                 f"values"], [f"glyph:appendix C.1 {name} unit factor"]))
    return out[0]


def _cofactor(sol, d, N):
    """``expand(cancel(diff(sol, d) * N))``: the cofactor of the deviation ``d`` in a closed
    form ``sol`` = numerator / denominator over the determinant ``N``.  Where the denominator
    divides N times the numerator's derivative (Cramer's rule: always), the quotient is
    computed exactly in a polynomial ring and is the same expanded expression; else sympy's."""
    num, den = sol.as_numer_denom()
    gens = tuple(sorted(num.free_symbols | den.free_symbols | N.free_symbols | {d}, key=str))
    try:
        R, *_ = sp.ring(gens, sp.QQ)
        q, r = divmod(R(num).diff(R(d)) * R(N), R(den))
    except Exception:  # noqa: BLE001 - not polynomials: sympy decides
        r = None
    if r is None or r != 0:
        return sp.expand(sp.cancel(sp.diff(sol, d) * N))
    return sp.expand(q.as_expr())


def audit_c1(c1: dict) -> list[Verdict]:
    loc = _c1_locals("x")
    cf = closed_form("x")
    N = sp.expand(cf["N"])
    printed_N = sp.expand(sp.sympify(c1["N"], locals=loc))
    n_sign = 1 if sp.expand(printed_N - N) == 0 else (-1 if sp.expand(printed_N + N) == 0 else 0)
    devs = _deviations()
    by_dev = {sp.expand(v): k for k, v in devs.items()}
    arms = [sp.Symbol(f"{c}_{lab}", real=True) for lab in "PQK" for c in "xyz"]
    out = []
    for name, motion in MOTIONS.items():
        sol = cf[motion]
        cof = {d: _cofactor(sol, d, N) * n_sign for d in devs}
        terms = [t for t in c1.get("term", []) if t["formula"] == name]
        damaged = [d["what"] for d in c1.get("damaged", []) if d["formula"] == name]
        checked, bad = _c1_terms(terms, cof, devs, by_dev, loc)
        factor = c1["factors"][name]
        unit = "* 1e3" if motion in ("EX", "EY", "EZ") else "* 1e6"
        n_is = ("the derived determinant" if n_sign == 1 else "minus the derived determinant"
                if n_sign == -1 else "not the determinant")
        span = _line_span(terms)
        late = [str(t["line"]) for t in terms if any("followed by N" in r for r in t["repairs"])]
        n_where = (f"every term of the six formulas has its own '/(...)' denominator; the one "
                   f"legible in full is that of E_XX's last term (lines 86-89), which, read "
                   f"with its repairs, is {n_is} (15 monomials); the other denominators"
                   + (f" of {name} ({span})" if name != "E_XX" else " of E_XX") +
                   " are damaged by the extraction (debris, repeated spans) and were not "
                   "compared one by one -- where a '/' is followed directly by a legible "
                   "start, it reads as N's first monomials"
                   + ("" if not late else
                      f"; at line {', '.join(late)} the '/' is followed first by a repeated "
                      f"span of the deviation, and N starts on the next line (see that "
                      f"term's repair)"))
        tried = [f"Cramer's rule on eq. 32 (the derived cofactor of each deviation over N): "
                 f"{len(checked)} legible terms compared, {len(bad)} differ",
                 f"the denominator: {n_where}"]
        degrees = sorted({sp.Poly(sp.sympify(t["cofactor"], locals=loc), *arms).total_degree()
                          for t in terms})
        want_deg = sorted({sp.Poly(c, *arms).total_degree() for c in cof.values() if c != 0})
        ev = (f"{name} = sum of cofactor * deviation / N, the solution of the selected system of "
              f"eq. 32 by Cramer's rule (derive.three_point.closed_form); {n_where}. "
              f"Legible terms (with the repairs each reading needs): "
              + "; ".join(checked + bad) + ". "
              + (f"Every legible cofactor, so read, has degree {degrees[0]} in the lengths, as "
                 f"every derived one ({name} = cofactor * deviation / N with N of degree 3"
                 f"{' is a length' if motion in ('EX', 'EY', 'EZ') else ' is an angle'}). "
                 if terms and degrees == want_deg and len(degrees) == 1 else "")
              + (f"Not comparable: {'; '.join(damaged)}. " if damaged else "")
              + f"Unit factor {factor} ({'mm to um' if unit == '* 1e3' else 'rad to urad'}"
              + ("" if factor == unit else f"; printed '{factor}', see its own verdict") + ").")
        if bad or n_sign == 0:
            out.append(_v(f"{c1['id']} {name}", "formula", "printing_error", "legible terms "
                          "differ from Cramer's rule", ev, f"{name} (appendix C.1)",
                          f"Cramer's rule, selection of eq. 32", tried))
        elif damaged or any(t["repairs"] for t in terms):
            out.append(_v(f"{c1['id']} {name}", "formula", "extraction",
                          f"{len(checked)} legible terms as derived; the rest lost to the "
                          f"extraction", ev + " Category extraction: every legible term is the "
                          "derived one; the damage -- lines whose numbers remain without text, "
                          "LaTeX debris such as '\\sum_{i=1}^{n} (x_i - x_i)^{i}' inside Python "
                          "code, products rendered as subscripts -- is the extraction's (a "
                          "Python listing cannot carry it)"
                          + ("; a repair whose printed form is valid Python (a repeated factor) "
                             "rests on the degree of the term as printed instead (see that "
                             "repair)" if any("degree" in r for t in terms for r in t["repairs"])
                             else ""), f"{name} (appendix C.1)",
                          "Cramer's rule, selection of eq. 32", tried,
                          [f"ocr:appendix C.1 {name} damaged lines"]))
        else:
            out.append(_v(f"{c1['id']} {name}", "formula", "identical", "", ev,
                          f"{name} (appendix C.1)", "Cramer's rule", tried))
        if factor != unit:
            out.append(_unit_factor_verdict(c1, name, factor, unit))
    return out


# ------------------------------------------------------------------------------- D.1
def _system(points, theta, axis: str, rotate_arms: bool):
    """(A, nominal) of the selected rows for points turned by theta about ``axis``."""
    c, s = np.cos(theta), np.sin(theta)
    R = {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
         "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
         "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]
    A, nominal = [], []
    for lab, comp in ROWS:
        r = points[lab]
        arm = R @ r if rotate_arms else r
        x, y, z = arm
        i = "xyz".index(comp)
        A.append([[1, 0, 0, 0, z, -y], [0, 1, 0, -z, 0, x], [0, 0, 1, y, -x, 0]][i])
        nominal.append((R @ r)[i])
    return np.array(A, float), np.array(nominal), R


def _trig(axis: str, rng) -> tuple[bool, list]:
    """For the model with unturned arms and the nominal point turned about ``axis``: whether
    the determinant depends on theta, and which components hold sin(theta)."""
    pts = {lab: rng.uniform(-150, 150, 3) for lab in "PQK"}
    act = rng.normal(0, 1, 6)
    sols = {}
    for th in (0.0, np.pi / 2, np.pi):
        A, nom, _ = _system(pts, th, axis, False)
        sols[th] = np.linalg.solve(A, act - nom)
    sin_part = sols[np.pi / 2] - (sols[0.0] + sols[np.pi]) / 2
    return [abs(v) > 1e-9 * (1 + abs(sols[0.0]).max()) for v in sin_part]


def _det_varies(axis: str, rotate: bool, rng) -> bool:
    pts = {lab: rng.uniform(-150, 150, 3) for lab in "PQK"}
    d = [np.linalg.det(_system(pts, th, axis, rotate)[0]) for th in (0.3, 1.1, 2.0)]
    return max(d) - min(d) > 1e-9 * max(abs(x) for x in d)


def audit_d1(d1: dict) -> Verdict:
    rng = np.random.default_rng(31)
    loc = {}
    for lab in "PQK":
        for c in "xyz":
            loc[f"{c}_B{lab}"] = sp.Symbol(f"{c}_{lab}", real=True)
    N = sp.expand(closed_form("x")["N"])
    den = []
    for dd in d1["denominators"]:
        p = sp.expand(sp.sympify(dd["text"], locals=loc))
        den.append((dd["formula"], "+N" if sp.expand(p - N) == 0 else
                    "-N" if sp.expand(p + N) == 0 else "other"))
    comps = ["E_XB", "E_YB", "E_ZB", "E_AB", "E_BB", "E_CB"]
    printed_sin = {k: "sin" in v for k, v in d1["trig"].items()}
    tried, fits = [], []
    for axis, rotate in itertools.product("xyz", (True, False)):
        varies = _det_varies(axis, rotate, rng)
        if rotate:
            tried.append(f"nominal point turned about {axis}, lever arms turned with it (eq. "
                         f"3.5's form): the determinant {'depends' if varies else 'does not depend'}"
                         f" on theta -- the printed denominators do not")
            continue
        sins = _trig(axis, rng)
        pattern = {c: s for c, s in zip(comps, sins)}
        match = not varies and all(pattern[k] == v for k, v in printed_sin.items())
        tried.append(f"nominal point turned about {axis}, lever arms at theta = 0: determinant "
                     f"{'depends on' if varies else 'free of'} theta; sin(theta) in "
                     + (", ".join(c for c in comps if pattern[c]) or "none")
                     + (" -- as printed" if match else " -- not as printed"))
        if match:
            fits.append(axis)
    # what the printed model returns for a pure tilt error at theta = 90 deg
    pts = {lab: rng.uniform(-150, 150, 3) for lab in "PQK"}
    th = np.pi / 2
    A_true, nom, R = _system(pts, th, "z", True)
    e_true = np.array([0, 0, 0, 10e-6, 0, 0])                 # E_A of the B axis, 10 urad
    act = nom + A_true @ e_true
    A_pr, nom_pr, _ = _system(pts, th, "z", False)
    got = np.linalg.solve(A_pr, act - nom_pr)
    demo = ", ".join(f"{c} {v * (1e3 if i < 3 else 1e6):+.2f} {'um' if i < 3 else 'urad'}"
                     for i, (c, v) in enumerate(zip(comps, got)))
    ok_den = all(s in ("+N", "-N") for _, s in den)
    ev = ("the legible denominators (" + ", ".join(f"{f}: {s}" for f, s in den) + ") are all "
          "+-N, the determinant of the selected system with the lever arms of the points at "
          "theta = 0 (the same 15 monomials as appendix C.1's N with B for x), free of theta; "
          f"the numerators hold {d1['trig_text']}. Of the models tried, only the nominal point "
          f"turned about {', '.join(fits) or 'no axis'} with the lever arms left at theta = 0 "
          f"gives both features. The thesis' model of a table axis (eq. 3.4-3.6, {d1['frame_text']}) "
          f"turns the lever arms with the axis, and then the determinant depends on theta: the "
          f"printed formulas solve with the arms of theta = 0 while the point has turned, a "
          f"mixture of the fixed-frame model (which turns the arms) and the body-frame model "
          f"(which turns the deviations back). It is right only at theta = 0: at theta = 90 deg "
          f"(points drawn at random within 150 mm of the axis -- assumed, the text prints no "
          f"positions), a pure tilt E_AB of 10 urad makes the printed model return {demo}; "
          f"other point positions change these numbers (they scale with the error, and the "
          f"mixing with the placement of the points) but not that the result is wrong at "
          f"theta != 0. Category printing_error: the printed code solves another model than the "
          f"one the thesis states (legible structure, not extraction damage)")
    return _v(d1["id"], "B-axis model", "printing_error" if fits and ok_den else "undecidable",
              "lever arms not turned with the axis (the coefficients of theta = 0)", ev,
              d1["signature"], "eq. 3.4-3.6: A(theta) with the turned lever arms", tried,
              ["inconsistent:appendix D.1 lever arms of theta = 0"])


def audit(printed: dict, layouts=None) -> list[Verdict]:
    if layouts is not None and "DMU50" not in layouts:
        return []
    out = []
    if "c1" in printed:
        out.extend(audit_c1(printed["c1"]))
    if "d1" in printed:
        out.append(audit_d1(printed["d1"]))
    return out
