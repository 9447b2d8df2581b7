"""``volerr map LAYOUT --errors DIR``: volumetric error map over the working volume; see
``volerr map --help`` and :mod:`volerr.cmm.volmap` (the grid, the columns and the plots)."""

from __future__ import annotations

from ._common import (add_accept_implausible, add_common, add_identification_arguments,
                      command_parser, options_of, parse_at)


def register(sub) -> None:
    p, H = command_parser(sub, "map")
    add_common(p)
    p.add_argument("--grid", nargs="+", type=int, default=None, metavar="N", help=H["--grid"])
    p.add_argument("--out", metavar="CSV", help=H["--out"])
    p.add_argument("--plot", metavar="PNG", help="nominal vs actual grid, magnified")
    p.add_argument("--plot-random", metavar="PNG", help=H["--plot-random"])
    p.add_argument("--magnify", type=float, default=None, metavar="K", help=H["--magnify"])
    p.add_argument("--json", metavar="F", help="summary as JSON")
    p.add_argument("--approach", default=None, metavar="DIRS", help=H["--approach"])
    add_accept_implausible(p)
    add_identification_arguments(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..cmm.api import error_map
    from ..cmm.volmap import map_inputs
    from ..results import run_command

    res = error_map(args.layout, args.errors, probe=tuple(args.probe), at=parse_at(args.at),
                    **options_of(args, "grid volume approach method degree extrapolate "
                                       "accept_implausible magnify"))
    rnd_plot = res.random_plot_path(args.plot_random, args.plot)
    run_command(vars(args), map_inputs(args.layout, args.errors), lambda *_: res, first={
        "--out": args.out, "--plot": args.plot, "--plot-random": rnd_plot})
    print(res.summary({"map": args.out, "plot": args.plot, "random plot": rnd_plot,
                       "summary": args.json}))
    return 0
