"""Audit of the HTMs, axis error models and chains of Ellingsdalen (2021) outside ch. 3.5: the
conference paper (thesis appendix A, eq. 1.1-1.19), ch. 3 (eq. 3.1-3.3, 3.16-3.18, 3.39-3.40)
and the specialization project report (appendix B, eq. 1-9, 16, 17, 23, 24, 27-29); sympy, no
file I/O.

The printed material is the parsed ``data/printed_htm.toml``.  The authority:

* chain factors: :func:`volerr.derive.audit.dmu50.derived_factors` of the DMU50 layout (the
  factor form the DMU 50 audit checks against the chain), products against
  ``Chain.nominal_htm()`` (tool -> workpiece, T_w^t);
* linear axis HTMs: the first-order stage of :func:`volerr.derive.kinematics.stage_factors`
  (motion, squareness twist, error twist) of the DMU50 layout; the squareness symbols of the
  print are compared in both signs -- the thesis defines them by the direction vectors of eq.
  3.11 and 3.13 (an axis leaning toward the positive other axis is positive), ISO 230-1 and
  volerr by the right-handed rotation about A/B/C;
* the rotary axis model: volerr's rotary stage order (location and orientation errors, error
  motions, nominal rotation) in the axis' own frame, its deviation (T_E - I) Rz(q);
* relations of the three-point method (eq. 3.1-3.3, 27-29): the nominal positions of a point
  on the moving body.

Each verdict lists the readings tried (rotation sense, inverse/transpose, sign conventions of
the squareness symbols, extraction readings of the labels) and the keys it rests on.
"""

from __future__ import annotations

import functools
import itertools

import numpy as np
import sympy as sp

from volerr.machine.layout import read_layout

from .framework import Verdict, category_of, fmt, is_zero, worst_case_um
from .dmu50 import (T22_UNDECIDED, T23_CROSS_COPY, derived_factors, derived_forward,
                          forward_note, forward_tried, t23_forward)
from ..kinematics import Chain, position_symbol, rotation, stage_factors, translation

DATA_FILE = "printed_htm.toml"
LAYOUTS = ("DMU50",)
SOURCE = "Ellingsdalen 2021"
LAYOUT = "DMU50"
DOCS = {"paper": "conference paper (appendix A)", "thesis": "thesis ch. 3",
        "project": "project report (appendix B)"}

X, Y, Z, B, C = (position_symbol(a) for a in "XYZBC")
D = sp.Symbol("d", real=True)
_NAMES = ("EXX EYX EZX EAX EBX ECX EXY EYY EZY EAY EBY ECY EXZ EYZ EZZ EAZ EBZ ECZ "
          "EXB EYB EZB EAB EBB ECB EX0B EY0B EA0B EB0B EC0XY EB0XZ EA0YZ "
          "xo yo zo x xP yP zP xmP ymP zmP xx yx zx").split()
SYM = {n: sp.Symbol(n, real=True) for n in _NAMES}
_LOC = {**SYM, "X": X, "Y": Y, "Z": Z, "B": B, "C": C, "d": D,
        "c45": sp.sqrt(2) / 2, "s45": sp.sqrt(2) / 2}
#: paper symbol -> ISO parameter of the DMU50 layout (the physical sign)
SQUARENESS = {"EC0XY": ("EC0Y", "E_C(0X)Y", "eq. 3.11 n_X = [cos E, sin E, 0]: X leans toward "
                        "+Y for E > 0, i.e. Y toward +X relative to X"),
              "EB0XZ": ("EB0Z", "E_B(0X)Z", "eq. 3.13 n_Z x-component sin E_B(0X)Z: Z leans "
                        "toward +X"),
              "EA0YZ": ("EA0Z", "E_A(0Y)Z", "eq. 3.13 n_Z y-component cos E_B sin E_A(0Y)Z: Z "
                        "leans toward +Y")}


@functools.lru_cache(maxsize=None)
def _parse(text: str):
    """A printed entry -> sympy, once per text (the matrices repeat their entries)."""
    return sp.sympify(text, locals=_LOC)


def _mat(rows) -> sp.Matrix:
    return sp.Matrix([[_parse(c) for c in r] for r in rows])


def _v(item, comp, category, erratum, evidence, printed, derived, tried=(), used=(),
       **fields) -> Verdict:
    eq = f"{item['doc']} eq. {item['id']}"
    same = category == "identical"
    return Verdict(SOURCE, eq, LAYOUT, "identical" if same else "differs",
                   "" if same else erratum, evidence, printed, derived, comp,
                   category=category, readings_tried=list(tried), readings_used=list(used),
                   **fields)


def _entries(p: sp.Matrix, d: sp.Matrix) -> list[str]:
    return [f"({i + 1},{j + 1}) printed {fmt(p[i, j])}, derived {fmt(d[i, j])}"
            for i in range(d.rows) for j in range(d.cols)
            if not is_zero(p[i, j] - d[i, j])]


