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

from ._common import command_parser, layout_inputs, planned_outputs


def register(sub) -> None:
    p, H = command_parser(sub, "audit")
    p.add_argument("layouts", nargs="*", metavar="LAYOUT", help=H["layouts"])
    p.add_argument("--json", metavar="F", help="write the verdicts with evidence as JSON")
    p.add_argument("--html", metavar="F", help=H["--html"])
    p.add_argument("--detail", action="store_true",
                   help="one row per component (dX, RY2, the rule of dx(X) ...)")
    p.add_argument("--numeric", action="store_true",
                   help="also spot-check the generated models against the printed equations")
    p.add_argument("--points", type=int, default=200, help="points of the numeric spot check")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..audit import run as audit_run  # the capability: when the command runs
    from ..audit.api import audit
    from ..progress import progress

    inputs = [q for item in args.layouts or [] for q in layout_inputs(item)]
    outs = planned_outputs(args, inputs + audit_run.data_paths())
    res = audit(args.layouts, detail=args.detail, numeric=args.numeric, points=args.points,
                progress=progress)
    with outs:
        if args.json:
            res.write_json(outs.path("--json"))
        if args.html:
            res.write_html(outs.path("--html"))
    print(res.summary(evidence=[args.json, args.html]))
    return 0
