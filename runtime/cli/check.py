"""``volerr check [plan] LAYOUT --reference CAL.json ...``: the interim check."""

from __future__ import annotations

from ._common import (add_fit_switches, add_max_change, add_report_options, command_parser,
                      help_text, options_of)

USAGE = help_text("check.usage").rstrip("\n")


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


def run(args):
    from ..check._run import command_form

    plan, args.words, args.reference = command_form(args.words, args.reference, vars(args))
    return _plan(args) if plan else _check(args)


def _plan(args):
    from ..check import plan_check
    from ..check._plan import DEFAULT_DETECT_UM, check_plan_options
    from ..fileio import layout_inputs
    from ..results import run_command

    check_plan_options(args.instrument, args.readings, args.minutes, args.detect_um, args.out,
                       args.force)
    inputs = layout_inputs(args.words[1]) + [args.reference]
    return run_command(vars(args), inputs, lambda *_: plan_check(
        args.words[1], args.reference, args.instrument, **options_of(
            args, "minutes readings", detect_um=args.detect_um or DEFAULT_DETECT_UM)),
        ident_files=inputs[-1:] + inputs[:-1], **{"--out": (args.out, None)})


def _check(args):
    from ..check import check
    from ..fileio import layout_inputs
    from ..instruments import split_spec
    from ..results import run_command

    files = [split_spec(f)[1] for f in args.words[1:]]
    inputs = layout_inputs(args.words[0]) + [args.reference] + files
    return run_command(vars(args), inputs, lambda *_: check(args.words[0], args.words[1:], **(
        options_of(args, "reference tolerance date accept_residual max_change accept_change"))),
        ident_files=files + inputs)