@functools.lru_cache(maxsize=1)
def _derived():
    layout = read_layout("DMU50")
    chain = Chain.from_layout(layout)
    return layout, chain, derived_factors(layout)


# ------------------------------------------------------------------------ chain factors
def _sense_reversed(m: sp.Matrix):
    """The factor with its rotation angle reversed (B -> -B, C -> -C), and its transpose of
    the rotation block (inverse rotation)."""
    rev = m.subs({B: -B, C: -C}, simultaneous=True)
    inv = m.copy()
    inv[:3, :3] = m[:3, :3].T
    return rev, inv


def audit_matrix(item: dict) -> list[Verdict]:
    _, _, factors = _derived()
    name = item["name"]
    derived = factors[name]
    printed = _mat(item["rows"])
    out = []
    bad = _entries(printed, derived) if printed.shape == derived.shape else ["shape"]
    tried = [f"the derived factor {name} (DMU50 layout): "
             + ("exact" if not bad else "; ".join(bad))]
    if not bad:
        out.append(_v(item, "matrix", "identical", "", f"all entries equal the derived "
                      f"{name} (the DMU50 chain's factor, {DOCS[item['doc']]})", str(item["rows"]),
                      fmt(derived), tried))
    else:
        rev, inv = _sense_reversed(derived)
        srev = sp.simplify(printed - rev) == sp.zeros(4, 4)
        sinv = sp.simplify(printed - inv) == sp.zeros(4, 4)
        tried += [f"rotation sense reversed: {'exact' if srev else 'differs'}",
                  f"inverse (transposed rotation block): {'exact' if sinv else 'differs'}"]
        det = sp.simplify(printed[:3, :3].det())
        if name == "T_5^w" and srev:
            tried[1] = ("rotation sense reversed: exact, but the documents fix the sense of C "
                        "(see the evidence): a reading the document contradicts")
            tried[2] = (f"inverse (transposed rotation block): {'exact' if sinv else 'differs'}"
                        ", but eq. 1.8 writes the inverse explicitly, (T_5^w)^{-1}: the factor "
                        "printed here is T_5^w itself")
            tried.append("extraction damage: a minus moved from (2,1) to (1,2), two glyph "
                         "defects at once; the block's eq. 1.4 is read with its minus at (3,2)")
            ev = ("printed Rz(+C), extraction text '" + item.get("text", "") + "'; the derived "
                  "T_5^w turns by -C: " + "; ".join(bad) + ". Readings: (1) the reversed sense "
                  "of C reproduces it exactly, but the documents fix the sense: the project "
                  "report's frame 7 'x_w y_w z_w rotates x_5 y_5 z_5 an angle -C about z_5', "
                  "thesis eq. 3.35, project eq. (6) and Listing 3.3 T_C print Rz(-C), and "
                  "Sorby's forward kinematics (eq. 3.19-3.24) need it. (2) The inverse (the "
                  "transposed rotation block) reproduces it too, but eq. 1.8 writes the inverse "
                  "explicitly, (T_5^w)^{-1}: the factor printed here is T_5^w itself, and read "
                  "as its inverse the chain would invert it twice. (3) Extraction damage would "
                  "have to move a minus from (2,1) to (1,2) -- lose one and insert one, two "
                  "glyph defects that turn one rotation into the other -- while the same block "
                  "is read with the minus of a rotation's other sign pattern (eq. 1.4, "
                  "'0 & -s_{45^\\circ} & c_{45^\\circ}' in its row 3): it does not normalise "
                  "rotations to one sign pattern; the vertical bars and lower-case c_c, s_c of "
                  "the extraction change no entry. The print is the well-formed Rz(+C), eq. "
                  "1.3's sign pattern with B replaced by C (the label T_2^3 is eq. 1.3's too, "
                  "see the label's verdict; the category does not rest on the label, as labels "
                  "of this block are damaged elsewhere). Category printing_error: a rotation "
                  "sense that contradicts the one the same documents fix")
            out.append(_v(item, "matrix", "printing_error", "rotation sense of C reversed (eq. "
                          "1.3's sign pattern with B -> C)", ev, str(item["rows"]),
                          fmt(derived), tried, ["inconsistent:paper eq. 1.6 sense of C"]))
        elif name == "T_2^3":
            fwd = t23_forward(item["rows"])
            tried += forward_tried(fwd)
            ev = ("; ".join(bad) + f"; the printed 3x3 block has det = {fmt(det)}: not a "
                  "rotation in either sense. " + T23_CROSS_COPY.format(
                      other="thesis eq. 3.32, typeset separately, prints the same [[c_B, s_B], "
                            "[s_B, c_B]], and so does the thesis' 'updated' chain after eq. "
                            "3.37 (T_2^{3,c})", fwd=forward_note(fwd)))
            out.append(_v(item, "matrix", "printing_error", "sign error in 1 entry (as thesis "
                          "eq. 3.32)", ev, str(item["rows"]), fmt(derived), tried,
                          ["inconsistent:T_2^3 sign of s_B (1,2)"]))
        else:
            out.append(_v(item, "matrix", "printing_error", "wrong entries", "; ".join(bad),
                          str(item["rows"]), fmt(derived), tried, []))
    if item["label"] != name:
        kind = item.get("label_kind", "glyph")
        cat = {"glyph": "undecidable", "copy": "printing_error", "cross": "printing_error",
               "extraction": "extraction"}[kind]
        why = {"glyph": "Category undecidable: glyph-level, explained equally by the print and "
                        "by the text extraction; what would decide: the page of the original PDF",
               "copy": "Category printing_error by the cross-copy rule: the label of another "
                       "equation, which an extraction would have to carry from that image "
                       "into this one",
               "cross": "Category printing_error by the cross-copy rule: the same "
                        "substitution at the same place in two images",
               "extraction": "Category extraction"}[kind]
        key = {"glyph": "glyph", "copy": "copy", "cross": "copy",
               "extraction": "ocr"}[kind]
        out.append(_v(item, "label", cat, f"labelled {item['label']} for {name}",
                      f"the factor at this place of the chain is {name}; printed label "
                      f"{item['label']}: {item.get('label_note', '')}. "
                      f"{item.get('label_why', why)}", item["label"],
                      name, [f"the label as printed, {item['label']}: not {name}",
                             f"read as {name}: the factor's place in eq. 1.8"],
                      [f"{key}:{item['doc']} eq. {item['id']} label"]))
    return out


