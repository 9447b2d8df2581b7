"""One audit run: collect the verdicts of every provider, group them per printed item and
format them as the text table of ``volerr audit`` (sympy is imported only by :func:`collect`).

Steps, in the order ``volerr audit`` calls them: :func:`resolve_layouts` (layout files -> the
names they audit), :func:`collect` (verdicts of :data:`volerr.derive.audit.PROVIDERS`),
:func:`group` (one :class:`Row` per source, equation and layout), :func:`detail_rows` (one
:class:`Row` per component), :func:`table` (fixed-width text), :func:`totals_line`, and
:func:`numeric_table` (the generated models against the printed equations, no sympy).
"""

from __future__ import annotations

import math
import sys
import textwrap
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from ..errors import InputError, require
from ..machine.layout import layout_names, read_layout


@dataclass
class Row:
    """One line of the audit table: a printed item (or, in detail, one of its components)."""

    source: str
    equation: str
    layout: str
    verdict: str = "identical"
    erratum: str = ""
    n: int = 0
    differs: int = 0
    errata: list = field(default_factory=list)


def data_file(name: str) -> dict:
    """The printed material of a provider, ``volerr/derive/audit/data/<name>`` (TOML), as a
    dict (the audit room's data folder: importing its package does not import sympy)."""
    path = resources.files("volerr.derive.audit") / "data" / name
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"audit data file {name} is missing from the package") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"audit data file {name}: not valid TOML ({exc})") from None


def data_paths(mods=None) -> list[str]:
    """Paths of the data files read by the provider modules ``mods`` (default: every provider;
    imports sympy), the inputs of the run."""
    if mods is None:
        from volerr.derive.audit import providers

        mods = providers()
    return [str(resources.files("volerr.derive.audit") / "data" / m.DATA_FILE) for m in mods
            if getattr(m, "DATA_FILE", None)]


def resolve_layouts(items) -> list[str]:
    """Layout names; a layout file counts as the layout it names (``name = ...``), with a note
    on stderr when it differs from the shipped layout of that name."""
    names = []
    for item in items or []:
        p = Path(item)
        if p.suffix.lower() == ".toml" or p.is_file():
            require(p.is_file(), f"layout file {p} does not exist")
            lay = read_layout(str(p))
            names.append(lay.name)
            if lay.name in layout_names() and lay.sha256 != read_layout(lay.name).sha256:
                print(f"volerr audit: note: {p} differs from the shipped layout {lay.name}: the "
                      f"printed equations are audited against the derivation of the shipped "
                      f"{lay.name}", file=sys.stderr)
        else:
            names.append(item)
    return names


def collect(layouts: list[str] | None, progress=None):
    """All verdicts of all providers, restricted to ``layouts`` when given (imports sympy).

    Parameters
    ----------
    layouts : list of str or None
        Layout names (audited or shipped); None audits everything.
    progress : callable, optional
        ``progress(iterable, desc=..., unit=...)`` wrapper (a tqdm bar in the command).

    Returns
    -------
    mods : list of module
        The provider modules of :mod:`volerr.derive.audit`.
    verdicts : list of Verdict
        Every verdict, provider by provider.
    """
    from volerr.derive.audit import providers

    mods = providers()
    known = set(layout_names())
    for m in mods:
        known |= set(getattr(m, "LAYOUTS", ()))
    for name in layouts or []:
        require(name in known, f"unknown layout {name!r}; audited layouts and shipped layouts: "
                               f"{' '.join(sorted(known))}")
    verdicts = []
    steps = progress(mods, desc="audit", unit="source") if progress else mods
    for m in steps:
        covered = getattr(m, "LAYOUTS", None)
        if layouts and covered is not None and not set(layouts) & set(covered):
            continue
        printed = data_file(m.DATA_FILE) if getattr(m, "DATA_FILE", None) else {}
        verdicts.extend(m.audit(printed, layouts or None))
    return mods, verdicts


