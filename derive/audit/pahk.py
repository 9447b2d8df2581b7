"""Audit of Pahk (1995), sec. 2 and appendix, against the derivation (sympy, no file I/O).

The printed equations come as the parsed ``data/printed_pahk.toml`` (its header states
the symbol mapping and the geometries the text allows).  The authority is the derivation from
the physical layout (``volerr/layouts/<name>.toml``: :func:`volerr.derive.volumetric.
volumetric_error` of ``Chain.from_layout(layout)``), written in the paper's symbols through the
layout's ``[paper_symbols]`` (ISO name -> paper symbol with sign).

Every combination of the named readings is tried and the category follows the rule of
:data:`volerr.derive.audit.framework.PRIORITY_RULE`; each verdict lists the readings tried
(``readings_tried``) and the keys it rests on (``readings_used``):

* volumetric equations (4, 7, A2, A5, A8): table pivot x axis stacking (the geometries the
  text allows; any other order of the axes is another machine) x signs of squareness symbols
  and of table axes (:mod:`volerr.derive.audit.pahk_model`).  One reading holds for the whole
  equation (one machine); each component reports the fewest of its readings it needs;
* random error (5, 8): exact first-order propagation (the authority), Pahk's term-wise
  quadrature (stated), the other printed layout's equation (a copy: printing error);
* transfer rules (9, 10, A3, A6, A9): :mod:`volerr.derive.audit.pahk_rules`;
* chains (1, 6, A1, A4, A7) and their vectors: :mod:`volerr.derive.audit.pahk_chain`.
"""

from __future__ import annotations

import sympy as sp

from .framework import (RANK, TYPICAL, Verdict, best_combination, category_of, classify,
                    describe_diff, fmt, hits_text, is_identical, lost_glyphs, n_diff,
                    n_issues, repetition_check, terms, typical_text, worst_case_um)
from .pahk_chain import audit_chain, audit_vectors, chain_error  # noqa: F401
from .pahk_model import (COMPONENTS, P, Reading, derived_error, geometries,  # noqa: F401
                               geometry_text, iso_error, layout, paper_map, paper_name, parse,
                               printed_component, readings, stacking_text)
from .pahk_rules import (CONVENTION_TABLE, RULE1, _bounds, audit_transfer,
                                fill_verdict_refs)

SOURCE = "Pahk 1995"
DATA_FILE = "printed_pahk.toml"
LAYOUTS = ("MB1", "MH2", "FB1", "FH1", "CY")
RANDOM_COMPONENTS = ("RX2", "RY2", "RZ2")

#: the statements of Pahk (1995) that the categories quote (verbatim from the seed, translated)
STATEMENTS = {
    "quadrature": "Sec. 2.2: \"입체오차의 랜덤성분은 오차전파이론에 의한 구적공식(quadrature "
                  "formula)을 이용하여 계산할 수 있다\" (the random component of the volumetric "
                  "error can be computed with the quadrature formula of error propagation)",
    "rule1": RULE1,
}


def _verdict(eq, comp, verdict, erratum, evidence, printed, derived) -> Verdict:
    text = eq.get("expr", {}).get(comp, "") if comp else ""
    p = text if isinstance(text, str) and text else fmt(printed) if printed is not None else ""
    return Verdict(SOURCE, eq["id"], eq["layout"], verdict, erratum, evidence, p,
                   fmt(derived) if derived is not None else "", comp)


def _ocr_category(v: Verdict, eq: dict, note: str) -> Verdict:
    """A verdict identical only after reading damaged text: extraction when the data file says
    the text shows extraction damage, undecidable for a glyph-level defect."""
    if not note or v.verdict != "identical":
        return v
    if eq.get("ocr", {}).get("kind", "extraction") == "glyph":
        v.readings_used = [f"glyph:{eq['id']} {v.component}"]
        return classify(v, "undecidable", evidence=v.evidence + (
            " Category undecidable: the print equals the derivation once a lost glyph is "
            "restored, and a lost glyph is explained equally by the print and by the text "
            "extraction; what would decide: the page of the original PDF."))
    v.readings_used = [f"ocr:{eq['id']} {v.component}"]
    return classify(v, "extraction")


