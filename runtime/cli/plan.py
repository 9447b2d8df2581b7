"""``volerr plan LAYOUT --instrument SPEC --readings N --out DIR``: design a measurement campaign;
see ``volerr plan --help``."""

from __future__ import annotations

from ._common import (add_force, add_report_options, command_parser, identification_from_args,
                      layout_inputs, planned_outputs, write_certificates)


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


def run(args) -> int:
    from ..plan.api import check_plan_folder, check_options, plan

    check_options(args.readings, args.minutes, args.parameters, args.dialect)
    inputs = layout_inputs(args.layout)
    check_plan_folder(args.out, args.force)
    outs = planned_outputs(args, inputs, **{"--out": (args.out, None)})
    ident = identification_from_args(args, inputs)
    with outs:
        result = plan(args.layout, args.instrument, args.readings, parameters=args.parameters,
                      minutes=args.minutes, criterion=args.criterion, seed=args.seed)
        result.write(outs.path("--out"), outs.path("--json"), outs.path("--html"), inputs,
                     args.dialect)
        write_certificates(outs, result, ident, inputs)
    print(result.summary())
    return 0