# ----------------------------------------------------------------------------- products
def _htm_inv(m: sp.Matrix) -> sp.Matrix:
    """Inverse of an HTM: [[R^T, -R^T p], [0, 1]]."""
    out = sp.eye(4)
    out[:3, :3] = m[:3, :3].T
    out[:3, 3] = -(m[:3, :3].T * m[:3, 3])
    return out


def _factor(name: str):
    """A printed factor name -> derived matrix (None for a name that is no frame pair)."""
    _, chain, f = _derived()
    inv = name.startswith("(") and name.endswith(")^-1")
    base = name[1:-4] if inv else name
    a, b = base[2:].split("^")
    if f"T_{a}^{b}" in f:
        m = f[f"T_{a}^{b}"]
    elif f"T_{b}^{a}" in f:
        m = _htm_inv(f[f"T_{b}^{a}"])
    elif base == "T_t^0":
        m = _htm_inv(f["T_0^t"])
    else:
        return None
    return _htm_inv(m) if inv else m


def audit_product(item: dict) -> Verdict:
    layout, chain, f = _derived()
    tw = chain.nominal_htm()                      # T_w^t: tool frame -> workpiece frame
    args = (X, Y, Z, B, C, D)
    target = sp.lambdify(args, tw, "numpy")
    mats = [_factor(n) for n in item["factors"]]
    order = ["T_w^5", "T_5^4", "T_4^3", "T_3^2", "T_2^1", "T_1^0", "T_0^t"]
    tried = []
    if all(m is not None for m in mats):
        fns = [sp.lambdify(args, m, "numpy") for m in mats]
        rng = np.random.default_rng(16)
        worst = 0.0
        for _ in range(5):
            q = (*rng.uniform(-300, 300, 3), *rng.uniform(-3, 3, 2), 154.996)
            prod = np.eye(4)
            for fn in fns:
                prod = prod @ np.array(fn(*q), dtype=float)
            want = np.array(target(*q), dtype=float)
            if item["id"] == "(16)":
                want = np.linalg.inv(want)
            worst = max(worst, float(np.max(np.abs(prod - want))))
        same = worst < 1e-9
        tried.append(f"the printed product evaluated at 5 random poses against the chain's "
                     f"{'inverse ' if item['id'] == '(16)' else ''}T_w^t: max |difference| "
                     f"{worst:.2g}")
        what = "(T_w^t)^-1 = T_t^w" if item["id"] == "(16)" else "T_w^t"
        return _v(item, "", "identical" if same else "printing_error", "product differs",
                  f"the product of the printed factors (each the derived factor of its name, "
                  f"T_b^a the inverse of T_a^b) equals the chain's {what} at 5 random poses "
                  f"(max |difference| {worst:.2g})", item["text"], " ".join(order), tried)
    bad = [n for n, m in zip(item["factors"], mats) if m is None]
    tried.append(f"the printed factors as frame pairs: {', '.join(bad)} map no frame of the "
                 f"chain")
    tried.append("the subscripts of T_2^2 and T_1^1 repetitions of their superscripts (print "
                 "or extraction): T_2^2 not decided by thesis eq. 3.37, an image of the same "
                 "layout with the same defect; T_1^1 in this copy only")
    return _v(item, "", "undecidable", f"{', '.join(bad)} printed for T_3^2, T_2^1",
              f"derived order {' '.join(order)}; printed {' '.join(item['factors'])}: "
              f"{', '.join(bad)} are no frame pairs of the chain (a frame does not map into "
              f"itself). " + T22_UNDECIDED.format(
                  here="T_2^2 stands where T_3^2 belongs and T_1^1 where T_2^1 belongs",
                  there="thesis eq. 3.37, typeset separately, has T_2^2 at the same place "
                        "('T_w^5 T_5^4 T_4^3 T_2^2 T_1^0 T_1^d'); T_1^1 stands in this copy "
                        "only (the thesis has no factor between T_2^2 and T_1^0)")
              + " Category undecidable; what would decide: the page of the original PDF",
              item["text"], " ".join(order), tried,
              ["glyph:product factors T_2^2, T_1^1 repeat their superscripts"])


