"""``volerr uncertainty LAYOUT --task T.csv --evaluate E --json F``: task-specific measurement
uncertainty by Monte Carlo (virtual CMM, ISO/TS 15530-4; JCGM 101).

Machine knowledge: identified error tables with their std / u95 columns (--errors), or a
specification only (--spec "E0=A+L/K", constrained Monte Carlo), plus probing noise
(--noise-um), a probe error map (--probe-map) and temperature.  With only --noise-um the
machine is perfect and the noise independent per point.  Reports the result corrected for the
bias of the known errors (or, with --bias uncorrected, the reading with an interval that
contains the bias), u, U (k = 2) and the 95 % coverage interval.  Models and conventions:
volerr.uncertainty.
"""

from __future__ import annotations

from pathlib import Path

from ._common import (add_error_arguments, add_html, add_identification_arguments, add_json,
                      add_plot, identification_from_args, write_certificates)
from ..errors import require
from ..fileio import Outputs, write_bytes
from ..choices import BIAS_MODES


def register(sub) -> None:
    p = sub.add_parser("uncertainty", help="task-specific uncertainty by Monte Carlo (virtual CMM)",
                       description=__doc__.split("\n\n")[1].replace("``", ""))
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


#: captions of the report's figures
def _temperature(args):
    from ..uncertainty import ensemble
    from ..units import check_cte

    vals = {k: getattr(args, k) for k in ("part_cte", "part_dt", "scale_cte", "scale_dt")}
    if all(v is None for v in vals.values()):
        return None
    kw = {}
    for k, v in vals.items():
        v = v or (0.0, 0.0)
        require(all(abs(x) < 1e3 for x in v) and v[1] >= 0,
                f"--{k.replace('_', '-')}: value and a non-negative u")
        if k.endswith("cte"):   # in 1/K: 11.5 (ppm/K typed) refused, naming the unit
            check_cte(v[0], f"--{k.replace('_', '-')}", "1/K")
        kw[k], kw[f"u_{k}"] = float(v[0]), float(v[1])
    return ensemble.Temperature(**kw, compensated=args.temperature_compensated)


def _check_options(args) -> None:
    """Option values first, before any file is read or anything is decided."""
    import math

    def finite(v):
        return v is not None and math.isfinite(v)

    require(finite(args.noise_um) and args.noise_um >= 0, "--noise-um must be >= 0")
    require(finite(args.correlation_mm) and args.correlation_mm >= 0,
            "--correlation-mm must be >= 0")
    require(finite(args.spec_acceptance) and 0 < args.spec_acceptance < 1,
            "--spec-acceptance must lie in (0, 1)")
    require(args.samples is None or 2 <= args.samples <= 10**8,
            "--samples must be between 2 and 1e8")
    require(1 <= args.digits <= 4, "--digits must be between 1 and 4")
    require(args.max_samples >= 2, "--max-samples must be >= 2")
    require(args.seed >= 0, "--seed must be a non-negative integer")
    require(args.chunks >= 1, "--chunks must be >= 1")
    require(args.workers >= 1, "--workers must be >= 1")
    require(0 <= args.contributions <= 10 ** 6, "--contributions must be between 0 and 1e6")
    require(args.max_samples <= 10 ** 9, "--max-samples must be at most 1e9")
    _temperature(args)  # validates the temperature options


def run(args) -> int:
    from ..machine.model import load  # the capability: when the command runs
    from ..uncertainty import tasks
    from ..uncertainty.api import uncertainty
    from ._common import inputs_of, layout_inputs

    _check_options(args)
    require(args.evaluate in tasks.EVALUATIONS, f"unknown evaluation {args.evaluate!r} "
                                                f"(one of {', '.join(tasks.EVALUATIONS)})")
    load(args.layout)
    inputs = [Path(args.task)] + ([Path(args.probe_map)] if args.probe_map else [])
    if args.errors:
        inputs += inputs_of(args)
    inputs += layout_inputs(args.layout)
    outs = Outputs(inputs).file("--json", args.json).file("--html", args.html) \
        .plot("--plot", args.plot).file("--pdf", args.pdf).check()
    ident = identification_from_args(args, inputs)
    pmap = None
    if args.probe_map:
        from ..probe import read_probe_map
        pmap = read_probe_map(args.probe_map)
    res = uncertainty(
        args.layout, args.task, args.evaluate, errors=args.errors, method=args.method,
        degree=args.degree, extrapolate=args.extrapolate, spec=args.spec,
        noise_um=args.noise_um, table_std=args.table_std, repeatability=args.repeatability,
        correlation_mm=args.correlation_mm, spec_acceptance=args.spec_acceptance,
        temperature=_temperature(args), probe_map=pmap, samples=args.samples,
        adaptive=args.adaptive, digits=args.digits, max_samples=args.max_samples,
        seed=args.seed, chunks=args.chunks, scheduler=args.scheduler,
        scheduler_address=args.scheduler_address, workers=args.workers,
        contributions=args.contributions, backend=args.backend, bias=args.bias,
        progress=not args.quiet, accept_implausible=args.accept_implausible)
    if not args.quiet:
        print(res.summary())
    with outs:
        if args.json:
            res.write_json(outs.path("--json"), inputs)
        if args.plot:
            from ..uncertainty import plots
            write_bytes(outs.path("--plot"), plots.histogram_png(
                res.values, res.names, res.summary_stats, res.title), inputs)
        if args.html:
            res.write_html(outs.path("--html"), inputs)
        write_certificates(outs, res, ident, inputs)
    return 0
