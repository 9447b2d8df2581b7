"""Audit of the DMU 50 kinematics printed in Ellingsdalen (2021) against the derivation.

The printed material comes as the parsed ``data/printed_dmu50.toml`` (no file I/O here):
Sorby's forward kinematics (eq. 3.19-3.24) and inverse (eq. 3.25-3.29), the chain of HTMs
(eq. 3.30-3.36), their product (eq. 3.37), the chain "updated" with the errors, and Listing 3.3
(``T_r``, ``rot_x/y/z``, ``T_er``).  The authority is the derivation from
``volerr/layouts/DMU50.toml``: the nominal ``tool2work`` of
:class:`volerr.derive.kinematics.Chain` and the generated inverse of
:mod:`volerr.derive.inverse`.

How each item is judged
* forward formulas: ``simplify(derived - printed) == 0`` (symbolic), confirmed numerically;
* inverse formulas: printed and derived inverse evaluated at the forward kinematics of 200
  random poses with 0 < B < 180 deg (the branch of eq. 3.25); identical if they agree to 1e-9
  (mm, rad) -- the printed inverse is a function of (x, y, z, i, j, k), so "identical" means
  identical as a function on that branch;
* matrices: the derived factors of the workpiece side of the chain, in the thesis' form
  ``T_0^w = Trans(c_B) Rx(alpha) Rz(B) Rx(-alpha) Trans(-c_B) Rz(-C)`` with ``alpha`` the angle
  that turns z onto the table's B axis (45 deg) -- its product is checked against the chain
  first -- compared entry by entry, with missing or duplicated rows named;
* products: the printed factor order against the derived one;
* Listing 3.3 ``T_er``: the first-order effect of each error parameter of B and C on a table
  point (machine frame), listing against derived model, at the listing's own pose
  (B = C = 90 deg, point (179.009, 94.545, 143.533) mm).
"""

from __future__ import annotations

import difflib
import functools

import numpy as np
import sympy as sp

from volerr.machine.layout import read_layout

from .framework import RECURRENCE_UNSHOWN, TYPICAL, Verdict, fmt, is_zero, simplified
from ..inverse import BRANCH, TIP, TOOL_AXIS, linear_inverse, rotary_inverse
from ..kinematics import Chain, position_symbol, rotation, translation
from ..volumetric import nominal_point, nominal_tool_axis, volumetric_error

DATA_FILE = "printed_dmu50.toml"
LAYOUTS = ("DMU50",)
SOURCE = "Ellingsdalen 2021"

X, Y, Z, B, C = (position_symbol(a) for a in "XYZBC")
D = sp.Symbol("d", real=True)
A_SYM = sp.Symbol("a", real=True)
_LOCALS = {"X": X, "Y": Y, "Z": Z, "B": B, "C": C, "d": D, "a": A_SYM,
           "c45": sp.sqrt(2) / 2, "s45": sp.sqrt(2) / 2,
           **{str(s): s for s in TIP + TOOL_AXIS}}


@functools.lru_cache(maxsize=None)
def _parse(text: str):
    """A printed entry -> sympy, once per text (the matrices repeat their entries)."""
    return sp.sympify(text, locals=_LOCALS)


def _verdict(eq, same, erratum, evidence, printed, derived, component="",
             category: str = "printing_error", **fields) -> Verdict:
    return Verdict(SOURCE, eq, "DMU50", "identical" if same else "differs",
                   "" if same else erratum, evidence, printed, derived, component,
                   category="identical" if same else category, **fields)


#: matrices of the chain printed again in the other documents of the thesis: (equation,
#: what it prints) -- separately typeset copies decide whether a defect is in the author's
#: source (the same defect there) or not
COPIES = {
    "T_0^1": ("paper eq. 1.1, project eq. (1)", "the same matrix"),
    "T_1^2": ("paper eq. 1.2, project eq. (2)", "all four rows"),
    "T_2^3": ("paper eq. 1.3 ([[c_B, -s_B], [s_B, c_B]]: the rotation), project eq. (3) "
              "([[c_B, s_B], [s_B, c_B]]: the same sign defect), Listing 3.3 T_B ([[c_B, -s_B], "
              "[s_B, c_B]])", ""),
    "T_3^4": ("paper eq. 1.4, project eq. (4)", "four rows, none repeated"),
    "T_4^5": ("paper eq. 1.5, project eq. (5)", "the translation by -d"),
    "T_5^w": ("project eq. (6), Listing 3.3 T_C", "the same matrix"),
}


#: why the missing minus of T_2^3 (thesis eq. 3.32, project eq. (3)) is decided as printed
T23_CROSS_COPY = (
    "Category printing_error by the cross-copy rule and a consequence printed elsewhere. A "
    "single sign, but {other} -- the same defect at the same entry in two separately typeset "
    "documents -- while the extraction reads the same matrix with its minus in the paper's "
    "eq. 1.3 ('c_{{B}} & -s_{{B}} & 0 & 0 \\\\ s_{{B}} & c_{{B}}') and eq. 1.16 (T_BB, the "
    "same entries), and '-s_C' in thesis eq. 3.35: an extraction that lost the minus would have to do "
    "so at the same entry in three renderings while reading it in the others, and it is not "
    "deterministic between renderings (the thesis' two renderings of T_1^2 and T_2^3 are "
    "damaged differently: eq. 3.31 and 3.32 against the chain after eq. 3.37). The defect is "
    "a sign, not a repeated entry: the symbol s_B at (1,2) is the right one, only its minus is "
    "missing, and a bare sign is no candidate repetition (it stands everywhere). The consequence: the project's forward kinematics eq. (10)-(15), "
    "'found' from its chain by eq. (9), print the same six formulas as thesis eq. 3.19-3.24, "
    "which equal the derivation (their verdicts); computed here at 5 random poses, the chain "
    "T_w^t = (T_0^w)^-1 T_0^t reproduces {fwd}. So the author computed with the rotation "
    "Rz(B): the other rotation sense (the transposed matrix) is no convention of the author, "
    "and the print, not the computation, has the sign wrong. The paper's eq. 1.3 and Listing "
    "3.3's T_B (np.array([[c_B, -s_B, 0, 0]], ...)) show the intended rotation")


