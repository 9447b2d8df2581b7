"""``volerr loop LAYOUT DATA.csv --json F [--html F]``: close the loop on measured deviations.

Fits the declared model, traces what is left to candidate effects "parameter P of the chain
varies with covariate C" (thermal, drift, reversal, coupling, periodic, higher_order, step,
probe_direction, setup, group ...), writes the augmented layout and its
generated module where ``--out-dir`` says (not given: not written) and reports the error
before and after on held-out points.  See :mod:`volerr.loop.run`.

Drift runs (``drift:FILE`` or a file detected as one; ``volerr formats loop-lags``): the loop
on a position held while the machine heats and cools, ``--holdout-time`` / ``--holdout-files``
and ``--predictions-out``; see :mod:`volerr.loop.drift`.  The command checks its outputs,
calls :func:`volerr.loop` (the one entry for both kinds) and writes its result.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from ..fileio import Outputs
from ._common import (add_accept_implausible, add_accept_residual, add_errors_out, add_force,
                      add_html, add_identification_arguments, add_json,
                      identification_from_args, write_certificates)


def register(sub) -> None:
    p = sub.add_parser(
        "loop", help="fit measured deviations, find missing effects, augment the model",
        description="Fit LAYOUT's model to measured volumetric deviations (CSV: axis columns, "
                    "optional Xp,Yp,Zp, dx_um,dy_um,dz_um, covariates such as T_C, t_s, "
                    "dir_X, nx,ny,nz, setup), search candidate effects by forward stepwise "
                    "selection (BIC and cross-validated residual), augment the layout and "
                    "report RMS/max before and after on held-out points.  Logged temperatures "
                    "(T_<name>) with a time column (t_s, t_min, t_h) are also tried through a "
                    "first-order lag, its time constant estimated with its uncertainty "
                    "(lag_s); explanations the data cannot tell apart are named "
                    "(alternatives, separate_by): 'volerr formats loop-lags'.  LAYOUT may be "
                    "an augmented layout (*_aug.toml) written by an earlier run.")
    p.add_argument("layout", help="layout name or layout file")
    p.add_argument("data", nargs="+", metavar="FILE",
                   help="measurement files of any instruments (deviations, ballbar, sphere; "
                        "KIND:FILE to name the kind), one campaign")
    add_json(p, "the report")
    add_html(p, "the report with figures")
    add_identification_arguments(p, "the instruments")
    p.add_argument("--out-dir", metavar="DIR",
                   help="folder for the augmented layout and its generated module (not given: "
                        "not written)")
    p.add_argument("--holdout-time", metavar="A:B",
                   help="hold out the readings (points) with A <= t < B of the time column "
                        "(units s, min, h; an open end allowed: 100035s:); default: whole "
                        "stretches of time where there is a time column")
    p.add_argument("--holdout-files", nargs="+", metavar="FILE",
                   help="drift runs: hold out every run of these files")
    p.add_argument("--predictions-out", metavar="P.csv",
                   help="drift runs: CSV file,run,t_s,channel,measured_um,before_um,after_um,"
                        "split of every reading")
    p.add_argument("--differences", action="store_true",
                   help="drift runs: try differences of two sensors as well (off by default: "
                        "volerr formats loop-lags)")
    add_errors_out(p, "the fitted error functions (effects removed)")
    add_force(p)
    add_accept_residual(p)
    add_accept_implausible(p)
    p.add_argument("--seed", type=int, default=0, help="seed of the held-out split and folds")
    p.add_argument("--folds", type=int, help="k-fold cross-validation with this k (default: "
                                             "leave-one-point-out, exact via the hat matrix)")
    p.add_argument("--test-fraction", type=float, default=0.25,
                   help="fraction of points held out for before/after (default 0.25)")
    p.add_argument("--degree", type=int, help="degree of the component series (default: by "
                                              "cross-validation, 1..10)")
    p.add_argument("--families", help="comma list of candidate families to search (default: "
                                      "all)")
    p.set_defaults(func=run)


def run(args) -> int:
    """Check the outputs, call :func:`volerr.loop` (measured deviations or drift runs alike:
    it refuses the options that do not apply, one line), write the result, print its
    summary."""
    from .. import loop as api_loop
    from ..instruments import split_spec
    from ..machine.model import load
    from ._common import layout_inputs

    inputs = [split_spec(d)[1] for d in list(args.data) + list(args.holdout_files or [])] \
        + layout_inputs(args.layout)
    model = load(args.layout)
    aug = (f"{model.name}_aug.toml", f"{model.name.lower()}_aug.py")
    # as the user named it (no resolve): the report names the files where they end up
    out_dir = Path(args.out_dir) if args.out_dir else None
    OUT_DIR = "--out-dir"
    outs = Outputs(inputs, force=args.force).file("--json", args.json).file("--html", args.html) \
        .file("--pdf", args.pdf) \
        .file("--predictions-out", args.predictions_out).folder(OUT_DIR, out_dir, files=aug) \
        .folder("--errors-out", args.errors_out,
                files=[f"{a}.csv" for a in model.axes] + ["constants.csv"]).check()
    ident = identification_from_args(args, inputs)
    with outs:
        report = api_loop(args.layout, list(args.data), out_dir=outs.path(OUT_DIR),
                          seed=args.seed, folds=args.folds, test_fraction=args.test_fraction,
                          degree=args.degree, families=args.families,
                          holdout_time=args.holdout_time,
                          holdout_files=list(args.holdout_files or []),
                          differences=args.differences, inputs=inputs,
                          accept_residual=args.accept_residual)
        moved = {k: str(out_dir / Path(v).name) for k, v in report.data.items()
                 if k in ("augmented_layout", "generated_module") and v}
        if moved:       # the final paths, not staging (a new result)
            report = replace(report, data={**report.data, **moved})
        if args.predictions_out:
            report.write_predictions(outs.path("--predictions-out"), inputs=inputs)
        if args.errors_out:
            report.write_error_tables(outs.path("--errors-out"), inputs=inputs,
                                      accept_implausible=args.accept_implausible,
                                      shown=args.errors_out)
        if args.json:
            report.write_json(outs.path("--json"), inputs=inputs)
        if args.html:
            report.write_html(outs.path("--html"), inputs=inputs)
        write_certificates(outs, report, ident, inputs)
    print(report.summary())
    return 0
