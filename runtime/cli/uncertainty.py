"""``volerr uncertainty``: task uncertainty by Monte Carlo (:func:`volerr.uncertainty`)."""

from __future__ import annotations

from pathlib import Path

from ..choices import BIAS_MODES
from ._common import (add_error_arguments, add_html, add_identification_arguments, add_json,
                      add_plot, command_parser, options_of)


def register(sub) -> None:
    p, H = command_parser(sub, "uncertainty")
    a = p.add_argument
    a("layout", help="layout name (volerr layouts) or layout file")
    a("--task", required=True, metavar="CSV", help="probing points X,Y,Z[,i,j,k][,Xp,Yp,Zp] mm")
    a("--evaluate", required=True, metavar="E", help="distance, circle, sphere or plane")
    add_error_arguments(p, required=False)
    a("--table-std", choices=("systematic", "repeatability"), default="systematic",
      help=H["--table-std"])
    a("--repeatability", action="store_true", help=H["--repeatability"])
    a("--bias", choices=BIAS_MODES, default="corrected", help=H["--bias"])
    a("--correlation-mm", type=float, default=0.0, metavar="L", help=H["--correlation-mm"])
    a("--spec", metavar="'E0=A+L/K'", help=H["--spec"])
    a("--spec-acceptance", type=float, default=0.5, metavar="F", help=H["--spec-acceptance"])
    a("--noise-um", type=float, default=0.0, metavar="S", help=H["--noise-um"])
    a("--probe-map", metavar="MAP.csv", help=H["--probe-map"])
    for name in ("part-cte", "part-dt", "scale-cte", "scale-dt"):
        a(f"--{name}", nargs=2, type=float, metavar=("VALUE", "U"), help=H[f"--{name}"])
    a("--temperature-compensated", action="store_true", help=H["--temperature-compensated"])
    g = p.add_mutually_exclusive_group()
    g.add_argument("--samples", type=int, metavar="N", help=H["--samples"])
    g.add_argument("--adaptive", action="store_true", help=H["--adaptive"])
    a("--digits", type=int, default=2, help=H["--digits"])
    a("--max-samples", type=int, default=1_000_000, metavar="N", help=H["--max-samples"])
    a("--seed", type=int, default=0, metavar="K", help=H["--seed"])
    a("--chunks", type=int, default=1, metavar="M", help=H["--chunks"])
    a("--scheduler", choices=("none", "dask"), default="none", help=H["--scheduler"])
    a("--scheduler-address", metavar="ADDR", help="an existing dask scheduler")
    a("--workers", type=int, default=2, help=H["--workers"])
    a("--contributions", type=int, default=2000, metavar="N", help=H["--contributions"])
    add_json(p, "the results")
    add_html(p, H["--html"])
    add_plot(p, "the histogram with the coverage interval")
    add_identification_arguments(p)
    a("--backend", choices=("numpy", "numba"), default="numpy", help=H["--backend"])
    a("--quiet", action="store_true", help="print nothing (no progress, no result lines)")
    p.set_defaults(func=run)


def run(args):
    from ..cmm.volmap import map_inputs
    from ..fileio import layout_inputs
    from ..probe import read_probe_map
    from ..results import run_command
    from ..uncertainty.api import uncertainty

    inputs = [Path(f) for f in (args.task, args.probe_map) if f]
    inputs += (map_inputs(args.layout, args.errors) if args.errors else []) \
        + layout_inputs(args.layout)
    res = run_command(vars(args), inputs, lambda *_: uncertainty(**options_of(
        args, "layout task evaluate errors method degree extrapolate spec noise_um table_std "
              "repeatability correlation_mm spec_acceptance samples adaptive digits "
              "max_samples seed chunks scheduler scheduler_address workers contributions "
              "backend bias accept_implausible", progress=not args.quiet,
        probe_map=read_probe_map(args.probe_map) if args.probe_map else None,
        temperature=options_of(args, "part_cte part_dt scale_cte scale_dt",
                               compensated=args.temperature_compensated))))
    return 0 if args.quiet else res
