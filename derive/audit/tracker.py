"""Audit of the three-point identification equations of Ellingsdalen (2021) (sympy, no I/O).

The printed equations come as the parsed ``data/printed_tracker.toml`` (its header gives
the symbol mapping).  The authority is :mod:`volerr.derive.three_point`: the small-angle
displacement of a point fixed on the moving body (``(I + D) r - r`` with the error twist of
:mod:`volerr.derive.kinematics`), the ``3n x 6`` system, and the Zhang & Hu closed forms solved
by Cramer's rule.

Checks per printed item

* displacement (eq. 30, 3.4): each row, right-hand side (``expand`` / trigonometric
  simplification of derived - printed) and left-hand side (measured - nominal position);
* systems (eq. 31, 32, 35, 36, 37, 3.5, 3.6): the coefficient rows (each against the derived
  row of the equation its right-hand side names), the number of rows (9 or 6, duplicates), the
  unknown vector, the right-hand side entries, and for a selected system its determinant;
* closed forms (eq. 33-34, 3.7-3.8, the appendix Z-axis solution): every motion with the
  printed M and N substituted, ``cancel(derived - printed) == 0``; the appendix solution is in
  raw coordinates (``d_xP = x'_Pt - x_zP - x_o`` ...);
* denominators (appendix): equal to the derived ones up to a constant factor.

For a closed form that differs, the audit searches the *readings* that reproduce the derived
result exactly: one printed symbol replaced by another lever-arm symbol, or the sign between
the two triple products of N restored (eq. 3.8 prints a product); the first that works names
the erratum.  Identities of rational functions are decided by exact rational evaluation at random points
(:func:`_equal`); polynomial rows and displacements by ``expand``.
"""

from __future__ import annotations

import difflib
import random
import re
from functools import lru_cache

import sympy as sp

from .framework import RECURRENCE_UNSHOWN, Verdict, describe_diff, fmt
from ..three_point import (COORDS, MOTIONS, SELECTIONS, closed_form_once, point_displacement,
                          point_symbols, rotated_lever_arm, system)

SOURCE = "Ellingsdalen 2021"
DATA_FILE = "printed_tracker.toml"
LAYOUTS = ("DMU50",)
LAYOUT = "DMU50"
LABELS = ("P", "Q", "K")
C = sp.Symbol("C", real=True)


def S(name: str) -> sp.Symbol:
    return sp.Symbol(name, real=True)


def _locals(axis: str) -> dict:
    loc = {"C": C, "cos": sp.cos, "sin": sp.sin}
    for lab in LABELS:
        for c in COORDS:
            for pre in ("", "h", "m"):
                n = f"{c}{pre}_{lab}"
                loc[n] = S(n)
            loc[f"d_{c}{lab}"] = S(f"d_{c}{lab}")
    for c in COORDS:
        loc[f"{c}_o"] = S(f"{c}_o")
        loc[c] = S(c)
    for m in MOTIONS:
        loc[m + axis] = S(m + axis)
    for n in ("M", "N"):
        loc[n] = S(n)
    return loc


@lru_cache(maxsize=None)
def parse(text: str, axis: str) -> sp.Expr:
    """A printed expression in the data file's notation -> sympy (ValueError if garbled);
    each text parsed once per process (the checks and readings parse the same entries
    again; the expression is immutable)."""
    loc = _locals(axis)
    try:
        expr = sp.parse_expr(text, local_dict=loc)
    except Exception as exc:  # noqa: BLE001 - any parse failure means "garbled"
        raise ValueError(f"unparsable {text!r}: {exc}") from None
    unknown = [s for s in expr.free_symbols if s not in set(loc.values())]
    if unknown:
        raise ValueError(f"unknown symbol {unknown[0]} in {text!r}")
    return expr


def _hat(expr):
    """Lever-arm symbols x_P, y_P -> the rotated ones xh_P, yh_P (z unchanged): a renaming of
    symbols, so ``xreplace`` (what ``subs(..., simultaneous=True)`` ends in, without its
    detour through dummy products; the same expressions, checked on every closed form)."""
    return expr.xreplace({S(f"{c}_{lab}"): S(f"{c}h_{lab}") for lab in LABELS for c in "xy"})


def _motion_map(axis: str) -> dict:
    return {S(m): S(m + axis) for m in MOTIONS}


def _deviation(label: str, coord: str, axis: str, rotated: bool = False) -> sp.Expr:
    """Derived deviation of point ``label`` along ``coord``: measured - nominal position."""
    m = S(f"{coord}m_{label}")
    o = S(f"{coord}_o")
    if rotated:
        r = rotated_lever_arm(point_symbols(label), (0, 0, 1), C)
        return m - r[COORDS.index(coord)] - o
    nominal = S(f"{coord}_{label}") + o
    if coord == axis.lower():
        nominal += S(coord)
    return m - nominal


# ----------------------------------------------------------------------- exact screening
_RNG = random.Random(20210601)


def _samples(symbols, n: int) -> list[dict]:
    return [{s: sp.Rational(_RNG.randint(-99991, 99991), _RNG.randint(101, 997))
             for s in sorted(symbols, key=str)} for _ in range(n)]


def _equal(a, b, n: int = 8) -> bool:
    """Identity of two rational functions by exact rational evaluation at ``n`` random points
    (Schwartz-Zippel: for the low-degree polynomials here a false "identical" has probability
    far below 1e-20); points where a denominator vanishes are skipped."""
    d = a - b
    exact = _exact_evaluator(d)
    hits = 0
    for point in _samples(d.free_symbols, 3 * n):
        v = exact(point) if exact is not None else None
        if v is None:                     # not a rational function, or a zero denominator
            v = d.xreplace(point)
            if v.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
                continue
        if v != 0:
            return False
        hits += 1
        if hits == n:
            return True
    return False


class _NotRational(Exception):
    pass


def _exact_evaluator(expr):
    """``point -> value`` of a rational function with rational coefficients, evaluated exactly
    in Python fractions (the same value as ``expr.xreplace(point)``, which rebuilds the whole
    expression in sympy at each point), None at a point where a denominator vanishes (sympy
    is asked there); None instead of a function for anything else (floats, functions, I).
    ``point``: {symbol: sympy Rational}."""
    from fractions import Fraction

    consts: list = []
    syms: list = []

    def src(e) -> str:
        if e.is_Symbol:
            if e not in syms:
                syms.append(e)
            return f"p[{syms.index(e)}]"
        if e.is_Rational:
            consts.append(Fraction(int(e.p), int(e.q)))
            return f"c[{len(consts) - 1}]"
        if e.is_Add or e.is_Mul:
            return "(" + (" + " if e.is_Add else " * ").join(src(a) for a in e.args) + ")"
        if e.is_Pow and e.exp.is_Integer:
            return f"({src(e.base)} ** {int(e.exp)})"
        raise _NotRational

    try:
        fn = eval(f"lambda p, c: {src(expr)}")  # noqa: S307 - built above from the tree
    except (_NotRational, SyntaxError, RecursionError, MemoryError):
        return None

    def value(point):
        try:
            return fn([Fraction(int(point[s].p), int(point[s].q)) for s in syms], consts)
        except ZeroDivisionError:
            return None
    return value


def _closed(selection: str) -> dict:
    return closed_form_once(selection)


@lru_cache(maxsize=None)
def _factored(expr: sp.Expr) -> sp.Expr:
    """``sp.factor(expr)``, computed once per expression: a closed form's derived solution is
    factored for its evidence and again for its verdict, and a denominator's is the closed
    form's of the same selection (factor is a pure function of the expression; the verdicts'
    text is unchanged).

    The factorization is sympy's, term for term (:func:`_factor_linear`): the same
    irreducible factors, each with a positive leading coefficient, the same coefficient and
    the same expression built from them."""
    return _factor_linear(expr)