#: why T_2^2 of the printed chains (thesis eq. 3.37, project eq. (8)) is undecided
T22_UNDECIDED = (
    "{here}: its subscript 2 repeats the superscript 2 written next to it, a candidate "
    "repetition within the image; {there}. By the cross-copy rule that does not decide a "
    "repetition: the two chains are images of the same layout (one line of factors T_a^b in "
    "the same order); the same defect at the same place weighs towards the print, but "
    + RECURRENCE_UNSHOWN.replace("{", "{{").replace("}", "}}") + ". For the print: the author's chain written with these indices (the thesis' chain taken from the "
    "project's). For the extraction: the superscript digit read again as the subscript, a "
    "repetition of the kind it demonstrably makes within an image (the error matrix of "
    "T_0^{{t,c}} after eq. 3.37 has three rows '-E_{{DX}} & ... & 1 & E_{{ZX}}', two of them "
    "identical).")


def _matrix_category(name: str, erratum: str, evidence: str,
                     context: dict | None = None) -> tuple[str, str, list, list]:
    """(category, evidence, readings tried, readings used) of a printed matrix that differs
    from the derived one; ``context``: "renderings" (:func:`_renderings`), "chain_T_4^5" (how
    the chain after eq. 3.37 prints T_4^5) and "t23_forward" (:func:`_t23_forward`)."""
    where = COPIES.get(name, ("", ""))[0]
    if "missing" in erratum:
        return "undecidable", evidence + (
            f". Category undecidable: a lost row, which the print and the text extraction "
            f"explain equally; the thesis prints the factor again in the 'updated' chain after "
            f"eq. 3.37 with the row, and the separately typeset copies ({where}) have it, which "
            f"shows the intended matrix but not whether this print lost the row; what would "
            f"decide: the page of the original PDF"), [
                "the matrix as printed: 3 rows, not a 4x4 HTM",
                "a row lost by the print or by the extraction: the derived factor without "
                "that row (exact)"], [f"glyph:{name} lost row"]
    if "printed twice" in erratum:
        two = (context or {}).get("renderings", {})
        mine = two.get(name, {})
        same_dup = bool(mine) and mine["eq"] == mine["chain"] and bool(mine["eq"][1])
        others = "; ".join(f"{n} has {_said(r['eq'], 'in eq. ' + r['id'])} and "
                           f"{_said(r['chain'], 'in the chain')}"
                           for n, r in two.items() if n != name and r["eq"] != r["chain"])
        t45 = (context or {}).get("chain_T_4^5", "")
        return "undecidable", evidence + (
            f". Category undecidable: a duplicated row, which the print (a repeated line of "
            f"the source) and the text extraction (a repeated span) explain equally. "
            + (f"The 'updated' chain after eq. 3.37 renders {name} again with the same "
               f"defect ({'; '.join(mine['chain'][1]) if mine else ''}). That is no proof of either explanation. It weighs towards "
               f"the author's source (the chain's factor copied from this equation): the "
               f"extraction is not deterministic between these two renderings, it damages the "
               f"neighbouring factors differently there ({others}), yet it would have to "
               f"repeat this row identically in both. It does not decide: this extraction "
               f"demonstrably repeats rows within that same chain (the error matrix of "
               f"T_0^{{t,c}} has five rows, three of them '-E_{{DX}} & ... & 1 & E_{{ZX}}'), "
               f"so a repetition in each rendering is possible; and the chain's next factor "
               f"T_4^5 prints {name}'s rotation with {t45} -- a {name} copied with the duplicate in "
               f"the author's source would carry it there too, and an extraction that "
               f"repeated the factor just read would have read it without the duplicate this "
               f"time, so that block fits neither explanation cleanly. "
               if same_dup else "")
            + f"The separately typeset copies ({where}) print four rows, which shows the "
            f"intended matrix but not whether this print repeated one; what would decide: the "
            f"page of the original PDF"), [
                "the matrix as printed: 5 rows, not a 4x4 HTM",
                "a row repeated by the print or by the extraction: the derived factor with the "
                "repeated row removed (exact)"] + ([
                "the chain after eq. 3.37 as a second rendering: the same duplicate, while "
                "the extraction damages the neighbouring factors differently in the two "
                "renderings (weighs towards the print) and repeats rows within that chain; "
                f"its T_4^5 has {name}'s rotation without the duplicate: decides neither"]
                if same_dup else []), [f"glyph:{name} repeated row"]
    if name == "T_2^3" and "sign error" in erratum:
        fwd = (context or {}).get("t23_forward", {})
        return "printing_error", evidence + ". " + T23_CROSS_COPY.format(
            other="the specialization project's eq. (3) (appendix B) prints the same "
                  "'T_2^3 = [[c_B, s_B], [s_B, c_B]]' and the 'updated' chain after eq. 3.37 "
                  "repeats it (T_2^{3,c})", fwd=forward_note(fwd)), [
                "right-handed rotation Rz(B) (derived; paper eq. 1.3, Listing 3.3 T_B): entry "
                "(1,2) differs",
                "left-handed Rz(-B) (the other rotation sense, the transposed matrix): entry "
                "(2,1) differs"] + forward_tried(fwd) + [
                "a minus lost by the print or by the extraction: the derived factor exactly; "
                "the extraction's part contradicted by the same defect in project eq. (3) and "
                "the minus read in the same matrix of paper eq. 1.3 and 1.16"], [
                "inconsistent:T_2^3 sign of s_B (1,2)"]
    return "printing_error", evidence, [], []


#: why a data source of Listing 3.3 repeated from the line above is undecidable
LISTING_SOURCE_UNDECIDABLE = (
    "Category undecidable: the quoted file name {src} is the one of the line above, a token "
    "repeated within one image, which the print and the extraction explain equally. For the "
    "print: a line of code copied and its file name left unchanged, the usual copy-paste "
    "defect, and the same pattern stands in the B block (E_CB reads E_BB's data) and the C "
    "block (E_CC reads E_BC's), as a C block copied from the B block would carry it; the "
    "line of {name} keeps its own variable name. For the extraction: it demonstrably repeats "
    "tokens and rows within an image (the error matrix of T_0^{{t,c}} after thesis eq. 3.37 "
    "has five rows, three of them '-E_{{DX}} & ... & 1 & E_{{ZX}}'; appendix B sec. 2.4 lists "
    "'(E_AX, E_BX, E_BX) E_CX'). The same repetition in both blocks weighs towards the print, "
    "the more so as the extraction renders the two defective lines differently ({modes}), so "
    "they are no one rendering failing twice alike; by the cross-copy rule a repetition "
    "within an image still does not decide: "
    + RECURRENCE_UNSHOWN.replace("{", "{{").replace("}", "}}") + ". What would decide: the "
    "original listing (or a figure of the compensation that shows whether {name} was used)")


