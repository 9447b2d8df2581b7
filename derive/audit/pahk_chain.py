"""Pahk (1995) audit: the printed kinematic chains (eq. 1, 6, A1, A4, A7) and their
translation vectors (eq. 3 and the appendix; sympy, no file I/O).

A printed chain ``lhs = rhs`` (Tx Ty Tz the small-angle rotations of eq. 2, Lx Ly Lz the
vectors, P the probe offset, A the actual point) is evaluated literally to first order
(:func:`chain_error`) and compared with the layout's derived model under every reading of
:mod:`volerr.derive.audit.pahk_model`.  Its category follows the readings that reproduce it:
the literal chain is the layout under a combination of conventions (convention), under the
stacking the layout's result equation needs (or else the chain contradicts it: printing
error), or under no reading (printing error; the relabelled chain that would give the model is
named).  A damaged vector (a lost factor, a duplicated entry) gets its own verdict: the data
file says whether the defect is glyph-level (print or extraction: undecidable) or decided.
"""

from __future__ import annotations

import ast
import itertools
from functools import lru_cache

import sympy as sp

from .framework import (TYPICAL, Verdict, best_combination, category_of, classify,
                    describe_diff, fmt, is_identical, n_diff, typical_text, worst_case_um)
from .pahk_model import (COMPONENTS, POS, derived_error, error_symbols, is_paper, layout,
                               parse, printed_component, readings)
from .pahk_rules import CONVENTION_TABLE, _bounds
from ..kinematics import PROBE

SOURCE = "Pahk 1995"


#: the error symbols of the small-angle rotations Tx, Ty, Tz (:func:`_T`)
_T_SYMS = {k: tuple(sp.Symbol(f"E{c}({k.upper()})", real=True) for c in "xyz") for k in "xyz"}


def _T(axis: str) -> sp.Matrix:
    ex, ey, ez = _T_SYMS[axis.lower()]
    return sp.Matrix([[1, -ez, ey], [ez, 1, -ex], [-ey, ex, 1]])


A_SYMS = sp.symbols("Xa Ya Za", real=True)


def _vectors(L: dict) -> dict:
    out = {}
    for k in "xyz":
        v = L[k]
        if len(v) != 3:
            raise ValueError(f"L{k} has {len(v)} entries")
        out["L" + k] = sp.Matrix([parse(c) for c in v])
    return out


class _Dual:
    """A matrix with a nominal part and a part linear in the error symbols (first order)."""

    def __init__(self, nom: sp.Matrix, eps: sp.Matrix):
        self.nom, self.eps = nom, eps

    def __add__(self, o):
        return _Dual(self.nom + o.nom, self.eps + o.eps)

    def __sub__(self, o):
        return _Dual(self.nom - o.nom, self.eps - o.eps)

    def __neg__(self):
        return _Dual(-self.nom, -self.eps)

    def __mul__(self, o):
        return _Dual(self.nom * o.nom, self.nom * o.eps + self.eps * o.nom)


def _evaluate(text: str, names: dict) -> _Dual:
    """Evaluate a chain expression (names, +, -, * and parentheses only)."""

    def ev(node):
        if isinstance(node, ast.Expression):
            return ev(node.body)
        if isinstance(node, ast.Name) and node.id in names:
            return names[node.id]
        if isinstance(node, ast.BinOp) and type(node.op) in (ast.Add, ast.Sub, ast.Mult):
            a, b = ev(node.left), ev(node.right)
            return {ast.Add: a.__add__, ast.Sub: a.__sub__, ast.Mult: a.__mul__}[
                type(node.op)](b)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            return -ev(node.operand)
        raise ValueError(f"chain {text!r}: unsupported {ast.dump(node)[:40]}")

    return ev(ast.parse(text, mode="eval"))


def _split(v: sp.Matrix) -> _Dual:
    errs = set().union(*(error_symbols(e) for e in v))
    nom = v.subs({e: 0 for e in errs})
    return _Dual(nom, (v - nom).applyfunc(sp.expand))


def _split_vectors(L: dict) -> dict:
    """``{"Lx": _split(...), ...}`` of the L vectors, each split once per process (the readings
    of a chain exchange the same few vectors); the values are never changed in place."""
    try:
        key = tuple(tuple(L[k]) for k in "xyz")
        hash(key)
    except TypeError:             # entries that cannot be a key: split them as they are
        return {k: _split(v) for k, v in _vectors(L).items()}
    return _split_key(key)