#: the lever arms (mm): the symbols a closed form's numerator is not linear in
_LEVERS = frozenset(S(f"{c}{pre}_{lab}") for lab in LABELS for c in COORDS for pre in ("", "h"))


def _factor_linear(expr: sp.Expr) -> sp.Expr:
    """``sp.factor(expr)`` for a quotient of polynomials whose numerator is of degree at most
    one in the symbols other than the lever arms (a Cramer's-rule solution is linear in the
    right-hand side: the deviations, or the measured positions and offsets they stand for).

    Such a polynomial is its content (the gcd of its coefficients as polynomials in the lever
    arms, factored by sympy) times a primitive part of degree one in the other symbols, which
    is irreducible (a factorization would give one factor of degree zero in them, a common
    divisor of the coefficients).  Sympy proves the same irreducibility with Wang's algorithm
    at many times the cost; the factors are normalized as sympy's (primitive, positive leading
    coefficient in the generators' order) and multiplied as in ``sympy.factor``.  The factors
    of a product are those of its polynomial factors (sympy's ``together`` first is not needed:
    irreducible factors so normalized are unique).  Anything else (a non-integer power, a
    non-polynomial factor, rational coefficients, degree two) is left to ``sp.factor``."""
    from sympy.core.exprtools import _keep_coeff

    coeff, factors = sp.S.One, {}
    for arg in sp.Mul.make_args(expr):   # factors of a product: those of its factors
        if arg.is_Rational:
            coeff *= arg
            continue
        base, exp = arg.as_base_exp() if arg.is_Pow else (arg, sp.S.One)
        poly = sp.Poly(base) if exp.is_Integer and not base.is_Number else None
        listed = _factor_list_linear(poly) if poly is not None and all(
            g.is_Symbol for g in poly.gens) else None
        if listed is None:
            return sp.factor(expr)
        c, fs = listed
        coeff *= c ** exp
        for f, k in fs:
            factors[f] = factors.get(f, 0) + k * exp
    return _keep_coeff(coeff, sp.Mul(*[f.as_expr() ** k for f, k in factors.items()]))


def _factor_list_linear(p: sp.Poly):
    """``p.factor_list()`` (coefficient, [(Poly, multiplicity)]) when ``p`` is over ZZ and
    of degree at most one in its non-lever-arm generators, else None (see
    :func:`_factor_linear`).  A polynomial of lever arms alone (a denominator) is sympy's."""
    if p.domain != sp.ZZ:
        return None
    lin = [i for i, g in enumerate(p.gens) if g not in _LEVERS]
    if not lin:
        return _lever_factor_list(p)
    parts: dict = {}
    for monom, c in p.terms():
        if sum(monom[i] for i in lin) > 1:
            return None
        key = tuple(monom[i] for i in lin)
        rest = tuple(0 if i in lin else e for i, e in enumerate(monom))
        parts.setdefault(key, {})[rest] = c
    R = sp.ring(p.gens, sp.ZZ)[0]       # sparse: gcds far cheaper than the dense Poly's
    content = None
    for terms in sorted(parts.values(), key=len):
        q = R.from_dict(terms)
        content = q if content is None else content.gcd(q)
        if content.is_ground:
            break
    if content.is_ground:                # the usual case: the primitive part is p itself
        c0, fs, rest = sp.S.One, [], p
    else:
        content = sp.Poly.from_dict(dict(content.items()), *p.gens, domain=sp.ZZ)
        (c0, fs), rest = content.factor_list(), p.exquo(content)
    c1, prim = rest.primitive()
    if prim.LC() < 0:
        c1, prim = -c1, -prim
    if not prim.is_ground:
        fs = fs + [(prim, 1)]
    return c0 * c1, fs


@lru_cache(maxsize=None)
def _lever_factor_list(p: sp.Poly):
    """``p.factor_list()``, once per polynomial: the six motions of a selection share their
    denominator."""
    return p.factor_list()


#: the extraction's demonstrated repetitions and losses within one image (quoted by verdicts)
EXTRACTION_REPEATS = (
    "appendix B sec. 2.4 lists the three rotational errors as '(E_AX, E_BX, E_BX) E_CX'; "
    "the error matrix of T_0^{t,c} after thesis eq. 3.37 has five rows, three of them "
    "'-E_{DX} & ... & 1 & E_{ZX}' (D names no axis)")
EXTRACTION_LOSSES = (
    "in the chain after thesis eq. 3.37 T_2^{3,c} has three rows (its row '0 & 0 & 1 & 0' "
    "lost) and the bottom row of the Y axis' error matrix reads '0 & 0 & 0'")


def _letters(unknowns) -> list[str]:
    return [u[1] for u in unknowns]


def _vector_defects(got: list, want: list, others: dict, me: str) -> list[tuple[str, str]]:
    """The defects of a printed unknown vector, each with its cross-copy check against the
    other printed vectors (``others``: equation id -> {"unknowns": ...}): [(defect, copies)]."""
    name = lambda u: f"E_{u[1:]}"  # noqa: E731
    vecs = {o: info["unknowns"] for o, info in others.items() if o != me
            and info.get("unknowns")}
    out = []
    if len(got) == len(want):
        for k, (g, w) in enumerate(zip(got, want)):
            if g == w:
                continue
            again = [j + 1 for j, x in enumerate(got) if x == g and j != k]
            moved = [j + 1 for j, x in enumerate(want) if x == g and j != k]
            what = (f"{name(g)} in the {_ordinal(k + 1)} entry, where {name(w)} belongs"
                    + (f" (a repeat of the {_ordinal(again[0])} entry)" if again else
                       f" (the token of the {_ordinal(moved[0])} entry, which is not printed "
                       f"there)" if moved else ""))
            same = [o for o, v in vecs.items() if len(v) == len(got) and v[k][:2] == g[:2]]
            diff = [f"eq. {o} has {name(v[k])}" for o, v in vecs.items()
                    if len(v) == len(got) and v[k][:2] != g[:2]]
            copies = (f"the same letter stands at the same place in eq. {', '.join(same)} "
                      f"(separately typeset images of the same layout)" if same else
                      f"one image only ({'; '.join(diff)} at this place)")
            out.append((what, copies))
        lost = [w for w in want if w not in got]
        if lost:
            out.append((f"{', '.join(name(w) for w in lost)} printed in no entry (lost)",
                        "follows from the entries above"))
        return out
    lost = [w for w in want if w not in got]
    same = [o for o, v in vecs.items() if len(v) == len(got)
            and [w for w in [m + v[0][2:] for m in MOTIONS] if w not in v] != []
            and [m for m in MOTIONS if m + v[0][2:] not in v] ==
            [m for m in MOTIONS if m + got[0][2:] not in got]]
    out.append((f"{', '.join(name(w) for w in lost)} lost ({len(got)} entries for "
                f"{len(want)} columns, the others in order)",
                f"the same entry is lost in eq. {', '.join(same)} (images of the same layout)"
                if same else "one image only"))
    return out


def _ordinal(k: int) -> str:
    return {1: "1st", 2: "2nd", 3: "3rd"}.get(k, f"{k}th")


