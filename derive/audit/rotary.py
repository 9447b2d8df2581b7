"""Audit of the axis error models of Ellingsdalen (2021), sec. 2.5 and eq. 3.15 (sympy, no I/O).

The printed material is the parsed ``data/printed_rotary.toml``.  The authority is
written here from first principles, independently of the printed matrices:

* a linear axis X: the moved point is ``Trans(x) E p`` with the small-angle error HTM
  ``E = I + [e]x + t`` (e = (E_AX, E_BX, E_CX), t = (E_XX, E_YX, E_ZX)), so the deviation from
  the nominal ``Trans(x) p`` is ``[e]x p + t``;
* a rotary axis C (eq. 2.42 without squareness): ``T = T_ES T_CC`` with the nominal
  ``T_CC = Rz(C)``, right-handed as in the thesis' own eq. 3.2, and the small-angle error HTM
  ``T_ES``; the deviation of a table point p is ``(T_ES - I) Rz(C) p`` (first order), whose
  matrix has a zero bottom row;
* the squareness matrix ``T_SS`` is the small-angle rotation by S_XC about x and S_YC about y;
* eq. 3.15: the first-order series (in the angles) of the exact squareness translations of
  eq. 3.12 and 3.14.

Every printed matrix is compared entry by entry, every printed equation by
``expand(derived - printed) == 0``.
"""

from __future__ import annotations

import sympy as sp

from .framework import RECURRENCE_UNSHOWN, Verdict, fmt, is_zero

DATA_FILE = "printed_rotary.toml"
LAYOUTS = ("DMU50",)
SOURCE = "Ellingsdalen 2021"
LAYOUT = "DMU50"

C = sp.Symbol("C", real=True)
_NAMES = ("EXX EYX EZX EAX EBX ECX EXC EYC EZC EAC EBC ECC SXC SYC xx yx zx xC yC zC x z "
          "EC0XY EB0XZ EA0YZ").split()
SYM = {n: sp.Symbol(n, real=True) for n in _NAMES}


def _parse(text: str):
    return sp.sympify(text, locals={**SYM, "C": C, "cos": sp.cos, "sin": sp.sin})


def _mat(rows) -> sp.Matrix:
    return sp.Matrix([[_parse(c) for c in r] for r in rows])


def _skew(a, b, c) -> sp.Matrix:
    return sp.Matrix([[0, -c, b], [c, 0, -a], [-b, a, 0]])


def _small_htm(rot, trans) -> sp.Matrix:
    """I + [e]x + t as a 4x4 HTM (first order in the six error motions)."""
    m = sp.eye(4)
    m[:3, :3] += _skew(*rot)
    m[:3, 3] = sp.Matrix(trans)
    return m


def _rz(a) -> sp.Matrix:
    m = sp.eye(4)
    m[:2, :2] = sp.Matrix([[sp.cos(a), -sp.sin(a)], [sp.sin(a), sp.cos(a)]])
    return m


def _v(eq, comp, same, erratum, evidence, printed, derived, category="printing_error",
       **fields) -> Verdict:
    return Verdict(SOURCE, eq, LAYOUT, "identical" if same else "differs",
                   "" if same else erratum, evidence, printed, derived, comp,
                   category="identical" if same else category, **fields)


def _entries(printed: sp.Matrix, derived: sp.Matrix) -> list[str]:
    return [f"entry ({i + 1},{j + 1}): printed {fmt(printed[i, j])}, derived "
            f"{fmt(derived[i, j])}"
            for i in range(derived.rows) for j in range(derived.cols)
            if not is_zero(printed[i, j] - derived[i, j])]


