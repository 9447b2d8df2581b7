"""Audit framework: the verdict of a printed equation against the derivation, and the rule
that gives it a category (the provider protocol: :mod:`volerr.derive.audit`).

The derivation from the physical layout is the authority.  Every printed equation (or each
component of it: ``dX``, ``RY2``, the rule of ``dx(X)`` ...) gets a :class:`Verdict`:
``identical`` when ``expand(derived - printed) == 0``, else ``differs`` with a named erratum
and the evidence (which terms differ, and which alternative reading reproduces the print).

Every verdict also carries a *category* (:data:`CATEGORIES`), what a reviewer needs to weigh it:

* ``identical``: the printed form is the derived one;
* ``printing_error``: a typo, wrong symbol, wrong sign or lost row that no consistent convention
  explains;
* ``extraction``: damage of the OCR / text extraction of the seed (garbled subscripts, lost
  brackets), where the evidence allows telling it from the print;
* ``convention``: reproduced exactly under a named alternative convention (``alternative``
  holds the derivation under it, ``evidence`` names it and shows ``expand(alt - printed) == 0``);
* ``simplification``: the author's stated approximation (``statement`` quotes it,
  ``alternative`` is the approximate derivation that reproduces the print, ``dropped`` the terms
  it drops and ``dropped_um`` their size on a typical machine, :data:`TYPICAL`);
* ``undecidable``: the evidence does not decide; ``evidence`` says what is missing.

How a category is chosen (:data:`PRIORITY_RULE`): every combination of the named *readings*
a provider knows is tried -- conventions and simplifications, each with its own evidence, and
every geometry the text allows -- and the verdict follows from the readings that reproduce the
print exactly, by the rule ``identical`` > ``convention`` / ``simplification`` (fewest
readings) > ``extraction`` > ``printing_error`` (no reading reproduces it and the text itself
decides that it is not extraction damage) > ``undecidable`` (otherwise: only an unstated
assumption reproduces it, or a glyph-level defect the print and the extraction explain
equally).  Every
verdict lists the readings tried (``readings_tried``) and the keys of the readings it rests on
(``readings_used``); a reading key has one kind (:data:`READING_KINDS`), hence one category,
on every layout and in every document (:func:`category_of`).

This module holds the shared pieces: :class:`Verdict`, the category rule and the
term-by-term comparison of two polynomials (:func:`term_diff`, :func:`describe_diff`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from functools import lru_cache

import sympy as sp

#: the assumption behind "a repetition or loss at the same place in two images does not
#: decide" (quoted by the rule and by the verdicts that apply it): the documents show neither
#: that a failure of the extraction recurs at the same place of another image nor that it
#: cannot
RECURRENCE_UNSHOWN = (
    "that a failure driven by the image recurs at the same place in another image of the "
    "same layout is an assumption the documents neither show nor exclude (the thesis renders "
    "the chain's factors twice, eq. 3.31-3.33 and the chain after eq. 3.37, and the "
    "extraction damages them differently there -- T_1^2 loses a row in eq. 3.31 only, T_2^3 "
    "in the chain only -- while T_3^4 has the same repeated row in both)")


#: the rule that picks a verdict's category from the readings tried (quoted by the HTML page
#: and docs/formats.md)
PRIORITY_RULE = (
    "Every combination of the named readings is tried (conventions and simplifications, each "
    "with its own evidence; every geometry the text allows; repairs of text-extraction "
    "damage; unstated assumptions) and the category follows, in this order of preference: "
    "(1) identical -- the derivation itself reproduces the print, no reading needed; "
    "(2) convention / simplification -- a combination of stated conventions and the author's "
    "stated approximations reproduces it exactly; the combination with the fewest readings "
    "is reported (simplification when it contains an approximation); "
    "(3) extraction -- only a repair of text-extraction damage reproduces it, and the "
    "evidence tells that damage from the print (a symbol no print carries, a line number "
    "without its line); "
    "(4) printing_error -- no reading reproduces it, and the text itself decides that it is "
    "not extraction damage (a well-formed wrong symbol, term or sign; the same substitution "
    "at the same place in a separately typeset copy, by the cross-copy rule below; a "
    "consequence printed elsewhere; a sign or axis stacking that "
    "contradicts the one the same document uses; a whole block of entries in another order, "
    "which the extraction is not seen to produce); an item with several defects is "
    "printing_error when one of them is decided so, and its evidence names the defects that "
    "stay undecided; "
    "(5) undecidable -- otherwise: only an unstated assumption reproduces it, or the defect "
    "is glyph-level (a lost letter, sign, row or column, a duplicated row, a confusable glyph "
    "such as mm for um) and the print and the extraction explain it equally; both "
    "explanations are named, and what would decide. "
    "Readings of the kinds inconsistent, copy and stacking do not explain a print, they name "
    "a printing error: a combination that contains one is taken only when no combination "
    "without one reproduces the print (an unstated assumption that reproduces it leaves the "
    "verdict undecidable); only minimal combinations are counted (one that adds a reading "
    "to an exact combination without changing the result is not). "
    "Cross-copy rule: the same defect at the same place in two separately typeset images -- "
    "the thesis, its appendix A (the conference paper) and its appendix B (the "
    "specialization project), or two equations of one document -- decides for the author's "
    "source (printing_error) when it is a substitution: another well-formed symbol, index, "
    "sign, number, label or component, which an extraction would have to invent identically "
    "in both images while it reads the same notation right elsewhere; a whole component or "
    "label of another equation is such a substitution (this extraction is not seen to carry "
    "text from one image into another). It does not decide a repetition within an image (a "
    "row, entry, token or matrix repeated, with what it displaces lost) nor a lost entry: "
    "this extraction demonstrably repeats within an image (the error matrix of T_0^{t,c} "
    "after thesis eq. 3.37 has five rows, three of them '-E_{DX} & ... & 1 & E_{ZX}' and two "
    "of these identical, with the letter D that names no axis), and " + RECURRENCE_UNSHOWN
    + "; so the same repetition or loss at the same place in two images weighs towards the "
    "author's source but does not decide: such defects are undecidable, and the evidence "
    "says which way the copies weigh. "
    "A candidate repetition: the wrong whole symbol or term stands elsewhere in the same "
    "printed equation, before or after it (an extraction reads the whole image; an author "
    "writes from the neighbouring line), or a wrong index repeats the index written next to "
    "it in the same symbol (T_2^2 for T_3^2); a bare sign or a 0/1 entry of a matrix is no "
    "candidate (they stand everywhere). A printed text that is cut off (a line ending early) "
    "is read with every restoration the text allows; when they lead to different categories "
    "the verdict is undecidable.")

#: kind of every reading key prefix -> the category it implies (see :func:`category_of`)
READING_KINDS = {
    "table_origin": "convention",      # Pahk's chain form: table rotations about its origin
    "geometry": "convention",          # an axis stacking the text allows
    "flip": "convention",              # a sign convention of a symbol (used consistently)
    "line": "convention",              # squareness as the slope of one line
    "notation": "convention",          # a notational convention (atan for atan2 ...)
    "rounding": "convention",          # a printed number from rounded printed intermediates
    "rule1": "simplification",         # Pahk's rule (1) of sec. 2.3
    "termwise": "simplification",      # Pahk's term-wise quadrature
    "stated": "simplification",        # another approximation the author states
    "ocr": "extraction",               # repair of extraction damage told from the print
    "zero": "assumption",              # an unstated zero offset
    "glyph": "assumption",             # glyph-level defect or a repetition within an image:
                                       # print or extraction
    "missing": "assumption",           # a value the text does not print
    "stacking": "other_machine",       # an axis stacking the text excludes
    "copy": "other_machine",           # a component copied from another equation
    "inconsistent": "other_machine",   # a sign the same document uses the other way
}

_KIND_ORDER = {"other_machine": "printing_error", "assumption": "undecidable",
               "simplification": "simplification", "convention": "convention",
               "extraction": "extraction"}

#: rank of a category among the combinations that reproduce the print (lower wins): an
#: unstated assumption still beats a reading that contradicts the document (which only
#: diagnoses the printing error)
RANK = {"identical": 0, "convention": 1, "simplification": 1, "extraction": 2,
        "undecidable": 3, "printing_error": 4}


def reading_kind(key: str) -> str:
    """Kind of a reading key (``"flip:alpha"`` -> ``"convention"``)."""
    return READING_KINDS[key.split(":", 1)[0]]


def category_of(keys) -> str:
    """The category a combination of reading keys implies, by :data:`PRIORITY_RULE`."""
    kinds = {reading_kind(k) for k in keys}
    for kind, cat in _KIND_ORDER.items():
        if kind in kinds:
            if kind == "extraction" and kinds - {"extraction"}:
                continue
            return cat
    return "identical"


def best_combination(hits):
    """Among ``hits`` = [(keys, payload)] of combinations that reproduce the print exactly,
    the one the rule prefers: lowest category rank, then fewest unstated assumptions, then
    fewest readings, then stable order.
    Returns ``(keys, payload)`` or None."""
    if not hits:
        return None
    return min(hits, key=lambda h: (RANK[category_of(h[0])],
                                    sum(reading_kind(k) == "assumption" for k in h[0]),
                                    len(h[0]), repr(h[0])))


def minimal_hits(hits):
    """The combinations of ``hits`` = [(keys, payload)] that no other hit's key set is a
    proper subset of: a reading added to an exact combination without changing the result is
    not counted (:data:`PRIORITY_RULE`)."""
    sets = [frozenset(k) for k, _ in hits]
    return [h for h, s in zip(hits, sets) if not any(o < s for o in sets)]


def _not_taken(keys, chosen, why=None) -> str:
    """Why the combination ``keys`` is not the one the rule takes (``chosen``), "" if it is;
    ``why(keys)``: a reason the caller knows first (or None)."""
    if chosen is None or tuple(keys) == tuple(chosen):
        return ""
    first = why(keys) if why is not None else None
    if first:
        return f" (not taken: {first})"
    cat, cc = category_of(keys), category_of(chosen)
    if RANK[cat] > RANK[cc]:
        if cat == "printing_error":
            return (" (not taken: it names a printing error -- a reading the document "
                    "contradicts -- and counts only when no combination without one "
                    "reproduces the print; one does)")
        if cat == "undecidable":
            return (" (not taken: it rests on an unstated assumption, and a combination of "
                    "stated readings reproduces the print)")
        return f" (not taken: {cat} comes after {cc} in the rule's order)"
    n_ass = sum(reading_kind(k) == "assumption" for k in keys)
    c_ass = sum(reading_kind(k) == "assumption" for k in chosen)
    if n_ass > c_ass:
        return " (not taken: more unstated assumptions)"
    if len(keys) > len(chosen):
        return " (not taken: more readings)"
    return " (as good by the rule; the one reported comes first in a fixed order)"


def hits_text(hits, chosen=None, limit: int = 4, why=None) -> str:
    """The minimal combinations of ``hits`` ([(keys, payload)]) for ``readings_tried``, in the
    rule's order, each with its category and, if it is not ``chosen``, why not."""
    mins = sorted((tuple(k) for k, _ in minimal_hits(hits)),
                  key=lambda k: (RANK[category_of(k)],
                                 sum(reading_kind(x) == "assumption" for x in k), len(k),
                                 repr(k)))
    shown = "; ".join(f"[{', '.join(k)}] -> {category_of(k)}{_not_taken(k, chosen, why)}"
                      for k in mins[:limit])
    more = " ..." if len(mins) > limit else ""
    return (f"{len(mins)} minimal combination(s) reproduce it exactly (a reading added to one "
            f"of them without changing the result is not counted)"
            + (f": {shown}{more}" if mins else ""))