# ----------------------------------------------------------------------- linear axes
@functools.lru_cache(maxsize=None)
def _linear_stage(axis: str) -> sp.Matrix:
    """First-order HTM of a DMU50 linear stage: motion + squareness twist + error twist."""
    layout, _, _ = _derived()
    m = sp.zeros(4, 4)
    for fac in stage_factors(layout, axis):
        m += fac.nominal if fac.nominal is not None else fac.first_order()
    iso = {sp.Symbol(k, real=True): SYM[p] for p, (k, _, _) in SQUARENESS.items()}
    return m.xreplace(iso)


def audit_linear(item: dict) -> Verdict:
    axis = item["axis"]
    printed = _mat(item["rows"])
    stage = _linear_stage(axis)
    if item["kind"] == "deviation":
        stage = stage - sp.diag(1, 1, 1, 1)
        stage[0, 3] -= X                        # the deviation: T - T_nominal
    sq = [s for s in SQUARENESS if printed.has(SYM[s])]
    hits, tried = [], []
    for k in range(len(sq) + 1):
        for flips in itertools.combinations(sq, k):
            d = stage.subs({SYM[s]: -SYM[s] for s in flips}, simultaneous=True)
            bad = _entries(printed, d)
            label = ("the derived stage" if not flips else
                     "the derived stage with " + ", ".join(
                         f"{SQUARENESS[s][1]} signed as the thesis does ({SQUARENESS[s][2]})"
                         for s in flips))
            tried.append(f"{label}: " + ("exact" if not bad else "; ".join(bad)))
            if not bad:
                hits.append(flips)
    ocr = item.get("ocr_note", "")
    ocr_txt = f" Extraction reading: {ocr}." if ocr else ""
    what = {"linear": f"the {axis} stage of the DMU50 chain to first order: Trans(q u) + "
                      f"squareness twist + error twist (volerr.derive.kinematics.stage_factors)",
            "deviation": "the X stage minus its nominal motion (the deviation matrix)"}[
                item["kind"]]
    if not hits:
        return _v(item, "", "printing_error", "entries differ", f"compared with {what}: "
                  + tried[0] + ocr_txt, str(item["rows"]), fmt(stage), tried)
    flips = min(hits, key=len)
    if not flips:
        cat = "extraction" if ocr else "identical"
        used = [f"ocr:{item['doc']} eq. {item['id']} subscripts"] if ocr else []
        return _v(item, "", cat, "identical once the subscripts are read", f"every entry "
                  f"equals {what}." + ocr_txt + (" Category extraction: the printed symbols "
                                                 "are no symbols of the document's notation."
                                                 if ocr else ""),
                  str(item["rows"]), fmt(stage), tried, used)
    used = [f"flip:thesis {SQUARENESS[s][1]} (slope convention, eq. 3.11/3.13)" for s in flips]
    if ocr:
        # the repair of the extraction's symbols is part of what reproduces the print
        used.append(f"ocr:{item['doc']} eq. {item['id']} symbols")
        tried.append(f"the extraction's reading ({ocr}) with the thesis' squareness signs: "
                     "exact (the printed symbols are read before any comparison)")
    names = "; ".join(f"{SQUARENESS[s][1]} positive when the moving axis leans toward the "
                      f"positive other axis ({SQUARENESS[s][2]})" for s in flips)
    iso = "; ".join(f"volerr/ISO 230-1 {SQUARENESS[s][0]}: right-handed rotation about "
                    f"{SQUARENESS[s][0][1]}, {SQUARENESS[s][1]} = -{SQUARENESS[s][0]}"
                    for s in flips)
    return _v(item, "", category_of(used), "squareness sign: " + ", ".join(
        SQUARENESS[s][1] for s in flips) + " signed as in eq. 3.11/3.13",
        f"equals {what} with the squareness symbol(s) signed as the thesis defines them: "
        f"{names}; {iso}. The thesis' sec. 2.3.1 calls a squareness positive when the angle "
        f"between the axes exceeds 90 deg, which is the opposite sign for these symbols; eq. "
        f"3.11 and 3.13 define the sign the matrices use." + ocr_txt,
        str(item["rows"]), fmt(stage), tried, used, statement=names,
        alternative=fmt(stage.subs({SYM[s]: -SYM[s] for s in flips}, simultaneous=True)))


