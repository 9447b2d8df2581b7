"""``volerr tcpmap``: five-axis tool-tip error over the rotary range (:func:`volerr.tcpmap`)."""

from __future__ import annotations

import sys
from pathlib import Path

from ..fileio import planned_outputs
from ._common import (add_error_arguments, add_plot, add_vector, command_parser, options_of,
                      progress_bar)


def register(sub) -> None:
    p, H = command_parser(sub, "tcpmap")
    p.add_argument("layout", help="five-axis layout name or file")
    add_error_arguments(p)
    add_vector(p, "--point", required=True, help=H["--point"])
    add_vector(p, "--tool", default=(0.0, 0.0, 0.0), help=H["--tool"])
    p.add_argument("--steps", type=int, default=73, help="grid steps per rotary axis")
    add_plot(p, "the map", "--out", required=True)
    p.add_argument("--csv", metavar="F.csv", help="write the grid (CSV)")
    p.add_argument("--approach", metavar="DIRS", help=H["--approach"])
    p.set_defaults(func=run)


def run(args) -> int:
    from ..fileio import layout_inputs
    from ..fiveaxis.api import tcpmap

    inputs = [*Path(args.errors).glob("*.csv"), *layout_inputs(args.layout)]
    outs = planned_outputs(vars(args), inputs, **{"--csv": args.csv})
    with progress_bar(None, "tcpmap", total=args.steps * args.steps, unit="points") as tick:
        res = tcpmap(**options_of(args, "layout errors point tool steps approach method degree "
                                        "extrapolate accept_implausible",
                                  plot_name=args.plot, progress=tick))
    with outs:
        res.write_files(outs, vars(args), inputs, ("plot", "csv"))
    print(res.summary())
    for note in res.notes:    # after success: bad input gets exactly one line on stderr
        print(note, file=sys.stderr)
    return 0
