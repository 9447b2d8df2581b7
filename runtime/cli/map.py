"""``volerr map LAYOUT --errors DIR``: volumetric error map over the working volume; see
``volerr map --help`` and :mod:`volerr.cmm.volmap` (the grid, the columns and the plots)."""

from __future__ import annotations

from ._common import (add_accept_implausible, add_common, add_identification_arguments,
                      command_parser, identification_from_args, inputs_of, parse_at,
                      planned_outputs, write_outputs)


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
    from ..cmm.volmap import random_plot_path

    res = error_map(args.layout, args.errors, grid=args.grid, probe=tuple(args.probe),
                    at=parse_at(args.at), volume=args.volume, approach=args.approach,
                    method=args.method, degree=args.degree, extrapolate=args.extrapolate,
                    accept_implausible=args.accept_implausible, magnify=args.magnify)
    rnd_plot = args.plot_random or (random_plot_path(args.plot) if args.plot and
                                    res.has_random else None)
    inputs = inputs_of(args)
    outs = planned_outputs(args, inputs, first={"--out": args.out, "--plot": args.plot,
                                                "--plot-random": rnd_plot})
    ident = identification_from_args(args, inputs)
    with outs:
        if args.out:
            res.write_csv(outs.path("--out"), inputs)
        if rnd_plot:    # before write_outputs: the --json holds the magnifications
            res.write_random_plot(outs.path("--plot-random"), inputs)
        write_outputs(args, outs, res, ident, inputs)
    print(res.summary({"map": args.out, "plot": args.plot, "random plot": rnd_plot,
                       "summary": args.json}))
    return 0
