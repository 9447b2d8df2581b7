"""``volerr uncertainty``: task uncertainty by Monte Carlo (:func:`volerr.uncertainty`)."""

from __future__ import annotations

from ..choices import BIAS_MODES
from ._common import (add_error_arguments, add_html, add_identification_arguments, add_json,
                      add_plot, command_parser, identification_from_args, inputs_of,
                      layout_inputs, options_of, planned_outputs, write_outputs)


def register(sub) -> None:
    p, _ = command_parser(sub, "uncertainty")
    a = p.add_argument
    a("layout", help="layout name (volerr layouts) or layout file")
    a("--task", required=True, metavar="CSV", help="probing points X,Y,Z[,i,j,k][,Xp,Yp,Zp] mm")
    a("--evaluate", required=True, metavar="E", help="distance, circle, sphere or plane")
    add_error_arguments(p, required=False)
    a("--table-std", choices=("systematic", "repeatability"), default="systematic", help="how the "
      "tables' _std columns are drawn (below)")
    a("--repeatability", action="store_true", help="also draw the tables' _s columns (below)")
    a("--bias", choices=BIAS_MODES, default="corrected",
      help="the result corrected for the bias of the known errors, or not (below)")
    a("--correlation-mm", type=float, default=0.0, metavar="L",
      help="correlation length of the node perturbations along an axis (0: independent nodes)")
    a("--spec", metavar="'E0=A+L/K'", help="ISO 10360-2 specification (A um, L mm, K), "
                                           "optionally ',PFTU=P' um: constrained Monte Carlo")
    a("--spec-acceptance", type=float, default=0.5, metavar="F",
      help="fraction of prior candidates passing the test (sets the prior scale)")
    a("--noise-um", type=float, default=0.0, metavar="S",
      help="probing noise, standard deviation per point, um")
    a("--probe-map", metavar="MAP.csv", help="probe-cal's error map (needs i,j,k in the task)")
    for name, what in (("part-cte", "part expansion coefficient and its u, 1/K"),
                       ("part-dt", "part temperature - 20 C and its u, K"),
                       ("scale-cte", "scale expansion coefficient and its u, 1/K"),
                       ("scale-dt", "scale temperature - 20 C and its u, K")):
        a(f"--{name}", nargs=2, type=float, metavar=("VALUE", "U"), help=what)
    a("--temperature-compensated", action="store_true",
      help="the CMM corrects the nominal expansion; only the uncertainties remain")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--samples", type=int, metavar="N", help="Monte Carlo samples (default 10000)")
    g.add_argument("--adaptive", action="store_true",
                   help="adaptive Monte Carlo, JCGM 101 7.9 (--digits significant digits)")
    a("--digits", type=int, default=2, help="significant digits of u for --adaptive")
    a("--max-samples", type=int, default=1_000_000, metavar="N",
      help="--adaptive: stop after this many samples even when not converged")
    a("--seed", type=int, default=0, metavar="K", help="seed of the random draws (reproducible)")
    a("--chunks", type=int, default=1, metavar="M",
      help="split the samples into M chunks (results identical for any M)")
    a("--scheduler", choices=("none", "dask"), default="none", help="where the chunks run (below)")
    a("--scheduler-address", metavar="ADDR", help="an existing dask scheduler")
    a("--workers", type=int, default=2, help="LocalCluster workers")
    a("--contributions", type=int, default=2000, metavar="N",
      help="samples per source for the one-at-a-time ranking (0: skip)")
    add_json(p, "the results")
    add_html(p, "the report (result, contributions, histogram and convergence plots)")
    add_plot(p, "the histogram with the coverage interval")
    add_identification_arguments(p)
    a("--backend", choices=("numpy", "numba"), default="numpy",
      help="evaluation of the samples: numpy or the fused numba kernel (below; same values)")
    a("--quiet", action="store_true", help="print nothing (no progress, no result lines)")
    p.set_defaults(func=run)


def run(args) -> int:
    from pathlib import Path

    from ..probe import read_probe_map
    from ..uncertainty.api import uncertainty

    inputs = [Path(f) for f in (args.task, args.probe_map) if f]
    inputs += (inputs_of(args) if args.errors else []) + layout_inputs(args.layout)
    outs = planned_outputs(args, inputs)
    ident = identification_from_args(args, inputs)
    res = uncertainty(**options_of(
        args, "layout task evaluate errors method degree extrapolate spec noise_um table_std "
              "repeatability correlation_mm spec_acceptance samples adaptive digits "
              "max_samples seed chunks scheduler scheduler_address workers contributions "
              "backend bias accept_implausible", progress=not args.quiet,
        probe_map=read_probe_map(args.probe_map) if args.probe_map else None,
        temperature=options_of(args, "part_cte part_dt scale_cte scale_dt",
                               compensated=args.temperature_compensated)))
    if not args.quiet:
        print(res.summary())
    with outs:
        write_outputs(args, outs, res, ident, inputs)
    return 0
