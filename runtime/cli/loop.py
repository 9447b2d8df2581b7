"""``volerr loop LAYOUT DATA.csv --json F [--html F]``: close the loop on measured deviations.

Fits the declared model, traces what is left to candidate effects "parameter P of the chain
varies with covariate C" (thermal, drift, reversal, coupling, periodic, higher_order, step,
probe_direction, setup, group ...), writes the augmented layout and its
generated module (``--out-dir``, default: the folder of the json report) and reports the error
before and after on held-out points.  See :mod:`volerr.loop.run`.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import require
from ..fileio import Outputs
from ._common import add_errors_out, add_force, add_html, add_json


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
    p.add_argument("--out-dir", metavar="DIR",
                   help="folder for the augmented layout and its generated module (not given: "
                        "the folder of --json or --html; neither: not written)")
    add_errors_out(p, "the fitted error functions (effects removed)")
    add_force(p)
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


def loop_lines(e: dict) -> list:
    """Console lines of an effect's lag and of the explanations the data cannot tell from it."""
    out = []
    lag = e.get("lag_s")
    if lag:
        std = f" +- {lag['std']:.0f}" if lag.get("std") is not None else ""
        out.append(f"through a first-order lag of {e['covariate']}: tau = {lag['value']:.0f}"
                   f"{std} s ({lag['value'] / 60:.1f} min)")
    for a in e.get("alternatives") or []:
        lag_a = f" through a lag of {a['lag_s']:.0f} s" if a.get("lag_s") else ""
        out.append(f"these data cannot tell it from {a['parameter']} x {a['covariate']}"
                   f"{lag_a} (held-out RMS {a['held_out_rms_um']:.3f} um)")
    if e.get("separate_by"):
        out.append(f"would separate them: {e['separate_by']}")
    return out


def run(args) -> int:
    from ..loop import candidates
    from ..loop.run import run_loop

    from ._common import layout_inputs
    from ..machine.model import load

    from ..instruments import split_spec

    inputs = [split_spec(d)[1] for d in args.data] + layout_inputs(args.layout)
    model = load(args.layout)
    aug = (f"{model.name}_aug.toml", f"{model.name.lower()}_aug.py")
    # as the user named it (no resolve): the report names the files where they end up
    out_dir = (Path(args.out_dir) if args.out_dir else
               Path(args.json or args.html).parent if (args.json or args.html) else None)
    # named in messages: the option, or where its default put the folder
    OUT_DIR = "--out-dir" if args.out_dir else "--out-dir (not given: the report's folder)"
    outs = Outputs(inputs, force=args.force).file("--json", args.json).file("--html", args.html) \
        .folder(OUT_DIR, out_dir, files=aug) \
        .folder("--errors-out", args.errors_out,
                files=[f"{a}.csv" for a in model.axes] + ["constants.csv"]).check()
    families = candidates.FAMILIES
    if args.families:
        families = tuple(f.strip() for f in args.families.split(",") if f.strip())
        bad = [f for f in families if f not in candidates.FAMILIES]
        require(not bad, f"unknown family {bad[0] if bad else ''!r}; families are "
                f"{' '.join(candidates.FAMILIES)}")
    with outs:
        staged = outs.path(OUT_DIR)
        data = args.data[0] if len(args.data) == 1 else args.data
        report = run_loop(args.layout, data, seed=args.seed, folds=args.folds,
                          test_fraction=args.test_fraction, degree=args.degree,
                          out_dir=staged, families=families, inputs=inputs)
        for key in ("augmented_layout", "generated_module"):  # the final paths, not staging
            if report.data.get(key):
                report.data[key] = str(out_dir / Path(report.data[key]).name)
        if args.json:
            report.write_json(outs.path("--json"), inputs=inputs)
        if args.html:
            report.write_html(outs.path("--html"), inputs=inputs)
        if args.errors_out:
            report.write_error_tables(outs.path("--errors-out"), inputs=inputs)
    for w in report["warnings"]:
        print(f"  warning: {w}")
    print(report.summary())
    for e in report.effects:
        pars = ", ".join(f"{k} = {v:.4g} {e['units'][k]}" for k, v in e["parameters"].items())
        print(f"  {e['kind']} {e['name']}: {pars}")
        for line in loop_lines(e):
            print(f"    {line}")
    if report["augmented_layout"]:
        print(f"  augmented layout: {report['augmented_layout']}; generated module: "
              f"{report['generated_module']}")
    if report["residual_note"]:
        print(f"  {report['residual_note']}")
    hidden = [u["parameters"][0] for u in report["unidentifiable"]
              if not (u["parameters"][0].startswith("setup.") and u.get("no_sensitivity"))]
    if hidden:
        print(f"  not separable by these data: {', '.join(hidden)} (see the report)")
    return 0
