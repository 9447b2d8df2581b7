"""``volerr audit [LAYOUT...] [--json F] [--html F] [--detail] [--numeric]``: printed vs derived
equations, a verdict and its category for each (docs/commands.md, ``volerr formats audit``).
Finding errata is the purpose: exit 0 when errata are found, 2 for bad input (unknown layout)."""

from __future__ import annotations

from ..fileio import planned_outputs
from ._common import command_parser


def register(sub) -> None:
    p, H = command_parser(sub, "audit")
    p.add_argument("layouts", nargs="*", metavar="LAYOUT", help=H["layouts"])
    p.add_argument("--json", metavar="F", help="write the verdicts with evidence as JSON")
    p.add_argument("--html", metavar="F", help=H["--html"])
    p.add_argument("--detail", action="store_true", help=H["--detail"])
    p.add_argument("--numeric", action="store_true", help=H["--numeric"])
    p.add_argument("--points", type=int, default=200, help="points of the numeric spot check")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..audit import run as audit_run  # the capability: when the command runs
    from ..audit.api import audit
    from ..fileio import layout_inputs
    from ..progress import progress

    inputs = [q for item in args.layouts or [] for q in layout_inputs(item)]
    outs = planned_outputs(vars(args), inputs + audit_run.data_paths())
    res = audit(args.layouts, detail=args.detail, numeric=args.numeric, points=args.points,
                progress=progress)
    with outs:
        res.write_files(outs, vars(args), roles=("json", "html"))
    print(res.summary(evidence=[args.json, args.html]))
    return 0