#: verdict categories, in report order
CATEGORIES = ("identical", "printing_error", "extraction", "convention", "simplification",
              "undecidable")

#: a typical machine for the size of dropped terms: Pahk's CMM A (sec. 4: MB1, 900 x 575 x
#: 400 mm; X pitch band 11.18 urad, repeatabilities 10.75 um and 12.30 urad as 2 sigma), measuring
#: (Abbe) offsets and probe offsets as met in practice.  Units: mm and rad.
TYPICAL = {
    "travel_mm": {"X": 900.0, "Y": 575.0, "Z": 400.0},
    "measuring_offset_mm": 200.0,     # |Xo|, |Yo|, |Zo| of a laser set-up
    "probe_offset_mm": 100.0,         # |Xp|, |Yp|, |Zp| of a stylus
    "angular_rad": 10e-6,             # an angular error motion
    "translational_mm": 5e-3,         # a translational error motion
    "sigma_angular_rad": 6e-6,        # random (1 sigma) angular error
    "sigma_translational_mm": 5e-3,   # random (1 sigma) translational error
}


def typical_text(extra: str = "", layout: str | None = None, term=None) -> str:
    """The typical machine's assumptions (``extra``: more assumed values, appended).  With
    ``layout``, it names the machine whose travels scale the worst case against the layout's
    own machine in Pahk (its layout file's ``source``); with ``term`` (the dropped
    expression), whether the travels enter the size at all."""
    t = TYPICAL
    machine = "Pahk's CMM A (900 x 575 x 400 mm)"
    if layout is not None:
        import re

        from volerr.machine.layout import read_layout
        m = re.search(r"(CMM [A-Z]) of sec\. 4 \(([^)]*)\)", read_layout(layout).source or "")
        if m and m.group(1) == "CMM A":
            machine += f", this {layout} layout's own machine in Pahk's sec. 4"
        else:
            machine = (f"the travels of Pahk's CMM A (an MB1, 900 x 575 x 400 mm) taken for "
                       f"this {layout} layout -- "
                       + (f"Pahk's own {layout} machine is {m.group(1)} ({m.group(2)})" if m
                          else f"Pahk describes no {layout} machine"))
    if term is not None:
        axes = sorted({str(s_) for s_ in sp.sympify(term).free_symbols}
                      & {"X", "Y", "Z"})
        machine += ("; the term depends on the offsets only, so its size does not depend on "
                    "the machine's travels" if not axes else
                    f"; the travel{'s' if len(axes) > 1 else ''} of {', '.join(axes)} "
                    f"({', '.join('%g mm' % t['travel_mm'][a] for a in axes)}) "
                    f"enter{'' if len(axes) > 1 else 's'} the size")
    return (f"typical machine: {machine}, offsets up to "
            f"{t['measuring_offset_mm']:g} mm, probe offsets up to {t['probe_offset_mm']:g} mm, "
            f"angular errors {t['angular_rad'] * 1e6:g} urad{extra} -- assumed values, not "
            f"printed; the size scales in proportion to the lengths and angles assumed")


