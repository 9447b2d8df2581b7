"""``volerr audit [LAYOUT...] [--json F] [--html F] [--detail] [--numeric]``: printed vs derived.

Every provider of :data:`volerr.derive.audit.PROVIDERS` audits its source document: the command
reads the provider's data file (``volerr/derive/audit/data/<DATA_FILE>``, the printed equations
kept as printed) and passes it on. Output: a table with one row per printed equation (source,
equation, layout, verdict, erratum) on stdout; ``--detail`` gives one row per component; ``--json
F`` writes the list of verdicts with their evidence; ``--html F`` one page with a section per
source document (rendered math, category, evidence). Every verdict has a category (identical,
printing_error, extraction, convention, simplification, undecidable); the summary line counts them.
Finding errata is the purpose, so the exit code is 0 when errata are found; 2 for bad input
(unknown layout ...). ``--numeric`` also spot-checks the generated models numerically against the
printed equations of their layouts (no derivation involved).
"""

from __future__ import annotations


from ..errors import require
from ..fileio import json_text, write_text


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


def run(args) -> int:
    from ..audit import run as audit_run  # the capability: when the command runs
    from ..audit import summary_line
    from ._common import layout_inputs, progress
    from ..fileio import Outputs

    require(args.points >= 1, "--points must be at least 1")
    inputs = [q for item in args.layouts or [] for q in layout_inputs(item)]
    inputs += audit_run.data_paths()
    outs = Outputs(inputs).file("--json", args.json).file("--html", args.html).check()
    args.layouts = audit_run.resolve_layouts(args.layouts)
    mods, verdicts = audit_run.collect(args.layouts, progress=progress)
    entries = [v.as_dict() for v in verdicts]
    files = {}
    if args.json:
        files["--json"] = json_text(entries, indent=1, ensure_ascii=False)
    if args.html:
        from ..audit import render_html

        files["--html"] = render_html(entries)
    with outs:
        for role, text in files.items():
            write_text(outs.path(role), text, inputs=audit_run.data_paths(mods))
    rows = audit_run.detail_rows(verdicts) if args.detail else audit_run.group(verdicts)
    print(audit_run.table(rows))
    print("\n" + audit_run.totals_line(verdicts))
    print(summary_line(entries) + "."
          + (f" Evidence: {', '.join(p for p in (args.json, args.html) if p)}" if files
             else " Evidence: --json F, --html F"))
    if args.numeric:
        print()
        print(audit_run.numeric_table(args.layouts or None, args.points))
    return 0