@lru_cache(maxsize=None)
def _split_key(key: tuple) -> dict:
    return {k: _split(v) for k, v in _vectors(dict(zip("xyz", key))).items()}


def chain_error(lhs: str, rhs: str, L: dict) -> list:
    """First-order (dX, dY, dZ) implied by a printed chain ``lhs = rhs``: with f = lhs - rhs
    affine in A, nominal A0 solves f0(A0) = 0 and A1 = -J0^-1 f1(A0).  Each chain is
    evaluated once per process (the readings of the layouts repeat chains: 115 calls, 61
    chains); a chain that cannot be evaluated raises each time."""
    try:
        key = (lhs, rhs, tuple(tuple(L[k]) for k in "xyz"))
        hash(key)
    except TypeError:             # entries that cannot be a key: evaluated as they are
        return _chain_error(lhs, rhs, L)
    return list(_chain_error_key(key))


@lru_cache(maxsize=None)
def _chain_error_key(key: tuple) -> tuple:
    lhs, rhs, vectors = key
    return tuple(_chain_error(lhs, rhs, dict(zip("xyz", vectors))))


def _chain_error(lhs: str, rhs: str, L: dict) -> list:
    """:func:`chain_error` computed in a polynomial ring (:func:`_chain_error_ring`), else
    (or to raise its error) with sympy matrices of expressions."""
    fast = _chain_error_ring(lhs, rhs, L)
    return fast if fast is not None else _chain_error_sympy(lhs, rhs, L)


def _chain_error_sympy(lhs: str, rhs: str, L: dict) -> list:
    names = {"T" + k: _Dual(sp.eye(3), _T(k.upper()) - sp.eye(3)) for k in "xyz"}
    names.update(_split_vectors(L))
    names["P"] = _Dual(sp.Matrix(PROBE), sp.zeros(3, 1))
    names["A"] = _Dual(sp.Matrix(A_SYMS), sp.zeros(3, 1))
    f = _evaluate(lhs, names) - _evaluate(rhs, names)
    J0 = f.nom.jacobian(sp.Matrix(A_SYMS))
    c0 = f.nom.subs({a: 0 for a in A_SYMS})
    J0i = J0.inv()
    a0 = -(J0i * c0)
    a1 = -(J0i * f.eps.subs(dict(zip(A_SYMS, a0))))
    nominal = [POS[k] + PROBE[i] for i, k in enumerate("XYZ")]
    if any(sp.expand(a0[i] - nominal[i]) != 0 for i in range(3)):
        raise ValueError(f"chain {lhs} = {rhs}: nominal point is not (X + Xp, Y + Yp, Z + Zp)")
    return [sp.expand(a1[i]) for i in range(3)]


class _RDual(_Dual):
    """:class:`_Dual` of 3 x 3 or 3 x 1 matrices (lists of rows) of polynomial-ring elements;
    a shape mismatch raises :class:`_NotRing` (sympy then raises its own error)."""

    def __add__(self, o):
        return _RDual(_madd(self.nom, o.nom, 1), _madd(self.eps, o.eps, 1))

    def __sub__(self, o):
        return _RDual(_madd(self.nom, o.nom, -1), _madd(self.eps, o.eps, -1))

    def __neg__(self):
        return _RDual([[-x for x in r] for r in self.nom], [[-x for x in r] for r in self.eps])

    def __mul__(self, o):
        return _RDual(_mmul(self.nom, o.nom),
                      _madd(_mmul(self.nom, o.eps), _mmul(self.eps, o.nom), 1))


class _NotRing(Exception):
    pass


def _madd(a, b, sign):
    if len(a) != len(b) or len(a[0]) != len(b[0]):
        raise _NotRing
    return [[x + y if sign > 0 else x - y for x, y in zip(r, s)] for r, s in zip(a, b)]


def _mmul(a, b):
    if len(a[0]) != len(b):
        raise _NotRing
    return [[sum((a[i][k] * b[k][j] for k in range(len(b))), a[0][0].ring.zero)
             for j in range(len(b[0]))] for i in range(len(a))]