# ------------------------------------------------------------------------------ linear axis
def audit_linear(item: dict) -> list[Verdict]:
    e = [SYM[n] for n in ("EAX", "EBX", "ECX")]
    t = [SYM[n] for n in ("EXX", "EYX", "EZX")]
    p = sp.Matrix([SYM["xx"], SYM["yx"], SYM["zx"], 1])
    dev = (_small_htm(e, t) - sp.eye(4)) * p               # deviation, bottom entry 0
    out = []
    literal = _mat(item["matrix"]) * sp.Matrix([_parse(c) for c in item["vector"]])
    diffs = [f"row {i + 1}: {item['lhs'][i]} = {fmt(sp.expand(literal[i]))}"
             for i in range(4) if sp.expand(literal[i] - dev[i]) != 0]
    out.append(_v(item["id"], "matrix equation", not diffs,
                  "the matrix equation gives the moved point, not its deviation",
                  "taken literally, the printed product is the moved point: " + "; ".join(diffs)
                  + " (the bottom row reads 0 = 1). The deviation is (T - T_nominal) p: the "
                  "printed matrix without its identity part and without the nominal x, with a "
                  "zero bottom row; the three equations printed under it are that deviation. "
                  "Category printing_error: left- and right-hand side disagree within the "
                  "equation, no convention reconciles them; the specialization project's eq. "
                  "(23) (appendix B, typeset separately) prints the same model as the deviation "
                  "matrix (zero diagonal, no nominal x, zero bottom row); the thesis' matrix "
                  "differs from it in five entries at once (the three 1s of the diagonal, the "
                  "'+ x' and the bottom 1), all consistently those of the X axis' HTM, which ch. 3.3.2 prints with exactly these entries: "
                  "another well-formed matrix, not glyph damage, so the author's edit",
                  "Delta = T p", "Delta = (T - T_nominal) p"))
    out[-1].readings_tried = ["the printed matrix times p, literally: the moved point (row 1 "
                              "holds x + xx, row 4 reads 0 = 1)",
                              "the matrix read as T - T_nominal (the deviation): gives the three "
                              "printed equations; the project's eq. (23) prints it so"]
    out[-1].readings_used = ["inconsistent:sec. 2.5 matrix equation lhs vs rhs"]
    for i, c in enumerate(("Delta_x", "Delta_y", "Delta_z")):
        pr = _parse(item["expr"][c])
        same = sp.expand(pr - dev[i]) == 0
        out.append(_v(item["id"], c, same, "differs",
                      "derived ([e]x p + t) with e = (E_AX, E_BX, E_CX), t = (E_XX, E_YX, E_ZX); "
                      f"expand(derived - printed) = {fmt(sp.expand(dev[i] - pr))}",
                      item["expr"][c], fmt(dev[i])))
    return out


# ------------------------------------------------------------------------------ rotary axis
def _deviation_rows(eq: str, item: dict, dev: sp.Matrix, printed_m: sp.Matrix) -> list[Verdict]:
    """The printed rows Delta_x, Delta_y, Delta_z against (T_ES - I) Rz(C) applied to a point
    of the table."""
    out = []
    p = sp.Matrix([SYM["xC"], SYM["yC"], SYM["zC"], 1])
    derived_eqs = dev * p
    printed_rows = printed_m * p
    for i, c in enumerate(("Delta_x", "Delta_y", "Delta_z")):
        pr = _parse(item["expr"][c])
        d = sp.expand(derived_eqs[i])
        diff = sp.simplify(d - pr)
        ev = f"derived row {i + 1} of (T_ES - I) Rz(C) [x_C, y_C, z_C, 1]^T = {fmt(d)}; " \
             f"derived - printed = {fmt(diff)}"
        erratum = "differs"
        cat, tried, used = "printing_error", [], []
        if diff != 0 and sp.simplify(sp.expand(d + pr - 2 * (d - d.coeff(SYM["ECC"])
                                                             * SYM["ECC"]))) == 0:
            erratum = "sign of the E_CC term"
            ecc = SYM["ECC"]
            same_as_matrix = sp.simplify(sp.expand(printed_rows[i]).coeff(ecc)
                                         - d.coeff(ecc)) == 0
            ev += ("; only the sign of the E_CC term differs"
                   + ("; the printed matrix just above gives the derived sign (+E_CC cos C, "
                      "-E_CC sin C in its row 2), so the equation contradicts its own matrix"
                      if same_as_matrix else "")
                   + "; eq. 3.4 (ch. 3) prints the same row with the derived sign. Category "
                   "undecidable: one extra minus sign, glyph-level damage that the print and "
                   "the text extraction explain equally (the matrix above and eq. 3.4 show the "
                   "intended sign, not whether this print has the minus); what would decide: "
                   "the page of the original PDF")
            cat = "undecidable"
            tried = ["row 2 of (T_ES - I) Rz(C) p (derived; the printed matrix above; eq. 3.4): "
                     "the sign of the E_CC term differs",
                     "a minus inserted by the print or by the extraction: exact"]
            used = ["glyph:eq. 2.42 Delta_y extra minus"]
        out.append(_v(eq, c, diff == 0, erratum, ev, item["expr"][c], fmt(d), category=cat))
        out[-1].readings_tried, out[-1].readings_used = tried, used
    return out