@dataclass
class Verdict:
    """The verdict on one printed equation (or one component of it).

    ``verdict`` is ``"identical"``, ``"differs"`` or ``"unchecked"`` (a printed number whose
    inputs the text does not print: nothing to compare, no discrepancy claimed); ``erratum``
    is "" when identical, else a
    short name of the printing error; ``evidence`` says which terms differ and which chain,
    sign convention or reading reproduces the printed form; ``printed`` and ``derived`` are the
    two expressions (strings, in the paper's symbols).  ``category`` is one of
    :data:`CATEGORIES` (``identical`` whenever ``verdict`` is); ``alternative``, ``statement``,
    ``dropped`` and ``dropped_um`` document a ``convention`` or ``simplification`` (see the
    module docstring); ``readings_tried`` lists the readings (and combinations) tried with
    their outcome, ``readings_used`` the keys of the readings the category rests on."""

    source: str
    equation: str
    layout: str
    verdict: str
    erratum: str
    evidence: str
    printed: str
    derived: str
    component: str = ""
    category: str = ""
    alternative: str = ""
    statement: str = ""
    dropped: str = ""
    dropped_um: float | None = None
    readings_tried: list = field(default_factory=list)
    readings_used: list = field(default_factory=list)

    def __post_init__(self):
        if self.verdict == "identical" and not self.category:
            self.category = "identical"
        if self.category and self.category not in CATEGORIES:
            raise ValueError(f"unknown verdict category {self.category!r}")

    def as_dict(self) -> dict:
        out = asdict(self)
        if not out["readings_tried"] and self.category == "identical":
            out["readings_tried"] = ["the derivation itself reproduces the print (no reading "
                                     "needed)"]
        return out