def _vector_evidence(eq: dict, others: dict) -> str:
    """Why a wrong unknown vector is undecidable: each defect with its own cross-copy check
    (the same at the same place elsewhere, or one image only), the extraction's record, and
    what would decide."""
    axis = eq["axis"]
    got, want = list(eq["unknowns"]), [m + axis for m in MOTIONS]
    defects = _vector_defects(got, want, others, eq["id"])
    repeat = len(got) == len(want)
    out = " Its defects: " + "; ".join(f"{what} -- {copies}" for what, copies in defects) + "."
    out += (" Category undecidable: print or extraction, and the text decides none of them. "
            "For the print: a vector typed or copied wrong in the author's source. For the "
            "extraction: " + ("a repeated token, with the entry it displaces lost, is damage "
                              "it demonstrably does within one image (" + EXTRACTION_REPEATS
                              + ")" if repeat else "it demonstrably loses entries and rows "
                              "within one image (" + EXTRACTION_LOSSES + ")")
            + ". By the cross-copy rule (docs/formats.md, audit) neither a defect in one "
              "image only nor a repetition or loss at the same place in images of the same "
              "layout decides: the same defect at the same place weighs towards the print, "
              "but " + RECURRENCE_UNSHOWN + ". What would decide: the pages of the original "
              "PDF.")
    return out


#: why a repeated coefficient row is undecidable (print or extraction), by the cross-copy rule
UNDECIDABLE_ROW = (
    " Category undecidable: a row repeated within one image, which the print and the "
    "extraction explain equally. For the print (a matrix copied in the author's source): the "
    "specialization project repeats the same row K y at the same place in eq. 31 (X axis) and "
    "eq. 35 (Y axis), and eq. 35 is eq. 31 with the subscript x changed to y, so a matrix "
    "copied in the source carries the row into both. For the extraction: it demonstrably "
    "repeats matrix rows within an image (the error matrix of T_0^{t,c} after thesis eq. 3.37 "
    "has five rows, three of them '-E_{DX} & ... & 1 & E_{ZX}' and two of these identical, "
    "with the letter D that names no axis), and eq. 31 and 35 are images of the same layout "
    "(they differ only in the subscripts x and y). The same row at the same place in the two "
    "images weighs towards the print, but by the cross-copy rule a repetition at the same "
    "place does not decide: " + RECURRENCE_UNSHOWN + ". The thesis' eq. 3.5 (the same nine "
    "rows for the C axis, other symbols) has no repeated row, which decides neither. What "
    "would decide: the page of the original PDF.")
UNDECIDABLE_ENTRIES = (
    ". Category undecidable: lost, repeated or merged entries of a column vector, which the "
    "print (a line of the column typed wrong, left out or typed twice) and the extraction "
    "explain equally -- this extraction demonstrably repeats and loses entries within one "
    "image (" + EXTRACTION_REPEATS + "; " + EXTRACTION_LOSSES + "); what would decide: the "
    "page of the original PDF.")
UNDECIDABLE_N = (
    " Category undecidable: a '-' between two bracketed triple products is lost (the printed "
    "N is one product of six factors). For the print: a sign left out while typing. For the "
    "extraction: it damages operators in this document (Listing 3.1 reads 'if degree = 1:', "
    "a Python syntax error, where the copy of the same code in the appendix reads 'if degree "
    "== 1:'). The specialization project prints the same formula for the X axis (x_x "
    "symbols) with its minus (eq. 34, 'N = (x_{xK} - x_{xQ})(y_{xP} - y_{xQ})(z_{xP} - "
    "z_{xK}) - (x_{xK} - x_{xP})...'), and the denominators of the thesis' appendix D.1 script "
    "are the determinant up to its sign (see the D.1 verdict): the author computed with the "
    "right N. Neither separates the print from the extraction -- the defect stands in this "
    "copy only, so the cross-copy rule does not decide it; missing to decide: the page of the "
    "original PDF.")


def _verdict(eq, comp, ok, erratum, evidence, printed, derived,
             category: str = "printing_error") -> Verdict:
    return Verdict(SOURCE, f"eq. {eq['id']}" if eq["id"][0].isdigit() else eq["id"], LAYOUT,
                   "identical" if ok else "differs", "" if ok else erratum, evidence,
                   printed if isinstance(printed, str) else fmt(printed),
                   derived if isinstance(derived, str) else fmt(derived), comp,
                   category="identical" if ok else category)


# ------------------------------------------------------------------------- displacement
def audit_displacement(eq: dict) -> list[Verdict]:
    axis = eq["axis"]
    rotated = axis in "ABC"
    r = point_symbols("P")
    lever = rotated_lever_arm(r, (0, 0, 1), C) if rotated else sp.Matrix(r)
    disp = point_displacement(lever).subs(_motion_map(axis))
    out = []
    for i, c in enumerate(COORDS):
        pr = parse(eq["expr"][c], axis)
        de = sp.expand(disp[i])
        diff = sp.simplify(sp.expand_trig(de - pr))
        if diff == 0:
            out.append(_verdict(eq, f"Delta_{c} right-hand side", True, "",
                                "expand(derived - printed) == 0: derived as (I + D) r - r with "
                                "the error twist D of the six motions"
                                + (", r = Rz(C) r_P (eq. 3.2)" if rotated else ""),
                                eq["expr"][c], de))
        else:
            named = describe_diff(de, sp.expand(pr))
            out.append(_verdict(
                eq, f"Delta_{c} right-hand side", False,
                named,
                f"the derived row is {fmt(sp.collect(de, list(r)))}; the printed row differs by "
                f"{fmt(sp.collect(sp.expand(pr - de), list(r)))} (derived - printed = "
                f"{fmt(diff)}). The printed coefficient of x_P, {fmt(sp.expand(pr).coeff(r[0]))}"
                f", is not the z-row of e x r_hat = EAC*yh - EBC*xh with xh = x cos C - y sin "
                f"C, yh = x sin C + y cos C." if rotated else
                f"derived - printed = {fmt(diff)}", eq["expr"][c], de))
            if rotated:
                raw_z = next((ln.strip() for ln in eq.get("text", "").splitlines()
                              if ln.strip().startswith(f"{c}'_{{Pt}}")), "")
                out[-1].evidence += (
                    (f" The extraction text of the row: '{raw_z}'." if raw_z else "")
                    + " Read as [-E_BC cos C + E_AC sin C] x_P the row is the derived one: the "
                    "printed coefficient lost a minus sign and the factor 'sin C' (the thesis' "
                    "eq. 2.42 prints the same row with both). Category undecidable: lost "
                    "glyphs, which the print and the text extraction explain equally; what "
                    "would decide: the page of the original PDF.")
                out[-1].category = "undecidable"
                out[-1].readings_tried = ["the z-row of (I + D) Rz(C) r - Rz(C) r (derived): "
                                          "the x_P coefficient differs",
                                          "a minus and 'sin C' lost by the print or by the "
                                          "extraction: exact"]
                out[-1].readings_used = [f"glyph:eq. {eq['id']} Delta_{c} lost glyphs"]
        lhs = parse(eq["lhs"][c], axis)
        dl = _deviation("P", c, axis, rotated)
        ok = sp.simplify(sp.expand(dl - lhs)) == 0
        out.append(_verdict(eq, f"Delta_{c} left-hand side", ok,
                            f"row {c}: measured - nominal printed as {eq['lhs'][c]}",
                            "measured minus nominal position of P"
                            + (" (nominal: Rz(C) r_P + o)" if rotated else
                               f" (nominal: r_P + o + displacement along {axis})"),
                            eq["lhs"][c], dl))
    return out


# ------------------------------------------------------------------ the raw extraction text
_BMATRIX = re.compile(r"\\begin\{bmatrix\}(.*?)\\end\{bmatrix\}", re.S)
_X_SUBSCRIPT = re.compile(r"\\hat\{[xy]\}_\{x[PQK]\}")


def _raw_blocks(eq: dict) -> list[list[str]]:
    """The rows (raw LaTeX, stripped) of every bmatrix of the equation's extraction text."""
    return [[r.strip() for r in body.split("\\\\")]
            for body in _BMATRIX.findall(eq.get("text", ""))]


def _raw_matrix(eq: dict) -> list[str]:
    blocks = _raw_blocks(eq)
    return blocks[0] if blocks else []