def audit_deviation_rows(item: dict) -> Verdict:
    dev = _linear_stage("X") - sp.diag(1, 1, 1, 1)
    dev[0, 3] -= X
    p = sp.Matrix([SYM["xx"], SYM["yx"], SYM["zx"], 1])
    rows = dev * p
    printed = [_parse(r[0]) for r in item["rows"]]
    bad = [i for i in range(3) if sp.expand(rows[i] - printed[i]) != 0]
    return _v(item, "", "identical" if not bad else "printing_error", "rows differ",
              "each printed row equals the row of the deviation matrix (X stage minus its "
              "nominal motion) times [x_x, y_x, z_x, 1]" if not bad else f"rows {bad} differ",
              "; ".join(r[0] for r in item["rows"]), fmt(list(rows[:3])))


# ---------------------------------------------------------------------- rotary axis (B)
def _skew(a, b, c) -> sp.Matrix:
    return sp.Matrix([[0, -c, b], [c, 0, -a], [-b, a, 0]])


def _small(rot, trans) -> sp.Matrix:
    m = sp.eye(4)
    m[:3, :3] += _skew(*rot)
    m[:3, 3] = sp.Matrix(trans)
    return m


def audit_rotary(item: dict) -> Verdict:
    kind = item["kind"]
    e = [SYM[n] for n in ("EAB", "EBB", "ECB")]
    t = [SYM[n] for n in ("EXB", "EYB", "EZB")]
    rz = rotation((0, 0, 1), B)
    if kind == "rotary_product":
        order = item["rows"][0]
        same = order == ["T_OB", "T_SB", "T_EB", "T_BB"]
        return _v(item, "", "identical" if same else "printing_error", "factor order differs",
                  "volerr's rotary stage (volerr.derive.kinematics.stage_factors): Trans(c) "
                  "(I + D_location) (I + D_B(q)) Rot(u, q) Trans(-c) -- location (position "
                  "O_XB, O_YB and orientation E_A0B, E_B0B, first order: T_OB T_SB), error "
                  "motions (T_EB), nominal rotation (T_BB), in this order, as printed; the "
                  "same order as the thesis' eq. 2.42 for C", item["text"],
                  "T_OB T_SB T_EB T_BB")
    derived = {"rotary_location": _small((0, 0, 0), (SYM["EX0B"], SYM["EY0B"], 0)),
               "rotary_orientation": _small((SYM["EA0B"], SYM["EB0B"], 0), (0, 0, 0)),
               "rotary_error": _small(e, t),
               "rotary_nominal": rz}[kind] if kind != "rotary_deviation" else None
    printed = _mat(item["rows"])
    if derived is not None:
        bad = _entries(printed, derived)
        what = {"rotary_location": "the translation by the position errors E_X0B, E_Y0B "
                                   "(O_XB, O_YB)",
                "rotary_orientation": "the small-angle rotation by the orientation errors "
                                      "E_A0B about x and E_B0B about y",
                "rotary_error": "I + [e]x + t of the six error motions of B",
                "rotary_nominal": "the right-handed rotation Rz(B) (as the thesis' eq. 3.2 "
                                  "for C; eq. 2.42 prints -cos on the diagonal)"}[kind]
        note = f" {item['glyph_note']}." if item.get("glyph_note") else ""
        return _v(item, "", "identical" if not bad else "printing_error", "; ".join(bad),
                  f"every entry equals {what}" + ("" if not bad else ": " + "; ".join(bad))
                  + "." + note, str(item["rows"]), fmt(derived))
    dev = (_small(e, t) - sp.eye(4)) * rz
    bad = _entries(printed, dev)
    tried = [f"(T_EB - I) Rz(B), the deviation (derived): {len(bad)} entries differ"]
    alts = {"rotation sense reversed, (T_EB - I) Rz(-B)": (_small(e, t) - sp.eye(4))
            * rotation((0, 0, 1), -B),
            "error rotation transposed, (T_EB^T - I) Rz(B)": (_small([-x for x in e], t)
                                                               - sp.eye(4)) * rz,
            "the HTM T_EB Rz(B) instead of the deviation": _small(e, t) * rz}
    for name, m in alts.items():
        n = len(_entries(printed, m))
        tried.append(f"{name}: {'exact' if n == 0 else f'{n} entries differ'}")
    htm = _small(e, t) * rz
    no_error = {s_: 0 for s_ in (*e, *t)}
    missing = [(i + 1, j + 1) for i in range(3) for j in range(3)
               if not is_zero(printed[i, j].subs(no_error) - rz[i, j])]
    n_htm = len(_entries(printed, htm))
    return _v(item, "", "printing_error", f"{len(bad)} entries differ from (T_EB - I) Rz(B)",
              "derived (T_EB - I) Rz(B), first order (the squareness neglected as stated): "
              + "; ".join(bad) + ". No reading (rotation sense, transposed error rotation, "
              "the HTM instead of the deviation) reproduces it. The paper prints no left-hand "
              "side: the matrix is introduced as 'the error model for the B-axis' and labelled "
              "'^{T}T_{0}^{B}', like eq. 1.12's HTM '^{e}T_{0}^{B} = T_OB T_SB T_EB T_BB'. "
              f"Read as that HTM, T_EB Rz(B) to first order, its bottom row 0 0 0 1 is right and "
              f"{n_htm} entries differ: the nominal rotation is missing from "
              f"{len(missing)} of them ({', '.join(f'({i},{j})' for i, j in missing)}: the "
              "c_B, s_B of the rotation block and the 1 at (3,3)), which print only error "
              "terms, the deviation's form -- a whole, well-formed pattern (the error terms "
              "without the rotation they multiply), not damage to a few glyphs, which no "
              "extraction produces: the author's source. Read as the deviation, as the thesis "
              "prints it for C (eq. 2.42, with the deviation vector on its left), the bottom "
              "row 0 0 0 1 is eq. 2.42's defect at the same place in a separately typeset "
              "document: a digit of a matrix row, not a symbol repeated from its "
              "neighbourhood, which the extraction reads right in the same place of the "
              "specialization project's eq. (23) ('0 & 0 & 0 & 0'), an image of the same "
              "layout there: by the cross-copy rule the author's source. Entry (2,3) -E_XB (a "
              "translational error where the rotation -E_AB belongs) is eq. 2.42's defect too, "
              "but E_XB also stands at (1,4) of this matrix, three entries before: a candidate "
              "repetition, and the two product matrices are images of the same layout, so it "
              "stays undecided (see the verdict on eq. 2.42's error matrix). The other three "
              "are single signs only this copy has (the thesis' matrix does not): print or "
              "extraction, undecided. Category printing_error under either reading: read as "
              "the HTM its label names, the missing nominal rotation; read as the deviation, "
              "the bottom row is decided to be printed",
              str(item["rows"]), fmt(dev), tried,
              ["copy:paper eq. 1.17 bottom row of thesis eq. 2.42",
               "inconsistent:paper eq. 1.17 labelled as eq. 1.12's HTM without its nominal "
               "rotation"])