def _chain_error_ring(lhs: str, rhs: str, L: dict) -> list | None:
    """The first-order error of :func:`chain_error` with every matrix entry an element of
    one polynomial ring over QQ (sympy's sparse polynomials: the same exact arithmetic as
    expanded expressions, without rebuilding expressions at each product); the expanded
    result is the same expression.  None where that does not apply (a vector that is no
    polynomial, a nominal Jacobian that is not constant, any error: sympy decides)."""
    try:
        vecs = _vectors(L)
        gens = set(A_SYMS) | set(PROBE) | set(POS.values()) | set().union(*_T_SYMS.values())
        for m in vecs.values():
            gens |= m.free_symbols
        R, g = _ring(tuple(sorted(gens, key=str)))
        one, zero = R.one, R.zero
        eye = [[one if i == j else zero for j in range(3)] for i in range(3)]
        names = {}
        for k in "xyz":
            ex, ey, ez = (g[s] for s in _T_SYMS[k])
            names["T" + k] = _RDual(eye, [[zero, -ez, ey], [ez, zero, -ex], [-ey, ex, zero]])
        for k, v in vecs.items():
            names[k] = _ring_split(R, tuple(v))
        col = lambda v: [[g[s]] for s in v]               # noqa: E731
        names["P"] = _RDual(col(PROBE), [[zero]] * 3)
        names["A"] = _RDual(col(A_SYMS), [[zero]] * 3)
        f = _evaluate(lhs, names) - _evaluate(rhs, names)
        J0 = [f.nom[i][0].diff(g[a]) for i in range(3) for a in A_SYMS]
        if not all(x.is_ground for x in J0):
            return None
        J0i = sp.Matrix(3, 3, [R.domain.to_sympy(x.LC) for x in J0]).inv()
        J0i = [[R.ground_new(R.domain.from_sympy(J0i[i, k])) for k in range(3)]
               for i in range(3)]
        c0 = [f.nom[i][0].compose([(g[a], zero) for a in A_SYMS]) for i in range(3)]
        a0 = [-sum((J0i[i][k] * c0[k] for k in range(3)), zero) for i in range(3)]
        nominal = [g[POS[k]] + g[PROBE[i]] for i, k in enumerate("XYZ")]
        off = any(a0[i] != nominal[i] for i in range(3))
        if not off:
            e1 = [f.eps[i][0].compose([(g[a], x) for a, x in zip(A_SYMS, a0)])
                  for i in range(3)]
            a1 = [-sum((J0i[i][k] * e1[k] for k in range(3)), zero) for i in range(3)]
            return [sp.expand(x.as_expr()) for x in a1]
    except Exception:  # noqa: BLE001 - sympy's path raises the error the caller expects
        return None
    # the same exact a0 as sympy's: its check fails the same way, with the same message
    raise ValueError(f"chain {lhs} = {rhs}: nominal point is not (X + Xp, Y + Yp, Z + Zp)")


@lru_cache(maxsize=None)
def _ring(gens: tuple):
    """(ring over QQ, {symbol: generator}) of a chain's symbols."""
    R, *g = sp.ring(gens, sp.QQ)
    return R, dict(zip(gens, g))


@lru_cache(maxsize=None)
def _ring_split(R, vector: tuple) -> _RDual:
    """A vector as :func:`_split` splits it, in the ring ``R`` (nominal part: the terms free
    of error symbols); never changed in place."""
    errs = [i for i, s in enumerate(R.symbols) if is_paper(s)]
    full = [[R(e)] for e in vector]
    nom = [[R({m: c for m, c in x.terms() if not any(m[i] for i in errs)})] for (x,) in full]
    return _RDual(nom, _madd(full, nom, -1))


def _relabel(text: str, tmap: dict, lmap: dict) -> str:
    out = []
    i = 0
    while i < len(text):
        two = text[i:i + 2]
        if two[:1] == "T" and two in tmap:
            out.append(tmap[two])
            i += 2
        elif two[:1] == "L" and two in lmap:
            out.append(lmap[two])
            i += 2
        else:
            out.append(text[i])
            i += 1
    return "".join(out)


def chain_readings(eq: dict, L: dict) -> list:
    """[(name, lhs, rhs, L, cost)]: the printed chain, the data file's readings, every exchange
    of T labels and of L labels."""
    out = [("the printed chain", eq["lhs"], eq["rhs"], L, 0)]
    for r in eq.get("reading", []):
        out.append((f"{r['short']}: {r['lhs']} = {r['rhs']}" if "short" in r else r["name"],
                    r["lhs"], r["rhs"], r["L"], 1))
    names = ["Tx", "Ty", "Tz"]
    lnames = ["Lx", "Ly", "Lz"]
    for tp in itertools.permutations(names):
        for lp in itertools.permutations(lnames):
            if tp == tuple(names) and lp == tuple(lnames):
                continue
            tmap, lmap = dict(zip(names, tp)), dict(zip(lnames, lp))
            lhs, rhs = _relabel(eq["lhs"], tmap, lmap), _relabel(eq["rhs"], tmap, lmap)
            cost = 2 + (tp != tuple(names)) + (lp != tuple(lnames))
            out.append((f"{lhs} = {rhs} (labels exchanged; vectors as printed)", lhs, rhs, L,
                        cost))
    return sorted(out, key=lambda r: r[4])