def _raw_vector(eq: dict) -> str:
    blocks = _raw_blocks(eq)
    return ", ".join(blocks[1]) if len(blocks) > 1 else ""


def wrong_subscripts(eq: dict) -> list[tuple[str, int, str]]:
    """Lever arms of a rotary system printed with the X axis' subscript (``\\hat{x}_{xP}``
    where the C axis' ``\\hat{x}_{CP}`` belongs): (row label, column 1..6, raw entry).  The
    data file's rows read them with C (its symbol mapping); this reads the raw text."""
    if eq.get("axis") not in ("A", "B", "C"):
        return []
    out = []
    for (lab, _), raw in zip(eq["rows"], _raw_matrix(eq)):
        for j, cell in enumerate(raw.split("&"), start=1):
            if _X_SUBSCRIPT.search(cell):
                out.append((lab, j, cell.strip()))
    return out


def _pair_note(eq: dict, wrong) -> str:
    """' ('\\hat{x}_{CK}' (row Ky) and '\\hat{x}_{xK}' (row Kz) stand in one matrix)' for the
    first wrong lever arm whose C-subscripted form is printed in the same matrix."""
    cells = [(lab, c.strip()) for (lab, _), raw in zip(eq["rows"], _raw_matrix(eq))
             for c in raw.split("&")]
    for lab, _, text in wrong:
        m = re.search(r"\\hat\{([xy])\}_\{x([PQK])\}", text)
        right = f"\\hat{{{m.group(1)}}}_{{C{m.group(2)}}}"
        hit = next((lb for lb, c in cells if right in c), None)
        if hit:
            return (f" ('{right}' in row {hit} and '{m.group(0)}' in row {lab} stand in one "
                    f"matrix)")
    return ""


def _same_places(wrong, other_labels, other_wrong, labels) -> bool:
    """Whether another system's wrong subscripts stand at exactly the same entries as
    ``wrong`` in every row the two systems share (and there is at least one)."""
    shared = set(labels) & set(other_labels)
    mine = {(lab, j) for lab, j, _ in wrong if lab in shared}
    theirs = {(lab, j) for lab, j, _ in other_wrong if lab in shared}
    return bool(mine) and mine == theirs


# ------------------------------------------------------------------------------- systems
def _derived_rows(axis: str, rotated: bool) -> dict:
    A, rows = system(LABELS)
    if rotated:
        # the rotary system is the linear one at the rotated lever arms (eq. 3.5): check it
        Ar, _ = system(LABELS, rotary_axis=(0, 0, 1), angle=C)
        sub = {}
        for lab in LABELS:
            xr, yr, _ = rotated_lever_arm(point_symbols(lab), (0, 0, 1), C)
            sub[S(f"x_{lab}")], sub[S(f"y_{lab}")] = xr, yr
        assert sp.simplify(Ar - A.subs(sub, simultaneous=True)) == sp.zeros(*A.shape)
        A = _hat(A)
    return {f"{lab}{c}": list(A.row(i)) for i, (lab, c) in enumerate(rows)}


def _wrong_subscripts_reading(eq: dict, wrong: list, others: dict | None, labels: list,
                              raw: list, problems: list) -> tuple[str, list, list]:
    """Lever arms printed with the X axis' subscript where the C axis' belongs: the problem
    (appended to ``problems``), the note on its category, the readings tried and used."""
    problems.append(f"{len(wrong)} lever arms printed with the X axis' subscript x where "
                    f"the C axis' C belongs: " + ", ".join(
                        f"row {lab} column {j}: '{text}'" for lab, j, text in wrong))
    same_in = [other for other, info in (others or {}).items()
               if other != eq["id"] and _same_places(wrong, info["labels"], info["wrong"],
                                                     labels)]
    note = (
        f" Read with C, every coefficient is the derived one (the rotated lever arms "
        f"x^_Ci = x_Ci cos C - y_Ci sin C, y^_Ci = y_Ci cos C + x_Ci sin C the thesis "
        f"defines under eq. 3.5); the other hatted lever arms of this matrix carry C."
        + (f" Category printing_error by the cross-copy rule: eq. "
           f"{', '.join(same_in)} prints the x at exactly the same entries of the rows it "
           f"shares (two images), a substitution an extraction would have to invent "
           f"identically in both while reading C in the other entries of the same form"
           f"{_pair_note(eq, wrong)}. It is no repetition within an image: "
           + ("none of the x-subscripted lever arms stands elsewhere in its matrix"
              if all(" & ".join(raw).count(re.search(r"\\hat\{[xy]\}_\{x[PQK]\}",
                                                       t).group(0)) == 1
                     for _, _, t in wrong) else
              "(an x-subscripted lever arm stands twice in its matrix)")
           + f", and the rows that "
           f"carry them stand at other places in the two images ("
           + "; ".join(f"eq. {o}: rows " + ", ".join(
               str(k + 1) for k, lab in enumerate((others or {})[o]["labels"])
               if lab in {w[0] for w in wrong}) for o in [eq["id"], *same_in])
           + f"), so the x follows the rows' content, not their places in the "
           f"images. The competing explanation, the "
           f"extraction writing x for C, would need the same five misreadings in two "
           f"images of another row order; the author's source explains it: the C-axis "
           f"system adapted from the X-axis system of the specialization project (eq. 31 "
           f"and 32 print x_{{xP}}, y_{{xQ}} ... at these places) with some subscripts "
           f"left unchanged."
           if same_in else
           " Category printing_error: a well-formed lever arm of another axis' "
           "system (the X axis' subscript of eq. 31-32)."))
    tried = ["every printed row against the derived row its right-hand side names, the "
             "lever arms read as printed: " + f"{len(wrong)} entries name the X axis' "
             f"lever arms", "the entries read with the C axis' subscript: every row the "
             "derived one"]
    used = [f"copy:eq. {eq['id']} lever arms of the X-axis system"]
    return note, tried, used


def _unknown_vector_verdicts(eq: dict, axis: str, others: dict | None) -> list[Verdict]:
    """The verdict on the printed unknown vector: E_X ... E_C of the axis, in this order."""
    out = []
    want_u = [m + axis for m in MOTIONS]
    got_u = list(eq["unknowns"])
    if got_u == want_u:
        out.append(_verdict(eq, "unknown vector", True, "", "E_X, E_Y, E_Z, E_A, E_B, E_C of "
                            f"axis {axis}", ", ".join(got_u), ", ".join(want_u)))
    else:
        missing = [u for u in want_u if u not in got_u]
        twice = sorted({u for u in got_u if got_u.count(u) > 1})
        parts = []
        if missing:
            parts.append(f"{', '.join(missing)} missing")
        if twice:
            parts.append(f"{', '.join(twice)} listed twice")
        if len(got_u) != 6:
            parts.append(f"{len(got_u)} unknowns for 6 columns")
        vec = _raw_vector(eq)
        out.append(_verdict(eq, "unknown vector", False, "; ".join(parts),
                            "the six columns multiply E_X ... E_C of the axis in this order "
                            "(every coefficient column is the derived one, read with the "
                            "subscripts of the axis: see the verdict on the coefficient "
                            "matrix); the printed vector"
                            + (f" [{vec}]" if vec else "") + " mislabels them: "
                            + "; ".join(parts) + "." + _vector_evidence(eq, others or {}),
                            ", ".join(got_u), ", ".join(want_u), category="undecidable"))
        out[-1].readings_tried = ["the vector as printed: " + "; ".join(parts),
                                  "entries repeated or lost by the print (a copied vector) or "
                                  "by the extraction (a repeated token): the vector the six "
                                  "columns multiply (E_X ... E_C of the axis)"]
        out[-1].readings_used = [f"glyph:eq. {eq['id']} unknown vector"]
    return out


