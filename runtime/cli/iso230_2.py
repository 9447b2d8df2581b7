"""``volerr iso230-2``: ISO 230-2 evaluation of positioning runs (:func:`volerr.iso230_2`)."""

from __future__ import annotations

import sys

from ._common import (add_errors_out, add_force, add_html, add_identification_arguments, add_json,
                      add_plot, command_parser, options_of)


def register(sub) -> None:
    p, H = command_parser(sub, "iso230-2")
    a = p.add_argument
    a("runs", nargs="+", metavar="RUN.csv", help="positioning run(s), long or wide format (below)")
    a("--axis", default="X", help=H["--axis"])
    add_json(p, "the results")
    add_plot(p, "the ISO 230-2 plot")
    add_html(p, "the certificate (identification, results with U, verdicts, plot, budget)")
    add_errors_out(p, H["--errors-out"], "--table-out")
    add_force(p)
    a("--tolerance", metavar="'A=..,E=..'", help=H["--tolerance"])
    u = p.add_argument_group("measurement uncertainty (ISO/TR 230-9)").add_argument
    u("--instrument-ppm", type=float, default=0.5, metavar="P", help=H["--instrument-ppm"])
    u("--alignment-mm", type=float, default=0.1, metavar="D", help=H["--alignment-mm"])
    u("--temperature-u-K", type=float, default=0.2, metavar="U", help=H["--temperature-u-K"])
    u("--cte-u-ppm-per-K", type=float, default=1.0, metavar="U", help=H["--cte-u-ppm-per-K"])
    u("--eve-um", type=float, metavar="V", help=H["--eve-um"])
    add_identification_arguments(p, "the laser interferometer")
    g = p.add_argument_group("correction to 20 degC").add_argument
    g("--cte-ppm-per-K", type=float, metavar="A", help=H["--cte-ppm-per-K"])
    g("--material-temp-C", type=float, metavar="T", help=H["--material-temp-C"])
    g("--cte-reference-mm", type=float, default=0.0, metavar="P", help=H["--cte-reference-mm"])
    p.set_defaults(func=run)


def run(args) -> int:
    from ..positioning.api import correction_conditions, iso230_2, run_axes
    from ..results import run_command

    names = sorted({f"{a}.csv" for a in run_axes(args.axis, len(args.runs))})
    res = run_command(vars(args), args.runs, lambda _, ident: iso230_2(**options_of(
        args, "runs axis tolerance instrument_ppm alignment_mm temperature_u_K "
              "cte_u_ppm_per_K eve_um cte_ppm_per_K material_temp_C cte_reference_mm",
        identification=ident, errors_out=bool(args.errors_out))),
        conditions=correction_conditions(args.cte_ppm_per_K, args.material_temp_C),
        **{"--errors-out": (args.errors_out, names)})
    print(res.summary())
    for n in res.notes:
        print(f"volerr iso230-2: note: {n}", file=sys.stderr)
    return 0
