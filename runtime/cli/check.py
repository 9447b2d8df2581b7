"""``volerr check [plan] LAYOUT --reference CAL.json ...``: the interim check."""

from __future__ import annotations

from ..errors import require
from ._common import (add_fit_switches, add_max_change, add_report_options, command_parser,
                      help_text, identification_from_args, layout_inputs, planned_outputs,
                      write_certificates, write_outputs)

USAGE = help_text("check.usage").rstrip("\n")
#: options of one form only
PLAN_ONLY = ("instrument", "minutes", "readings", "detect_um", "out")
CHECK_ONLY = ("tolerance", "date", "max_change")


def register(sub) -> None:
    p, H = command_parser(sub, "check", usage=USAGE)
    p.add_argument("words", nargs="+", metavar="LAYOUT FILE", help=H["words"])
    p.add_argument("--reference", required=True, nargs="+", metavar=("CAL.json", "FILE"),
                   help=H["--reference"])
    p.add_argument("--instrument", action="append", metavar="SPEC", help=H["--instrument"])
    p.add_argument("--minutes", type=float, metavar="M", help=H["--minutes"])
    p.add_argument("--readings", type=int, metavar="N", help=H["--readings"])
    p.add_argument("--detect-um", type=float, metavar="D", help=H["--detect-um"])
    p.add_argument("--out", metavar="DIR", help="check plan: folder of the check's files")
    p.add_argument("--tolerance", metavar="T", help=H["--tolerance"])
    p.add_argument("--date", metavar="YYYY-MM-DD", help=H["--date"])
    add_report_options(p, H["--json"], H["--html"])
    add_fit_switches(p, implausible=False)
    add_max_change(p, reference=False)
    p.set_defaults(func=run)


def run(args) -> int:
    args.words = args.words + args.reference[1:]      # the files after --reference CAL.json
    args.reference = args.reference[0]
    plan = args.words[0] == "plan"
    require(not plan or len(args.words) == 2, "check plan: give one LAYOUT (usage: "
            + USAGE.split("\n")[0].strip() + ")")
    require(plan or len(args.words) >= 2, "give LAYOUT and the check's files (or 'check plan "
                                          "LAYOUT ...' to plan one)")
    form = "volerr check LAYOUT FILE..." if plan else "volerr check plan"
    for name in CHECK_ONLY if plan else PLAN_ONLY:
        require(getattr(args, name) is None, f"--{name.replace('_', '-')} belongs to '{form}'")
    return _plan(args) if plan else _check(args)


def _plan(args) -> int:
    from ..check import plan_check
    from ..check._plan import DEFAULT_DETECT_UM, check_plan_options
    from ..plan.api import check_plan_folder

    check_plan_options(args.instrument, args.readings, args.minutes, args.detect_um)
    require(args.out, "check plan: give --out DIR")
    inputs = layout_inputs(args.words[1]) + [args.reference]
    check_plan_folder(args.out, args.force, "check", (".csv", ".nc", ".html"))
    outs = planned_outputs(args, inputs, **{"--out": (args.out, None)})
    ident = identification_from_args(args, inputs[-1:] + inputs[:-1])
    with outs:
        result = plan_check(args.words[1], args.reference, args.instrument,
                            minutes=args.minutes, readings=args.readings,
                            detect_um=args.detect_um or DEFAULT_DETECT_UM)
        result.write(outs.path("--out"), outs.path("--json"), outs.path("--html"), inputs)
        write_certificates(outs, result, ident, inputs)
    print(result.summary())
    return 0


def _check(args) -> int:
    from ..check import check
    from ..instruments import split_spec

    files = [split_spec(f)[1] for f in args.words[1:]]
    inputs = layout_inputs(args.words[0]) + [args.reference] + files
    outs = planned_outputs(args, inputs)
    ident = identification_from_args(args, files + inputs)
    with outs:
        result = check(args.words[0], args.words[1:], reference=args.reference,
                       tolerance=args.tolerance, date=args.date,
                       accept_residual=args.accept_residual, max_change=args.max_change,
                       accept_change=args.accept_change)
        write_outputs(args, outs, result, ident, inputs)
    print(result.summary())
    return 0