def chain_vectors(eq: dict, by_id: dict) -> tuple[dict, str, dict]:
    """(vectors read, note, the equation that prints them) of a chain: a vector whose text is
    damaged is taken as the data file reads it (``[equation.ocr]``), and the note says so."""
    src = by_id[eq["L_from"]] if "L_from" in eq else eq
    ocr = src.get("ocr", {})
    L = dict(src["L"])
    notes = []
    for k in "xyz":
        if f"L.{k}" in ocr:
            notes.append(f"L{k} printed {src['L'][k]} read as {ocr[f'L.{k}']}")
            L[k] = ocr[f"L.{k}"]
    if notes and ocr.get("note"):
        notes.append(f"({ocr['note']}; see the verdict on eq. {vector_label(src)} L{k})")
    where = f" (vectors of eq. {eq['L_from']})" if "L_from" in eq else ""
    return L, "; ".join(notes) + where, src


def vector_label(src: dict) -> str:
    return src.get("ocr", {}).get("vectors_of", src["id"])


def audit_vectors(eq: dict, verdict) -> list[Verdict]:
    """One verdict per damaged translation vector of a chain equation (``[equation.ocr]``
    ``L.x``/``L.y``/``L.z`` with ``kind`` glyph or extraction and ``why``)."""
    ocr = eq.get("ocr", {})
    out = []
    for k in "xyz":
        if f"L.{k}" not in ocr:
            continue
        printed, read = eq["L"][k], ocr[f"L.{k}"]
        kind = ocr.get("kind", "glyph")
        cat = "undecidable" if kind == "glyph" else "extraction"
        ev = (f"L{k} printed [{', '.join(printed)}], read as [{', '.join(read)}]: "
              f"{ocr.get('note', '')}. {ocr.get('why', '')}")
        v = verdict(eq, f"L{k}", "differs", ocr.get("erratum", "vector entry damaged"), ev,
                    None, None)
        v.printed = "[" + ", ".join(printed) + "]"
        v.derived = "[" + ", ".join(read) + "]"
        v.equation = vector_label(eq)
        v.readings_tried = [f"the vector as printed: {ocr.get('literal', 'not a valid vector')}",
                            f"the entry repaired ({ocr.get('note', '')}): gives the vector "
                            f"the chain needs"]
        v.readings_used = [f"glyph:{vector_label(eq)} L{k}" if kind == "glyph"
                           else f"ocr:{vector_label(eq)} L{k}"]
        out.append(classify(v, cat))
    return out


def _vec(exprs) -> str:
    return "[" + ", ".join(f"{c} = {fmt(e)}" for c, e in zip(COMPONENTS, exprs)) + "]"


def _key(exprs) -> tuple:
    return tuple(sp.expand(e) for e in exprs)


@lru_cache(maxsize=None)
def _reading_index(name: str, geoms: tuple) -> dict:
    """Derived (dX, dY, dZ) -> every reading of the layout that gives it."""
    out: dict = {}
    for r in readings(name, geoms):
        out.setdefault(_key(derived_error(name, r)), []).append(r)
    return out


def _chain_erratum(found: list, best, best_lit, name: str, lay, geoms: tuple, literal,
                   ev: list) -> str:
    """The erratum of a chain that differs: the chain reading that repairs it, else the reading
    of the layout it is, else the closest reading (the evidence is appended to ``ev``)."""
    if best is not None and best[0][0] != found[0][0]:
        fix = best[0][0].split(" (labels exchanged")[0]
        how = "" if best[1].cost() == 0 else f" read as: {best[1].describe(lay)}"
        ev.append(f"The chain {best[0][0]} gives the layout's model{how}.")
        kind = "labels misplaced" if "labels exchanged" in best[0][0] else "misprinted"
        fix = fix.split(":")[0] if kind == "misprinted" else fix
        erratum = f"chain {kind}: {fix}" + ("" if best[1].cost() == 0
                                            else f" ({best[1].short(lay)} reading)")
    elif best_lit is not None:
        erratum = f"{best_lit[1].short(lay)} reading"
    else:
        closest = min(readings(name, geoms), key=lambda r: (sum(
            n_diff(a, b) for a, b in zip(derived_error(name, r), literal)), r.cost()))
        dd = derived_error(name, closest)
        k = sum(n_diff(a, b) for a, b in zip(dd, literal))
        erratum = f"chain matches no reading ({k} terms off {closest.short(lay)})"
        ev.append(f"No chain reading gives the layout's model under any reading; the printed "
                  f"chain is closest to the layout read as: {closest.describe(lay)} (" +
                  " | ".join(describe_diff(a, b) for a, b in zip(dd, literal) if n_diff(a, b))
                  + ").")
    return erratum