def _stacking(lay) -> str:
    return stacking_text(lay.tool_chain, lay.workpiece_chain)


# ------------------------------------------------------------------------- volumetric
def _rows(name: str, geoms: tuple, printed: list) -> list:
    """[(reading, derived, exact per component, monomials off)] for every reading."""
    out = []
    pts = [terms(p) for p in printed]
    for r in readings(name, geoms):
        d = derived_error(name, r)
        off = []
        for a, pt in zip(d, pts):
            ta = terms(a)
            off.append(sum(1 for m in set(ta) | set(pt) if ta.get(m, 0) != pt.get(m, 0)))
        out.append((r, d, [k == 0 for k in off], off))
    return out


def equation_reading(name: str, geoms: tuple, printed: list, rows=None):
    """The reading of a whole volumetric equation (one machine): among the readings that
    reproduce every component, the one the rule prefers; else the closest (fewest differing
    terms), ties by the rule.  Returns (reading, derived components, rows)."""
    lay = layout(name)
    rows = rows if rows is not None else _rows(name, geoms, printed)
    hits = [(r.keys(lay), (r, d)) for r, d, ex, _ in rows if all(ex)]
    best = best_combination(hits)
    if best is not None:
        return best[1][0], best[1][1], rows
    near = sorted(rows, key=lambda row: sum(row[3]))[:12]
    r, d, _, _ = min(near, key=lambda row: (sum(n_issues(a, b) for a, b in zip(row[1], printed)),
                                            RANK[category_of(row[0].keys(lay))],
                                            len(row[0].keys(lay)), repr(row[0])))
    return r, d, rows


def audit_volumetric(eq: dict, geoms: tuple) -> tuple[list[Verdict], Reading]:
    """Verdicts on the components of a volumetric equation, and the equation's reading."""
    name = eq["layout"]
    lay = layout(name)
    printed, notes = [], []
    for c in COMPONENTS:
        e, note = printed_component(eq, c)
        printed.append(e)
        notes.append(note)
    physical = derived_error(name)
    best, best_d, rows = equation_reading(name, geoms, printed)
    best_keys = set(best.keys(lay))
    left = {c: n_issues(a, b) for c, a, b in zip(COMPONENTS, best_d, printed)}
    whole = (f"whole equation (one machine) read as: {best.describe(lay)} "
             f"[{', '.join(sorted(best_keys)) or 'no reading'}]; "
             f"{sum(left.values())} differing term(s) left"
             + (" (" + ", ".join(f"{n} in {c}" for c, n in left.items() if n) + ")"
                if sum(left.values()) else ""))
    out = []
    for i, c in enumerate(COMPONENTS):
        ocr = f" {notes[i]}." if notes[i] else ""
        tried = _tried(rows, i, printed[i], lay) + [whole]
        if is_identical(physical[i], printed[i]):
            tried = _tried(rows, i, printed[i], lay, ()) + [whole]
            v = _verdict(eq, c, "identical", "",
                         f"expand(derived - printed) == 0 for the physical layout "
                         f"{name} ({_stacking(lay)})." + ocr, printed[i], physical[i])
            v.readings_tried = tried
            out.append(_ocr_category(v, eq, notes[i]))
            continue
        diff0 = describe_diff(physical[i], printed[i])
        if is_identical(best_d[i], printed[i]):
            # the fewest of the equation's readings that reproduce this component
            sub = [(r.keys(lay), (r, d)) for r, d, ex, _ in rows
                   if ex[i] and set(r.keys(lay)) <= best_keys and (r.tool, r.work) ==
                   (best.tool, best.work)]
            keys, (r, d) = best_combination(sub)
            tried = _tried(rows, i, printed[i], lay, keys, best_keys) + [whole]
            erratum = f"{r.short(lay)} reading"
            evidence = (f"differs from the physical layout: {diff0}. Reproduced exactly by the "
                        f"reading: {r.describe(lay)} (expand(alternative - printed) == 0).")
            v = _verdict(eq, c, "differs", erratum, evidence + ocr, printed[i], physical[i])
            v.readings_tried, v.readings_used = tried, list(keys)
            out.append(_reading_category(v, r, keys, lay, d[i], physical[i], geoms))
            continue
        resid = describe_diff(best_d[i], printed[i])
        erratum = resid if best.cost() == 0 else f"{resid} [under {best.short(lay)}]"
        glyphs = lost_glyphs(best_d[i], printed[i])
        evidence = (f"differs from the physical layout: {diff0}. No reading reproduces it "
                    f"(the whole equation is read as one machine); closest: "
                    f"{best.describe(lay)}, which leaves: {resid}")
        v = _verdict(eq, c, "differs", erratum, evidence + "." + ocr, printed[i], physical[i])
        v.readings_tried = tried
        if glyphs:
            v.readings_used = [f"glyph:{eq['id']} {c}"]
            out.append(classify(v, "undecidable", evidence=v.evidence + (
                f" The residual is a lost glyph ({'; '.join(glyphs)}), which the print and the "
                f"text extraction explain equally; what would decide: the page of the "
                f"original PDF.")))
            continue
        rep, repeated = repetition_check(best_d[i], printed[i],
                                         dict(zip(COMPONENTS, printed)), c)
        if repeated:
            v.readings_used = [f"glyph:{eq['id']} {c} repeats a token of the same image"]
            out.append(classify(v, "undecidable", evidence=v.evidence + rep + (
                " Category undecidable."), alternative=fmt(best_d[i]) if best.cost() else ""))
            continue
        out.append(classify(v, "printing_error", evidence=v.evidence + rep + (
            " The residual is no lost or confusable glyph but a well-formed term, symbol or "
            "sign of the paper's notation (the axis letters X, Y, Z do not resemble one "
            "another), which an extraction would have to invent; no convention or geometry "
            "explains it: a printing error."),
            alternative=fmt(best_d[i]) if best.cost() else ""))
    return out, best