# ------------------------------------------------------------------------------- items
def _linear_deviation(item: dict, o: sp.Matrix, r: sp.Matrix) -> list[Verdict]:
    """The deviation of a point on the X carriage (measured minus nominal): the result and
    the middle member of the printed equation."""
    xm = sp.Matrix([SYM["xmP"], SYM["ymP"], SYM["zmP"], 1])
    derived = xm - translation(o + sp.Matrix([SYM["x"], 0, 0])) * r
    res = sp.Matrix([_parse(t) for t in item["result"]])
    same = sp.expand(res - derived) == sp.zeros(4, 1)
    out = [_v(item, "result", "identical" if same else "printing_error", "differs",
              "the right-most member equals measured minus nominal, [x'_Pt - x_xP - x_o - "
              "x, y'_Pt - y_xP - y_o, z'_Pt - z_xP - z_o, 0]", item["text"],
              fmt(list(derived)))]
    out.append(_v(item, "middle member", "undecidable", "entry z'_Pt misplaced",
                  "the middle member subtracts [x_Pt, y_Pt, z'_Pt, 1] from [x'_Pt, y'_Pt, 1]: "
                  "the first vector has three entries and the second a measured entry "
                  "z'_Pt where the nominal z_Pt belongs -- the entry z'_Pt moved from one "
                  "vector to the other. The right-most member and eq. (30) are right. "
                  "Category undecidable: a misplaced entry, which the print (a slip while "
                  "typing) and the text extraction (entries of two stacked vectors "
                  "exchanged) explain equally; what would decide: the page of the original "
                  "PDF", "[x'_Pt, y'_Pt, 1] - [x_Pt, y_Pt, z'_Pt, 1]",
                  "[x'_Pt, y'_Pt, z'_Pt, 1] - [x_Pt, y_Pt, z_Pt, 1]",
                  ["the vectors as printed: a 3-vector minus a 4-vector",
                   "z'_Pt read in the first vector and z_Pt in the second: the right-most "
                   "member exactly"], [f"glyph:project eq. {item['id']} entry z'_Pt"]))
    return out