def classify(v: Verdict, category: str, **fields) -> Verdict:
    """Set the category (and the fields that document it) of a verdict; returns it."""
    if category not in CATEGORIES:
        raise ValueError(f"unknown verdict category {category!r}")
    v.category = category
    for k, val in fields.items():
        setattr(v, k, val)
    return v


def worst_case_um(expr, bounds: dict, unnamed: float = 1.0) -> float:
    """Worst-case |expr| in um for a polynomial whose every term is a product of bounded
    symbols: sum over terms of |coefficient| * product of the bounds (``bounds``: symbol name
    -> bound, mm or rad; symbols not named count ``unnamed``)."""
    total = 0.0
    for t in sp.Add.make_args(sp.expand(expr)):
        if t == 0:
            continue
        c, m = t.as_coeff_Mul()
        val = abs(float(c))
        for f, e in m.as_powers_dict().items():
            val *= float(bounds.get(str(f), unnamed)) ** int(e)
        total += val
    return total * 1e3


# ---------------------------------------------------------------- term-by-term comparison
def terms(expr) -> dict:
    """Polynomial ``expr`` -> {monomial (coefficient 1): numeric coefficient}."""
    out: dict = {}
    for t in sp.Add.make_args(sp.expand(expr)):
        if t == 0:
            continue
        c, m = t.as_coeff_Mul()
        out[m] = out.get(m, 0) + c
    return {m: c for m, c in out.items() if c != 0}