def _tried(rows, i, printed, lay, chosen=None, whole_keys=None) -> list[str]:
    """Readings tried for component ``i``: the physical layout, every single reading, and the
    minimal combinations that reproduce it (``chosen``: the keys the verdict rests on)."""
    out = []
    for r, d, ex, off in rows:
        if r.cost() > 1:
            continue
        what = r.describe(lay) if r.cost() else f"the physical layout ({_stacking(lay)})"
        out.append(f"{what}: " + ("exact" if ex[i] else f"{off[i]} term(s) differ"))
    hits = [(r.keys(lay), None) for r, d, ex, _ in rows if ex[i]]
    why = None
    if whole_keys is not None:
        def why(keys):
            if set(keys) <= set(whole_keys):
                return None
            return ("the whole equation is read as one machine, and this combination is not "
                    "part of the reading that reproduces the equation")
    out.append(f"all {len(rows)} combinations of pivot x stacking x signs tried for this "
               f"component; " + hits_text(hits, chosen, why=why))
    return out


def _reading_category(v: Verdict, r: Reading, keys, lay, alt, physical, geoms=()) -> Verdict:
    """Category of a volumetric verdict reproduced exactly by reading ``r`` (keys ``keys``)."""
    cat = category_of(keys)
    if cat == "printing_error":
        return classify(v, "printing_error", alternative=fmt(alt), evidence=v.evidence + (
            " That stacking of the axes is another machine: the text fixes this layout's "
            "geometry, so the printed equation stacks the axes wrongly."))
    names = []
    if r.pivot == "table_origin":
        names.append(CONVENTION_TABLE)
    if r.tool is not None or r.work is not None:
        passage = geometry_text(geoms, r.stacking(lay))
        names.append(f"axes stacked {stacking_text(*r.stacking(lay))}: a geometry the text "
                     f"allows (the layout file has {_stacking(lay)}; the text: {passage}); the "
                     f"verdict rests on it")
    for f in r.flips:
        names.append(f"the errors of table {f} signed as the table's own motion"
                     if f in lay.axes else
                     f"{paper_name(lay, f)} signed the other way (its sign convention)")
    diff = sp.expand(physical - alt)
    size = worst_case_um(diff, _bounds(diff))
    return classify(v, "convention", alternative=fmt(alt), statement="; ".join(names),
                    dropped=fmt(diff), dropped_um=size,
                    evidence=v.evidence + f" Convention: {'; '.join(names)}. The two readings "
                    f"differ by {fmt(diff)} (up to {size:.2g} um on the "
                    f"{typical_text(layout=lay.name, term=diff)}).")


