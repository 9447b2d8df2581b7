"""``volerr calibrate LAYOUT FILE... --json F``: identify a layout's parameters from the files of
any instruments (deviations, ballbar, sphere ...), mixed in one campaign.  See
:mod:`volerr.calibrate.run`."""

from __future__ import annotations

from ..errors import require
from ..fileio import Outputs
from ._common import (add_accept_implausible, add_accept_residual, add_errors_out, add_force,
                      add_html, add_identification_arguments, add_json, add_max_change,
                      identification_from_args, write_certificates)


def register(sub) -> None:
    p = sub.add_parser(
        "calibrate", help="identify the layout's parameters from instrument files (any mix)",
        description="Identify LAYOUT's parameters by weighted least squares from measurement "
                    "files of any instrument kind, in one campaign: 3-D deviations, ballbar "
                    "traces, sphere probing / R-test, artifacts (ball / hole plate, step "
                    "gauge), laser-interferometer runs, tracking-interferometer distances "
                    "('volerr formats deviations|ballbar|sphere|artifact|interferometer|"
                    "distances').  A file's kind is detected from its columns or given as "
                    "KIND:FILE.  Reports the identified values with standard uncertainties, "
                    "what the campaign cannot determine (and which file sees what), set-up "
                    "estimates per file and placement (artifact poses, station positions), "
                    "residuals per file on all and on held-out readings, the consistency of "
                    "every file with its stated uncertainty and with the others, the "
                    "volumetric error map with its uncertainty and the ISO 10360-2 length "
                    "errors of the identified model.")
    p.add_argument("layout", help="layout name (volerr layouts) or layout file")
    p.add_argument("files", nargs="+", metavar="FILE", help="measurement files (KIND:FILE to "
                   "name the kind: deviations, ballbar, sphere, artifact, interferometer, "
                   "distances)")
    add_json(p, "the report (parameters, identifiability, set-ups, residuals per file)")
    add_html(p, "the report with figures")
    add_identification_arguments(p, "the instruments")
    add_errors_out(p, "the identified model (for map, compensate, uncertainty)")
    p.add_argument("--map-out", metavar="MAP.csv", help="write the identified volumetric "
                   "error map over the measured range with its standard uncertainty "
                   "(dx_um ... u_dx_um ...)")
    p.add_argument("--map-grid", type=int, default=9, metavar="N",
                   help="points per linear axis of --map-out")
    add_force(p)
    add_accept_residual(p)
    add_accept_implausible(p)
    add_max_change(p, reference=True)
    p.add_argument("--parameters", metavar="SPEC",
                   help="parameters fitted, the others held at zero: comma list of names "
                        "(EC0Y, EX0C), terms as printed (EXX@slope, EZY@P2, EXC@cos1), "
                        "reversals (RV_X), axes (X: its six component errors) and groups "
                        "(all, constants, squareness, location, linear, rotary); default: "
                        "what each instrument kind of the campaign is used for, the union "
                        "for a mixed campaign ('volerr formats calibrate-json')")
    p.add_argument("--degree", type=int, help="degree of the component errors' Legendre series "
                                              "(default: by cross-validation, 1..8)")
    p.add_argument("--seed", type=int, default=0, help="seed of the held-out split")
    p.add_argument("--test-fraction", type=float, default=0.25,
                   help="fraction of the points held out for the held-out residual")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..calibrate.run import calibrate
    from ..instruments import split_spec
    from ..machine.model import load
    from ._common import layout_inputs

    require(2 <= args.map_grid <= 60, "--map-grid must be between 2 and 60")
    model = load(args.layout)
    inputs = [split_spec(f)[1] for f in args.files] + layout_inputs(args.layout) \
        + ([args.reference] if args.reference else [])
    outs = Outputs(inputs, force=args.force).file("--json", args.json) \
        .file("--html", args.html).file("--map-out", args.map_out).file("--pdf", args.pdf) \
        .folder("--errors-out", args.errors_out,
                files=[f"{a}.csv" for a in model.axes] + ["constants.csv"]).check()
    ident = identification_from_args(args, inputs)
    with outs:
        result = calibrate(model, args.files, parameters=args.parameters,
                           degree=args.degree, seed=args.seed,
                           test_fraction=args.test_fraction,
                           accept_residual=args.accept_residual, reference=args.reference,
                           max_change=args.max_change, accept_change=args.accept_change)
        if args.json:
            result.write_json(outs.path("--json"), inputs=inputs)
        if args.html:
            result.write_html(outs.path("--html"), inputs=inputs)
        if args.errors_out:
            result.write_error_tables(outs.path("--errors-out"), inputs=inputs,
                                      accept_implausible=args.accept_implausible,
                                      shown=args.errors_out)
        if args.map_out:
            from ..calibrate.mapping import write_csv

            write_csv(outs.path("--map-out"), result, (args.map_grid,) * 3, inputs=inputs)
        write_certificates(outs, result, ident, inputs)
    print(result.summary())
    beyond = result.data.get("max_change", {}).get("beyond")
    if beyond:
        print("  changes beyond --max-change, accepted (--accept-change): " + ", ".join(
            f"{c['parameter']} {c['old']:.4g} -> {c['new']:.4g} {c['unit']}" for c in beyond))
    return 0