def _chain_category(v: Verdict, best, best_lit, vol_reading, result_eq: dict | None, name: str,
                    lay, literal, physical, geoms: tuple) -> list[Verdict]:
    """The category of a chain that differs: by the reading of the layout it is (a stacking
    the result equation contradicts is a printing error), else a printing error."""
    want = vol_reading.stacking(lay) if vol_reading is not None else \
        (tuple(lay.tool_chain), tuple(lay.workpiece_chain))
    if best_lit is not None:
        keys, r = best_lit
        cat = category_of(keys)
        if r.stacking(lay) != want and cat != "printing_error":
            from .pahk_model import stacking_text
            v.evidence += (f" The chain stacks the axes {stacking_text(*r.stacking(lay))}, a "
                           f"geometry the text allows, but the same layout's result equation "
                           f"{result_eq['id'] if result_eq else ''} needs "
                           f"{stacking_text(*want)}: the document contradicts itself, a "
                           f"printing error of the chain. The other way round (the chain "
                           f"right, eq. {result_eq['id'] if result_eq else ''} misprinted) "
                           f"would need every component of the result equation misprinted in "
                           f"the same way, while the layout's own stacking reproduces it "
                           f"(see its verdicts); an extraction would have to exchange the "
                           f"well-formed axis labels of the chain consistently, which no "
                           f"glyph resemblance explains.")
            v.readings_used = list(keys) + [f"inconsistent:{name} stacking of the chain"]
            return [classify(v, "printing_error", alternative=_vec(best[0][2])
                             if best is not None else "")]
        v.readings_used = list(keys)
        if cat in ("convention", "simplification"):
            return [_convention(v, r, lay, literal, physical, keys, geoms)]
        if cat == "printing_error":
            v.evidence += (" The printed chain is the layout only with an axis stacking the "
                           "text excludes (another machine): a printing error.")
        return [classify(v, cat, alternative=_vec(best[0][2]) if best is not None else "")]
    v.evidence += (" The printed chain is not the layout under any reading (conventions, "
                   "geometries the text allows, or other stackings): a printing error.")
    if best is not None and "labels exchanged" in best[0][0]:
        v.evidence += (" The printed labels are a permutation of the right ones (each stands "
                       "once, none is lost or repeated): no repetition within the image; an "
                       "extraction would have to exchange well-formed labels consistently, "
                       "which no glyph resemblance explains (x, y, z).")
    v.readings_used = []
    return [classify(v, "printing_error",
                     alternative=_vec(best[0][2]) if best is not None else "")]


