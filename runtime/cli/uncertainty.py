"""``volerr uncertainty LAYOUT --task T.csv --evaluate E``: task-specific measurement
uncertainty by Monte Carlo (see ``volerr uncertainty --help``; the Python API
:func:`volerr.uncertainty`)."""

from __future__ import annotations

from ..choices import BIAS_MODES
from ._common import (add_error_arguments, add_html, add_identification_arguments, add_json,
                      add_plot, command_parser, identification_from_args, inputs_of,
                      layout_inputs, planned_outputs, write_outputs)


def register(sub) -> None:
    p = command_parser(sub, "uncertainty",
                       "task-specific uncertainty by Monte Carlo (virtual CMM)")
    p.add_argument("layout", help="layout name (volerr layouts) or layout file")
    p.add_argument("--task", required=True, metavar="CSV", help="probing points X,Y,Z[,i,j,k]"
                                                                 "[,Xp,Yp,Zp] mm")
    p.add_argument("--evaluate", required=True, metavar="E",
                   help="distance, circle, sphere or plane")
    add_error_arguments(p, required=False)
    p.add_argument("--table-std", choices=("systematic", "repeatability"), default="systematic",
                   help="how the tables' _std columns are drawn.  systematic: as what _std is "
                        "('volerr formats tables'), the standard uncertainty of the tabulated "
                        "value, one perturbed error function per machine.  repeatability: for "
                        "old tables whose _std held a single-reading scatter, drawn "
                        "independently per probing point")
    p.add_argument("--repeatability", action="store_true",
                   help="also draw the tables' _s columns (repeatability of one reading) "
                        "independently at every probing point (the machine's scatter during "
                        "the task; an identify table's _s holds the tracker's scatter too)")
    p.add_argument("--bias", choices=BIAS_MODES, default="corrected",
                   help="corrected: state the estimate minus the bias of the known errors, "
                        "with U; uncorrected: the reading, with an interval widened to "
                        "contain the bias")
    p.add_argument("--correlation-mm", type=float, default=0.0, metavar="L",
                   help="correlation length of the node perturbations along an axis "
                        "(default 0: independent nodes)")
    p.add_argument("--spec", metavar="'E0=A+L/K'", help="ISO 10360-2 specification (A um, L mm, "
                   "K), optionally ',PFTU=P' um: constrained Monte Carlo")
    p.add_argument("--spec-acceptance", type=float, default=0.5, metavar="F",
                   help="fraction of prior candidates passing the test (sets the prior scale)")

    p.add_argument("--noise-um", type=float, default=0.0, metavar="S",
                   help="probing noise, standard deviation per point, um")
    p.add_argument("--probe-map", metavar="MAP.csv", help="probe error map of probe-cal "
                                                          "(needs i,j,k in the task)")
    for name, what in (("part-cte", "part expansion coefficient and its u, 1/K"),
                       ("part-dt", "part temperature - 20 C and its u, K"),
                       ("scale-cte", "scale expansion coefficient and its u, 1/K"),
                       ("scale-dt", "scale temperature - 20 C and its u, K")):
        p.add_argument(f"--{name}", nargs=2, type=float, metavar=("VALUE", "U"), help=what)
    p.add_argument("--temperature-compensated", action="store_true",
                   help="the CMM corrects the nominal expansion; only the uncertainties remain")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--samples", type=int, default=None, metavar="N",
                   help="number of Monte Carlo samples (default 10000)")
    g.add_argument("--adaptive", action="store_true",
                   help="adaptive Monte Carlo, JCGM 101 7.9 (--digits significant digits)")
    p.add_argument("--digits", type=int, default=2, help="significant digits of u for "
                                                        "--adaptive (default 2)")
    p.add_argument("--max-samples", type=int, default=1_000_000, metavar="N",
                   help="--adaptive: stop after this many samples even when not converged")
    p.add_argument("--seed", type=int, default=0, metavar="K",
                   help="seed of the random draws (same seed, same numbers)")
    p.add_argument("--chunks", type=int, default=1, metavar="M",
                   help="split the samples into M chunks (results identical for any M)")
    p.add_argument("--scheduler", choices=("none", "dask"), default="none",
                   help="none: chunks in this process; dask: on a dask cluster (pip install "
                        "'volerr[dask]')")
    p.add_argument("--scheduler-address", metavar="ADDR", help="an existing dask scheduler")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster workers (default 2)")
    p.add_argument("--contributions", type=int, default=2000, metavar="N",
                   help="samples per source for the one-at-a-time ranking (0: skip)")
    add_json(p, "the results")
    add_html(p, "the report (header, result statement, contributions, histogram and "
                "convergence plots)")
    add_plot(p, "the histogram with the coverage interval")
    add_identification_arguments(p)
    p.add_argument("--backend", choices=("numpy", "numba"), default="numpy",
                   help="evaluation of the samples: numpy (default) or the fused numba kernel "
                        "(pip install 'volerr[fast]'; 1-4 s to compile once, pays from ~1e8 "
                        "point evaluations; same values)")
    p.add_argument("--quiet", action="store_true",
                   help="print nothing (no progress, no result lines)")
    p.set_defaults(func=run)


def run(args) -> int:
    from pathlib import Path

    from ..uncertainty.api import uncertainty

    inputs = [Path(args.task)] + ([Path(args.probe_map)] if args.probe_map else [])
    inputs += (inputs_of(args) if args.errors else []) + layout_inputs(args.layout)
    outs = planned_outputs(args, inputs)
    ident = identification_from_args(args, inputs)
    pmap = None
    if args.probe_map:
        from ..probe import read_probe_map
        pmap = read_probe_map(args.probe_map)
    temps = {k: getattr(args, k) for k in ("part_cte", "part_dt", "scale_cte", "scale_dt")}
    res = uncertainty(
        args.layout, args.task, args.evaluate, errors=args.errors, method=args.method,
        degree=args.degree, extrapolate=args.extrapolate, spec=args.spec,
        noise_um=args.noise_um, table_std=args.table_std, repeatability=args.repeatability,
        correlation_mm=args.correlation_mm, spec_acceptance=args.spec_acceptance,
        probe_map=pmap, samples=args.samples, adaptive=args.adaptive, digits=args.digits,
        max_samples=args.max_samples, seed=args.seed, chunks=args.chunks,
        scheduler=args.scheduler, scheduler_address=args.scheduler_address,
        workers=args.workers, contributions=args.contributions, backend=args.backend,
        bias=args.bias, progress=not args.quiet, accept_implausible=args.accept_implausible,
        temperature_compensated=args.temperature_compensated, **temps)
    if not args.quiet:
        print(res.summary())
    with outs:
        write_outputs(args, outs, res, ident, inputs)
    return 0