def is_identical(derived, printed) -> bool:
    """Structural identity: ``expand(derived - printed) == 0``."""
    return sp.expand(derived - printed) == 0


def n_diff(derived, printed) -> int:
    """Number of monomials in which the two polynomials differ."""
    return len(terms(derived - printed))


def n_issues(expected, printed) -> int:
    """Number of distinct defects (an exchanged symbol counts once, not as two terms)."""
    return sum(len(v) for v in term_diff(expected, printed).values())


@lru_cache(maxsize=None)
def simplified(expr):
    """``sp.simplify(expr)``, once per expression and process (the matrices of the audits
    compare the same entries again and again; simplify is a pure function of the
    expression, which is immutable)."""
    return sp.simplify(expr)


def is_zero(expr) -> bool:
    """``sp.simplify(expr) == 0``: an expression built as 0 needs no simplification (the usual
    case: two equal entries), anything else is :func:`simplified`."""
    return expr == 0 or simplified(expr) == 0


def fmt(expr) -> str:
    """A compact string of an expression (symbols print as the paper writes them); an
    expression is printed once per process (the evidence quotes the same ones again)."""
    if isinstance(expr, sp.Basic):
        return _fmt_basic(expr)
    return sp.sstr(expr, order="lex")


@lru_cache(maxsize=None)
def _fmt_basic(expr) -> str:
    # only sympy objects: equal ones (structurally) print alike, unlike 1 and 1.0
    return sp.sstr(expr, order="lex")


def _monomial(m) -> str:
    """A monomial with positions and offsets first (``Yo*Ez(X)``, as the paper writes it)."""
    factors = sorted(sp.Mul.make_args(m), key=lambda f: ("(" in str(f), str(f)))
    return "*".join(fmt(f) for f in factors)