#: why the T_4^5 of the chain "updated" with the errors (after eq. 3.37) is undecidable
UPDATED_CHAIN_REPEAT = (
    "Category undecidable: a whole matrix repeated, which the print and the extraction explain "
    "equally. For the print: the author may have copied the preceding factor in the source "
    "and not changed it. For the extraction: the updated chain is one image in which this "
    "extraction demonstrably repeats and merges rows -- T_1^2 has a first row of five "
    "entries ('1 & 0 & 0 & 0 & 0'), T_3^4 has the row '0 & -s_{45^\\circ} & c_{45^\\circ} & "
    "0' twice, the error matrix of T_0^{t,c} has five rows, three of them '-E_{DX} & ... & 1 & "
    "E_{ZX}', the tokens E_{DB}, E_{2B} and T_A name no error, T_6^{t,c} stands where the C "
    "axis' factor belongs, and the translation of T_0^{t,c} reads '1 & 0 & 0 & X \\\\ 0 & 1 "
    "& 0 & 0 \\\\ 0 & 0 & 1 & 1' -- so emitting the factor just read once more is within "
    "its failures here; no separately typeset copy of the updated chain exists (the cross-copy "
    "rule cannot decide). What would decide: the page of the original PDF")


# ------------------------------------------------------------------------------ derived pieces
def _chain():
    layout = read_layout("DMU50")
    return layout, Chain.from_layout(layout)


@functools.lru_cache(maxsize=1)
def _derived():
    """(layout, chain, forward, rotary inverse, linear inverse) of DMU50, derived once."""
    layout, chain = _chain()
    return layout, chain, derived_forward(chain), rotary_inverse(chain), linear_inverse(chain)


def derived_forward(chain) -> dict:
    p = nominal_point(chain).subs({s: 0 for s in sp.symbols("Xp Yp Zp", real=True)})
    k = nominal_tool_axis(chain)
    return {"x": p[0], "y": p[1], "z": p[2], "i": k[0], "j": k[1], "k": k[2]}


def derived_factors(layout) -> dict:
    """The thesis' factors of ``T_0^w`` (machine <- workpiece), derived from the layout."""
    b, c = layout.axes["B"], layout.axes["C"]
    cb = sp.Matrix([sp.sympify(v, locals={"d": D}) if isinstance(v, str) else sp.nsimplify(v)
                    for v in b.point])
    cc = sp.Matrix([sp.nsimplify(v) for v in c.point])
    assert cc == sp.zeros(3, 1), "the factor form assumes the C axis through the workpiece origin"
    # the table turns by +B about w = -u_B (u_B: tool-relative direction of B)
    w = -sp.Matrix([sp.nsimplify(v, [sp.sqrt(2)]) for v in b.direction])
    assert w[0] == 0, "the factor form assumes the B axis in the y-z plane"
    alpha = sp.atan2(-w[1], w[2])
    return {
        "T_0^1": translation(cb), "T_1^2": rotation((1, 0, 0), alpha),
        "T_2^3": rotation((0, 0, 1), B), "T_3^4": rotation((1, 0, 0), -alpha),
        "T_4^5": translation(-cb), "T_5^w": rotation((0, 0, 1), -C),
        "T_0^t": translation((X, Y, Z)),
    }


def _rows_note(rows, derived: sp.Matrix) -> tuple[int, list[str]]:
    """How a printed rendering of a factor differs in its rows from the derived factor:
    (number of rows, ['row [...] lost', 'the row [...] twice', 'its row 1 with 5 entries']).
    A printed row stands for a derived row when its first entries equal it, up to the signs
    (a sign defect is no row defect); exact matches are paired first."""
    parsed = [[simplified(_parse(c)) for c in r] for r in rows]
    drows = [[simplified(derived[i, j]) for j in range(derived.cols)]
             for i in range(derived.rows)]
    free, left = list(range(len(drows))), list(range(len(parsed)))
    for test in (lambda u, v: is_zero(u - v), lambda u, v: is_zero(u ** 2 - v ** 2)):
        for k in list(left):
            hit = next((i for i in free if len(parsed[k]) >= len(drows[i])
                        and all(test(u, v) for u, v in zip(parsed[k], drows[i]))), None)
            if hit is not None:
                free.remove(hit)
                left.remove(k)
    notes = [f"row [{', '.join(fmt(v) for v in drows[i])}] lost" for i in free]
    notes += [f"the row [{', '.join(fmt(v) for v in r)}] twice" for k, r in enumerate(parsed)
              if r in parsed[:k]]
    notes += [f"its row {k + 1} with {len(r)} entries" for k, r in enumerate(parsed)
              if len(r) != derived.cols]
    return len(rows), notes


def _renderings(printed: dict, factors: dict) -> dict:
    """Factors printed twice in the thesis -- eq. 3.31-3.33 and the chain after eq. 3.37 --
    each rendering's rows described: {name: {"id", "eq", "chain"}}."""
    out = {}
    for name, rows in printed.get("chain_rendering", {}).items():
        item = next((m for m in printed.get("matrix", []) if m["name"] == name
                     and m["id"][0].isdigit()), None)
        if item is not None:
            out[name] = {"id": item["id"], "eq": _rows_note(item["rows"], factors[name]),
                         "chain": _rows_note(rows, factors[name])}
    return out


def _said(note: tuple[int, list[str]], where: str) -> str:
    """'3 rows in eq. 3.31 (row [...] lost)'."""
    n, notes = note
    return f"{n} rows {where}" + (f" ({'; '.join(notes)})" if notes else "")


