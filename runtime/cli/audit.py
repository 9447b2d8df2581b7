"""``volerr audit [LAYOUT...] [--json F] [--html F] [--detail] [--numeric]``: printed vs derived.

Every provider of :data:`volerr.derive.audit.PROVIDERS` that exists audits its source document:
the command reads the provider's data file (``volerr/data/<DATA_FILE>``, the printed equations
kept as printed) and passes it on.  Output: a table with one row per printed equation (source,
equation, layout, verdict, erratum) on stdout; ``--detail`` gives one row per component;
``--json F`` writes the list of verdicts with their evidence; ``--html F`` one page with a
section per source document (rendered math, category, evidence).  Every verdict has a category
(identical, printing_error, extraction, convention, simplification, undecidable); the summary
line counts them.  Finding errata is the purpose,
so the exit code is 0 when errata are found; 2 for bad input (unknown layout ...).
``--numeric`` also spot-checks the generated models numerically against the printed equations
of their layouts (no derivation involved).
"""

from __future__ import annotations

import json
import math
import textwrap
import tomllib
from importlib import resources

from pathlib import Path

from volerr.audit import summary_line
from volerr.errors import InputError, require
from volerr.fileio import write_text
from volerr.machine.layout import layout_names


def register(sub) -> None:
    p = sub.add_parser("audit", help="derived equations against the printed ones (errata)")
    p.add_argument("layouts", nargs="*", metavar="LAYOUT",
                   help="restrict to these layouts, by name or layout file (default: every "
                        "audited equation)")
    p.add_argument("--json", metavar="F", help="write the verdicts with evidence as JSON")
    p.add_argument("--html", metavar="F",
                   help="write one HTML page: a section per source document, rendered math, "
                        "category and evidence of every verdict (no network needed to view)")
    p.add_argument("--detail", action="store_true",
                   help="one row per component (dX, RY2, the rule of dx(X) ...)")
    p.add_argument("--numeric", action="store_true",
                   help="also spot-check the generated models against the printed equations")
    p.add_argument("--points", type=int, default=200, help="points of the numeric spot check")
    p.set_defaults(func=run)


def _data(name: str) -> dict:
    path = resources.files("volerr") / "data" / name
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"audit data file {name} is missing from the package") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"audit data file {name}: not valid TOML ({exc})") from None


def _data_paths(mods) -> list:
    out = []
    for m in mods:
        if getattr(m, "DATA_FILE", None):
            out.append(str(resources.files("volerr") / "data" / m.DATA_FILE))
    return out


def collect(layouts: list[str] | None):
    """All verdicts of all providers (imports sympy)."""
    from volerr.derive.audit import providers

    mods = providers()
    known = set(layout_names())
    for m in mods:
        known |= set(getattr(m, "LAYOUTS", ()))
    for name in layouts or []:
        require(name in known, f"unknown layout {name!r}; audited layouts and shipped layouts: "
                               f"{' '.join(sorted(known))}")
    from volerr.cli._common import progress

    verdicts = []
    for m in progress(mods, desc="audit", unit="source"):
        covered = getattr(m, "LAYOUTS", None)
        if layouts and covered is not None and not set(layouts) & set(covered):
            continue
        printed = _data(m.DATA_FILE) if getattr(m, "DATA_FILE", None) else {}
        verdicts.extend(m.audit(printed, layouts or None))
    return mods, verdicts


def group(verdicts) -> list[dict]:
    """One row per (source, equation, layout), in first-seen order."""
    rows: dict = {}
    for v in verdicts:
        key = (v.source, v.equation, v.layout)
        row = rows.setdefault(key, {"source": v.source, "equation": v.equation,
                                    "layout": v.layout, "n": 0, "differs": 0, "errata": []})
        row["n"] += 1
        if v.verdict != "identical":
            row["differs"] += 1
            tag = f"[{v.category}] {v.erratum}"
            row["errata"].append(f"{v.component}: {tag}" if v.component else tag)
    out = []
    for row in rows.values():
        if row["differs"] == 0:
            row["verdict"] = "identical"
        elif row["n"] == 1:
            row["verdict"] = "differs"
        else:
            row["verdict"] = f"differs {row['differs']}/{row['n']}"
        row["erratum"] = "; ".join(row["errata"])
        out.append(row)
    return out


def table(rows: list[dict], width: int = 110) -> str:
    """Fixed-width text table; long errata wrap under their column."""
    cols = [("source", "source"), ("eq", "equation"), ("layout", "layout"),
            ("verdict", "verdict")]
    widths = [max(len(h), *(len(str(r[k])) for r in rows)) for h, k in cols] if rows else \
        [len(h) for h, _ in cols]
    lead = sum(widths) + 2 * len(widths)
    lines = ["  ".join(h.ljust(w) for (h, _), w in zip(cols, widths)) + "  erratum"]
    lines.append("-" * (lead + 8))
    for r in rows:
        head = "  ".join(str(r[k]).ljust(w) for (_, k), w in zip(cols, widths)) + "  "
        parts = r.get("errata") or [r["erratum"]]
        wrapped = [w for part in parts for w in
                   (textwrap.wrap(part, width=max(width - lead, 60),
                                  subsequent_indent="  ") or [""])] or [""]
        lines.append(head + wrapped[0])
        lines.extend(" " * lead + more for more in wrapped[1:])
    return "\n".join(lines)


def numeric_table(layouts: list[str] | None, points: int) -> str:
    from volerr.audit.numeric import printed_equations, spot_check
    from volerr.machine.model import load

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


def _layout_names(items) -> list:
    """Layout names; a layout file counts as the layout it names (``name = ...``)."""
    import sys

    from volerr.machine.layout import read_layout

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


def run(args) -> int:
    from volerr.cli._common import layout_inputs
    from volerr.fileio import Outputs

    from volerr.derive.audit import providers

    require(args.points >= 1, "--points must be at least 1")
    inputs = [q for item in args.layouts or [] for q in layout_inputs(item)]
    inputs += _data_paths(providers())
    outs = Outputs(inputs).file("--json", args.json).file("--html", args.html).check()
    args.layouts = _layout_names(args.layouts)
    mods, verdicts = collect(args.layouts)
    entries = [v.as_dict() for v in verdicts]
    files = {}
    if args.json:
        files["--json"] = json.dumps(entries, indent=1, ensure_ascii=False) + "\n"
    if args.html:
        from volerr.audit import render_html

        files["--html"] = render_html(entries)
    with outs:
        for role, text in files.items():
            write_text(outs.path(role), text, inputs=_data_paths(mods))
    if args.detail:
        rows = [{"source": v.source, "equation": v.equation, "layout": v.layout,
                 "verdict": (v.category + (f" {v.component}" if v.component else "")),
                 "erratum": v.erratum} for v in verdicts]
    else:
        rows = group(verdicts)
    print(table(rows))
    n_eq = len(group(verdicts))
    n_diff = sum(1 for r in group(verdicts) if r["verdict"] != "identical")
    print(f"\n{n_eq} printed items audited: {n_eq - n_diff} identical, {n_diff} differ "
          f"({sum(v.verdict != 'identical' for v in verdicts)} of {len(verdicts)} components).")
    print(summary_line(entries) + "."
          + (f" Evidence: {', '.join(p for p in (args.json, args.html) if p)}" if files
             else " Evidence: --json F, --html F"))
    if args.numeric:
        print()
        print(numeric_table(args.layouts or None, args.points))
    return 0