# ----------------------------------------------------------------------------- random
def _sensitivity(name: str):
    chain, err = iso_error(name, "tool_point", None, None)
    lay = layout(name)
    m = paper_map(lay)
    sens = {}
    for p in chain.parameters:
        sigma = P("R" + paper_name(lay, p.name))
        sens[sigma] = [sp.expand(sp.diff(e, p).xreplace(m)) for e in err]
    return sens


def random_squared(name: str, method: str) -> list:
    """(RX^2, RY^2, RZ^2) in paper symbols: ``exact`` = sum((dD/dp)^2 sigma^2), ``termwise`` =
    Pahk's quadrature (every monomial of dD/dp squared alone)."""
    out = []
    sens = _sensitivity(name)
    for i in range(3):
        acc = 0
        for sigma, s in sens.items():
            if method == "exact":
                acc += s[i] ** 2 * sigma ** 2
            else:
                acc += sum(t ** 2 for t in sp.Add.make_args(s[i]) if t != 0) * sigma ** 2
        out.append(sp.expand(acc))
    return out


def _random_size_um(name: str, i: int) -> float:
    """Largest sqrt(exact) - sqrt(term-wise) of component ``i`` (um) over the corners of the
    typical working volume and probe offsets of +-TYPICAL, every sigma at its typical value."""
    import numpy as np

    t = TYPICAL
    ex, tw = random_squared(name, "exact")[i], random_squared(name, "termwise")[i]
    syms = sorted(ex.free_symbols | tw.free_symbols, key=str)
    vals = []
    for s_ in syms:
        n = s_.name
        if n in ("X", "Y", "Z"):
            vals.append(np.array([0.0, t["travel_mm"][n]]))
        elif n in ("Xp", "Yp", "Zp"):
            vals.append(np.array([-1.0, 1.0]) * t["probe_offset_mm"])
        elif n.startswith("Rd"):
            vals.append(np.array([t["sigma_translational_mm"]]))
        else:
            vals.append(np.array([t["sigma_angular_rad"]]))
    grids = np.meshgrid(*vals, indexing="ij")
    f_ex = sp.lambdify(syms, ex, "numpy")
    f_tw = sp.lambdify(syms, tw, "numpy")
    a = np.sqrt(np.maximum(np.broadcast_to(f_ex(*grids), grids[0].shape), 0))
    b = np.sqrt(np.maximum(np.broadcast_to(f_tw(*grids), grids[0].shape), 0))
    return float(np.max(np.abs(a - b))) * 1e3


def _termwise_verdict(eq: dict, c: str, i: int, hit, tried: list, diff0: str, ocr: str, pr,
                      exact, tw) -> Verdict:
    """A random component reproduced by Pahk's term-wise quadrature: a simplification, with
    the size of the dropped cross terms on the typical machine."""
    m, n, d = hit[1]
    size = _random_size_um(eq["layout"], i)
    evidence = (f"differs from exact propagation: {diff0}. Reproduced exactly by {d} "
                f"(expand(term-wise - printed) == 0); the two agree when the probe offset "
                f"is zero. Size of the dropped cross terms: sqrt(exact) - sqrt(printed) "
                f"up to {size:.2g} um ("
                + typical_text(f", random angular errors "
                               f"{TYPICAL['sigma_angular_rad'] * 1e6:g} urad, "
                               f"translational "
                               f"{TYPICAL['sigma_translational_mm'] * 1e3:g} um, "
                               f"1 sigma") + "). "
                f"Category simplification: Pahk states the quadrature formula (quoted "
                f"in 'statement'), not that it is applied term by term; the term-wise "
                f"form is how he applies it -- every printed random component of both "
                f"layouts that is not a copy (eq. 5 RX^2, RY^2, RZ^2 and eq. 8 RX^2, the "
                f"latter up to a lost glyph) is built so -- and it drops the correlation "
                f"of one parameter's two lever arms (Z and Zp above): an approximation "
                f"of the stated method, small at the typical machine.")
    v = classify(_verdict(eq, c, "differs", "term-wise quadrature drops cross terms",
                          evidence + ocr, pr, exact),
                 "simplification", alternative=fmt(tw),
                 statement=STATEMENTS["quadrature"] + "; applied term by term",
                 dropped=fmt(sp.expand(exact - tw)), dropped_um=size)
    v.readings_tried, v.readings_used = tried, list(hit[0])
    return v