def _t23_forward(fwd: dict, factors: dict, printed_rows) -> dict:
    """Which of the forward formulas (tool axis i, j, k and tool tip x, y, z; the derivation,
    which eq. 3.19-3.24 print and the project's eq. (10)-(15) print again) the chain
    ``T_w^t = (T_0^w)^-1 T_0^t`` reproduces with T_2^3 taken as each candidate matrix:
    {candidate: [formula names]}, checked at 5 random poses."""
    rz = factors["T_2^3"]
    cands = {"Rz(B)": rz, "the printed matrix": sp.Matrix([[_parse(c) for c in r]
                                                          for r in printed_rows]),
             "Rz(-B)": rz.subs(B, -B)}
    rng = np.random.default_rng(2303)
    args = (X, Y, Z, B, C, D)
    poses = rng.uniform((-250, -225, 0, 0.1, -3, 100), (250, 225, 400, 3, 3, 200), (5, 6))
    t0t = sp.lambdify(args, factors["T_0^t"], "numpy")
    want = {q: sp.lambdify(args, fwd[q], "numpy") for q in "ijkxyz"}
    out = {}
    for label, t23 in cands.items():
        t0w = sp.lambdify(args, factors["T_0^1"] * factors["T_1^2"] * t23 * factors["T_3^4"]
                          * factors["T_4^5"] * factors["T_5^w"], "numpy")
        twt = [np.linalg.solve(np.array(t0w(*p), float), np.array(t0t(*p), float))
               for p in poses]
        ok = [q for q, (row, col) in zip("ijkxyz", ((0, 2), (1, 2), (2, 2), (0, 3), (1, 3),
                                                   (2, 3)))
              if all(abs(t[row, col] - float(want[q](*p))) < 1e-9 * (1 + abs(t[row, col]))
                     for t, p in zip(twt, poses))]
        out[label] = ok
    return out


def _formulas(found: list) -> str:
    return ("all six (i, j, k, x, y, z)" if len(found) == 6 else "none" if not found
            else "only " + ", ".join(found))


def forward_note(res: dict) -> str:
    """The result of :func:`_t23_forward` in words (quoted by the T_2^3 verdicts)."""
    return "; ".join(f"{_formulas(f)} with T_2^3 = {c}" + (" (-s_B at (1,2))" if c == "Rz(B)"
                                                          else "")
                     for c, f in res.items()) or "(not computed)"


def forward_tried(res: dict) -> list[str]:
    """The readings of T_2^3 checked against the printed forward kinematics."""
    if not res:
        return []
    return [f"the chain with T_2^3 = {c}: {_formulas(f)} of the project's forward formulas eq. "
            f"(10)-(15) (= thesis eq. 3.19-3.24)"
            + (" -- the other rotation sense ruled out as the author's convention"
               if c == "Rz(-B)" else "") for c, f in res.items()]


def t23_forward(printed_rows) -> dict:
    """:func:`_t23_forward` for the DMU50 layout's derived chain (cached derivation)."""
    layout, _, fwd, _, _ = _derived()
    return _t23_forward(fwd, derived_factors(layout), printed_rows)


DERIVED_ORDER = ["T_w^5", "T_5^4", "T_4^3", "T_3^2", "T_2^1", "T_1^0", "T_0^t"]


# ------------------------------------------------------------------------------ comparisons
def _matrix_diff(printed_rows, derived: sp.Matrix) -> tuple[bool, str, str]:
    """(same, erratum, evidence) of a printed matrix (list of rows) against ``derived``."""
    rows = [[simplified(_parse(c)) for c in r] for r in printed_rows]
    drows = [[simplified(derived[i, j]) for j in range(derived.cols)] for i in range(derived.rows)]

    def eq(r1, r2):
        return len(r1) == len(r2) and all(is_zero(a - b) for a, b in zip(r1, r2))

    if len(rows) == len(drows) and all(len(r) == len(d) for r, d in zip(rows, drows)):
        bad = [(i, j) for i in range(len(rows)) for j in range(len(rows[i]))
               if not is_zero(rows[i][j] - drows[i][j])]
        if not bad:
            return True, "", "all 16 entries agree with the derived factor"
        desc = "; ".join(f"entry ({i + 1},{j + 1}): printed {fmt(rows[i][j])}, derived "
                         f"{fmt(drows[i][j])}" for i, j in bad)
        kind = "sign error" if all(is_zero(rows[i][j] + drows[i][j]) for i, j in bad) \
            else "wrong entries"
        m = sp.Matrix(rows)
        extra = ""
        r3 = m[0:3, 0:3]
        if sp.simplify(r3.T * r3 - sp.eye(3)) != sp.zeros(3, 3):
            det = fmt(sp.simplify(r3.det()))
            extra = f"; the printed 3x3 block is not a rotation (det = {det})"
        return False, f"{kind} in {len(bad)} entr{'y' if len(bad) == 1 else 'ies'}", desc + extra
    if len(rows) == len(drows) - 1:
        for k in range(len(drows)):
            if all(eq(a, b) for a, b in zip(rows, drows[:k] + drows[k + 1:])):
                return False, f"row {k + 1} missing", (
                    f"printed with {len(rows)} rows; it is the derived factor without row "
                    f"{k + 1} [{', '.join(fmt(v) for v in drows[k])}]")
    if len(rows) == len(drows) + 1:
        for k in range(len(rows)):
            if all(eq(a, b) for a, b in zip(rows[:k] + rows[k + 1:], drows)):
                dup = [j for j in (k - 1, k + 1) if 0 <= j < len(rows) and eq(rows[k], rows[j])]
                erratum = f"row {min(k, dup[0]) + 1} printed twice" if dup else \
                    f"extra row {k + 1}"
                return False, erratum, (f"printed with {len(rows)} rows; removing row {k + 1} "
                                        f"[{', '.join(fmt(v) for v in rows[k])}] gives the "
                                        "derived factor")
    return False, "wrong matrix", f"printed {rows}, derived {drows}"


def _product_diff(printed: list, derived: list) -> tuple[bool, str, str]:
    if printed == derived:
        return True, "", "same factors in the same order"
    ops = difflib.SequenceMatcher(a=derived, b=printed, autojunk=False).get_opcodes()
    parts = []
    for tag, i1, i2, j1, j2 in ops:
        if tag == "replace":
            parts.append(f"{', '.join(derived[i1:i2])} printed as {', '.join(printed[j1:j2])}")
        elif tag == "delete":
            parts.append(f"{', '.join(derived[i1:i2])} missing")
        elif tag == "insert":
            parts.append(f"extra {' '.join(printed[j1:j2])}")
    return False, "; ".join(parts), (f"derived order {' '.join(derived)}; printed "
                                     f"{' '.join(printed)}")


