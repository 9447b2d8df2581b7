"""``volerr compensate LAYOUT PROGRAM --errors DIR --out F``: compensated NC program; see
``volerr compensate --help`` and :func:`volerr.compensate`."""

from __future__ import annotations

import sys
from pathlib import Path

from ._common import (add_error_arguments, add_identification_arguments, add_vector,
                      command_parser, options_of, progress_bar)


def register(sub) -> None:
    p, H = command_parser(sub, "compensate")
    p.add_argument("layout", help="layout name (see 'volerr layouts') or layout file")
    p.add_argument("program", help="G-code program in machine axis coordinates")
    p.add_argument("--out", required=True, help="compensated program (never the input)")
    add_error_arguments(p)
    p.add_argument("--strategy", choices=("full", "thesis"), default="full", help=H["--strategy"])
    p.add_argument("--orientation", action="store_true", help=H["--orientation"])
    p.add_argument("--types", default=None, help=H["--types"])
    add_vector(p, "--tool", default=(0.0, 0.0, 0.0), help=H["--tool"])
    p.add_argument("--tol-um", type=float, default=0.1, help=H["--tol-um"])
    p.add_argument("--decimals", type=int, default=4, help=H["--decimals"])
    p.add_argument("--initial", default=None, help=H["--initial"])
    p.add_argument("--ignore-travel", action="store_true", help=H["--ignore-travel"])
    p.add_argument("--arc-tolerance-um", type=float, default=1.0, metavar="T",
                   help=H["--arc-tolerance-um"])
    p.add_argument("--tool-length", type=float, default=None, metavar="MM",
                   help=H["--tool-length"])
    p.add_argument("--tool-table", default=None, metavar="CSV", help=H["--tool-table"])
    p.add_argument("--dialect", choices=("auto", "iso", "heidenhain"), default="auto",
                   help=H["--dialect"])
    p.add_argument("--decimal-less", choices=("auto", "mm"), default="auto",
                   help=H["--decimal-less"])
    p.add_argument("--datum", default="none", metavar="X,Y,Z[,B,C]", help=H["--datum"])
    p.add_argument("--report", help="per-block CSV report")
    p.add_argument("--json", help="summary as JSON")
    p.add_argument("--plot", help="PNG: predicted tool-tip error along the program")
    add_identification_arguments(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..fileio import layout_inputs
    from ..fiveaxis.api import compensate
    from ..results import run_command

    inputs = [args.program, *Path(args.errors).glob("*.csv"), *layout_inputs(args.layout),
              *([args.tool_table] if args.tool_table else [])]

    def call(outs, _):
        with progress_bar(Path(args.program), "compensate") as tick:
            return compensate(args.layout, Path(args.program), args.errors, **options_of(
                args, "datum tool_length tool_table orientation strategy types tol_um decimals "
                      "method degree extrapolate dialect accept_implausible decimal_less",
                tool=tuple(args.tool), initial=args.initial or "",
                check_travel=not args.ignore_travel, arc_tol_um=args.arc_tolerance_um,
                out=outs.path("--out"), report=outs.path("--report") if args.report else None,
                inputs=inputs, out_name=args.out, keep_errors=bool(args.plot), progress=tick))
    res = run_command(vars(args), inputs, call, first={"--out": args.out, "--report": args.report})
    print(res.summary())
    for note in res.notes:   # only after success: bad input gets one line on stderr
        print(note, file=sys.stderr)
    return 0
