"""``volerr diagonals LAYOUT --errors DIR``: length deviations of the space diagonals, face
diagonals and axis-parallel lines; see ``volerr diagonals --help`` and
:mod:`volerr.cmm.diagonals` (definitions, the propagation assumption)."""

from __future__ import annotations

from ..fileio import planned_outputs
from ._common import add_accept_implausible, add_common, command_parser, options_of, parse_at
from ..choices import DIAGONAL_KINDS


def register(sub) -> None:
    p, H = command_parser(sub, "diagonals")
    add_common(p)
    p.add_argument("--lines", nargs="+", choices=DIAGONAL_KINDS, default=list(DIAGONAL_KINDS),
                   help=H["--lines"])
    p.add_argument("--profile-points", type=int, default=21, metavar="N",
                   help="points along each line for the profile (default 21)")
    p.add_argument("--json", metavar="F", help="results with profiles as JSON")
    p.add_argument("--plot", metavar="PNG", help="space-diagonal profiles and all deviations")
    add_accept_implausible(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..cmm import api  # the capability: when the command runs
    from ..cmm.volmap import map_inputs

    res = api.diagonals(args.layout, args.errors, probe=tuple(args.probe), at=parse_at(args.at),
                        **options_of(args, "lines volume profile_points method degree "
                                           "extrapolate accept_implausible"))
    inputs = map_inputs(args.layout, args.errors)
    with planned_outputs(vars(args), inputs) as outs:
        res.write_files(outs, vars(args), inputs, roles=("plot", "json"))
    print(res.summary({"json": args.json, "plot": args.plot}))
    return 0