# ------------------------------------------------------------------------------ the audit
def _audit_formulas(printed: dict, fwd: dict, rinv: dict, linv: dict, q: dict, pose: dict,
                    n: int, subs_num: dict) -> list[Verdict]:
    """The printed forward and inverse formulas against the derivation, symbolically and at the
    ``n`` random poses ``q`` (axis positions) / ``pose`` (tool tip and axis)."""
    out = []
    for item in printed.get("formula", []):
        eq, qty = f"eq. {item['id']}", item["quantity"]
        pr = _parse(item["expr"])
        if qty in fwd:
            diff = sp.simplify(sp.expand_trig(fwd[qty] - pr))
            f = sp.lambdify((X, Y, Z, B, C), (fwd[qty] - pr).subs(subs_num), "numpy")
            num = float(np.max(np.abs(f(q["X"], q["Y"], q["Z"], q["B"], q["C"]))))
            same = diff == 0
            ev = (f"simplify(derived - printed) = {fmt(diff)}; max |difference| at {n} random "
                  f"poses = {num:.2g}")
            out.append(_verdict(eq, same, "wrong forward formula", ev, item["expr"],
                                fmt(fwd[qty]), qty))
            continue
        # inverse: printed and derived evaluated on the same poses
        args = (*TIP, *TOOL_AXIS)
        if qty in ("B", "C"):
            der = rinv[qty].subs(BRANCH, -1)
        else:
            der = linv[qty].subs({s: 0 for s in sp.symbols("Xp Yp Zp", real=True)})
        vals = [pose[str(s)] for s in args]
        g_der = sp.lambdify(args + (B, C), der.subs(subs_num), "numpy")
        g_pr = sp.lambdify(args + (B, C), pr.subs(subs_num), "numpy")
        # eq. 3.27-3.29 use C (and B) from eq. 3.25-3.26: evaluate them at the true angles
        a = np.asarray(g_der(*vals, q["B"], q["C"]), float)
        b = np.asarray(g_pr(*vals, q["B"], q["C"]), float)
        if qty in ("B", "C"):
            dev = np.abs((a - b + np.pi) % (2 * np.pi) - np.pi)
        else:
            dev = np.abs(a - b)
        truth = q[qty]
        err_true = np.abs(((b - truth + np.pi) % (2 * np.pi) - np.pi) if qty in ("B", "C")
                          else b - truth)
        same = bool(np.nanmax(dev) < 1e-9)
        ev = (f"printed and derived inverse (branch of eq. 3.25, 0 < B < 180 deg) agree at {n} "
              f"random poses to {np.nanmax(dev):.2g} ({'rad' if qty in 'BC' else 'mm'}); the "
              f"printed formula returns the commanded {qty} to {np.nanmax(err_true):.2g}")
        out.append(_verdict(eq, same, "wrong inverse formula", ev, item["expr"], fmt(der), qty))

    return out


def _audit_matrices(printed: dict, factors: dict, fwd: dict) -> list[Verdict]:
    """The printed factor matrices (thesis and updated error chain) against the derived factors."""
    out = []
    chain45 = next((m for m in printed.get("matrix", [])
                    if m["id"].startswith("error chain") and m["name"] == "T_4^5"), None)
    t32 = next((m for m in printed.get("matrix", []) if m["name"] == "T_2^3"
                and m["id"][0].isdigit()), None)
    context = {"renderings": _renderings(printed, factors),
               "chain_T_4^5": "" if chain45 is None else
               f"{len(chain45['rows'])} rows, none repeated"
               + " (the derived T_3^4)" * bool(_matrix_diff(chain45["rows"],
                                                            factors["T_3^4"])[0]),
               "t23_forward": {} if t32 is None else _t23_forward(fwd, factors, t32["rows"])}
    for item in printed.get("matrix", []):
        name = item["name"]
        eq = f"eq. {item['id']}" if item["id"][0].isdigit() else item["id"]
        same, erratum, ev = _matrix_diff(item["rows"], factors[name])
        if item["id"].startswith("error chain") and not same:
            for other, m in factors.items():
                if other != name and _matrix_diff(item["rows"], m)[0]:
                    erratum, ev = f"{name} printed as {other}", (
                        f"the printed matrix is the derived {other}; {name} is the translation "
                        f"by -c_B = (0, 0, -d)")
        tried, used = [], []
        if not same:
            cat, ev, tried, used = _matrix_category(name, erratum, ev, context)
            if item["id"].startswith("error chain"):
                cat = "undecidable"
                tried = ["the printed matrix against every derived factor: it is the derived "
                         "T_3^4 (a rotation), not T_4^5 (the translation by -d)",
                         "the preceding factor T_3^4 repeated by the print (a copied source) "
                         "or by the extraction (a repeated span, in a block it demonstrably "
                         "damages): the printed matrix exactly"]
                ev += (f" (thesis eq. 3.34 prints T_4^5 as that translation). The extraction "
                       f"text: '{item.get('text', '')}'. " + UPDATED_CHAIN_REPEAT)
        else:
            cat = "identical"
        v = _verdict(eq, same, erratum, ev, str(item["rows"]), fmt(factors[name]), name,
                     category=cat)
        if item["id"].startswith("error chain") and not same:
            used = [f"glyph:updated chain {name} repeats T_3^4"]
        v.readings_tried, v.readings_used = tried, used
        out.append(v)

    return out


