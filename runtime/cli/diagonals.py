"""``volerr diagonals LAYOUT --errors DIR``: length deviations of the space diagonals (Pahk
sec. 4), face diagonals and axis-parallel lines of the working volume.

Prints a table in um (with standard deviations in the tables also the random component u(dL),
k = 1), optionally writes ``--json`` (with the profiles along each line) and ``--plot``.
Definitions and the propagation assumption: :mod:`volerr.cmm.diagonals`.
"""

from __future__ import annotations


from ._common import (add_accept_implausible, add_common, error_functions_from_args,
                      inputs_of, parse_at)
from ..errors import require
from ..fileio import Outputs
from ..choices import DIAGONAL_KINDS


def register(sub) -> None:
    p = sub.add_parser("diagonals", help="space diagonals, face diagonals and axis-parallel "
                                         "lines of the working volume (length deviations)",
                       description=__doc__.split("\n\n")[1].replace("``", ""))
    add_common(p)
    p.add_argument("--lines", nargs="+", choices=DIAGONAL_KINDS, default=list(DIAGONAL_KINDS),
                   help="which lines: space diagonals, face diagonals, axis-parallel "
                        "lines")
    p.add_argument("--profile-points", type=int, default=21, metavar="N",
                   help="points along each line for the profile (default 21)")
    p.add_argument("--json", metavar="F", help="results with profiles as JSON")
    p.add_argument("--plot", metavar="PNG", help="space-diagonal profiles and all deviations")
    add_accept_implausible(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..cmm import api, diagonals  # the capability: when the command runs
    from ..machine.model import load

    require(2 <= args.profile_points <= 10000, "--profile-points must be between 2 and 10000")
    model = load(args.layout)
    funcs = error_functions_from_args(args, model)
    inputs = inputs_of(args)
    outs = Outputs(inputs).file("--json", args.json).plot("--plot", args.plot).check()
    res = api.diagonals(model, funcs, lines=args.lines, probe=tuple(args.probe),
                        at=parse_at(args.at), volume=args.volume,
                        profile_points=args.profile_points, method=args.method)
    print(res.summary())
    with outs:
        if args.json:
            res.write_json(outs.path("--json"), inputs)
        if args.plot:
            diagonals.plot_lines(res.lines, outs.path("--plot"),
                                 f"{model.name}: length deviations ({args.errors})", inputs)
    if args.json:
        print(f"json: {args.json}")
    if args.plot:
        print(f"plot: {args.plot}")
    return 0