def audit_system(eq: dict, others: dict | None = None) -> list[Verdict]:
    """Verdicts on a printed system; ``others``: equation id -> {"labels": row labels,
    "wrong": lever arms with the X axis' subscript (:func:`wrong_subscripts`), "unknowns":
    the printed unknown vector} of every printed system, for the cross-copy rule."""
    axis = eq["axis"]
    rotated = axis in "ABC"
    derived = _derived_rows(axis, rotated)
    out = []
    rows = eq["rows"]
    full = "selection" not in eq
    expect_n = 3 * len(LABELS) if full else 6
    labels = [lab for lab, _ in rows]
    dup = sorted({lab for lab in labels if labels.count(lab) > 1})
    bad_rows = []
    for k, (lab, coeffs) in enumerate(rows):
        pr = [parse(c, axis) for c in coeffs]
        if any(sp.expand(a - b) != 0 for a, b in zip(derived[lab], pr)):
            bad_rows.append(f"row {k + 1} ({lab}): printed {pr}, derived {derived[lab]}")
    problems = []
    if len(rows) != expect_n:
        problems.append(f"{len(rows)} rows printed for {expect_n} equations")
    if dup:
        problems.append(f"row(s) {', '.join(d[0] + ' ' + d[1] for d in dup)} printed twice")
    if full and set(labels) != set(derived):
        problems.append(f"row(s) {sorted(set(derived) - set(labels))} missing")
    problems.extend(bad_rows)
    sel_note = ""
    if not full:
        sel = eq["selection"]
        want = ["".join(r) for r in SELECTIONS[sel]]
        if labels != want:
            problems.append(f"rows {labels} are not the Zhang & Hu selection {want}")
        det = _closed(sel)["N"]
        sel_note = (f" The selected 6 x 6 system has determinant N = {fmt(_factored(det))} "
                    f"(rotated coordinates for a rotary axis): it is singular whenever N = 0, "
                    f"even for non-collinear points (e.g. all points at one height z).")
    raw = _raw_matrix(eq)
    wrong = wrong_subscripts(eq)
    note, tried, used, category = "", [], [], "printing_error"
    if dup and not bad_rows:
        rep = [r for k, r in enumerate(raw) if k and r == raw[k - 1]]
        note = (f" The repeated row reads '{rep[0]}' twice in a row; the right-hand side "
                f"has the {len(set(labels))} entries of the {len(set(labels))} equations, once "
                f"each." if rep else "") + UNDECIDABLE_ROW
        category = "undecidable"
        tried = ["every printed row against the derived row its right-hand side names: "
                 "row(s) " + ", ".join(d[0] + " " + d[1] for d in dup) + " printed twice",
                 "a row repeated by the print (a copied matrix) or by the extraction (a "
                 "repeated span): the derived system once the repeated row is read once"]
        used = [f"glyph:eq. {eq['id']} repeated row " + ", ".join(d[0] + " " + d[1]
                                                                  for d in dup)]
    elif wrong and not problems:
        note, tried, used = _wrong_subscripts_reading(eq, wrong, others, labels, raw,
                                                      problems)
    out.append(_verdict(eq, "coefficient matrix", not problems,
                        "; ".join(problems[:3]) if problems else "",
                        ("every printed row equals the derived row of the equation its "
                         "right-hand side names" if not problems else
                         "compared row by row with the derived system: " + "; ".join(problems)
                         + ".")
                        + sel_note + note,
                        f"{len(rows)} rows" if not wrong else
                        f"{len(rows)} rows; " + "; ".join(f"{lab} column {j}: {text}"
                                                         for lab, j, text in wrong),
                        f"{expect_n} rows", category=category))
    if problems:
        out[-1].readings_tried = tried or ["every printed row against the derived row its "
                                           "right-hand side names"]
        out[-1].readings_used = used
    out.extend(_unknown_vector_verdicts(eq, axis, others))
    # right-hand side: which equation does each printed entry belong to?
    out.append(_audit_rhs(eq, labels, others or {}))
    return out


def rhs_matched(eq: dict) -> list:
    """The row label (point + coordinate, ``"Kx"``) whose derived deviation each printed
    right-hand side entry is, or None for an entry that is no deviation of any point."""
    axis = eq["axis"]
    rotated = axis in "ABC"
    want = _rhs_wanted(axis, rotated)
    return [next((lab for lab, w in want.items() if sp.expand(parse(t, axis) - w) == 0), None)
            for t in eq.get("rhs", [])]


def _rhs_wanted(axis: str, rotated: bool) -> dict:
    labels = [f"{lab}{c}" for lab in LABELS for c in COORDS]
    return {lab: (S(f"d_{lab[1]}{lab[0]}") if rotated else _deviation(lab[0], lab[1], axis))
            for lab in labels}


def _order_kept(matched: list, labels: list) -> bool:
    """Whether the entries that name a row stand in the order of the rows."""
    distinct = list(dict.fromkeys(labels))
    order = [lab for lab in dict.fromkeys(m for m in matched if m) if lab in distinct]
    return order == [lab for lab in distinct if lab in order]


def _point_blocks(matched: list, distinct: list):
    """The printed column as blocks of one point each, ``[(point, [labels])]``, when every
    point's entries stand together and in the rows' order within the block (a column whose
    points are merely in another order); None otherwise."""
    runs = []
    for lab in (m for m in matched if m):
        if runs and runs[-1][0] == lab[0]:
            runs[-1][1].append(lab)
        else:
            runs.append((lab[0], [lab]))
    points = [p for p, _ in runs]
    if len(points) != len(set(points)):
        return None
    for p, labs in runs:
        seen = list(dict.fromkeys(labs))
        if seen != [lab for lab in distinct if lab in seen]:
            return None
    return runs


def _align(expected: list, printed: list) -> list[str]:
    """What the printed column lost, repeated or replaced against ``expected`` (labels;
    None for an entry that names no row), in words."""
    got = [m or "?" for m in printed]
    parts = []
    for tag, i1, i2, j1, j2 in difflib.SequenceMatcher(a=expected, b=got,
                                                       autojunk=False).get_opcodes():
        if tag == "delete":
            parts.append(f"lost {', '.join(expected[i1:i2])}")
        elif tag == "insert":
            parts.append(f"has {', '.join(got[j1:j2])} in addition")
        elif tag == "replace":
            for k, (e, g) in enumerate(zip(expected[i1:i2], got[j1:j2])):
                near = [got[j] for j in (j1 + k - 1, j1 + k + 1) if 0 <= j < len(got)]
                parts.append(f"has {g} where {e} belongs" + (" (a repeat of the entry "
                                                              "beside it)" if g in near else ""))
            if i2 - i1 > j2 - j1:
                parts.append(f"lost {', '.join(expected[i1 + j2 - j1:i2])}")
            elif j2 - j1 > i2 - i1:
                parts.append(f"has {', '.join(got[j1 + i2 - i1:j2])} in addition")
    return parts


def _points_named(eq: dict, order: list) -> str:
    """The text's own listings of the points (``points_named`` of the data file) that name
    them in ``order``, quoted."""
    hits = []
    for quote, where in eq.get("points_named", []):
        named = list(dict.fromkeys(re.findall(r"\b([PQK])\b", quote)))
        if named == order:
            hits.append(f"'{quote}' ({where})")
    return "; ".join(hits)


