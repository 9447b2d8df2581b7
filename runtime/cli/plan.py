"""``volerr plan LAYOUT --instrument SPEC --readings N --out DIR``: design a measurement campaign;
see ``volerr plan --help``."""

from __future__ import annotations

from ._common import add_force, add_report_options, command_parser, options_of


def register(sub) -> None:
    p, H = command_parser(sub, "plan")
    p.add_argument("layout", help="layout name (volerr layouts) or layout file")
    p.add_argument("--instrument", action="append", required=True, metavar="SPEC",
                   help=H["--instrument"])
    p.add_argument("--readings", type=int, required=True, metavar="N", help=H["--readings"])
    p.add_argument("--out", required=True, metavar="DIR", help=H["--out"])
    add_report_options(p, "the plan: predicted standard uncertainties, files, baseline",
                       "the set-up sheet (default: DIR/plan.html)")
    p.add_argument("--parameters", metavar="SPEC", help=H["--parameters"])
    p.add_argument("--minutes", type=float, metavar="M", help=H["--minutes"])
    p.add_argument("--criterion", choices=("I", "D"), default="I", help=H["--criterion"])
    p.add_argument("--dialect", default="iso", metavar="NAME", help=H["--dialect"])
    p.add_argument("--seed", type=int, default=0, help=H["--seed"])
    add_force(p)
    p.set_defaults(func=run)


def run(args):
    from ..fileio import layout_inputs
    from ..plan.api import check_options, plan
    from ..results import run_command

    check_options(args.readings, args.minutes, args.parameters, args.dialect, args.out,
                  args.force)
    return run_command(vars(args), layout_inputs(args.layout), lambda *_: plan(
        args.layout, args.instrument, args.readings, **options_of(
            args, "parameters minutes criterion seed")), **{"--out": (args.out, None)})