def audit_chain(eq: dict, by_id: dict, result_eq: dict | None, geoms: tuple,
                vol_reading) -> list[Verdict]:
    """One verdict on a printed chain: its first-order error against the derived model.
    ``vol_reading``: the reading of the layout's result equation (its stacking is the one the
    chain must agree with)."""
    name = eq["layout"]
    lay = layout(name)
    L, note, _ = chain_vectors(eq, by_id)
    physical = derived_error(name)
    index = _reading_index(name, geoms)
    text = f"{eq['lhs']} = {eq['rhs']}"
    printed_result = None
    if result_eq is not None:
        printed_result = _key(printed_component(result_eq, c)[0] for c in COMPONENTS)
    found = []
    for rname, lhs, rhs, LL, cost in chain_readings(eq, L):
        try:
            res = _key(chain_error(lhs, rhs, LL))
        except (ValueError, TypeError, sp.SympifyError):
            continue
        found.append((rname, cost, res, index.get(res, [])))
    ev = [note + "."] if note else []
    tried = []
    if not found or found[0][1] != 0:
        try:
            chain_error(eq["lhs"], eq["rhs"], L)
            why = "no result"
        except (ValueError, TypeError, sp.SympifyError) as exc:
            why = str(exc)
        v = Verdict(SOURCE, eq["id"], name, "differs", "printed chain cannot be evaluated",
                    f"{why}. " + " ".join(ev), text, _vec(physical), category="undecidable")
        v.readings_tried = [f"the printed chain: {why}"]
        return [v]
    literal = found[0][2]
    if printed_result is not None:
        k = sum(n_diff(a, b) for a, b in zip(literal, printed_result))
        ev.append(f"The printed chain {'reproduces' if k == 0 else 'does not reproduce'} the "
                  f"printed eq. {result_eq['id']}" + ("" if k == 0 else f" ({k} terms differ)")
                  + ".")
        hit = next((f for f in found[1:] if f[2] == printed_result), None)
        if k and hit:
            ev.append(f"Eq. {result_eq['id']} is reproduced by the chain: {hit[0]}.")
    n_all = len(readings(name, geoms))
    lit_hits = [(r.keys(lay), r) for r in found[0][3]]
    tried.append(f"the printed chain against the {n_all} readings of layout {name} (pivot x "
                 f"stacking x signs): " + (", ".join(
                     f"[{', '.join(k) or 'physical layout'}]" for k, _ in lit_hits[:4])
                     if lit_hits else "none gives it"))
    if all(is_identical(a, b) for a, b in zip(physical, literal)):
        if note:
            ev.append("The chain's own text is the derived model; the vector it uses is read "
                      "as stated (see that vector's verdict).")
        v = Verdict(SOURCE, eq["id"], name, "identical", "", "The printed chain's "
                    "first-order error equals the derived model of the physical layout. "
                    + " ".join(ev), text, _vec(physical))
        v.readings_tried = tried
        return [v]
    diffs = [f"{c}: {describe_diff(physical[i], literal[i])}" for i, c in enumerate(COMPONENTS)
             if not is_identical(physical[i], literal[i])]
    ev.insert(0, "The printed chain's first-order error differs from the physical layout's "
                 "model: " + " | ".join(diffs) + ".")
    best_lit = best_combination(lit_hits)
    if best_lit is not None:
        ev.append(f"The printed chain is exactly the layout read as: "
                  f"{best_lit[1].describe(lay)}.")
    matches = [(f, min(f[3], key=lambda r: (r.cost(), repr(r)))) for f in found if f[3]]
    best = min(matches, key=lambda m: (m[0][1] + m[1].cost(), m[0][1])) if matches else None
    for f in found[1:]:
        if f[3]:
            r = min(f[3], key=lambda r: (r.cost(), repr(r)))
            other = category_of(r.keys(lay)) == "printing_error"
            tried.append(f"the chain {f[0]}: gives the layout read as {r.short(lay)}"
                         + (" -- an axis stacking the text excludes for this layout (another "
                            "machine), so it repairs nothing" if other else ""))
    erratum = _chain_erratum(found, best, best_lit, name, lay, geoms, literal, ev)
    v = Verdict(SOURCE, eq["id"], name, "differs", erratum, " ".join(ev),
                f"{text}  =>  {_vec(literal)}", _vec(physical))
    v.readings_tried = tried
    return _chain_category(v, best, best_lit, vol_reading, result_eq, name, lay, literal,
                           physical, geoms)


def _convention(v: Verdict, r, lay, literal, physical, keys, geoms=()) -> Verdict:
    names = []
    if r.pivot == "table_origin":
        names.append(CONVENTION_TABLE)
    if r.tool is not None or r.work is not None:
        from .pahk_model import geometry_text, stacking_text
        names.append(f"axes stacked {stacking_text(*r.stacking(lay))} (a geometry the text "
                     f"allows; the text: {geometry_text(geoms, r.stacking(lay))})")
    for f in r.flips:
        names.append(f"the errors of table {f} signed as the table's own motion"
                     if f in lay.axes else f"{f} signed the other way")
    diffs = [sp.expand(a - b) for a, b in zip(physical, literal)]
    size = max(worst_case_um(d, _bounds(d)) for d in diffs)
    return classify(v, "convention", alternative=_vec(literal), statement="; ".join(names),
                    dropped=_vec(diffs), dropped_um=size,
                    evidence=v.evidence + f" Convention: {'; '.join(names)}. The two readings "
                    f"differ by {_vec(diffs)} (up to {size:.2g} um on the "
                    f"{typical_text(layout=lay.name, term=sum(diffs))}).")


__all__ = ["audit_chain", "audit_vectors", "chain_error", "chain_readings", "chain_vectors",
           "TYPICAL"]
