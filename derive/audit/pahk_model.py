"""Pahk (1995) audit, shared model: the paper's symbols, the layouts' derived volumetric error
and the *readings* under which it is compared with the print (sympy, no file I/O).

A :class:`Reading` is one combination of

* the table pivot (``table_origin``: table rotations about the table's moving origin, the
  form of Pahk's appendix chains ``Tx(Xa, Ya, Za)^T + Lx``),
* an axis stacking (which axis carries which): the layout file's, one of the geometries the
  text allows (``[[geometry]]`` of the data file, each with the passage that allows it), or any
  other order of the same axes (another machine: the text excludes it),
* the opposite sign of squareness symbols or of all errors of a table axis (a sign
  convention).

Every reading has keys (:meth:`Reading.keys`) whose kinds fix its category
(:data:`volerr.derive.audit.framework.READING_KINDS`), the same on every layout.

Sign convention of the paper symbols: the layout's ``[paper_symbols]`` (ISO name -> paper
symbol with sign).  A table axis' errors other than its positioning error are the table's own
motion (the opposite of the tool-relative ISO error); when a geometry moves an axis onto or off
the table that sign moves with it (:func:`paper_map`).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace
from functools import lru_cache

import sympy as sp

from volerr.machine.layout import read_layout

from .. import volumetric as vol
from ..kinematics import PROBE, Chain, parameter_symbol, position_symbol

FUNCS = ("dx", "dy", "dz", "Ex", "Ey", "Ez")
SCALARS = {"alpha": "alpha", "a": "alpha", "beta1": "beta1", "beta2": "beta2"}
POS = {t: position_symbol(t) for t in "XYZ"}
OFFSETS = vol.OFFSETS
COMPONENTS = ("dX", "dY", "dZ")


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
    loc = {}
    for f in FUNCS:
        loc[f] = _function(f)
        loc["R" + f] = _function("R" + f)
    for k, v in SCALARS.items():
        loc[k] = P(v)
        loc["R" + k] = P("R" + v)
    loc.update({str(s): s for s in (*POS.values(), *PROBE, *OFFSETS)})
    return tuple(loc.items())


def _locals() -> dict:
    return dict(_locals_cached())


def is_paper(s) -> bool:
    """Whether a symbol is one of the paper's error symbols (or its random R-form)."""
    n = s.name.lstrip("R")
    return n in SCALARS.values() or (n[:2] in FUNCS and n[2:] in ("(X)", "(Y)", "(Z)"))


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
    unknown = [s for s in expr.free_symbols if s not in known and not is_paper(s)]
    if unknown:
        raise ValueError(f"unknown symbol {unknown[0]} in {text!r}")
    return expr


def printed_component(eq: dict, comp: str) -> tuple[sp.Expr, str]:
    """(expression, note) of one printed component: the transcription, or the reading of
    extraction damage where the data file gives one (the note says so)."""
    raw = eq["expr"][comp]
    ocr = eq.get("ocr", {})
    if comp in ocr:
        note = ocr.get("notes", {}).get(comp, ocr.get("note", ""))
        return parse(ocr[comp]), f"Transcribed {raw!r} and read as {ocr[comp]!r} ({note})"
    return parse(raw), ""


def error_symbols(expr) -> set:
    return {s for s in expr.free_symbols if is_paper(s)}


# ------------------------------------------------------------------------------- layouts
@lru_cache(maxsize=None)
def layout(name: str):
    return read_layout(name)


def paper_name(lay, iso: str) -> str:
    return lay.paper_symbols.get(iso, iso).lstrip("-")


def stacking_text(tool, work) -> str:
    """``"tool X -> Z, table Y"`` (bed first)."""
    out = "tool " + " -> ".join(tool)
    if work:
        out += ", table " + " -> ".join(work)
    return out


@dataclass(frozen=True)
class Geometry:
    """An axis stacking the text allows for a layout, with the passage that allows it."""

    tool: tuple
    work: tuple
    text: str = ""

    def label(self) -> str:
        return stacking_text(self.tool, self.work)


def geometries(printed: dict, name: str) -> list[Geometry]:
    """The stackings the text allows for layout ``name``: the layout file's first, then the
    ``[[geometry]]`` entries of the data file (their passages quoted)."""
    lay = layout(name)
    own = Geometry(tuple(lay.tool_chain), tuple(lay.workpiece_chain))
    out = [own]
    for g in printed.get("geometry", []):
        if g["layout"] != name:
            continue
        geo = Geometry(tuple(g["tool"]), tuple(g["workpiece"]), g.get("text", ""))
        if (geo.tool, geo.work) == (own.tool, own.work):
            out[0] = geo
        else:
            out.append(geo)
    return out


def geometry_text(geoms, stacking) -> str:
    """The passage that allows ``stacking`` ((tool, work)) among ``geoms``, or ""."""
    for g in geoms:
        if (g.tool, g.work) == tuple(map(tuple, stacking)):
            return g.text
    return ""