def _audit_eq337(prod: dict) -> list[Verdict]:
    """The printed order of the factors of eq. 3.37 against the derived order."""
    out = []
    if "3.37" in prod:
        same, erratum, ev = _product_diff(prod["3.37"], DERIVED_ORDER)
        v = _verdict("eq. 3.37", same, erratum, ev + "; T_a^b maps frame b into frame a, "
                     "T_w^t = (T_0^w)^-1 T_0^t. " + T22_UNDECIDED.format(
                         here="'T_2^2' (no frame maps into itself) stands where T_3^2 T_2^1 "
                              "belong", there="the specialization project's eq. (8), a "
                              "separately typeset document, has it at the same place ('T_w^5 "
                              "T_5^4 T_4^3 T_2^2 T_1^1 T_1^0 T_0^t', where T_1^1 repeats its "
                              "superscript as well)")
                     + " 'T_1^d' for T_0^t (d is a length, not a frame) stands in this copy only "
                       "(project eq. (8) ends with T_0^t): glyph-level, print or extraction, "
                       "undecided too. Category undecidable; what would decide: the page of "
                       "the original PDF",
                     prod.get("3.37_text", ""), " ".join(DERIVED_ORDER),
                     category="undecidable")
        v.readings_tried = ["the derived order T_w^5 T_5^4 T_4^3 T_3^2 T_2^1 T_1^0 T_0^t: "
                            "differs in factors 4-7",
                            "the subscript of T_2^2 a repetition of its superscript (print or "
                            "extraction): not decided by project eq. (8), an image of the same "
                            "layout with the same defect; T_1^d: print or extraction",
                            "the paper's eq. 1.8 form (T_5^w)^-1 ... (T_0^1)^-1 T_0^t: equals "
                            "the derived order (see eq. 1.8)"]
        v.readings_used = ["glyph:eq. 3.37 factor T_2^2 repeats its superscript"]
        out.append(v)
    return out


def _listing_line46(prod: dict, lst: dict, t0w: sp.Matrix) -> list[Verdict]:
    """Line 46 of Listing 3.3 (T_r, the product of the listing's factors) against the derived
    T_0^w, with the reading of its leading minus."""
    out = []
    key = "listing 3.3 line 46"
    if key in prod:
        pr = prod[key]
        sign = -1 if pr and pr[0] == "-" else 1
        fac = [p for p in pr if p != "-"]
        m = sp.eye(4)
        for p in fac:
            m = m * sp.Matrix([[_parse(c) for c in r] for r in lst[p]])
        same_body = sp.simplify(m - t0w) == sp.zeros(4, 4)
        t_r_category = "printing_error"
        same = same_body and sign == 1
        if same:
            erratum, ev = "", "the product equals the derived T_0^w (machine <- workpiece)"
        elif same_body:
            erratum = "leading minus sign"
            t_r_category = "undecidable"
            ev = ("taken literally, T = -(T_d T_45 T_B T_n45 T_nd T_C) negates the whole HTM "
                  "(its homogeneous 1 becomes -1); without the minus the product equals the "
                  "derived T_0^w exactly (the minus may be an OCR artefact of 'T_-d')")
        else:
            erratum, ev = "wrong product", "the product differs from the derived T_0^w"
        if t_r_category == "undecidable":
            ev += ("; category undecidable: the extraction renders the underscores of this "
                   "line as '{-}' ('T = -T_{-}d @ T_{-}45 ...'), so the stray '-' may be the same "
                   "damage. A third reading the text does not exclude: a deliberate minus. "
                   "T_er(B, C) ends in '@ T_r (B, C)', so the minus negates T_er p as well, "
                   "and the third print, '(T_r (90, 90) @ p) - (T_er(90, 90) @ p)', becomes "
                   "(-P p) - (-E P p) = E P p - P p = T_er p - T_r p with the minus "
                   "dropped (P the product, E the error factors): the actual minus the ideal "
                   "position, which is how sec. 3.5 "
                   "defines the deviation ('the difference between the actual and the ideal "
                   "position'); without the minus the listing computes ideal - actual, and the "
                   "sign of the compensation, which the text obtains 'by reversing the signs of "
                   "the deviation', flips with it. Against that reading: the Figure 3.10 "
                   "caption calls the first line 'the coordinates of the point after "
                   "transformation using the ideal kinematics', which the negated HTM would "
                   "print with the opposite signs and a homogeneous -1. The printed output of "
                   "the listing (Figure 3.10), which would tell, is not in the text; missing: "
                   "the original listing")
        v = _verdict("Listing 3.3 line 46 (T_r)", same, erratum, ev,
                     prod.get(key + "_text", ""), "T_d @ T_45 @ T_B @ T_n45 @ T_nd @ T_C",
                     category=t_r_category)
        if not same:
            v.readings_tried = ["the line as printed: -(product), the homogeneous 1 becomes -1",
                                "a stray '-' of the print or of the extraction: the product "
                                "alone equals the derived T_0^w (exact)",
                                "a deliberate minus: the third print becomes actual - ideal "
                                "(sec. 3.5's deviation) instead of ideal - actual; the Figure "
                                "3.10 caption ('the coordinates of the point') argues against "
                                "it"]
            v.readings_used = ["glyph:Listing 3.3 line 46 leading minus"]
        out.append(v)
    return out


def _listing_rotations(lst: dict) -> list[Verdict]:
    """rot_x, rot_y, rot_z of Listing 3.3 against the right-handed rotations."""
    out = []
    std = {"rot_x": rotation((1, 0, 0), A_SYM), "rot_y": rotation((0, 1, 0), A_SYM),
           "rot_z": rotation((0, 0, 1), A_SYM)}
    for rname, m in std.items():
        if rname in lst:
            same, erratum, ev = _matrix_diff(lst[rname], m)
            tried, used = [], []
            if not same and sp.simplify(sp.Matrix([[_parse(c) for c in r] for r in lst[rname]])
                                        - m.subs(A_SYM, -A_SYM)) == sp.zeros(4, 4):
                erratum = f"{rname} turns by -a"
                ev = (f"{rname}(a) is the right-hand rotation by -a (signs of the sine terms "
                      f"swapped; rot_x and rot_z are right-handed): E_BB and E_BC enter T_er with "
                      f"the wrong sign; " + ev + ". Category printing_error: the left-handed "
                      f"sense would be a convention only if the listing used it for every "
                      f"axis; rot_x and rot_z of the same listing turn right-handed (code: "
                      f"not extraction damage, both sine signs are consistently swapped)")
                tried = ["right-handed rotation about y (derived): entries (1,3), (3,1) differ",
                         "left-handed rotation (rotation by -a): exact, but rot_x and rot_z of "
                         "the same listing are right-handed"]
                used = [f"inconsistent:Listing 3.3 {rname} rotation sense"]
            v = _verdict(f"Listing 3.3 {rname}", same, erratum, ev, str(lst[rname]), fmt(m), rname)
            v.readings_tried, v.readings_used = tried, used
            out.append(v)
    return out


