"""``volerr loop LAYOUT FILE...``: close the loop on measured deviations or drift runs; see
``volerr loop --help``."""

from __future__ import annotations

from ._common import (add_errors_out, add_fit_switches, add_report_options, command_parser,
                      options_of)


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


def run(args):
    from .. import loop as api_loop
    from ..fileio import layout_inputs
    from ..instruments import split_spec
    from ..machine.model import load
    from ..results import run_command
    from ..tables.table import error_dir_names

    holdout = list(args.holdout_files or [])
    inputs = [split_spec(d)[1] for d in list(args.data) + holdout] + layout_inputs(args.layout)
    model = load(args.layout)

    def call(outs, _):
        report = api_loop(args.layout, list(args.data), **options_of(
            args, "seed folds test_fraction degree families holdout_time differences "
                  "accept_residual", out_dir=outs.path("--out-dir"), holdout_files=holdout,
            inputs=inputs))     # with --out-dir: the final paths, not staging (a new result)
        return report.written_in(args.out_dir) if args.out_dir else report
    return run_command(vars(args), inputs, call, **{
        "--predictions-out": args.predictions_out,
        "--out-dir": (args.out_dir, [f"{model.name}_aug.toml", f"{model.name.lower()}_aug.py"]),
        "--errors-out": (args.errors_out, error_dir_names(model.axes))})