def _tcc_verdict(eq: str, item: dict, t_cc: sp.Matrix) -> Verdict:
    """The printed T_CC against the right-handed rotation Rz(C) of eq. 3.2."""
    out = []
    printed_cc = _mat(item["T_CC"])
    bad = _entries(printed_cc, t_cc)
    det = sp.simplify(printed_cc[:3, :3].det())
    out.append(_v(eq, "T_CC", not bad, "-cos C printed for cos C (not a rotation)",
                  "derived nominal rotation Rz(C), right-handed as the thesis' own eq. 3.2: "
                  + "; ".join(bad) + f"; the printed 3x3 block has det = {fmt(det)}, not 1: not "
                  "a rotation (at C = 0 it mirrors y). The matrix is also labelled "
                  f"{item['T_CC_label']}, the name of the product of eq. 2.42, where the text "
                  "announces T_CC. No rotation convention (active, passive, left- or "
                  "right-handed) has -cos C on the diagonal. Category undecidable: the defect "
                  "is one extra minus (and one subscript letter of the label), glyph-level "
                  "damage that the print and the text extraction explain equally; the "
                  "conference paper's eq. 1.16 (typeset separately) prints the nominal rotation "
                  "of B with +cos B, which shows the intended matrix but not this print; what "
                  "would decide: the page of the original PDF",
                  str(item["T_CC"]), fmt(t_cc), category="undecidable"))
    out[-1].readings_tried = ["right-handed Rz(C) (eq. 3.2): entry (2,2) differs",
                              "left-handed Rz(-C), transpose (passive): entry (2,2) differs",
                              "a minus inserted by the print or by the extraction: Rz(C) exactly"]
    out[-1].readings_used = ["glyph:eq. 2.42 T_CC extra minus"]
    return out[0]