def _listing_sources(lst: dict) -> list[Verdict]:
    """The data file each parameter of T_er in Listing 3.3 reads ('<name>_avg.')."""
    out = []
    if "sources" in lst:
        texts = lst.get("sources_text", {})
        modes = "; ".join(f"the line of {n} {'as LaTeX' if '_{' in ls[-1] else 'as plain code'}"
                          f" ('{ls[-1]}')" for n, ls in texts.items())
        for pname, src in lst["sources"].items():
            expected = f"{pname}_avg."
            same = src == expected
            lines = texts.get(pname, [])
            quoted = (" The extraction reads the line above and this one as '"
                      + "' and '".join(lines) + "'." if lines else "")
            v = _verdict(f"Listing 3.3 T_er {pname}", same,
                         f"{pname} read from the data of {src[:-5]}",
                         f"{pname} = cf_rot('{expected}', ...) reads its own data" if same
                         else f"line reads cf_rot('{src}', ...) for {pname}; expected "
                         f"'{expected}' (each other parameter of T_er reads '<its name>_avg.'; "
                         f"as printed the {pname} curve is never used).{quoted} "
                         + LISTING_SOURCE_UNDECIDABLE.format(name=pname, src=src[:-5],
                                                             modes=modes),
                         lines[-1] if lines else f"cf_rot('{src}')", f"cf_rot('{expected}')",
                         pname, category="undecidable")
            if not same:
                v.readings_tried = [f"the listing's own pattern (each parameter reads "
                                    f"'<name>_avg.'): differs",
                                    f"the file name of the line above repeated, by the print "
                                    f"(a line copied, the name left unchanged) or by the "
                                    f"extraction (a token repeated within the image): exact"]
                v.readings_used = [f"glyph:Listing 3.3 line for {pname} repeats the name above"]
            out.append(v)
    return out


def audit(printed: dict, layouts=None) -> list[Verdict]:
    if layouts is not None and "DMU50" not in layouts:
        return []
    layout, chain, fwd, rinv, linv = _derived()
    d_value = float(layout.parameters["d"])
    out: list[Verdict] = []
    rng = np.random.default_rng(20210)
    n = 200
    q = {"X": rng.uniform(-250, 250, n), "Y": rng.uniform(-225, 225, n),
         "Z": rng.uniform(0, 400, n), "B": np.deg2rad(rng.uniform(1, 179, n)),
         "C": np.deg2rad(rng.uniform(-179, 179, n))}
    subs_num = {D: d_value}
    fnum = {k: sp.lambdify((X, Y, Z, B, C), v.subs(subs_num), "numpy") for k, v in fwd.items()}
    pose = {k: np.broadcast_to(f(q["X"], q["Y"], q["Z"], q["B"], q["C"]), (n,)) for k, f in
            fnum.items()}

    out.extend(_audit_formulas(printed, fwd, rinv, linv, q, pose, n, subs_num))

    factors = derived_factors(layout)
    # the factor form must reproduce the chain (workpiece side, machine <- workpiece)
    t0w = sp.eye(4)
    for name in ("T_0^1", "T_1^2", "T_2^3", "T_3^4", "T_4^5", "T_5^w"):
        t0w = t0w * factors[name]
    # T_0^w @ tool2work(X = Y = Z = 0) must be the identity (checked at random angles)
    wp = chain.nominal_htm().subs({X: 0, Y: 0, Z: 0})
    check = sp.lambdify((B, C, D), t0w * wp - sp.eye(4), "numpy")
    for bb, cc in rng.uniform(-3, 3, (5, 2)):
        assert np.abs(np.array(check(bb, cc, d_value), float)).max() < 1e-9, \
            "factor form does not reproduce the chain"
    out.extend(_audit_matrices(printed, factors, fwd))

    prod = printed.get("product", {})
    out.extend(_audit_eq337(prod))
    lst = printed.get("listing", {})
    names = {"T_d": "T_0^1", "T_45": "T_1^2", "T_B": "T_2^3", "T_n45": "T_3^4", "T_nd": "T_4^5",
             "T_C": "T_5^w"}
    for lname, fname in names.items():
        if lname in lst:
            same, erratum, ev = _matrix_diff(lst[lname], factors[fname])
            out.append(_verdict(f"Listing 3.3 {lname}", same, erratum,
                                ev + f" (derived {fname})", str(lst[lname]),
                                fmt(factors[fname]), lname))
    out.extend(_listing_line46(prod, lst, t0w))
    out.extend(_listing_rotations(lst))
    out.extend(_listing_sources(lst))
    if "T_er" in lst:
        out.append(_audit_t_er(layout, chain, lst, factors, d_value))
    return out