def _cl_data(item: dict, chain) -> list[Verdict]:
    """The CL data (tool axis and tip) as T_w^t applied to e_z and the tool frame's origin,
    against the derived forward kinematics at a test pose."""
    fwd = derived_forward(chain)
    tw = chain.nominal_htm()
    cols = tw * sp.Matrix([[0, 0], [0, 0], [1, 0], [0, 1]])
    want = sp.Matrix([[fwd["i"], fwd["x"]], [fwd["j"], fwd["y"]], [fwd["k"], fwd["z"]],
                      [0, 1]])
    fn = sp.lambdify((X, Y, Z, B, C, D), cols - want, "numpy")
    worst = float(np.max(np.abs(np.array(fn(30.0, -20.0, 50.0, 0.7, -1.1, 154.996),
                                          dtype=float))))
    return [_v(item, "", "identical" if worst < 1e-9 else "printing_error", "differs",
               f"T_w^t applied to the tool axis e_z (direction, homogeneous 0) and to the "
               f"tool tip (the tool frame's origin) gives the tool axis (i, j, k) and tip "
               f"(x, y, z) of the derived forward kinematics (max |difference| {worst:.2g} "
               f"at a test pose)", item["text"], "[i x; j y; k z; 0 1] = T_w^t [e_z, o_t]")]


def audit_item(item: dict, axes: dict) -> list[Verdict]:
    kind = item["kind"]
    layout, chain, f = _derived()
    o = sp.Matrix([SYM["xo"], SYM["yo"], SYM["zo"]])
    r = sp.Matrix([SYM["xP"], SYM["yP"], SYM["zP"], 1])
    if kind == "origin_fixed":
        return [_v(item, "", "identical", "", "the C axis turns about the origin o of its "
                   "frame: its nominal position does not move (identity)", item["text"],
                   "o_t = o")]
    if kind == "deviation":
        return [_v(item, "", "identical", "", "volumetric error = measured minus nominal "
                   "homogeneous coordinates (the 4th entry 1 - 1 = 0), as volerr.identify "
                   "defines it", item["text"], "Delta = p_measured - p_nominal")]
    if kind in ("rotary_point", "linear_origin", "linear_point"):
        printed = _mat(item["rows"])
        derived = {"rotary_point": translation(o) * rotation((0, 0, 1), C),
                   "linear_origin": translation((sp.Symbol("x", real=True), 0, 0)),
                   "linear_point": translation(o + sp.Matrix([SYM["x"], 0, 0]))}[kind]
        bad = _entries(printed, derived)
        what = {"rotary_point": "the nominal position of a point fixed on the C table: "
                                "Trans(o) Rz(C) r_CP, the point turning by +C about the axis "
                                "through o (the three-point model of volerr.identify, the "
                                "identification's own sense of C)",
                "linear_origin": "the origin moved by the displacement x along X",
                "linear_point": "the nominal position of a point fixed on the X carriage: "
                                "Trans(o + x e_x) r"}[kind]
        return [_v(item, "", "identical" if not bad else "printing_error", "; ".join(bad),
                   f"every entry equals {what}" + ("" if not bad else ": " + "; ".join(bad)),
                   str(item["rows"]), fmt(derived))]
    if kind == "linear_deviation":
        return _linear_deviation(item, o, r)
    if kind == "cl_data":
        return _cl_data(item, chain)
    if kind == "inverse_cl":
        return [_v(item, "", "undecidable", "product of a 4x2 by a 4x2 matrix",
                   "as printed, T_t^w [i x; j y; k z; 0 1] (4 x 2) is multiplied by the 4 x 2 "
                   "matrix [0 0; 0 0; 1 0; 0 1]: the product is undefined. With an '=' between "
                   "the last two matrices it is T_t^w [i x; j y; k z; 0 1] = [0 0; 0 0; 1 0; "
                   "0 1] -- the CL data mapped back into the tool frame give the tool axis e_z "
                   "and the tip at the origin -- which is exactly eq. (9) multiplied by T_t^w "
                   "(checked: (T_w^t)^-1 T_w^t = I), and the a_ij are the entries that must "
                   "match. Category undecidable: one lost glyph ('='), which the print and the "
                   "text extraction explain equally; what would decide: the page of the "
                   "original PDF", item["text"],
                   "[a_ij] = T_t^w [i x; j y; k z; 0 1] = [0 0; 0 0; 1 0; 0 1]",
                   ["the printed product: undefined (4x2 times 4x2)",
                    "an '=' lost between the last two matrices: eq. (9) inverted, exact"],
                   [f"glyph:project eq. {item['id']} lost '='"])]
    if kind == "ideal_linear":
        t0w0 = sp.eye(4)
        for n in ("T_0^1", "T_1^2", "T_2^3", "T_3^4", "T_4^5", "T_5^w"):
            t0w0 = t0w0 * f[n]
        same = sp.simplify(t0w0.subs({B: 0, C: 0}) - sp.eye(4)) == sp.zeros(4, 4)
        return [_v(item, "", "identical" if same else "printing_error", "differs",
                   "with only the linear axes moved (B = C = 0) the workpiece frame is the "
                   "machine frame (T_0^w = I, checked), so the chain T_w^t reduces to T_0^t: "
                   "the ideal tool position is T_0^t P", item["text"], "T_0^t P")]
    if kind == "actual_linear":
        return [_actual_linear(item, axes)]
    raise ValueError(f"printed_htm: unknown item kind {kind!r}")