def audit_random(eq: dict, random_eqs: dict) -> list[Verdict]:
    name = eq["layout"]
    cands = [("exact", name, "exact first-order propagation (the authority)", ()),
             ("termwise", name, "Pahk's term-wise quadrature: every monomial of a sensitivity "
                                "squared alone, so cross terms such as 2*Z*Zp of (Z + Zp)^2 drop",
              ("termwise",))]
    for other, oid in sorted(random_eqs.items()):
        if other != name:
            cands.append(("termwise", other, f"the term-wise quadrature of {other} (eq. {oid}) "
                                             f"reprinted", (f"copy:{other} eq. {oid}",)))
            cands.append(("exact", other, f"the exact propagation of {other} reprinted",
                          (f"copy:{other} eq. {oid}",)))
    derived = {(m, n): random_squared(n, m) for m, n, _, _ in cands}
    out = []
    for i, c in enumerate(RANDOM_COMPONENTS):
        pr, note = printed_component(eq, c)
        ocr = f" {note}." if note else ""
        exact, tw = derived[("exact", name)][i], derived[("termwise", name)][i]
        tried = [f"{d}: " + ("exact" if is_identical(derived[(m, n)][i], pr) else
                             f"{n_diff(derived[(m, n)][i], pr)} term(s) differ")
                 for m, n, d, _ in cands]
        if is_identical(exact, pr):
            v = _verdict(eq, c, "identical", "", "expand(derived - printed) == 0 for exact "
                         "propagation." + ocr, pr, exact)
            v.readings_tried = tried
            out.append(_ocr_category(v, eq, note))
            continue
        diff0 = describe_diff(exact, pr)
        hits = [(keys, (m, n, d)) for m, n, d, keys in cands
                if keys and is_identical(derived[(m, n)][i], pr)]
        hit = best_combination(hits)
        if hit and category_of(hit[0]) == "simplification":
            v = _termwise_verdict(eq, c, i, hit, tried, diff0, ocr, pr, exact, tw)
            out.append(v)
            continue
        if hit:
            m, n, d = hit[1]
            erratum = f"{c[:2]}^2 of {n} (eq. {random_eqs[n]}) reprinted"
            evidence = (f"differs from exact propagation: {diff0}; from the term-wise quadrature "
                        f"of {name}: {describe_diff(tw, pr)}. Reproduced exactly by {d}: a "
                        f"whole component of another equation in place of this one's -- by "
                        f"the cross-copy rule a substitution, which an extraction would have to "
                        f"carry from one image into another"
                        + (f" ({eq['quote'][c]})" if c in eq.get("quote", {}) else "")
                        + f"; no convention of {name}: a printing error.")
            v = classify(_verdict(eq, c, "differs", erratum, evidence + ocr, pr, exact),
                         "printing_error")
            v.readings_tried, v.readings_used = tried, list(hit[0])
            out.append(v)
            continue
        resid = describe_diff(tw, pr)
        glyphs = lost_glyphs(tw, pr)
        evidence = (f"differs from exact propagation: {diff0}. No reading reproduces it; "
                    f"closest: the term-wise quadrature of {name}, which leaves: {resid}.")
        v = _verdict(eq, c, "differs", f"{resid} [term-wise]", evidence + ocr, pr, exact)
        v.readings_tried = tried
        if glyphs:
            v.readings_used = ["termwise", f"glyph:{eq['id']} {c}"]
            out.append(classify(v, "undecidable", evidence=v.evidence + (
                f" Under the term-wise quadrature the only difference is a lost glyph "
                f"({'; '.join(glyphs)}"
                + (f"; raw '{eq['quote'][c]}'" if c in eq.get("quote", {}) else "")
                + f"); a lost letter is explained equally by the print and "
                f"by the text extraction (the same extraction reads R before beta_2 in RY^2 of "
                f"this equation, which shows it can read the glyph, not that it did here); "
                f"what would decide: the page of the original PDF.")))
            continue
        out.append(classify(v, "printing_error"))
    return out