def _signed(c, m) -> str:
    if c == 1:
        return "+" + _monomial(m)
    if c == -1:
        return "-" + _monomial(m)
    s = fmt(c)
    return (s if s.startswith("-") else "+" + s) + "*" + _monomial(m)


def _swap(m_expected, m_printed):
    """(printed symbol, expected symbol) if the monomials differ by one symbol exchanged."""
    a, b = m_expected.as_powers_dict(), m_printed.as_powers_dict()
    only_a = {k: v for k, v in a.items() if b.get(k) != v}
    only_b = {k: v for k, v in b.items() if a.get(k) != v}
    if len(only_a) == 1 and len(only_b) == 1:
        (ka, va), = only_a.items()
        (kb, vb), = only_b.items()
        if va == vb:
            return kb, ka
    return None


def term_diff(expected, printed) -> dict:
    """Classify the difference of two polynomials term by term.

    Returns ``{"omitted": [...], "extra": [...], "sign": [...], "coefficient": [...],
    "swapped": [...]}``: terms of ``expected`` missing from ``printed``, terms of ``printed``
    that ``expected`` lacks, terms printed with the opposite sign or another coefficient, and
    pairs (printed term, expected term) that differ by one symbol (a garbled or mislabelled
    symbol)."""
    te, tp = terms(expected), terms(printed)
    out = {"omitted": [], "extra": [], "sign": [], "coefficient": [], "swapped": []}
    missing = {m: c for m, c in te.items() if m not in tp}
    extra = {m: c for m, c in tp.items() if m not in te}
    for m in te:
        if m in tp and te[m] != tp[m]:
            key = "sign" if te[m] == -tp[m] else "coefficient"
            out[key].append((tp[m] * m, te[m] * m))
    for mp, cp in list(extra.items()):
        for me, ce in list(missing.items()):
            if ce == cp and _swap(me, mp) is not None:
                out["swapped"].append((cp * mp, ce * me))
                del missing[me], extra[mp]
                break
    out["omitted"] = [c * m for m, c in missing.items()]
    out["extra"] = [c * m for m, c in extra.items()]
    return out


def describe_diff(expected, printed, limit: int = 4) -> str:
    """A short phrase naming the differences of ``printed`` from ``expected`` ("" if none)."""
    d = term_diff(expected, printed)
    parts = []

    def listing(items):
        items = sorted(items, key=fmt)
        shown = ", ".join(_signed(*t.as_coeff_Mul()) for t in items[:limit])
        return shown + (f" (+{len(items) - limit} more)" if len(items) > limit else "")

    for p, e in d["swapped"]:
        sym = _swap(e.as_coeff_Mul()[1], p.as_coeff_Mul()[1])
        parts.append(f"{fmt(sym[0])} for {fmt(sym[1])} in {_signed(*e.as_coeff_Mul())}")
    if d["omitted"]:
        parts.append(f"omitted {listing(d['omitted'])}")
    if d["extra"]:
        parts.append(f"extra {listing(d['extra'])}")
    for p, e in d["sign"]:
        parts.append(f"sign of {_signed(*e.as_coeff_Mul())} flipped")
    for p, e in d["coefficient"]:
        parts.append(f"{_signed(*p.as_coeff_Mul())} printed for {_signed(*e.as_coeff_Mul())}")
    return "; ".join(parts)


def wrong_printed_terms(expected, printed) -> list:
    """The printed terms (coefficient * monomial) that ``expected`` does not have: extra terms
    and the printed side of exchanged symbols or signs."""
    d = term_diff(expected, printed)
    return d["extra"] + [p for p, _ in d["swapped"]] + [p for p, _ in d["sign"]] + \
        [p for p, _ in d["coefficient"]]