def audit_rotary(item: dict) -> list[Verdict]:
    eq = f"eq. {item['id']}"
    e = [SYM[n] for n in ("EAC", "EBC", "ECC")]
    t = [SYM[n] for n in ("EXC", "EYC", "EZC")]
    t_es = _small_htm(e, t)
    t_ss = _small_htm((SYM["SXC"], SYM["SYC"], 0), (0, 0, 0))
    t_cc = _rz(C)
    out = []
    for name, derived, what in (("T_ES", t_es, "the small-angle HTM of the six error motions"),
                                ("T_SS", t_ss, "the small-angle rotation by S_XC about x and "
                                               "S_YC about y")):
        bad = _entries(_mat(item[name]), derived)
        out.append(_v(eq, name, not bad, "; ".join(bad), f"derived as {what}: "
                      + ("all 16 entries agree" if not bad else "; ".join(bad)),
                      str(item[name]), fmt(derived)))
    out.append(_tcc_verdict(eq, item, t_cc))
    # the deviation matrix "neglecting the squareness errors"
    dev = (t_es - sp.eye(4)) * t_cc
    printed_m = _mat(item["error_matrix"])
    bad = _entries(printed_m[:3, :], dev[:3, :])
    hint = ""
    if sp.simplify(printed_m[1, 2] + SYM["EXC"]) == 0:
        hint = (" The (2,3) entry is the rotation about x, -E_AC (the same row of T_ES printed "
                "above it has -E_AC): -E_XC there puts a translational error into a rotation "
                "entry.")
    out.append(_v(eq, "error matrix", not bad, "-E_XC printed where -E_AC belongs" if hint else
                  "; ".join(bad), "derived (T_ES - I) Rz(C), first order: "
                  + ("all entries of the first three rows agree" if not bad else "; ".join(bad))
                  + hint + (" Candidate repetition within one image: E_XC also stands at "
                            "(1,4) of this matrix, the entry read three entries before (2,3) "
                            "('... & E_{\\rm BC}(C) & E_{\\rm XC}(C) \\\\ E_{\\rm CC}(C)"
                            "cos\\theta & -E_{\\rm CC}(C)sin\\theta & -E_{\\rm XC}(C)'). "
                            "The conference paper's B-axis matrix eq. 1.17, typeset separately, "
                            "has -E_XB at the same entry below E_XB at (1,4), but the two "
                            "product matrices are images of the same layout (the same entries "
                            "with B for C): the same entry at the same place weighs towards "
                            "the print, but by the cross-copy rule a repetition there does not "
                            "decide (" + RECURRENCE_UNSHOWN + "). The "
                            "extraction reads -E_A right at (2,3) of the error matrices T_ES "
                            "just above and T_EB (paper eq. 1.15), whose other entries differ "
                            "(1 on the diagonal, no cos/sin), which decides neither. For the "
                            "print: the author writing E_X of the entry above-right (and the "
                            "paper's matrix made from the thesis' one). For the extraction: the "
                            "token E_X of (1,4) emitted again, a repetition of the kind it "
                            "demonstrably makes within an image (the error matrix of T_0^{t,c} "
                            "after eq. 3.37 has three rows '-E_{DX} & ... & 1 & E_{ZX}', two of "
                            "them identical). Category undecidable; what would decide: the page "
                            "of the original PDF" if hint else ""),
                  str(item["error_matrix"]), fmt(dev),
                  category="undecidable" if hint else "printing_error"))
    if hint:
        out[-1].readings_tried = ["(T_ES - I) Rz(C), derived: entry (2,3) is -E_AC",
                                  "E_XC of (1,4) repeated at (2,3), by the print or by the "
                                  "extraction: the printed entry; the separately typeset paper "
                                  "eq. 1.17 (an image of the same layout) repeats -E_X at (2,3)"]
        out[-1].readings_used = ["glyph:eq. 2.42 (2,3) repeats E_XC of (1,4), also paper eq. "
                                 "1.17"]
    row4 = [fmt(v) for v in printed_m[3, :]]
    ok4 = all(v == 0 for v in printed_m[3, :])
    out.append(_v(eq, "error matrix row 4", ok4, "bottom row 0 0 0 1 under a left-hand side 0",
                  f"the printed bottom row [{', '.join(row4)}] times [x_C, y_C, z_C, 1] gives 1, "
                  "the left-hand side says 0; a deviation matrix has the bottom row 0 0 0 0 "
                  "(the product T_ES T_CC minus T_CC). Category printing_error by the "
                  "cross-copy rule: the equation contradicts itself, and the conference paper's "
                  "eq. 1.17 (typeset separately) has the same bottom row 0 0 0 1 -- a '1' for a "
                  "'0' at the same place in two images (a digit of a matrix row, not a symbol "
                  "repeated from its neighbourhood), while the extraction reads the zero bottom "
                  "row '0 & 0 & 0 & 0' of the deviation matrix of the specialization project's "
                  "eq. (23) right, an image of the same layout at this place (a deviation "
                  "matrix between [Delta; 0] and [x; y; z; 1]): the author's source. The "
                  "paper's eq. 1.17 prints no left-hand side, but its 0 0 0 1 is a defect "
                  "there too: its diagonal is a deviation matrix's ((1,1) -E_CB s_B, (3,3) 0; "
                  "no 1 and no c_B, which an HTM T_EB Rz(B) has there), and a deviation "
                  "matrix has the bottom row 0 0 0 0 (see that verdict). The thesis' "
                  "error model of the X axis in ch. 2 (the linear-axis model before eq. 2.42, "
                  "'[Delta_x(x); Delta_y(x); Delta_z(x); 0] = [... ; 0 0 0 1] [x_x; y_x; z_x; "
                  "1]') also sets [Delta; 0] over a bottom row 0 0 0 1: the author's habit, "
                  "which supports the category",
                  str(row4), "[0, 0, 0, 0]"))
    if not ok4:
        out[-1].readings_tried = ["deviation matrix (T_ES - I) Rz(C): bottom row 0 0 0 0",
                                  "the HTM T_ES Rz(C) (bottom row 0 0 0 1): its other entries "
                                  "would need the identity part, which the printed matrix lacks"]
        out[-1].readings_used = ["inconsistent:eq. 2.42 bottom row vs lhs"]
    out.extend(_deviation_rows(eq, item, dev, printed_m))
    return out