def _actual_linear(item: dict, by_id: dict) -> Verdict:
    """eq. 1.19 / 3.40: the product of the printed axis HTMs with the angular errors dropped
    (the stated simplification) against the first-order product of the derived stages."""
    tp = sp.Matrix([*sp.symbols("xt yt zt", real=True), 1])
    ang = [SYM[n] for n in _NAMES if n[:2] in ("EA", "EB", "EC") and n[2] in "XYZ"
           and len(n) == 3]
    printed = sp.eye(4)
    for fid in item["factors"]:
        printed = printed * _mat(by_id[fid]["rows"])
    printed_pos = (printed * tp).subs({a: 0 for a in ang})
    derived = sp.eye(4)
    for a in "XYZ":
        derived = derived * _linear_stage(a)
    derived_pos = derived * tp
    errs = {s for s in derived_pos.free_symbols if s.name[0] == "E"}

    def first(v):
        """The terms of at most first order in the error symbols."""
        return sp.Add(*(t for t in sp.Add.make_args(sp.expand(v))
                        if sum(e for s_, e in t.as_powers_dict().items() if s_ in errs) <= 1))
    der = [first(derived_pos[i]) for i in range(3)]
    flipped = {SYM["EC0XY"]: -SYM["EC0XY"], SYM["EA0YZ"]: -SYM["EA0YZ"]}
    pr = [sp.expand(printed_pos[i].subs(flipped, simultaneous=True)) for i in range(3)]
    dropped = [sp.expand(a - b) for a, b in zip(der, pr)]
    only_angular = all(all(any(s in ang for s in t.free_symbols) for t in
                           sp.Add.make_args(d) if t != 0) for d in dropped)
    bounds = {"X": 500.0, "Y": 450.0, "Z": 400.0, "xt": 100.0, "yt": 100.0, "zt": 200.0}
    size = max(worst_case_um(d, bounds, unnamed=10e-6) for d in dropped)   # angles 10 urad
    used = ["stated:" + item["statement"], "flip:thesis E_C(0X)Y (slope convention, eq. "
            "3.11/3.13)", "flip:thesis E_A(0Y)Z (slope convention, eq. 3.11/3.13)"]
    return _v(item, "", category_of(used) if only_angular else "printing_error",
              "angular error terms neglected (stated)",
              f"the product of the printed HTMs ({', '.join(item['factors'])}) applied to the "
              f"tool point P = (xt, yt, zt) with the angular errors set to zero, against the "
              f"first-order product of the derived X, Y and Z stages (volerr's DMU50 chain, "
              f"X carries Y carries Z as printed): with the squareness symbols signed as the "
              f"thesis does (eq. 3.11/3.13, the convention of eq. 1.10-1.11 / 3.17-3.18) they "
              f"differ only by the Abbe terms of the angular errors: {fmt(dropped)}; up to "
              f"{size:.3g} um with every angular error at 10 urad, X 500, Y 450, Z 400 mm and a "
              f"tool point up to (100, 100, 200) mm (X 500 mm is printed, appendix C.1's "
              f"'linspace(0, 500, num = 11)' and appendix B; the Y and Z travels (the maker's "
              f"nominal values), the tool point and the error sizes are assumed, not printed; "
              f"the dropped terms scale in proportion to the angular errors and the lever "
              f"arms). The simplification is stated: {item['statement']} The thesis' Listing "
              f"3.4, the code that applies it (T_e, for eq. 3.40), confirms it in print: "
              f"T_e_X, T_e_Y, T_e_Z "
              f"have identity rotation blocks and carry only the translational errors and the "
              f"squareness terms (Y * S_YX, (-Z) * S_ZX, (-Z) * S_ZY).", item["text"], fmt(der),
              ["the product of the derived stages, first order: differs by the Abbe terms",
               "angular errors set to zero (stated) with the thesis' squareness signs: exact"],
              used, statement=item["statement"], alternative=fmt(pr), dropped=fmt(dropped),
              dropped_um=size)


# ------------------------------------------------------------------------------- entry
def audit(printed: dict, layouts=None) -> list[Verdict]:
    """Verdicts on the printed HTMs, axis models and chains (see the module docstring)."""
    if layouts is not None and "DMU50" not in layouts:
        return []
    axes = {a["id"]: a for a in printed.get("axis", [])}
    out: list[Verdict] = []
    for m in printed.get("matrix", []):
        out.extend(audit_matrix(m))
    for p in printed.get("product", []):
        out.append(audit_product(p))
    for a in printed.get("axis", []):
        if a["kind"] in ("linear", "deviation"):
            out.append(audit_linear(a))
        elif a["kind"] == "deviation_rows":
            out.append(audit_deviation_rows(a))
        else:
            out.append(audit_rotary(a))
    for it in printed.get("item", []):
        out.extend(audit_item(it, axes))
    return out
