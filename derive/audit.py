"""Audit framework: printed equations of a source document against the derivation.

A *provider* module audits one source document.  It has

* ``DATA_FILE``: the name of its data file in ``volerr/data/`` (the printed equations, kept
  exactly as printed), or ``None``;
* ``audit(printed: dict, layouts: list[str] | None) -> list[Verdict]``: ``printed`` is the
  parsed data file (the command reads it; providers do no file I/O), ``layouts`` restricts the
  audit to those layouts (``None``: all);
* optionally ``LAYOUTS``: the layout names it covers (for validating command-line names).

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

This module holds the shared pieces: :class:`Verdict`, the provider registry and the
term-by-term comparison of two polynomials (:func:`term_diff`, :func:`describe_diff`).
"""

from __future__ import annotations

import importlib
from dataclasses import asdict, dataclass

import sympy as sp

#: provider modules, imported when present
PROVIDERS = ("volerr.derive.audit_pahk", "volerr.derive.audit_tracker",
             "volerr.derive.audit_dmu50", "volerr.derive.audit_rotary",
             "volerr.derive.audit_listings", "volerr.derive.audit_probe",
             "volerr.derive.audit_numbers")


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


def typical_text() -> str:
    t = TYPICAL
    return (f"typical machine: Pahk's CMM A (900 x 575 x 400 mm), offsets up to "
            f"{t['measuring_offset_mm']:g} mm, probe offsets up to {t['probe_offset_mm']:g} mm, "
            f"angular errors {t['angular_rad'] * 1e6:g} urad")


@dataclass
class Verdict:
    """The verdict on one printed equation (or one component of it).

    ``verdict`` is ``"identical"`` or ``"differs"``; ``erratum`` is "" when identical, else a
    short name of the printing error; ``evidence`` says which terms differ and which chain,
    sign convention or reading reproduces the printed form; ``printed`` and ``derived`` are the
    two expressions (strings, in the paper's symbols).  ``category`` is one of
    :data:`CATEGORIES` (``identical`` whenever ``verdict`` is); ``alternative``, ``statement``,
    ``dropped`` and ``dropped_um`` document a ``convention`` or ``simplification`` (see the
    module docstring)."""

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

    def __post_init__(self):
        if self.verdict == "identical" and not self.category:
            self.category = "identical"
        if self.category and self.category not in CATEGORIES:
            raise ValueError(f"unknown verdict category {self.category!r}")

    def as_dict(self) -> dict:
        return asdict(self)


def classify(v: Verdict, category: str, **fields) -> Verdict:
    """Set the category (and the fields that document it) of a verdict; returns it."""
    if category not in CATEGORIES:
        raise ValueError(f"unknown verdict category {category!r}")
    v.category = category
    for k, val in fields.items():
        setattr(v, k, val)
    return v


def worst_case_um(expr, bounds: dict) -> float:
    """Worst-case |expr| in um for a polynomial whose every term is a product of bounded
    symbols: sum over terms of |coefficient| * product of the bounds (``bounds``: symbol name
    -> bound, mm or rad; symbols not named count 1)."""
    total = 0.0
    for t in sp.Add.make_args(sp.expand(expr)):
        if t == 0:
            continue
        c, m = t.as_coeff_Mul()
        val = abs(float(c))
        for f, e in m.as_powers_dict().items():
            val *= float(bounds.get(str(f), 1.0)) ** int(e)
        total += val
    return total * 1e3


def providers() -> list:
    """The provider modules that exist in this build, in :data:`PROVIDERS` order."""
    out = []
    for name in PROVIDERS:
        try:
            out.append(importlib.import_module(name))
        except ModuleNotFoundError as exc:
            if exc.name != name:
                raise
    return out


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


def fmt(expr) -> str:
    """A compact string of an expression (symbols print as the paper writes them)."""
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
