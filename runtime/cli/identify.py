"""``volerr identify``: laser-tracker identification of an axis (:func:`volerr.identify`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ._common import (add_accept_implausible, add_accept_residual, add_force,
                      add_identification_arguments, add_json, add_plot, add_vector, command_parser,
                      options_of)


def register(sub) -> None:
    p, H = command_parser(sub, "identify")
    p.add_argument("layout", help="layout name or layout file")
    p.add_argument("files", nargs="+", metavar="FILE", help="tracker data file(s)")
    p.add_argument("--axis", required=True, help="the measured axis (X, Y, Z, B, C ...)")
    out = p.add_mutually_exclusive_group(required=True)
    out.add_argument("--errors-out", metavar="DIR", help=H["--errors-out"])
    out.add_argument("--out", metavar="F.csv", help=H["--out"])
    p.add_argument("--format", choices=("csv", "thesis"), default="csv", help=H["--format"])
    p.add_argument("--positions", help=H["--positions"])
    p.add_argument("--labels", dest="points", help=H["--labels"])
    p.add_argument("--points", dest="points", help=argparse.SUPPRESS)  # old name of --labels
    p.add_argument("--method", choices=("lsq", "closed"), default="lsq", help=H["--method"])
    add_vector(p, "--tracker", help=H["--tracker"])
    add_vector(p, "--direction", help=H["--direction"])
    p.add_argument("--origin", nargs="+", metavar="X", help=H["--origin"])
    p.add_argument("--sense", choices=("auto", "+", "-"), default="auto", help=H["--sense"])
    p.add_argument("--max-cond", type=float, default=1e4, help=H["--max-cond"])
    p.add_argument("--outlier-k", type=float, default=5.0, help=H["--outlier-k"])
    p.add_argument("--fit", choices=("poly", "smooth", "linear", "cubic"), help=H["--fit"])
    p.add_argument("--residuals", help="write per-position, per-point residuals (CSV, um)")
    p.add_argument("--signs", choices=("component", "model"), default="component",
                   help=H["--signs"])
    add_accept_implausible(p)
    add_json(p, "a summary")
    add_plot(p, "a plot of the error motions")
    add_force(p)
    add_accept_residual(p)
    add_identification_arguments(p, "the laser tracker")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..fileio import layout_inputs
    from ..identify.api import identify
    from ..identify.inputs import refuse_repeated_files
    from ..results import run_command

    inputs = list(args.files) + layout_inputs(args.layout)
    refuse_repeated_files(args.files)
    table = f"{args.axis.strip().upper()}.csv"
    res = run_command(vars(args), inputs, lambda *_: identify(
        args.layout, args.axis, args.files, **options_of(
            args, "format positions points method tracker direction origin sense max_cond "
                  "outlier_k signs accept_implausible accept_residual fit")), **{
        "--out": args.out, "--errors-out": (args.errors_out, [table]),
        "--residuals": args.residuals})
    print(res.summary(args.out or str(Path(args.errors_out) / table)))
    for line in res.notes:
        print(line, file=sys.stderr)
    return 0