# ------------------------------------------------------------------------------ entry
def _chain_is_the_print(chain_eq: dict, by_id: dict, result_eq: dict, verdicts) -> None:
    """A convention verdict on a component of a result equation whose print is exactly what the
    layout's printed chain gives to first order says so: the convention is then Pahk's own
    chain, not only a reading that reproduces the print."""
    from .pahk_chain import chain_vectors
    L, note, _ = chain_vectors(chain_eq, by_id)
    try:
        literal = chain_error(chain_eq["lhs"], chain_eq["rhs"], L)
    except (ValueError, TypeError, sp.SympifyError):
        return
    for i, c in enumerate(COMPONENTS):
        v = next((x for x in verdicts if x.component == c), None)
        if v is None or v.category != "convention":
            continue
        if is_identical(literal[i], printed_component(result_eq, c)[0]):
            v.evidence += (f" The printed chain eq. {chain_eq['id']} ('{chain_eq['lhs']} = "
                           f"{chain_eq['rhs']}', with "
                           + (f"its vectors as read: {note}" if note else "its printed vectors")
                           + f"), expanded to first "
                           f"order, gives exactly this {c}: the convention is Pahk's own "
                           f"equation, not only a reading that reproduces the print.")


def audit(printed: dict, layouts: list[str] | None = None) -> list[Verdict]:
    """Verdicts on every printed equation of the data file (restricted to ``layouts``)."""
    eqs = printed.get("equation", [])
    by_id = {e["id"]: e for e in eqs}
    random_eqs = {e["layout"]: e["id"] for e in eqs if e["kind"] == "random"}
    result_of = {e["layout"]: e for e in eqs if e["kind"] == "volumetric"}
    wanted = None if layouts is None else set(layouts)
    geoms = {n: tuple(geometries(printed, n)) for n in {e["layout"] for e in eqs}}
    vol_verdicts, vol_reading = {}, {}
    for e in eqs:
        if e["kind"] == "volumetric" and (wanted is None or e["layout"] in wanted):
            vol_verdicts[e["id"]], vol_reading[e["layout"]] = \
                audit_volumetric(e, geoms[e["layout"]])
    for e in eqs:
        if e["kind"] == "chain" and e["layout"] in vol_reading \
                and result_of.get(e["layout"]) is not None:
            _chain_is_the_print(e, by_id, result_of[e["layout"]],
                                vol_verdicts[result_of[e["layout"]]["id"]])
    stackings = {n: r.stacking(layout(n)) for n, r in vol_reading.items()
                 if r is not None and (r.tool is not None or r.work is not None)}
    out: list[Verdict] = []
    for e in eqs:
        name = e["layout"]
        if wanted is not None and name not in wanted:
            continue
        kind = e["kind"]
        if kind == "volumetric":
            out.extend(vol_verdicts[e["id"]])
        elif kind == "random":
            out.extend(audit_random(e, random_eqs))
        elif kind == "transfer":
            out.extend(audit_transfer(e, vol_reading.get(name), _verdict, geoms[name], eqs,
                                      stackings))
        elif kind == "chain":
            out.extend(audit_vectors(e, _verdict))
            out.extend(audit_chain(e, by_id, result_of.get(name), geoms[name],
                                   vol_reading.get(name)))
        else:
            raise ValueError(f"equation {e['id']}: unknown kind {kind!r}")

    def category_of_rule(name, eq_id, key):
        """The category of a rule of a layout not audited in this run (restricted layouts)."""
        reading = vol_reading.get(name)
        if reading is None and name in result_of:
            reading = audit_volumetric(result_of[name], geoms[name])[1]
        st = dict(stackings)
        if reading is not None and (reading.tool is not None or reading.work is not None):
            st[name] = reading.stacking(layout(name))
        vs = audit_transfer(by_id[eq_id], reading, _verdict, geoms[name], eqs, st)
        return next(v.category for v in vs if v.component == key)

    fill_verdict_refs(out, category_of_rule)
    return out