def _audit_rhs(eq: dict, labels: list, others: dict) -> Verdict:
    """The verdict on a printed system's right-hand side: each entry matched against the
    derived deviation of every point and coordinate.  Lost, repeated or merged entries are
    glyph-level (print or extraction: undecidable); a column whose points' blocks stand in
    another order than the rows is a well-formed misordering the extraction is not seen to
    produce, decided as printed (the entry is then printing_error, its other defects named
    as undecided)."""
    rhs = eq.get("rhs", [])
    axis = eq["axis"]
    distinct = list(dict.fromkeys(labels))
    want = _rhs_wanted(axis, axis in "ABC")
    matched = rhs_matched(eq)
    problems = []
    order_note, order_decided, runs, row_points = "", False, None, []
    tried = ["each printed entry matched against the derived deviation of every point and "
             "coordinate"]
    used = [f"glyph:eq. {eq['id']} right-hand side entries"]
    if matched != distinct:
        if len(rhs) != len(distinct):
            problems.append(f"{len(rhs)} entries for {len(distinct)} equations")
        for k, (text, lab) in enumerate(zip(rhs, matched)):
            if lab is None:
                guess = distinct[k] if k < len(distinct) else None
                hint = f" (row {guess} needs {fmt(want[guess])})" if guess else ""
                blocks = _raw_blocks(eq)
                rawe = blocks[2][k] if len(blocks) > 2 and k < len(blocks[2]) else ""
                problems.append(f"entry {k + 1} {text!r}"
                                + (f" (raw '{rawe}')" if rawe else "")
                                + f" is no deviation of any point{hint}")
        twice = sorted({lab for lab in matched if lab and matched.count(lab) > 1})
        if twice:
            problems.append(f"entry for {', '.join(twice)} printed twice")
        missing = [lab for lab in distinct if lab not in matched]
        if missing:
            problems.append(f"no entry for row(s) {', '.join(missing)}")
        order = [lab for lab in dict.fromkeys(m for m in matched if m) if lab in distinct]
        rows_order = [lab for lab in distinct if lab in order]
        if order != rows_order:
            problems.append(f"entries in the order {', '.join(order)}, rows in the order "
                            f"{', '.join(rows_order)}")
            runs = _point_blocks(matched, distinct)
            row_points = list(dict.fromkeys(lab[0] for lab in distinct))
            col_points = [p for p, _ in runs] if runs else []
            if runs and col_points != [p for p in row_points if p in col_points]:
                order_decided = True
                order_note = _order_evidence(eq, matched, distinct, runs, row_points,
                                             others)
                tried.append(f"the entries' order: the blocks of the points in the order "
                             f"{', '.join(col_points)}, the rows {', '.join(row_points)} -- a "
                             f"block moved within the column, which the extraction is not "
                             f"seen to do; the author's order (print): decided")
                used.insert(0, f"inconsistent:eq. {eq['id']} right-hand side in the point "
                               f"order {', '.join(col_points)}, rows "
                               f"{', '.join(row_points)}")
            else:
                order_note = (" The order defect is no whole block of one point's entries "
                              "in another place (a point's entries stand apart or out of "
                              "their order): print or extraction, undecided too.")
        elif problems:
            order_note = (" The entries that name a row stand in the order of the rows (no "
                          "order defect).")
    tried.append("entries lost, repeated or garbled by the print or by the extraction: both "
                 "explain " + ("them" if order_decided else "the column"))
    if not problems:
        evidence = ("each entry is the deviation (measured - nominal) of the point and "
                    "coordinate of its row")
    elif order_decided:
        evidence = ("each entry matched against the derived deviations (measured - nominal) "
                    "of every point and coordinate: " + "; ".join(problems) + "." + order_note)
    else:
        evidence = ("each entry matched against the derived deviations (measured - nominal) "
                    "of every point and coordinate: " + "; ".join(problems) + "."
                    + order_note + UNDECIDABLE_ENTRIES.lstrip("."))
    short = [p for p in problems if not p.startswith("entries in the order")]
    if order_decided:
        short = [f"entries in the point order {', '.join(p for p, _ in runs)}, rows "
                 f"{', '.join(row_points)}"] + short
    elif len(short) < len(problems):
        short = short + [p for p in problems if p.startswith("entries in the order")]
    v = _verdict(eq, "right-hand side", not problems, "; ".join(short[:3]),
                 evidence, "; ".join(rhs), f"{len(distinct)} deviations",
                 category="printing_error" if order_decided else "undecidable")
    if problems:
        v.readings_tried, v.readings_used = tried, used
    return v


#: the extraction's record on the order of a column's entries (checked on every column vector
#: of the thesis' extraction, the seed text)
EXTRACTION_ORDER_RECORD = (
    "every other column vector of the thesis' extraction keeps its entries in their order -- "
    "the coordinates and deviations of eq. 3.1-3.3 and of the project's eq. (27)-(29), the "
    "unknown vectors of eq. 31-37, 3.5 and 3.6 -- and where it damages one it loses, repeats "
    "or exchanges entries in place (the project's eq. (29) prints z'_Pt at the z place of "
    "the nominal vector, beside the measured vector that lost it); what it does put out of "
    "order is whole numbered display "
    "equations laid out side by side on a page (eq. 3.34 is read between eq. 3.30 and 3.31), "
    "not entries within one bracket")


def _order_evidence(eq, matched, distinct, runs, row_points, others) -> str:
    """Why a right-hand side whose points' blocks stand in another order is decided as printed,
    and what stays undecided (its lost, repeated or merged entries)."""
    col_points = [p for p, _ in runs]
    moved = next(p for p, q in zip(col_points, [p for p in row_points if p in col_points])
                 if p != q)
    block = [lab for p, labs in runs if p == moved for lab in dict.fromkeys(labs)]
    where = col_points.index(moved)
    rows_at = [p for p in row_points if p in col_points].index(moved)
    place = lambda i, n: ("the top" if i == 0 else "the bottom" if i == n - 1  # noqa: E731
                          else f"place {i + 1}")
    kept = [f"eq. {o}" for o, info in others.items() if o != eq["id"] and info.get("rhs")
            and _order_kept(info["rhs"], info["labels"])]
    damaged = [f"eq. {o}" for o, info in others.items() if o != eq["id"] and info.get("rhs")
               and _order_kept(info["rhs"], info["labels"])
               and info["rhs"] != list(dict.fromkeys(info["labels"]))]
    not_kept = [f"eq. {o}" for o, info in others.items() if o != eq["id"] and info.get("rhs")
                and not _order_kept(info["rhs"], info["labels"])]
    expected = [lab for p in col_points for lab in distinct if lab[0] == p]
    named = _points_named(eq, col_points)
    same_rows = [o for o, info in others.items() if o != eq["id"]
                 and list(dict.fromkeys(info["labels"])) == distinct]
    n = len(col_points)
    return (
        f" Two kinds of defect. (1) The order: the block of point {moved} "
        f"({', '.join(block)}) stands at {place(where, n)} of the column while its rows stand "
        f"at {place(rows_at, n)} of the matrix (rows in the point order "
        f"{', '.join(row_points)}, entries in the point order {', '.join(col_points)}). That is "
        f"no lost, repeated or merged entry: the column is well formed in another point "
        f"order. The extraction is not seen to move entries within a column: "
        + (f"the right-hand sides of {', '.join(not_kept)} are out of order too" if not_kept
           else "no other printed system to compare" if not kept else
           f"the right-hand side of every other printed system keeps the order of its rows "
           f"({', '.join(kept)}"
           + (f"; {', '.join(damaged)} with entries lost or merged in place" if damaged else "")
           + ")")
        + f", and {EXTRACTION_ORDER_RECORD}. For the print: the author's column written in the "
        f"point order {', '.join(col_points)}"
        + (f", the order in which the text names the points ({named})" if named else "")
        + f", beside a matrix in the order {', '.join(row_points)}"
        + (f" (the row order of eq. {', '.join(same_rows)}"
           + ("; the X axis' subscripts left in this matrix show it adapted from the X-axis "
              "system, see the verdict on the coefficient matrix" if wrong_subscripts(eq)
              else "") + ")" if same_rows else "")
        + ". For the extraction: it would have to move a block of one column, which it is "
        f"nowhere seen to do. So the order is decided: the author's (a printing error). "
        f"(2) The entries: against the rows' entries in the column's own point order "
        f"({', '.join(expected)}) the column " + " and ".join(_align(expected, matched))
        + " -- lost, repeated or merged entries, which the print (a line of the column typed "
        "wrong, left out or typed twice) and the extraction explain equally (this extraction "
        "demonstrably repeats and loses entries within one image: " + EXTRACTION_REPEATS
        + "; " + EXTRACTION_LOSSES + "): undecided. Category printing_error: the order is "
        "decided to be printed; the lost and repeated entries stay undecided (what would "
        "decide them: the page of the original PDF).")