# ----------------------------------------------------------------------------- eq. 3.15
def audit_squareness(item: dict) -> list[Verdict]:
    eq = f"eq. {item['id']}"
    out = []
    angles = [SYM["EC0XY"], SYM["EB0XZ"], SYM["EA0YZ"]]
    eps = sp.Symbol("eps")
    for axis, key in (("X", "X"), ("Z", "Z")):
        for i, (pr_t, ex_t) in enumerate(zip(item[key], item[key + "_exact"])):
            exact = _parse(ex_t)
            scaled = exact.subs({a: eps * a for a in angles}, simultaneous=True)
            first = sp.expand(sp.series(scaled, eps, 0, 2).removeO().subs(eps, 1))
            pr = _parse(pr_t)
            diff = sp.expand(first - pr)
            out.append(_v(eq, f"{axis} axis, row {i + 1}", diff == 0,
                          f"{fmt(pr)} printed for {fmt(first)}",
                          f"first-order series of the exact {fmt(exact)} (eq. 3.12 / 3.14) in the "
                          f"squareness angles: {fmt(first)}"
                          + ("" if diff == 0 else
                             f"; the printed {fmt(pr)} is the angle times the displacement "
                             f"where cos(angle) ~ 1 belongs: the nominal displacement itself is "
                             f"lost (it is there in the Z-axis matrix, whose (3,4) entry is z). "
                             f"The printed entry repeats the entry below it (x E_C(0X)Y): a "
                             f"repeated entry, which the print (a copied line) and the text "
                             f"extraction (a repeated span) explain equally. Category "
                             f"undecidable; what would decide: the page of the original PDF"),
                          pr_t, fmt(first), category="undecidable"))
            if diff != 0:
                out[-1].readings_tried = [f"first-order series of eq. 3.12: {fmt(first)}",
                                          "the entry below repeated by the print or by the "
                                          "extraction: the printed entry exactly"]
                out[-1].readings_used = [f"glyph:eq. 3.15 {axis} row {i + 1} repeated entry"]
    return out


def audit(printed: dict, layouts=None) -> list[Verdict]:
    """Verdicts on the printed axis error models (sec. 2.5, eq. 3.15)."""
    if layouts is not None and not set(layouts) & set(LAYOUTS):
        return []
    out = []
    if "linear" in printed:
        out += audit_linear(printed["linear"])
    if "rotary" in printed:
        out += audit_rotary(printed["rotary"])
    if "squareness" in printed:
        out += audit_squareness(printed["squareness"])
    return out
