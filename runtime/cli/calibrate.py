"""``volerr calibrate LAYOUT FILE...``: a layout's parameters from any instruments' files; see
``volerr calibrate --help``."""

from __future__ import annotations

from ._common import (add_errors_out, add_fit_switches, add_max_change, add_report_options,
                      command_parser, options_of)


def register(sub) -> None:
    p, H = command_parser(sub, "calibrate")
    p.add_argument("layout", help="layout name (volerr layouts) or layout file")
    p.add_argument("files", nargs="+", metavar="FILE", help=H["files"])
    add_report_options(p, "the report (parameters, identifiability, set-ups, residuals per file)",
                       "the report with figures", "the instruments")
    add_errors_out(p, "the identified model (for map, compensate, uncertainty)")
    p.add_argument("--map-out", metavar="MAP.csv", help=H["--map-out"])
    p.add_argument("--map-grid", type=int, default=9, metavar="N", help=H["--map-grid"])
    add_fit_switches(p)
    add_max_change(p, reference=True)
    p.add_argument("--parameters", metavar="SPEC", help=H["--parameters"])
    p.add_argument("--degree", type=int, help=H["--degree"])
    p.add_argument("--seed", type=int, default=0, help="seed of the held-out split")
    p.add_argument("--test-fraction", type=float, default=0.25, help=H["--test-fraction"])
    p.set_defaults(func=run)


def run(args):
    from ..calibrate.mapping import grid_counts
    from ..calibrate.run import calibrate
    from ..fileio import layout_inputs
    from ..instruments import split_spec
    from ..machine.model import load
    from ..results import run_command
    from ..tables.table import error_dir_names

    grid_counts(args.map_grid)      # refused before anything else
    inputs = [split_spec(f)[1] for f in args.files] + layout_inputs(args.layout) \
        + ([args.reference] if args.reference else [])
    outputs = {"--map-out": args.map_out,
               "--errors-out": (args.errors_out, error_dir_names(load(args.layout).axes))}
    return run_command(vars(args), inputs, lambda *_: calibrate(args.layout, args.files, **(
        options_of(args, "parameters degree seed test_fraction accept_residual reference "
                         "max_change accept_change"))), **outputs)