def _occurrences(sym, image: dict, own: str, skip) -> list[str]:
    """Where symbol ``sym`` stands in ``image`` ({component: printed expression}) outside the
    term ``skip`` of component ``own``: ["+X*Ey(X) of this component", "dX", ...]."""
    out = []
    for name, expr in sorted(image.items(), key=lambda kv: kv[0] != own):
        for t in sp.Add.make_args(sp.expand(expr)):
            if t == 0 or (name == own and skip is not None and sp.expand(t - skip) == 0):
                continue
            if sym in t.free_symbols:
                c, m = t.as_coeff_Mul()
                out.append(f"{_signed(c, m)} of this component" if name == own else
                           f"{_signed(c, m)} of {name}")
    return out


def repetition_check(expected, printed, image: dict, own: str) -> tuple[str, bool]:
    """Whether the defect of ``printed`` against ``expected`` (the closest reading) is a
    candidate repetition within one printed image: every wrong element -- the symbol printed
    in place of another, or an extra term -- stands elsewhere in the same image (``image``:
    {component name: printed expression}, ``own`` this component's name), before or after it
    (an extraction reads the whole image; an author writes from the neighbouring line).
    Returns (evidence sentence, repeated).  A sign or coefficient defect is no repetition.
    When no wrong element stands elsewhere the sentence says so (for a printing error)."""
    d = term_diff(expected, printed)
    if d["sign"] or d["coefficient"] or not (d["swapped"] or d["extra"]):
        return "", False
    found, missing = [], []
    for p, e in d["swapped"]:
        sym = _swap(e.as_coeff_Mul()[1], p.as_coeff_Mul()[1])[0]
        where = _occurrences(sym, image, own, p)
        (found if where else missing).append((f"symbol {fmt(sym)}", where))
    for t in d["extra"]:
        c, m = t.as_coeff_Mul()
        where = [f"{_signed(*u.as_coeff_Mul())} of {name}" for name, expr in image.items()
                 if name != own for u in sp.Add.make_args(sp.expand(expr))
                 if u != 0 and u.as_coeff_Mul()[1] == m]
        (found if where else missing).append((f"term {fmt(t)}", where))
    if found and not missing:
        parts = "; ".join(f"the wrong {what} also stands in {', '.join(where[:3])}"
                          for what, where in found)
        return (f" Candidate repetition within one image: {parts} (the same printed "
                f"equation). The print (the author writing it from the neighbouring term or "
                f"line) and the extraction (a token of the neighbouring text emitted again in "
                f"place of the right one -- in either reading order, since an extraction reads "
                f"the whole image) explain it equally; by the cross-copy rule a repetition within "
                f"an image is not decided. What would decide: the page of the original PDF.",
                True)
    if missing and not found:
        return (" The wrong " + "; the wrong ".join(what for what, _ in missing)
                + " stand" + ("s" if len(missing) == 1 else "")
                + " nowhere else in this printed equation: no repetition of a neighbouring "
                  "token.", False)
    head = "; ".join(f"the wrong {what} also stands in {', '.join(where[:3])}"
                     for what, where in found)
    return (" " + head[0].upper() + head[1:] + "; " + "; ".join(f"the wrong {what} stands nowhere else" for what, _ in missing)
            + " in this printed equation: not every wrong element can be a repetition.",
            False)


def lost_glyphs(expected, printed) -> list[str]:
    """If ``printed`` differs from ``expected`` only by symbols printed with one character
    lost (``beta1`` for ``Rbeta1``), the list of those defects; else [] (a glyph-level defect
    that the print and a text extraction explain equally)."""
    d = term_diff(expected, printed)
    if d["omitted"] or d["extra"] or d["sign"] or d["coefficient"] or not d["swapped"]:
        return []
    out = []
    for p, e in d["swapped"]:
        ps, es = _swap(e.as_coeff_Mul()[1], p.as_coeff_Mul()[1])
        a, b = str(ps), str(es)
        if len(b) != len(a) + 1 or not any(b[:i] + b[i + 1:] == a for i in range(len(b))):
            return []
        lost = next(b[i] for i in range(len(b)) if b[:i] + b[i + 1:] == a)
        out.append(f"{a} for {b} (the letter {lost} lost)")
    return out
