"""Audit of Pahk (1995), sec. 2 and appendix, against the derivation (sympy, no file I/O).

The printed equations come as the parsed ``volerr/data/printed_pahk.toml`` (its header states
the symbol mapping).  The authority is the derivation from the physical layout
(``volerr/layouts/<name>.toml``: :func:`volerr.derive.volumetric.volumetric_error` of
``Chain.from_layout(layout)``), written in the paper's symbols through the layout's
``[paper_symbols]`` (ISO name -> paper symbol with sign).

For every difference a small, fixed set of alternative *readings* is tried, cheapest first, and
the first that reproduces the print exactly is reported (else the closest one):

* volumetric equations (4, 7, A2, A5, A8): the table pivot (``table_origin``: a table rotates
  about its moving origin, Pahk's chain form), another stacking order of the axes (e.g. Z riding
  on Y), and the opposite sign of a squareness symbol or of all six errors of a table axis;
* random error (5, 8): exact first-order propagation (the authority), Pahk's term-wise quadrature
  (each monomial of a sensitivity squared alone), and the other printed layout's equation;
* transfer rules (9, 10, A3, A6, A9): the full rigid-body Abbe shift (authority); Pahk's
  rule (1) of sec. 2.3 (positional errors transferred by pitch and yaw only, straightness by roll
  only); squareness from the slope of one straightness line alone instead of the angle between
  the two lines; the table pivot and the sign reading of the volumetric equation;
* chains (1, 6, A1, A4, A7): the printed chain evaluated literally (first order), the readings
  listed with it in the data, and every exchange of the T and L labels; each is compared with the
  derived model (and its readings) and with the printed result equation.

Sign convention of the rules: the underlined (transferred) value is the reference value,
``reference = measured - shift`` with the derived ``shift`` of
:func:`volerr.derive.volumetric.transfer_rules`.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace
from functools import lru_cache

import sympy as sp

from volerr.machine.layout import SQUARENESS, read_layout

from . import volumetric as vol
from .audit import (TYPICAL, Verdict, classify, describe_diff, fmt, is_identical, n_diff,
                    n_issues, typical_text, worst_case_um)
from .kinematics import PROBE, Chain, parameter_symbol, position_symbol

SOURCE = "Pahk 1995"
DATA_FILE = "printed_pahk.toml"
LAYOUTS = ("MB1", "MH2", "FB1", "FH1", "CY")

FUNCS = ("dx", "dy", "dz", "Ex", "Ey", "Ez")
SCALARS = {"alpha": "alpha", "a": "alpha", "beta1": "beta1", "beta2": "beta2"}
POS = {t: position_symbol(t) for t in "XYZ"}
OFFSETS = vol.OFFSETS
COMPONENTS = ("dX", "dY", "dZ")
RANDOM_COMPONENTS = ("RX2", "RY2", "RZ2")


def P(name: str) -> sp.Symbol:
    """A paper symbol: ``dx(X)``, ``Ey(Y)``, ``alpha``, ``Rdx(X)``, ``Rbeta1`` ..."""
    return sp.Symbol(name, real=True)


# ------------------------------------------------------------------------------- parsing
def _function(prefix: str):
    def f(arg):
        name = getattr(arg, "name", None)
        if name not in ("X", "Y", "Z", "Xo", "Yo", "Zo"):
            raise ValueError(f"{prefix}() of {arg!r}")
        return P(f"{prefix}({name[0]})")
    return f


@lru_cache(maxsize=None)
def _locals_cached() -> tuple:
    return tuple(_make_locals().items())


def _locals() -> dict:
    return dict(_locals_cached())


def _make_locals() -> dict:
    loc = {}
    for f in FUNCS:
        loc[f] = _function(f)
        loc["R" + f] = _function("R" + f)
    for k, v in SCALARS.items():
        loc[k] = P(v)
        loc["R" + k] = P("R" + v)
    loc.update({str(s): s for s in (*POS.values(), *PROBE, *OFFSETS)})
    return loc


@lru_cache(maxsize=None)
def parse(text: str) -> sp.Expr:
    """A printed expression (see the data file's symbol mapping) -> sympy; ValueError if the
    text does not parse into an expression of known symbols."""
    try:
        expr = sp.parse_expr(text, local_dict=_locals())
    except Exception as exc:  # noqa: BLE001 - any parse failure means "garbled"
        raise ValueError(f"unparsable {text!r}: {exc}") from None
    if not isinstance(expr, sp.Expr):
        raise ValueError(f"unparsable {text!r}: not an expression")
    known = {v for v in _locals().values() if isinstance(v, sp.Symbol)}
    unknown = [s for s in expr.free_symbols if s not in known and not _is_paper(s)]
    if unknown:
        raise ValueError(f"unknown symbol {unknown[0]} in {text!r}")
    return expr


def _is_paper(s) -> bool:
    n = s.name.lstrip("R")
    return n in SCALARS.values() or (n[:2] in FUNCS and n[2:] in ("(X)", "(Y)", "(Z)"))


def printed_component(eq: dict, comp: str) -> tuple[sp.Expr, str]:
    """(expression, note) of one printed component: the transcription, or the OCR reading where
    the data file gives one (the note says so)."""
    raw = eq["expr"][comp]
    ocr = eq.get("ocr", {})
    if comp in ocr:
        return parse(ocr[comp]), f"OCR text {raw!r} read as {ocr[comp]!r} ({ocr.get('note', '')})"
    return parse(raw), ""


def _error_symbols(expr) -> set:
    return {s for s in expr.free_symbols if _is_paper(s)}


# ------------------------------------------------------------------------ derived models
@dataclass(frozen=True)
class Reading:
    """A way of reading a layout: table pivot, axis stacking, sign of paper symbols."""

    pivot: str = "tool_point"
    tool: tuple | None = None
    work: tuple | None = None
    flips: tuple = ()

    def cost(self) -> int:
        return (self.pivot != "tool_point") + (self.tool is not None) + \
            (self.work is not None) + len(self.flips)

    def describe(self, layout) -> str:
        parts = []
        if self.pivot == "table_origin":
            parts.append("table errors act about the moving table origin (Pahk's chain form "
                         "Tx(A) + Lx: own-travel lever arms such as Y*Ez(Y))")
        if self.tool is not None:
            parts.append(f"tool side stacked {' -> '.join(self.tool)} "
                         f"({self.tool[-1]} riding on {self.tool[-2]}; the layout has "
                         f"{' -> '.join(layout.tool_chain)})")
        if self.work is not None:
            parts.append(f"table stacked {' -> '.join(self.work)} (layout: "
                         f"{' -> '.join(layout.workpiece_chain)})")
        for f in self.flips:
            if f in layout.axes:
                parts.append(f"the six errors of table {f} with the opposite sign (the table's "
                             f"own motion instead of the tool relative to the table)")
            else:
                parts.append(f"{_paper_name(layout, f)} with the opposite sign")
        return "; ".join(parts) or "the physical layout"

    def short(self, layout) -> str:
        parts = []
        if self.pivot == "table_origin":
            parts.append("table errors about the moving table origin")
        if self.tool is not None:
            parts.append(f"{self.tool[-1]} riding on {self.tool[-2]}")
        if self.work is not None:
            parts.append(f"table order {'-'.join(self.work)}")
        for f in self.flips:
            parts.append(f"table {f} error signs" if f in layout.axes
                         else f"sign of {_paper_name(layout, f)}")
        return ", ".join(parts) or "physical layout"


def _paper_name(layout, iso: str) -> str:
    return layout.paper_symbols.get(iso, iso).lstrip("-")


@lru_cache(maxsize=None)
def _layout(name: str):
    return read_layout(name)


@lru_cache(maxsize=None)
def _iso_error(name: str, pivot: str, tool, work) -> tuple:
    lay = _layout(name)
    if tool is not None or work is not None:
        lay = replace(lay, tool_chain=tool or lay.tool_chain,
                      workpiece_chain=work or lay.workpiece_chain)
    chain = Chain.from_layout(lay, table_pivot=pivot)
    return chain, tuple(vol.volumetric_error(chain))


def paper_map(layout, flips=()) -> dict:
    return dict(_paper_map(layout.name, tuple(flips)))


@lru_cache(maxsize=None)
def _paper_map(name: str, flips: tuple) -> tuple:
    layout = _layout(name)
    return tuple(_paper_map_items(layout, flips))


def _paper_map_items(layout, flips):
    """ISO parameter symbol -> its value in paper symbols (``EXY -> -dx(Y)`` ...)."""
    out = {}
    for iso, text in layout.paper_symbols.items():
        v = parse(text)
        axis = layout.parameter_axis.get(iso)
        if iso in flips or (axis is not None and axis in flips):
            v = -v
        out[parameter_symbol(iso)] = v
    return out.items()


def derived_error(name: str, reading: Reading = Reading()) -> list:
    """(dX, dY, dZ) of a layout under a reading, in paper symbols."""
    _, err = _iso_error(name, reading.pivot, reading.tool, reading.work)
    m = paper_map(_layout(name), reading.flips)
    return [sp.expand(e.xreplace(m)) for e in err]


def readings(name: str) -> list[Reading]:
    """All volumetric readings of a layout, cheapest first (the physical one first)."""
    lay = _layout(name)
    tools = [None] + [p for p in itertools.permutations(lay.tool_chain) if p != lay.tool_chain]
    works = [None] + [p for p in itertools.permutations(lay.workpiece_chain)
                      if p != lay.workpiece_chain]
    pivots = ["tool_point"] + (["table_origin"] if lay.workpiece_chain else [])
    flippable = sorted(lay.squareness) + list(lay.workpiece_chain)
    flipsets = [c for r in range(len(flippable) + 1) for c in itertools.combinations(flippable, r)]
    out = [Reading(p, t, w, f) for p in pivots for t in tools for w in works for f in flipsets]
    return sorted(out, key=lambda r: (r.cost(), repr(r)))


def _search(name: str, printed: list) -> tuple[Reading, list, int]:
    """The first reading (cheapest) reproducing all ``printed`` components, else the closest:
    (reading, its derived components, total number of differing monomials)."""
    best = None
    for r in readings(name):
        d = derived_error(name, r)
        score = sum(n_issues(a, b) for a, b in zip(d, printed))
        if best is None or score < best[2]:
            best = (r, d, score)
        if score == 0:
            break
    return best


# ------------------------------------------------------------------------- volumetric
def audit_volumetric(eq: dict) -> list[Verdict]:
    name = eq["layout"]
    lay = _layout(name)
    printed, notes = [], []
    for c in COMPONENTS:
        e, note = printed_component(eq, c)
        printed.append(e)
        notes.append(note)
    physical = derived_error(name)
    best, best_d, score = _search(name, printed)
    out = []
    for i, c in enumerate(COMPONENTS):
        ocr = f" {notes[i]}." if notes[i] else ""
        if is_identical(physical[i], printed[i]):
            v = _verdict(eq, c, "identical", "",
                         f"expand(derived - printed) == 0 for the physical layout "
                         f"{name} ({_stacking(lay)})." + ocr, printed[i], physical[i])
            out.append(_ocr_category(v, notes[i]))
            continue
        diff0 = describe_diff(physical[i], printed[i])
        if is_identical(best_d[i], printed[i]):
            erratum = f"{best.short(lay)} reading"
            evidence = (f"differs from the physical layout: {diff0}. Reproduced exactly by the "
                        f"reading: {best.describe(lay)} (expand(alternative - printed) == 0).")
            v = _verdict(eq, c, "differs", erratum, evidence + ocr, printed[i], physical[i])
            out.append(_reading_category(v, best, lay, best_d[i], physical[i]))
            continue
        resid = describe_diff(best_d[i], printed[i])
        erratum = resid if best.cost() == 0 else f"{resid} [under {best.short(lay)}]"
        evidence = (f"differs from the physical layout: {diff0}. No reading reproduces it; "
                    f"closest (for the whole equation): {best.describe(lay)}, which leaves: "
                    f"{resid}: a printing error (no consistent convention explains it).")
        out.append(classify(_verdict(eq, c, "differs", erratum, evidence + ocr, printed[i],
                                     physical[i]), "printing_error",
                            alternative=fmt(best_d[i]) if best.cost() else ""))
    return out


# ------------------------------------------------------------------ verdict categories
#: the statements of Pahk (1995) that the categories quote (verbatim from the seed, translated)
STATEMENTS = {
    "quadrature": "Sec. 2.2: \"입체오차의 랜덤성분은 오차전파이론에 의한 구적공식(quadrature "
                  "formula)을 이용하여 계산할 수 있다\" (the random component of the volumetric "
                  "error can be computed with the quadrature formula of error propagation)",
    "rule1": "Sec. 2.3, rule (1): \"한 축을 따라서의 오각도오차와 피치각도 오차는 그 축을 따라서의 "
             "위치오차 값에 아베오프셋을 통해서 영향을 준다. 또한, 롤각도오차는 축을 따라서의 "
             "진직도오차 값에 아베 오프셋을 통해서 영향을 준다.\" (the yaw and pitch errors of an "
             "axis act on its positional error through the Abbe offset; the roll error acts on "
             "its straightness errors through the Abbe offset); sec. 2.3.1: \"진직도오차들은 "
             "롤오차와 이와 관련된 아베옵셋에 의해 영향받게 되며\" (straightness errors are "
             "affected by the roll error and its Abbe offset)",
}

CONVENTION_TABLE = ("table rotations pivot about the moving table origin (Pahk's chain form "
                    "Tx(Xa, Ya, Za)^T + Lx of eq. A1, A4, A7), not about the tool point")
CONVENTION_SQUARENESS = ("squareness as the slope of ONE axis' straightness line in the machine "
                         "frame (Pahk's definition), not ISO 230-1's angle between the two "
                         "reference lines")


def _bounds(expr) -> dict:
    """Bounds of the symbols of a paper expression on the typical machine (mm, rad)."""
    t = TYPICAL
    out = {}
    for s in expr.free_symbols:
        n = s.name
        if n in ("X", "Y", "Z"):
            out[n] = t["travel_mm"][n]
        elif n in ("Xo", "Yo", "Zo"):
            out[n] = t["measuring_offset_mm"]
        elif n in ("Xp", "Yp", "Zp"):
            out[n] = t["probe_offset_mm"]
        elif n[:1] == "d":
            out[n] = t["translational_mm"]
        else:
            out[n] = t["angular_rad"]
    return out


def _ocr_category(v: Verdict, note: str) -> Verdict:
    """An identical verdict that needed an OCR reading is an extraction defect."""
    if note and v.verdict == "identical":
        return classify(v, "extraction")
    return v


def _reading_category(v: Verdict, r: Reading, lay, alt, physical) -> Verdict:
    """Category of a volumetric verdict reproduced exactly by reading ``r``."""
    alt_text = fmt(alt)
    if r.tool is not None or r.work is not None:
        return classify(v, "printing_error", alternative=alt_text, evidence=v.evidence + (
            " A different stacking of the axes is another machine, not a convention: the "
            "printed chain stacks the axes wrongly."))
    names = []
    if r.pivot == "table_origin":
        names.append(CONVENTION_TABLE)
    for f in r.flips:
        names.append(f"the six errors of table {f} signed as the table's own motion"
                     if f in lay.axes else
                     f"{_paper_name(lay, f)} signed the other way (its sign convention)")
    if isinstance(alt, sp.MatrixBase):
        diffs = [sp.expand(a - b) for a, b in zip(physical, alt)]
        alt_text, dropped = _vec(alt), _vec(diffs)
    else:
        diffs = [sp.expand(physical - alt)]
        dropped = fmt(diffs[0])
    size = max(worst_case_um(d, _bounds(d)) for d in diffs)
    return classify(v, "convention", alternative=alt_text, statement="; ".join(names),
                    dropped=dropped, dropped_um=size,
                    evidence=v.evidence + f" Convention: {'; '.join(names)}. The two conventions "
                    f"differ by {dropped} (up to {size:.2g} um on the {typical_text()}).")


def _stacking(lay) -> str:
    tool = "tool side " + " -> ".join(("bed",) + lay.tool_chain)
    if lay.workpiece_chain:
        return tool + "; table " + " -> ".join(("bed",) + lay.workpiece_chain)
    return tool


def _verdict(eq, comp, verdict, erratum, evidence, printed, derived) -> Verdict:
    text = eq.get("expr", {}).get(comp, "") if comp else ""
    p = text if isinstance(text, str) and text else fmt(printed) if printed is not None else ""
    return Verdict(SOURCE, eq["id"], eq["layout"], verdict, erratum, evidence, p,
                   fmt(derived) if derived is not None else "", comp)


# ----------------------------------------------------------------------------- random
def _sensitivity(name: str):
    chain, err = _iso_error(name, "tool_point", None, None)
    lay = _layout(name)
    m = paper_map(lay)
    sens = {}
    for p in chain.parameters:
        sigma = P("R" + _paper_name(lay, p.name))
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


def audit_random(eq: dict, random_eqs: dict) -> list[Verdict]:
    name = eq["layout"]
    cands = [("exact", name, "exact first-order propagation (the authority)"),
             ("termwise", name, "Pahk's term-wise quadrature: every monomial of a sensitivity "
                                "squared alone, so cross terms such as 2*Z*Zp of (Z + Zp)^2 drop")]
    for other, oid in sorted(random_eqs.items()):
        if other != name:
            cands.append(("termwise", other, f"the term-wise quadrature of {other} (eq. {oid}) "
                                             f"reprinted"))
            cands.append(("exact", other, f"the exact propagation of {other} reprinted"))
    derived = {(m, n): random_squared(n, m) for m, n, _ in cands}
    out = []
    for i, c in enumerate(RANDOM_COMPONENTS):
        pr, note = printed_component(eq, c)
        ocr = f" {note}." if note else ""
        exact, tw = derived[("exact", name)][i], derived[("termwise", name)][i]
        if is_identical(exact, pr):
            out.append(_ocr_category(_verdict(eq, c, "identical", "", "expand(derived - printed) "
                                              "== 0 for exact propagation." + ocr, pr, exact),
                                     note))
            continue
        diff0 = describe_diff(exact, pr)
        hit = next(((m, n, d) for m, n, d in cands if is_identical(derived[(m, n)][i], pr)), None)
        if hit and hit[1] == name:
            erratum = "term-wise quadrature drops cross terms"
            size = _random_size_um(name, i)
            evidence = (f"differs from exact propagation: {diff0}. Reproduced exactly by {hit[2]} "
                        f"(expand(term-wise - printed) == 0); the two agree when the probe offset "
                        f"is zero. Size of the dropped cross terms: sqrt(exact) - sqrt(printed) "
                        f"up to {size:.2g} um ({typical_text()}, random angular errors "
                        f"{TYPICAL['sigma_angular_rad'] * 1e6:g} urad, translational "
                        f"{TYPICAL['sigma_translational_mm'] * 1e3:g} um, 1 sigma).")
            out.append(classify(_verdict(eq, c, "differs", erratum, evidence + ocr, pr, exact),
                                "simplification", alternative=fmt(tw),
                                statement=STATEMENTS["quadrature"] + "; applied term by term",
                                dropped=fmt(sp.expand(exact - tw)), dropped_um=size))
            continue
        if hit:
            erratum = f"{c[:2]}^2 of {hit[1]} (eq. {random_eqs[hit[1]]}) reprinted"
            evidence = (f"differs from exact propagation: {diff0}; from the term-wise quadrature "
                        f"of {name}: {describe_diff(tw, pr)}. Reproduced exactly by {hit[2]}: "
                        f"a copy of another layout's component, no convention of {name}.")
        else:
            resid = describe_diff(tw, pr)
            erratum = f"{resid} [term-wise]"
            evidence = (f"differs from exact propagation: {diff0}. No reading reproduces it; "
                        f"closest: the term-wise quadrature of {name}, which leaves: {resid}.")
        out.append(classify(_verdict(eq, c, "differs", erratum, evidence + ocr, pr, exact),
                            "printing_error"))
    return out


# --------------------------------------------------------------------------- transfer
_ROLL = {"X": "EA", "Y": "EB", "Z": "EC"}
_LINES = {"EC0Y": ("X", "Y"), "EB0Z": ("X", "Z"), "EA0Z": ("Y", "Z")}


def _iso_of(layout, key: str) -> str:
    target = parse(key)
    for iso, text in layout.paper_symbols.items():
        if parse(text.lstrip("-")) == target:
            return iso
    raise ValueError(f"{layout.name}: no ISO parameter for paper symbol {key!r}")


@lru_cache(maxsize=None)
def _squareness_shift(name: str, pivot: str, tool, iso: str, mode: str):
    """Apparent squareness at (Xo, Yo, Zo) minus the true one, ISO symbols.  ``mode``: "both"
    (angle between the two straightness lines), or the line of one axis alone."""
    _, err = _iso_error(name, pivot, tool, None)
    about, b, a = SQUARENESS[iso]
    ia, ib = "XYZ".index(a), "XYZ".index(b)
    slope_b = sp.diff(err[ia], POS[b])   # tilt of the line of b (displacement along a)
    slope_a = sp.diff(err[ib], POS[a])   # tilt of the line of a
    slope = {"both": slope_b + slope_a, b: slope_b, a: slope_a}[mode]
    sign = {"EC0Y": -1, "EB0Z": 1, "EA0Z": -1}[iso]
    app = (sign * slope).subs({POS[t]: OFFSETS[i] for i, t in enumerate("XYZ")})
    app = app.subs({p: 0 for p in PROBE})
    return sp.expand(app - parameter_symbol(iso))


@dataclass(frozen=True)
class RuleReading:
    pivot: str = "tool_point"
    flips: tuple = ()
    rule1: bool = False
    line: str = "both"
    zero: tuple = ()

    def cost(self) -> int:
        return (self.pivot != "tool_point") + len(self.flips) + self.rule1 + \
            (self.line != "both") + len(self.zero)

    def describe(self, layout, iso) -> str:
        parts = []
        if self.rule1 and iso not in SQUARENESS:
            ax = iso[2]
            if iso[1] == ax:
                parts.append("Pahk's rule (1): a positional error is transferred by pitch and yaw "
                             "only (the Abbe term of an offset along the axis itself dropped)")
            else:
                parts.append(f"Pahk's rule (1): a straightness error is transferred by the roll "
                             f"{_paper_name(layout, _ROLL[ax] + ax)} only")
        if self.line != "both" and iso in SQUARENESS:
            a, b = _LINES[iso]
            other = a if self.line == b else b
            parts.append(f"squareness from the slope of the {self.line} line alone (the "
                         f"{other} line's tilt at the measuring position ignored)")
        if self.zero:
            parts.append("only if " + " = ".join(self.zero) + " = 0 (the rule ignores the Abbe "
                         "terms of that offset, as if the measuring line had no such offset)")
        if self.pivot == "table_origin":
            parts.append("table errors about the moving table origin")
        for f in self.flips:
            parts.append(f"table {f} error signs reversed" if f in layout.axes
                         else f"sign of {_paper_name(layout, f)} reversed")
        return "; ".join(parts) or "the full rigid-body transfer of the physical layout"


@lru_cache(maxsize=None)
def _translational_shifts(name: str) -> dict:
    chain, err = _iso_error(name, "tool_point", None, None)
    return vol.transfer_rules(chain, sp.Matrix(err)).shift


@lru_cache(maxsize=None)
def derived_rule(name: str, key: str, r: RuleReading = RuleReading()):
    """The reference (transferred) value of paper symbol ``key`` in measured paper symbols."""
    lay = _layout(name)
    iso = _iso_of(lay, key)
    if iso in SQUARENESS:
        shift = _squareness_shift(name, r.pivot, None, iso, r.line)
    else:
        shift = _translational_shifts(name)[iso]
        if r.rule1:
            ax = iso[2]
            keep = (lambda s: s.name[:2] != _ROLL[ax]) if iso[1] == ax else \
                (lambda s: s.name[:2] == _ROLL[ax])
            shift = sum((t for t in sp.Add.make_args(shift)
                         if all(keep(s) for s in t.free_symbols if s.name[:1] == "E")),
                        sp.Integer(0))
        if r.zero:
            shift = shift.subs({o: 0 for o in OFFSETS if o.name in r.zero})
    m = paper_map(lay, r.flips)
    iso_sym = parameter_symbol(iso)
    ref_iso = iso_sym - shift                      # reference = measured - shift (ISO)
    sign = m[iso_sym] / P(_paper_name(lay, iso))   # paper = sign * ISO
    return sp.expand(sign * ref_iso.xreplace(m))


def rule_readings(name: str, flips: tuple) -> list[RuleReading]:
    lay = _layout(name)
    pivots = ["tool_point"] + (["table_origin"] if lay.workpiece_chain else [])
    single = [(f,) for f in sorted(lay.squareness) + list(lay.workpiece_chain)]
    flipsets = [()] + ([flips] if flips else []) + [f for f in single if f != flips]
    lines = ["both", "X", "Y", "Z"]
    offs = [o.name for o in OFFSETS]
    zeros = [z for k in range(4) for z in itertools.combinations(offs, k)]
    out = [RuleReading(p, f, r1, ln, z) for p in pivots for f in flipsets
           for r1 in (False, True) for ln in lines for z in zeros]
    # Pahk's own rule (1) and the squareness readings before assumed zero offsets
    return sorted(out, key=lambda r: (r.cost(), len(r.zero), repr(r)))


def audit_transfer(eq: dict, flips: tuple) -> list[Verdict]:
    name = eq["layout"]
    lay = _layout(name)
    out = []
    for key in eq["expr"]:
        pr, note = printed_component(eq, key)
        ocr = f" {note}." if note else ""
        iso = _iso_of(lay, key)
        rr = [r for r in rule_readings(name, flips)
              if (iso in SQUARENESS or r.line == "both")
              and (iso not in SQUARENESS or not r.rule1)
              and (r.line == "both" or r.line in _LINES.get(iso, ()))
              and (iso not in SQUARENESS or not r.zero)]
        d0 = derived_rule(name, key)
        label = f"{key}"
        if is_identical(d0, pr):
            out.append(_ocr_category(_verdict(
                eq, label, "identical", "", "expand(derived - printed) == 0 for the full "
                "rigid-body transfer of the physical layout." + ocr, pr, d0), note))
            continue
        diff0 = describe_diff(d0, pr)
        term = "Abbe term" if iso not in SQUARENESS else "term"
        erratum = diff0.replace("omitted ", f"omitted {term} ").replace("extra ", f"extra {term} ")
        best = None
        for r in rr:
            d = derived_rule(name, key, r)
            k = n_issues(d, pr)
            if best is None or k < best[1]:
                best = (r, k, d)
            if k == 0:
                break
        r, k, d = best
        if k == 0:
            evidence = (f"derived {key} = {fmt(d0)}; printed differs by: {diff0}. Reproduced "
                        f"exactly by the reading: {r.describe(lay, iso)} (expand(alternative - "
                        f"printed) == 0).")
            v = _verdict(eq, label, "differs", erratum, evidence + ocr, pr, d0)
            out.append(_rule_category(v, r, flips, lay, iso, d, d0))
        else:
            evidence = (f"derived {key} = {fmt(d0)}; printed differs by: {diff0}. No reading "
                        f"reproduces it; closest: {r.describe(lay, iso)}, which leaves: "
                        f"{describe_diff(d, pr)}: a printing error.")
            out.append(classify(_verdict(eq, label, "differs", erratum, evidence + ocr, pr, d0),
                                "printing_error"))
    return out


def _rule_category(v: Verdict, r: RuleReading, vol_flips: tuple, lay, iso: str, alt, d0):
    """Category of a transfer-rule verdict reproduced exactly by reading ``r``."""
    dropped = sp.expand(d0 - alt)
    size = worst_case_um(dropped, _bounds(dropped)) if iso not in SQUARENESS else None
    fields = {"alternative": fmt(alt), "dropped": fmt(dropped), "dropped_um": size}
    extra_flips = [f for f in r.flips if f not in vol_flips]
    if extra_flips:
        sym = ", ".join(_paper_name(lay, f) for f in extra_flips)
        return classify(v, "printing_error", evidence=v.evidence + (
            f" The sign of {sym} needed here is the opposite of the one the same layout's "
            f"volumetric equation uses: no consistent convention, a sign error."), **fields)
    where = f" (worst case {size:.2g} um on the {typical_text()})" if size is not None else ""
    if r.zero:
        zero = " = ".join(r.zero) + " = 0"
        return classify(v, "undecidable", evidence=v.evidence + (
            f" Pahk states no zero-offset assumption: the rule is exact only for a measuring "
            f"set-up with {zero}. Missing to decide between a deliberate set-up choice and a "
            f"printing error: the offsets of the set-up the rule was written for. Terms "
            f"omitted otherwise: {fmt(dropped)}{where}."), **fields)
    if r.rule1:
        return classify(v, "simplification", statement=STATEMENTS["rule1"],
                        evidence=v.evidence + f" Terms dropped by the stated rule: "
                                              f"{fmt(dropped)}{where}.", **fields)
    names = []
    if r.line != "both":
        names.append(CONVENTION_SQUARENESS)
        ang = sum(abs(float(c)) for c in sp.Poly(dropped, *dropped.free_symbols).coeffs()) \
            if dropped != 0 else 0.0
        v.evidence += (f" The two definitions differ by {fmt(dropped)} (up to "
                       f"{ang * TYPICAL['angular_rad'] * 1e6:.3g} urad with angular errors of "
                       f"{TYPICAL['angular_rad'] * 1e6:g} urad).")
    if r.pivot == "table_origin":
        names.append(CONVENTION_TABLE)
    for f in r.flips:
        names.append(f"{_paper_name(lay, f)} signed as in the volumetric equation")
    return classify(v, "convention", statement="; ".join(names), **fields)


# ------------------------------------------------------------------------------ chains
def _T(axis: str) -> sp.Matrix:
    ex, ey, ez = (P(f"E{c}({axis})") for c in "xyz")
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
    import ast

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
    errs = set().union(*(_error_symbols(e) for e in v))
    nom = v.subs({e: 0 for e in errs})
    return _Dual(nom, (v - nom).applyfunc(sp.expand))


def chain_error(lhs: str, rhs: str, L: dict) -> list:
    """First-order (dX, dY, dZ) implied by a printed chain ``lhs = rhs``: with f = lhs - rhs
    affine in A, nominal A0 solves f0(A0) = 0 and A1 = -J0^-1 f1(A0)."""
    names = {"T" + k: _Dual(sp.eye(3), _T(k.upper()) - sp.eye(3)) for k in "xyz"}
    names.update({k: _split(v) for k, v in _vectors(L).items()})
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


def _chain_L(eq: dict, by_id: dict) -> tuple[dict, str]:
    src = by_id[eq["L_from"]] if "L_from" in eq else eq
    ocr = src.get("ocr", {})
    L = dict(src["L"])
    notes = []
    for k in "xyz":
        if f"L.{k}" in ocr:
            notes.append(f"OCR/print: L{k} {src['L'][k]} read as {ocr[f'L.{k}']}")
            L[k] = ocr[f"L.{k}"]
    if notes and ocr.get("note"):
        notes.append(f"({ocr['note']})")
    where = f" (vectors of eq. {eq['L_from']})" if "L_from" in eq else ""
    return L, "; ".join(notes) + where


def _vec(exprs) -> str:
    return "[" + ", ".join(f"{c} = {fmt(e)}" for c, e in zip(COMPONENTS, exprs)) + "]"


def _key(exprs) -> tuple:
    return tuple(sp.expand(e) for e in exprs)


@lru_cache(maxsize=None)
def _reading_index(name: str) -> dict:
    """Derived (dX, dY, dZ) -> the cheapest reading of the layout giving it."""
    out = {}
    for r in readings(name):
        out.setdefault(_key(derived_error(name, r)), r)
    return out


def audit_chain(eq: dict, by_id: dict, result_eq: dict | None) -> list[Verdict]:
    """One verdict on a printed chain: its first-order error against the physical model."""
    name = eq["layout"]
    lay = _layout(name)
    L, note = _chain_L(eq, by_id)
    physical = derived_error(name)
    index = _reading_index(name)
    text = f"{eq['lhs']} = {eq['rhs']}"
    printed_result = None
    if result_eq is not None:
        printed_result = _key(printed_component(result_eq, c)[0] for c in COMPONENTS)
    # every chain reading, cheapest first: what it gives, and which derived reading that is
    found = []
    for rname, lhs, rhs, LL, cost in chain_readings(eq, L):
        try:
            res = _key(chain_error(lhs, rhs, LL))
        except (ValueError, TypeError, sp.SympifyError):
            continue
        found.append((rname, cost, res, index.get(res)))
    ev = [note + "."] if note else []
    if not found or found[0][1] != 0:
        try:
            chain_error(eq["lhs"], eq["rhs"], L)
            why = "no result"
        except (ValueError, TypeError, sp.SympifyError) as exc:
            why = str(exc)
        return [Verdict(SOURCE, eq["id"], name, "differs", "printed chain cannot be evaluated",
                        f"{why}. " + " ".join(ev), text, _vec(physical),
                        category="undecidable")]
    literal = found[0][2]
    if printed_result is not None:
        k = sum(n_diff(a, b) for a, b in zip(literal, printed_result))
        ev.append(f"The printed chain {'reproduces' if k == 0 else 'does not reproduce'} the "
                  f"printed eq. {result_eq['id']}" + ("" if k == 0 else f" ({k} terms differ)")
                  + ".")
        hit = next((f for f in found[1:] if f[2] == printed_result), None)
        if k and hit:
            ev.append(f"Eq. {result_eq['id']} is reproduced by the chain: {hit[0]}.")
    if all(is_identical(a, b) for a, b in zip(physical, literal)):
        if note:
            # the equality holds only for the repaired vectors, also when they are borrowed
            # from another equation (eq. 6 uses the Lz of eq. 3): an extraction defect
            ev.append("Category extraction: the derived form equals the print only once the "
                      "extraction damage of the vectors" + (f" (eq. {eq['L_from']})"
                                                            if "L_from" in eq else "")
                      + " is repaired as read above.")
        return [Verdict(SOURCE, eq["id"], name, "identical", "", "The printed chain's "
                        "first-order error equals the derived model of the physical layout. "
                        + " ".join(ev), text, _vec(physical),
                        category="extraction" if note else "identical")]
    diffs = [f"{c}: {describe_diff(physical[i], literal[i])}" for i, c in enumerate(COMPONENTS)
             if not is_identical(physical[i], literal[i])]
    ev.insert(0, "The printed chain's first-order error differs from the physical layout's "
                 "model: " + " | ".join(diffs) + ".")
    if found[0][3] is not None:
        ev.append(f"The printed chain is exactly the layout read as: "
                  f"{found[0][3].describe(lay)}.")
    matches = [f for f in found if f[3] is not None]
    best = min(matches, key=lambda f: (f[1] + f[3].cost(), f[1])) if matches else None
    if best is not None and best[0] != found[0][0]:
        fix = best[0].split(" (labels exchanged")[0]
        how = "" if best[3].cost() == 0 else f" read as: {best[3].describe(lay)}"
        ev.append(f"The chain {best[0]} gives the layout's model{how}.")
        kind = "labels misplaced" if "labels exchanged" in best[0] else "misprinted"
        fix = fix.split(":")[0] if kind == "misprinted" else fix
        erratum = f"chain {kind}: {fix}" + ("" if best[3].cost() == 0
                                            else f" ({best[3].short(lay)} reading)")
    elif best is not None:
        erratum = f"{best[3].short(lay)} reading"
    else:
        closest = min(readings(name), key=lambda r: (sum(
            n_diff(a, b) for a, b in zip(derived_error(name, r), literal)), r.cost()))
        dd = derived_error(name, closest)
        k = sum(n_diff(a, b) for a, b in zip(dd, literal))
        erratum = f"chain matches no reading ({k} terms off {closest.short(lay)})"
        ev.append(f"No chain reading gives the layout's model under any reading; the printed "
                  f"chain is closest to the layout read as: {closest.describe(lay)} (" +
                  " | ".join(describe_diff(a, b) for a, b in zip(dd, literal) if n_diff(a, b))
                  + ").")
    for f in found[1:]:
        if f[1] == 1 and f[3] is not None and (best is None or f[0] != best[0]):
            ev.append(f"The chain {f[0]} gives the layout's model read as: "
                      f"{f[3].describe(lay)}.")
    v = Verdict(SOURCE, eq["id"], name, "differs", erratum, " ".join(ev),
                f"{text}  =>  {_vec(literal)}", _vec(physical))
    lit = found[0][3]
    if lit is not None and lit.tool is None and lit.work is None:
        # the printed chain, taken literally, is the layout under a convention
        return [_reading_category(v, lit, lay, sp.Matrix(literal), sp.Matrix(physical))]
    v.evidence += (" The printed chain is not the layout under any convention (a different "
                   "stacking of the axes is another machine): a printing error.")
    return [classify(v, "printing_error",
                     alternative=_vec(best[2]) if best is not None else "")]


# ------------------------------------------------------------------------------ entry
def audit(printed: dict, layouts: list[str] | None = None) -> list[Verdict]:
    """Verdicts on every printed equation of the data file (restricted to ``layouts``)."""
    eqs = printed.get("equation", [])
    by_id = {e["id"]: e for e in eqs}
    random_eqs = {e["layout"]: e["id"] for e in eqs if e["kind"] == "random"}
    result_of = {e["layout"]: e for e in eqs if e["kind"] == "volumetric"}
    wanted = None if layouts is None else set(layouts)
    out: list[Verdict] = []
    flips: dict = {}
    for e in eqs:
        if e["kind"] == "volumetric" and (wanted is None or e["layout"] in wanted):
            pr = [printed_component(e, c)[0] for c in COMPONENTS]
            flips[e["layout"]] = _search(e["layout"], pr)[0].flips
    for e in eqs:
        if wanted is not None and e["layout"] not in wanted:
            continue
        kind = e["kind"]
        if kind == "volumetric":
            out.extend(audit_volumetric(e))
        elif kind == "random":
            out.extend(audit_random(e, random_eqs))
        elif kind == "transfer":
            out.extend(audit_transfer(e, flips.get(e["layout"], ())))
        elif kind == "chain":
            chain_v = audit_chain(e, by_id, result_of.get(e["layout"]))
            out.extend(chain_v)
        else:
            raise ValueError(f"equation {e['id']}: unknown kind {kind!r}")
    return out