# --------------------------------------------------------------------------- closed forms
def raw_line(eq: dict, motion: str) -> str:
    """The extraction's line of ``motion`` (``EY`` -> the line 'E_{YX}(x) = ...') in the
    equation's text, "" if not found."""
    head = f"E_{{{motion[1]}{eq['axis']}}}("
    for line in eq.get("text", "").splitlines():
        if line.strip().startswith(head):
            return line.strip()
    return ""


def _printed_solution(eq: dict, motion: str, use_ocr: bool = True) -> tuple[sp.Expr, str]:
    axis = eq["axis"]
    text = eq["expr"][motion]
    note = ""
    if use_ocr and motion in eq.get("ocr", {}):
        raw = raw_line(eq, motion)
        scoped = re.findall(r"z_\{x[PQK]\([^{}]*(?:\{[^{}]*\}[^{}]*)*\)\}", raw)
        others = [f"{m}{axis}: '{f}'" for m in eq.get("ocr", {}) if m != motion
                  for f in re.findall(r"z_\{x[PQK]\([^{}]*(?:\{[^{}]*\}[^{}]*)*\)\}",
                                      raw_line(eq, m))]
        note = (f" The extraction text of the line is '{raw}': "
                + (f"the subscript {scoped[0][2:]!s} of z holds the factor that multiplies "
                   f"z, i.e. the printed formula reads z indexed by an expression, which no "
                   f"formula of the document's notation does" if scoped else
                   "a subscript swallowed the multiplied factor")
                + f"; transcribed {text!r} and read as {eq['ocr'][motion]!r}"
                + (f"; the same scope defect stands in the line of {', '.join(others)}"
                   if others else "") + ".")
        text = eq["ocr"][motion]
    expr = parse(text, axis)
    define = {S(k): parse(v, axis) for k, v in eq.get("define", {}).items()}
    return expr, note, define


def _derived_solution(eq: dict, motion: str) -> sp.Expr:
    sol = _closed(eq["selection"])[motion]
    if eq.get("rotated"):
        sol = _hat(sol)
    if eq.get("variables") == "raw":
        axis = eq["axis"]
        sub = {S(f"d_{c}{lab}"): _deviation(lab, c, axis) for lab in LABELS for c in COORDS}
        sol = sol.subs(sub, simultaneous=True)
    return sol


def _top_level_factors(text: str) -> list[str]:
    """The parenthesised factors of a printed product, in printed order: ``(a)(b)*(c)``."""
    out, depth, start = [], 0, None
    for i, ch in enumerate(text):
        if ch == "(":
            if depth == 0:
                start = i
            depth += 1
        elif ch == ")":
            depth -= 1
            if depth == 0:
                out.append(text[start:i + 1])
        elif depth == 0 and ch not in " *":
            return []
    return out


def _product_readings(text, axis, det):
    """Readings of a printed N that is one product of six factors: the minus sign between two
    consecutive partial products restored.  Returns the repaired N or None."""
    factors = [parse(f, axis) for f in _top_level_factors(text)]
    if len(factors) != 6:
        return None
    for split in range(1, 6):
        a, b = sp.Mul(*factors[:split]), sp.Mul(*factors[split:])
        for cand in (a - b, b - a):
            if _equal(cand, det) or _equal(cand, -det):
                return cand
    return None


def _swap_search(printed, define, derived):
    """One printed lever-arm symbol of the solution (not of M, N) replaced by another makes it
    equal the derived one: ``(old, new)`` or None.  Screened numerically (the replacement is a
    change of one argument value), confirmed exactly."""
    import numpy as np

    full = printed.subs(define)
    syms = sorted(full.free_symbols | derived.free_symbols, key=str)
    aux = sorted(define, key=str)
    outer = printed.free_symbols
    lever = [s for s in syms if s.name[0] in "xyz" and s.name[1:3] in ("_P", "_Q", "_K", "h_")]
    f_pr = sp.lambdify(syms + aux, printed, "numpy")
    f_aux = [sp.lambdify(syms, define[a], "numpy") for a in aux]
    f_de = sp.lambdify(syms, derived, "numpy")
    rng = np.random.default_rng(7)
    points = [rng.uniform(-300, 300, len(syms)) for _ in range(2)]
    with np.errstate(all="ignore"):
        want = [f_de(*p) for p in points]
        auxv = [[f(*p) for f in f_aux] for p in points]
        for old in (s for s in lever if s in outer):
            io = syms.index(old)
            for new in lever:
                if new == old:
                    continue
                ok = True
                for p, w, av in zip(points, want, auxv):
                    q = p.copy()
                    q[io] = p[syms.index(new)]
                    v = f_pr(*q, *av)
                    if not np.isfinite(v) or abs(v - w) > 1e-9 * max(1.0, abs(w)):
                        ok = False
                        break
                if ok and _equal(derived, printed.subs(old, new).subs(define)):
                    return old, new
    return None


#: how a rotated lever-arm symbol of the data file is written in the extraction text
def _tex(sym) -> str:
    n = str(sym)
    if "h_" in n:
        return f"\\hat{{{n[0]}}}_{{C{n[-1]}}}"
    return f"{n[0]}_{{x{n[-1]}}}" if n[1] == "_" else n


def _swap_evidence(eq: dict, motion: str, old, new, n_fixed: bool) -> str:
    """Why one lever-arm symbol printed for another is undecidable when the printed symbol
    stands in the neighbouring lines of the same equation block (a candidate repetition),
    and why the other copy of the solution does not decide it."""
    axis = eq["axis"]
    others = [m for m in eq["expr"] if m != motion
              and old in parse(eq["expr"][m], axis).free_symbols]
    pattern = f"+ ({old} - "
    same_place = [m for m in others if pattern in eq["expr"][m] and pattern in eq["expr"][motion]]
    names = {m: f"E_{m[1]}{axis}" for m in eq["expr"]}
    where = ", ".join(names[m] for m in others)
    out = (f" The printed symbol {_tex(old)} (read {old}) stands where {_tex(new)} belongs. It "
           f"also stands in the lines of {where} of the same equation block"
           + (f" -- in the line of {', '.join(names[m] for m in same_place)} at the same place "
              f"(the first symbol of the numerator of the second fraction, '{pattern[2:]}...')"
              if same_place else "")
           + ": a candidate repetition within one image. For the print: the author writing "
             "the numerator from the neighbouring line. For the extraction: a token of the "
             "neighbouring line emitted again in place of the right one, damage it "
             "demonstrably does within one image (" + EXTRACTION_REPEATS + "); it also "
             "invents well-formed symbols in this document (T_6^{t,c} where the C axis' factor "
             "belongs in the chain after eq. 3.37), so a well-formed wrong symbol alone does not "
             "decide. The cross-copy rule does not decide it: the specialization project's eq. "
             "33 is the X-axis solution and prints the right symbol at this place ('\\frac{x_{xP} "
             "- x_{xK}}{z_{xP} - z_{xK}} \\cdot \\frac{M}{N}'), which shows the intended "
             "formula, not the same defect in a second image: the defect stands in one image "
             "only.")
    if n_fixed:
        out += (" The second defect, N printed as one product of six factors (its minus lost), "
                "is undecided too (see the verdict on N).")
    return out + " Category undecidable; what would decide: the page of the original PDF."