def _audit_t_er(layout, chain, lst, factors, d_value) -> Verdict:
    """First-order effect of each B/C error on a table point: Listing 3.3 T_er (with its rot_y
    and data sources corrected) against the derived model, at the listing's pose
    (B = C = 90 deg) and at a general one (B = 37, C = 23 deg)."""
    t0w = sp.eye(4)
    for name in ("T_0^1", "T_1^2", "T_2^3", "T_3^4", "T_4^5", "T_5^w"):
        t0w = t0w * factors[name]
    t0w_num = sp.lambdify((B, C, D), t0w, "numpy")
    err_expr = volumetric_error(chain)
    params = [sp.Symbol(p, real=True) for p in layout.parameter_names]
    probe = sp.symbols("Xp Yp Zp", real=True)
    err_num = sp.lambdify((X, Y, Z, B, C, D, *probe, *params), list(err_expr), "numpy")
    p_table = np.array([179.009, 94.545, 143.533, 1.0])
    rows = []
    for bdeg, cdeg in ((90.0, 90.0), (37.0, 23.0)):
        rows += [f"(B {bdeg:g}, C {cdeg:g}) {r}" for r in
                 _t_er_pose(np.deg2rad(bdeg), np.deg2rad(cdeg), p_table, t0w_num, err_num,
                            layout, d_value)]
    same = not rows
    size = _t_er_size_um(lst, factors, t0w_num, err_num, layout, d_value, p_table)
    ev = (f"size of the difference with every angular error of B and C at "
          f"{TYPICAL['angular_rad'] * 1e6:g} urad (signs worst case; an assumed size, the "
          f"errors are not printed as numbers -- the difference scales in proportion to them): "
          f"up to {size:.2g} um at the listing's point; first-order effect per error parameter on the table point (179.009, "
          "94.545, 143.533) mm (workpiece frame), listing with rot_y and the data sources "
          "corrected -- each effect is the displacement of the tool relative to the workpiece, "
          "expressed in the workpiece (table) frame, per 1 um or 1 urad of the parameter: " +
          ("; ".join(rows) if rows else "all effects agree") +
          ". Reasons: T_er applies every error in the machine frame after the whole rotation "
          "-- the tilts of B turn about the machine origin instead of about the B axis (lever "
          "arm to the B/C intersection at (0, 0, d)), and the errors of C are not turned with "
          "the B axis that carries C")
    v = _verdict("Listing 3.3 T_er (error model)", same, "errors applied in the wrong frame",
                    ev + ". Category simplification, the audit's category for a model the "
                    "author states (here sec. 3.5 states it as the method, not as an "
                    "approximation): the listing implements exactly that statement, so it is "
                    "no printing error, but the model is not the machine's -- its effect, up to "
                    f"{size:.2g} um at the listing's point with {TYPICAL['angular_rad'] * 1e6:g} "
                    "urad angular errors of B and C, is as large as the residual errors the "
                    "thesis reports after compensation (E_YY about 10 um, sec. 4.2.2), so the "
                    "compensation of the rotary axes is off by up to that much",
                    " @ ".join(lst["T_er"]),
                    "derived first-order chain (DMU50 layout)", "T_er",
                    category="simplification", statement=T_ER_STATEMENT,
                    alternative="every B and C error motion applied in the machine frame after "
                                "the nominal rotation T_r (errors pivot about the machine "
                                "origin)", dropped_um=size)
    v.readings_tried = ["the derived first-order chain (errors of B about the B axis, errors of "
                        "C turned with B): differs (table above)",
                        "every error applied in the machine frame after T_r, the method sec. "
                        "3.5 states: the listing, exactly"]
    v.readings_used = ["stated:sec. 3.5 errors applied in the machine frame"]
    return v


T_ER_STATEMENT = (
    "Sec. 3.5: \"The coordinate system is rotated by the amount of each angular error. It is "
    "then translated by the amount of the translational errors before it is rotated according "
    "to the desired position of the B- and C-axis.\"")


def _t_er_size_um(lst, factors, t0w_num, err_num, layout, d_value, p_table) -> float:
    """Largest |listing - derived| (um) over poses B in 0..180, C in 0..360 (30 deg steps) with
    the six angular errors of B and C at +-TYPICAL angular (worst sign per parameter)."""
    worst = 0.0
    for bdeg in range(0, 181, 30):
        for cdeg in range(0, 360, 30):
            per = _t_er_effects(np.deg2rad(bdeg), np.deg2rad(cdeg), p_table, t0w_num, err_num,
                                layout, d_value)
            tot = sum(np.abs(lt - mo) for e, (lt, mo) in per.items() if e[3] in "ABC"
                      and e[2] in "ABC") * TYPICAL["angular_rad"] / 1e-6
            worst = max(worst, float(np.max(tot)))
    return worst * 1e3


def _rot(axis: int, a: float) -> np.ndarray:
    """Right-handed 4x4 rotation by ``a`` rad about machine axis 0/1/2 (x/y/z)."""
    c, s_ = np.cos(a), np.sin(a)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m = np.eye(4)
    m[i, i] = m[j, j] = c
    m[i, j], m[j, i] = -s_, s_
    return m


def _tr(v) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = v
    return m


_T_ER_ERRS = ("E_XB", "E_YB", "E_ZB", "E_AB", "E_BB", "E_CB", "E_XC", "E_YC", "E_ZC", "E_AC",
              "E_BC", "E_CC")


def _t_er_effects(bq, cq, p_table, t0w_num, err_num, layout, d_value) -> dict:
    """Per error parameter of Listing 3.3 (rot_y and sources corrected): (listing effect,
    derived effect) on the table point, tool relative to the workpiece, mm per 1 um / 1 urad."""
    t_r = np.array(t0w_num(bq, cq, d_value), dtype=float)
    machine = t_r @ p_table
    r = t_r[:3, :3]
    names = layout.parameter_names
    out = {}
    for e in _T_ER_ERRS:
        unit = 1e-3 if e[2] in "XYZ" else 1e-6
        v = dict.fromkeys(_T_ER_ERRS, 0.0)
        v[e] = unit
        t_er = (_rot(0, v["E_AB"]) @ _rot(1, v["E_BB"]) @ _rot(2, v["E_CB"])
                @ _rot(0, v["E_AC"]) @ _rot(1, v["E_BC"]) @ _rot(2, v["E_CC"])
                @ _tr([v["E_XB"], v["E_YB"], v["E_ZB"]])
                @ _tr([v["E_XC"], v["E_YC"], v["E_ZC"]]) @ t_r)
        d_machine = (t_er @ p_table - t_r @ p_table)[:3]
        listing_tool = -(r.T @ d_machine)  # tool relative to the workpiece, workpiece frame
        iso = "E" + e[2] + e[3]
        pv = [(-unit if n == iso else 0.0) for n in names]
        model = np.array([float(x) for x in err_num(machine[0], machine[1], machine[2], bq, cq,
                                                    d_value, 0.0, 0.0, 0.0, *pv)])
        out[e] = (listing_tool, model)
    return out


def _t_er_pose(bq, cq, p_table, t0w_num, err_num, layout, d_value) -> list[str]:
    rows = []
    for e, (listing_tool, model) in _t_er_effects(bq, cq, p_table, t0w_num, err_num, layout,
                                                  d_value).items():
        if np.linalg.norm(model - listing_tool) > 1e-9:
            rows.append(f"{e}: listing {np.round(listing_tool * 1e3, 4).tolist()} um, derived "
                        f"{np.round(model * 1e3, 4).tolist()} um per "
                        f"{'1 um' if e[2] in 'XYZ' else '1 urad'}")
    return rows