def group(verdicts) -> list[Row]:
    """One row per (source, equation, layout), in first-seen order; ``verdict`` is
    ``identical``, ``differs`` (one component) or ``differs k/n`` -- ``unchecked`` instead of
    ``differs`` when every component that is not identical could not be compared."""
    rows: dict = {}
    unchecked: dict = {}
    for v in verdicts:
        key = (v.source, v.equation, v.layout)
        row = rows.setdefault(key, Row(v.source, v.equation, v.layout))
        row.n += 1
        if v.verdict != "identical":
            row.differs += 1
            unchecked[key] = unchecked.get(key, 0) + (v.verdict == "unchecked")
            tag = f"[{v.category}] {v.erratum}"
            row.errata.append(f"{v.component}: {tag}" if v.component else tag)
    for key, row in rows.items():
        word = "unchecked" if row.differs and unchecked.get(key) == row.differs else "differs"
        if row.differs == 0:
            row.verdict = "identical"
        elif row.n == 1:
            row.verdict = word
        else:
            row.verdict = f"{word} {row.differs}/{row.n}"
        row.erratum = "; ".join(row.errata)
    return list(rows.values())


def detail_rows(verdicts) -> list[Row]:
    """One row per verdict (component): the category (and component) as its verdict."""
    return [Row(v.source, v.equation, v.layout,
                verdict=v.category + (f" {v.component}" if v.component else ""),
                erratum=v.erratum) for v in verdicts]


def table(rows: list[Row], width: int = 110) -> str:
    """Fixed-width text table; long errata wrap under their column."""
    cols = [("source", "source"), ("eq", "equation"), ("layout", "layout"),
            ("verdict", "verdict")]
    widths = [max(len(h), *(len(str(getattr(r, k))) for r in rows)) for h, k in cols] \
        if rows else [len(h) for h, _ in cols]
    lead = sum(widths) + 2 * len(widths)
    lines = ["  ".join(h.ljust(w) for (h, _), w in zip(cols, widths)) + "  erratum"]
    lines.append("-" * (lead + 8))
    for r in rows:
        head = "  ".join(str(getattr(r, k)).ljust(w) for (_, k), w in zip(cols, widths)) + "  "
        parts = r.errata or [r.erratum]
        wrapped = [w for part in parts for w in
                   (textwrap.wrap(part, width=max(width - lead, 60),
                                  subsequent_indent="  ") or [""])] or [""]
        lines.append(head + wrapped[0])
        lines.extend(" " * lead + more for more in wrapped[1:])
    return "\n".join(lines)


def totals_line(verdicts) -> str:
    """``"N printed items audited: a identical, b differ (c of d components)."``"""
    rows = group(verdicts)
    n_diff = sum(1 for r in rows if r.verdict.startswith("differs"))
    n_unch = sum(1 for r in rows if r.verdict.startswith("unchecked"))
    return (f"{len(rows)} printed items audited: {len(rows) - n_diff - n_unch} identical, "
            f"{n_diff} differ ({sum(v.verdict == 'differs' for v in verdicts)} of "
            f"{len(verdicts)} components)" + (f", {n_unch} unchecked (inputs not printed)"
                                              if n_unch else "") + ".")


def numeric_table(layouts: list[str] | None, points: int) -> str:
    """Text table of :func:`volerr.audit.numeric.spot_check` for ``layouts`` (default: every
    layout with a printed equation) at ``points`` random points; differences in um."""
    from .numeric import printed_equations, spot_check
    from ..machine.model import load

    names = layouts or [n for n in layout_names() if printed_equations(n)]
    lines = ["numeric spot check: generated model vs printed equation, "
             f"{points} random points (max |difference|, um)",
             f"{'layout':7s} {'eq':4s} {'comp':5s} {'against':22s} {'max diff':>12s} "
             f"{'max value':>10s}  status"]
    for name in names:
        rows = spot_check(load(name), n=points)
        if not rows:
            lines.append(f"{name:7s} (no printed equation)")
        for r in rows:
            d = "n/a" if math.isnan(r["max_diff_um"]) else f"{r['max_diff_um']:.3g}"
            s = "n/a" if math.isnan(r["max_value_um"]) else f"{r['max_value_um']:.3g}"
            lines.append(f"{r['layout']:7s} {r['equation']:4s} {r['component']:5s} "
                         f"{r['against']:22s} {d:>12s} {s:>10s}  {r['status']}")
    return "\n".join(lines)
