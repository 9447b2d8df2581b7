"""``volerr iso230-2 RUN.csv [RUN2.csv ...]``: ISO 230-2 evaluation of laser-interferometer
positioning runs (see ``volerr iso230-2 --help``; the Python API :func:`volerr.iso230_2`)."""

from __future__ import annotations

from ._common import (add_errors_out, add_force, add_html, add_identification, add_json,
                      add_plot, command_parser, finite_option, identification_from_args,
                      planned_outputs, write_outputs)

def register(sub) -> None:
    p = command_parser(sub, "iso230-2",
                       "ISO 230-2 evaluation of laser-interferometer positioning runs")
    p.add_argument("runs", nargs="+", metavar="RUN.csv", help="positioning run(s), long or "
                                                               "wide format (below)")
    p.add_argument("--axis", default="X",
                   help="axis letter of the runs (X Y Z U V W; default X), or a comma list with "
                        "one letter per RUN file")
    add_json(p, "the results")
    add_plot(p, "the ISO 230-2 plot")
    add_html(p, "the certificate (identification, results with U, verdicts, plot, budget)")
    add_errors_out(p, "DIR/<axis>.csv: mean bidirectional deviation, its standard "
                      "uncertainty S/sqrt(2n) (_std), the single-reading repeatability S (_s) "
                      "and the reversal (RV_<axis>_um),", "--table-out")
    add_force(p)
    p.add_argument("--tolerance", metavar="'A=..,E=..'",
                   help="tolerances in um (or with a length unit: A=0.012 mm) of any of "
                        "A E M R B: verdicts per ISO 14253-1 (tolerance reduced / widened by U)")
    u = p.add_argument_group("measurement uncertainty (ISO/TR 230-9)")
    u.add_argument("--instrument-ppm", type=float, default=0.5, metavar="P",
                   help="accuracy of the interferometer with its environmental compensation, "
                        "ppm of the length (a maximum error, rectangular)")
    u.add_argument("--alignment-mm", type=float, default=0.1, metavar="D",
                   help="lateral offset of the beam over the travel after alignment, mm "
                        "(cosine error D^2 / 2L)")
    u.add_argument("--temperature-u-K", type=float, default=0.2, metavar="U",
                   help="standard uncertainty of the material temperature, K")
    u.add_argument("--cte-u-ppm-per-K", type=float, default=1.0, metavar="U",
                   help="standard uncertainty of the expansion coefficient, ppm/K")
    u.add_argument("--eve-um", type=float, metavar="V",
                   help="environmental variation error of a drift test, um (not given: not "
                        "included, noted)")
    add_identification(p, "the laser interferometer")
    g = p.add_argument_group("correction to 20 degC")
    g.add_argument("--cte-ppm-per-K", type=float, metavar="A",
                   help="coefficient of expansion of the scale / material, ppm/K (um/m/K); "
                        "needs a T_C column or --material-temp-C")
    g.add_argument("--material-temp-C", type=float, metavar="T",
                   help="material temperature for the whole run, degC (when the file has no "
                        "T_C column)")
    g.add_argument("--cte-reference-mm", type=float, default=0.0, metavar="P",
                   help="position where the expansion is zero (scale fixed point or where the "
                        "interferometer was zeroed), mm (default 0)")
    p.set_defaults(func=run)


def run(args) -> int:
    import sys

    from ..positioning.api import iso230_2, run_axes

    axes = run_axes(args.axis, len(args.runs))
    for opt in ("instrument_ppm", "alignment_mm", "temperature_u_K", "cte_u_ppm_per_K",
                "eve_um"):
        finite_option(getattr(args, opt), "--" + opt.replace("_", "-"), 0.0, 1e3)
    outs = planned_outputs(args, args.runs, **{"--errors-out": (
        args.errors_out, sorted({f"{a}.csv" for a in axes}))})
    ident = identification_from_args(args, args.runs, conditions_of_correction(args))
    with outs:
        res = iso230_2(args.runs, ",".join(axes), tolerance=args.tolerance,
                       instrument_ppm=args.instrument_ppm, alignment_mm=args.alignment_mm,
                       temperature_u_K=args.temperature_u_K,
                       cte_u_ppm_per_K=args.cte_u_ppm_per_K, eve_um=args.eve_um,
                       cte_ppm_per_K=args.cte_ppm_per_K, material_temp_C=args.material_temp_C,
                       cte_reference_mm=args.cte_reference_mm, identification=ident,
                       errors_out=bool(args.errors_out))
        if args.errors_out:
            res.write_error_tables(outs.path("--errors-out"), inputs=args.runs)
        write_outputs(args, outs, res, ident, args.runs)
    print(res.summary())
    for n in res.notes:
        print(f"volerr iso230-2: note: {n}", file=sys.stderr)
    return 0


def conditions_of_correction(args) -> dict:
    """The correction to 20 degC as test conditions of the report."""
    out = {}
    if args.cte_ppm_per_K is not None:
        out["expansion coefficient"] = f"{args.cte_ppm_per_K:g} ppm/K (corrected to 20 \u00b0C)"
    if args.material_temp_C is not None:
        out["material temperature"] = f"{args.material_temp_C:g} \u00b0C"
    return out