def _n_verdict(eq: dict, axis: str) -> tuple[Verdict | None, dict]:
    """The verdict on the printed determinant N (None when not printed) and the reading of N
    that reproduces it ({N: determinant}, empty when N is right or no reading does)."""
    define_fix = {}
    n_verdict = None
    if "N" in eq.get("define", {}):
        N = parse(eq["define"]["N"], axis)
        det = _closed(eq["selection"])["N"]
        if eq.get("rotated"):
            det = _hat(det)
        ok = _equal(N, det) or _equal(N, -det)
        ev = f"derived determinant of the selected system: {fmt(_factored(det))}"
        erratum = ""
        if not ok:
            fixed = _product_readings(eq["define"]["N"], axis, det)
            if fixed is not None:
                erratum = ("N printed as one product of six factors: the minus sign between "
                           "the two triple products is lost")
                define_fix[S("N")] = fixed
                ev += f"; the reading N = {fmt(fixed)} reproduces it (up to sign)"
            else:
                erratum = "N differs from the determinant"
            ev += f"; printed N = {eq['define']['N']}"
        n_verdict = _verdict(eq, "N", ok, erratum, ev + (UNDECIDABLE_N if erratum.startswith(
            "N printed as one product") else ""), eq["define"]["N"], _factored(det),
            category="undecidable" if erratum.startswith("N printed as one product")
            else "printing_error")
        if erratum.startswith("N printed as one product"):
            n_verdict.readings_tried = ["the printed product of six factors: not the determinant",
                                        "a '-' between the two triple products lost by the print "
                                        "or by the extraction: the determinant (up to sign)"]
            n_verdict.readings_used = ["glyph:eq. 3.8 N lost minus"]
    return n_verdict, define_fix


def audit_closed_form(eq: dict) -> list[Verdict]:
    axis = eq["axis"]
    out = []
    n_verdict, define_fix = _n_verdict(eq, axis)
    for motion in MOTIONS:
        if motion not in eq["expr"]:
            continue
        printed, note, define = _printed_solution(eq, motion)
        derived = _derived_solution(eq, motion)
        name = motion + axis
        full = printed.subs(define)
        where = " with the printed M and N substituted" if define else ""
        if _equal(derived, full):
            out.append(_verdict(eq, name, True, "",
                                f"derived - printed == 0{where} (exact rational evaluation at "
                                f"8 random points); derived by Cramer's "
                                f"rule on the selected system (selection {eq['selection']!r})"
                                + (" in rotated coordinates" if eq.get("rotated") else "")
                                + (" in raw coordinates (d = measured - nominal)"
                                   if eq.get("variables") == "raw" else "") + "." + note,
                                eq["expr"][motion], _factored(derived)))
            if note:
                out[-1].evidence = "With the reading below: " + out[-1].evidence
                out[-1].printed = raw_line(eq, motion) or out[-1].printed
                out[-1].category = "undecidable"
                out[-1].verdict = "differs"
                out[-1].erratum = "factor typeset as part of a subscript"
                out[-1].evidence += (
                    " Category undecidable: the formula equals the derivation once the factor "
                    "written inside the subscript of z is read as multiplying it; a subscript "
                    "that swallowed its neighbour is explained equally by the print (a brace "
                    "misplaced in the source) and by the extraction (a misread scope); the "
                    "thesis' eq. 3.7, written for the C axis, has the factor outside the "
                    "subscript, which shows the intended formula, not this print; what would "
                    "decide: the page of the original PDF.")
                out[-1].readings_tried = ["the subscript as printed: z indexed by an expression, "
                                          "not a formula of the document's notation",
                                          "the factor read as multiplying z: exact"]
                out[-1].readings_used = [f"glyph:eq. {eq['id']} {name} subscript scope"]
            continue
        errs, ev = [], (f"derived {fmt(_factored(derived))}; the printed form{where} is not "
                        f"identical.")
        category = "printing_error"
        fixed_define = {**define, **define_fix}
        full_fixed = printed.subs(fixed_define)
        if define_fix and _equal(derived, full_fixed):
            errs.append("N printed as one product (minus sign lost); otherwise as derived")
            ev += (" With N read as the determinant (minus sign restored) it is identical; it "
                   "shares the verdict on N." + UNDECIDABLE_N)
            category = "undecidable"
        else:
            hit = _swap_search(printed, fixed_define, derived)
            if hit:
                old, new = hit
                errs.append(f"{old} printed for {new}")
                ev += (f" Reading {old} as {new}" + (" and N with its minus sign restored"
                                                      if define_fix else "")
                       + " reproduces the derived solution exactly.")
                if define_fix:
                    errs.append("and N printed as one product")
            else:
                errs.append("closed form differs (no single-symbol reading reproduces it)")
        v = _verdict(eq, name, False, " ".join(errs), ev + note, eq["expr"][motion],
                     _factored(derived), category=category)
        if category == "undecidable":
            v.readings_tried = ["the printed solution with the printed N: differs",
                                "N read with its minus sign restored: exact"]
            v.readings_used = ["glyph:eq. 3.8 N lost minus"]
        elif errs and " printed for " in errs[0]:
            old, new = hit
            v.evidence += _swap_evidence(eq, motion, old, new, bool(define_fix))
            v.category = "undecidable"
            v.readings_tried = ["the printed solution with N read as the determinant: differs",
                                f"one lever-arm symbol read as another: {errs[0]} reproduces "
                                f"it exactly (with N's minus restored)",
                                f"{old} repeated from the neighbouring line (print or "
                                f"extraction): the same reading"]
            v.readings_used = [f"glyph:eq. {eq['id']} {name} {old} repeats a token of the "
                               f"same image"]
        out.append(v)
    if n_verdict is not None:
        out.append(n_verdict)
    return out


def audit_denominator(eq: dict) -> list[Verdict]:
    axis = eq["axis"]
    out = []
    for motion in MOTIONS:
        if motion not in eq["expr"]:
            continue
        pr = parse(eq["expr"][motion], axis)
        de = sp.denom(_factored(_closed(eq["selection"])[motion]))
        ratio = sp.cancel(pr / de)
        ok = ratio.is_number and ratio != 0
        out.append(_verdict(eq, motion + axis, bool(ok),
                            "denominator differs",
                            f"printed denominator / derived denominator = {fmt(ratio)}"
                            + (" (a constant: the same up to the sign of the numerator)"
                               if ok else ""), eq["expr"][motion], de))
    return out


def audit(printed: dict, layouts=None) -> list[Verdict]:
    """Verdicts for every printed equation of the data file (see the module docstring)."""
    if layouts is not None and not (set(layouts) & set(LAYOUTS)):
        return []
    out = []
    systems = {eq["id"]: {"labels": [lab for lab, _ in eq["rows"]],
                          "wrong": wrong_subscripts(eq), "unknowns": eq["unknowns"],
                          "rhs": rhs_matched(eq)}
               for eq in printed.get("equation", []) if eq["kind"] == "system"}
    for eq in printed.get("equation", []):
        kind = eq["kind"]
        if kind == "displacement":
            out.extend(audit_displacement(eq))
        elif kind == "system":
            out.extend(audit_system(eq, systems))
        elif kind == "closed_form":
            out.extend(audit_closed_form(eq))
        elif kind == "denominator":
            out.extend(audit_denominator(eq))
        else:
            raise ValueError(f"printed_tracker: unknown kind {kind!r} of eq. {eq['id']}")
    return out