# ------------------------------------------------------------------------------ readings
@dataclass(frozen=True)
class Reading:
    """A way of reading a layout: table pivot, axis stacking, sign of paper symbols.
    ``tool``/``work`` None: the layout file's stacking; ``allowed``: the text allows the
    stacking (a geometry), else it is another machine."""

    pivot: str = "tool_point"
    tool: tuple | None = None
    work: tuple | None = None
    flips: tuple = ()
    allowed: bool = True

    def stacking(self, lay) -> tuple[tuple, tuple]:
        return (self.tool if self.tool is not None else tuple(lay.tool_chain),
                self.work if self.work is not None else tuple(lay.workpiece_chain))

    def keys(self, lay) -> tuple:
        out = []
        if self.pivot == "table_origin":
            out.append("table_origin")
        if self.tool is not None or self.work is not None:
            kind = "geometry" if self.allowed else "stacking"
            out.append(f"{kind}:{lay.name} {stacking_text(*self.stacking(lay))}")
        out.extend(flip_key(lay, f) for f in self.flips)
        return tuple(out)

    def cost(self) -> int:
        return (self.pivot != "tool_point") + (self.tool is not None or self.work is not None) \
            + len(self.flips)

    def describe(self, lay) -> str:
        parts = []
        if self.pivot == "table_origin":
            parts.append("table errors act about the moving table origin (Pahk's chain form "
                         "Tx(A) + Lx: own-travel lever arms such as Y*Ez(Y))")
        if self.tool is not None or self.work is not None:
            tool, work = self.stacking(lay)
            what = "a geometry the text allows" if self.allowed else \
                "another machine: a stacking the text does not allow"
            parts.append(f"axes stacked {stacking_text(tool, work)} ({what}; the layout file "
                         f"has {stacking_text(lay.tool_chain, lay.workpiece_chain)})")
        for f in self.flips:
            if f in lay.axes:
                parts.append(f"the errors of table {f} with the opposite sign (the table's "
                             f"own motion instead of the tool relative to the table)")
            else:
                parts.append(f"{paper_name(lay, f)} with the opposite sign")
        return "; ".join(parts) or "the physical layout"

    def short(self, lay) -> str:
        parts = []
        if self.pivot == "table_origin":
            parts.append("table errors about the moving table origin")
        if self.tool is not None or self.work is not None:
            parts.append(stacking_text(*self.stacking(lay)))
        for f in self.flips:
            parts.append(f"table {f} error signs" if f in lay.axes
                         else f"sign of {paper_name(lay, f)}")
        return ", ".join(parts) or "physical layout"


def flip_key(lay, f: str) -> str:
    return f"flip:{lay.name} table {f}" if f in lay.axes else \
        f"flip:{lay.name} {paper_name(lay, f)}"


@lru_cache(maxsize=None)
def iso_error(name: str, pivot: str, tool, work) -> tuple:
    """(chain, (dX, dY, dZ) in ISO symbols) of a layout under a pivot and stacking."""
    lay = layout(name)
    if tool is not None or work is not None:
        lay = replace(lay, tool_chain=tool if tool is not None else lay.tool_chain,
                      workpiece_chain=work if work is not None else lay.workpiece_chain)
    chain = Chain.from_layout(lay, table_pivot=pivot)
    return chain, tuple(vol.volumetric_error(chain))


def paper_map(lay, work=None, flips=()) -> dict:
    """ISO parameter symbol -> its value in paper symbols (``EXY -> -dx(Y)`` ...) for the
    stacking with table axes ``work`` (None: the layout's) and the sign flips ``flips``."""
    return dict(_paper_map(lay.name, None if work is None else tuple(work), tuple(flips)))


@lru_cache(maxsize=None)
def _paper_map(name: str, work, flips: tuple) -> tuple:
    lay = layout(name)
    table = set(lay.workpiece_chain if work is None else work)
    out = {}
    for iso, text in lay.paper_symbols.items():
        v = parse(text)
        axis = lay.parameter_axis.get(iso)
        if axis is not None and iso[1] != axis and \
                (axis in lay.workpiece_chain) != (axis in table):
            v = -v                        # moved onto / off the table: own-motion sign
        if iso in flips or (axis is not None and axis in flips):
            v = -v
        out[parameter_symbol(iso)] = v
    return tuple(out.items())


def derived_error(name: str, reading: Reading = Reading()) -> list:
    """(dX, dY, dZ) of a layout under a reading, in paper symbols (a new list; the expansion
    computed once per layout and reading: the audit asks for half of them twice)."""
    return list(_derived_error(name, reading))


@lru_cache(maxsize=None)
def _derived_error(name: str, reading: Reading) -> tuple:
    _, err = iso_error(name, reading.pivot, reading.tool, reading.work)
    m = paper_map(layout(name), reading.work, reading.flips)
    return tuple(sp.expand(e.xreplace(m)) for e in err)


def readings(name: str, geoms: tuple) -> list[Reading]:
    """Every reading of a layout: pivots x stackings (the layout's, the allowed geometries
    ``geoms``, every other order of the same axes) x sign sets; cheapest first."""
    lay = layout(name)
    own = (tuple(lay.tool_chain), tuple(lay.workpiece_chain))
    allowed = {(g.tool, g.work) for g in geoms}
    stackings = [own] + [(g.tool, g.work) for g in geoms if (g.tool, g.work) != own]
    for t in itertools.permutations(own[0]):
        for w in itertools.permutations(own[1]):
            if (t, w) not in stackings:
                stackings.append((t, w))
    out = []
    for tool, work in stackings:
        pivots = ["tool_point"] + (["table_origin"] if work else [])
        flippable = sorted(lay.squareness) + list(work)
        flipsets = [c for r in range(len(flippable) + 1)
                    for c in itertools.combinations(flippable, r)]
        same = (tool, work) == own
        for p in pivots:
            for f in flipsets:
                out.append(Reading(p, None if same else tool, None if same else work, f,
                                   (tool, work) in allowed))
    return sorted(out, key=lambda r: (r.cost(), repr(r)))
