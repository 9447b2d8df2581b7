"""``volerr loop LAYOUT FILE...``: close the loop on measured deviations or drift runs; see
``volerr loop --help``."""

from __future__ import annotations

from ._common import (add_errors_out, add_fit_switches, add_report_options, command_parser,
                      error_dir_names, identification_from_args, layout_inputs, planned_outputs,
                      write_errors_out, write_outputs)


def register(sub) -> None:
    p, H = command_parser(sub, "loop")
    p.add_argument("layout", help="layout name or layout file")
    p.add_argument("data", nargs="+", metavar="FILE", help=H["data"])
    add_report_options(p, "the report", "the report with figures", "the instruments")
    p.add_argument("--out-dir", metavar="DIR", help=H["--out-dir"])
    p.add_argument("--holdout-time", metavar="A:B", help=H["--holdout-time"])
    p.add_argument("--holdout-files", nargs="+", metavar="FILE", help=H["--holdout-files"])
    p.add_argument("--predictions-out", metavar="P.csv", help=H["--predictions-out"])
    p.add_argument("--differences", action="store_true", help=H["--differences"])
    add_errors_out(p, "the fitted error functions (effects removed)")
    add_fit_switches(p)
    p.add_argument("--seed", type=int, default=0, help="seed of the held-out split and folds")
    p.add_argument("--folds", type=int, help=H["--folds"])
    p.add_argument("--test-fraction", type=float, default=0.25, help=H["--test-fraction"])
    p.add_argument("--degree", type=int, help=H["--degree"])
    p.add_argument("--families", help=H["--families"])
    p.set_defaults(func=run)


def run(args) -> int:
    from .. import loop as api_loop
    from ..instruments import split_spec
    from ..machine.model import load

    inputs = [split_spec(d)[1] for d in list(args.data) + list(args.holdout_files or [])] \
        + layout_inputs(args.layout)
    model = load(args.layout)
    outs = planned_outputs(args, inputs, **{
        "--predictions-out": args.predictions_out,
        "--out-dir": (args.out_dir, [f"{model.name}_aug.toml", f"{model.name.lower()}_aug.py"]),
        "--errors-out": (args.errors_out, error_dir_names(model))})
    ident = identification_from_args(args, inputs)
    with outs:
        report = api_loop(
            args.layout, list(args.data), out_dir=outs.path("--out-dir"), seed=args.seed,
            folds=args.folds, test_fraction=args.test_fraction, degree=args.degree,
            families=args.families, holdout_time=args.holdout_time,
            holdout_files=list(args.holdout_files or []), differences=args.differences,
            inputs=inputs, accept_residual=args.accept_residual)
        if args.out_dir:    # the final paths, not staging (a new result)
            report = report.written_in(args.out_dir)
        if args.predictions_out:
            report.write_predictions(outs.path("--predictions-out"), inputs=inputs)
        write_errors_out(args, outs, report, inputs)
        write_outputs(args, outs, report, ident, inputs)
    print(report.summary())
    return 0
