"""``volerr iso10360 LAYOUT --errors DIR``: simulated ISO 10360-2 length measuring test.

7 positions (4 space diagonals, lines along X, Y, Z through the centre), 5 lengths, 3
repetitions, bidirectional; prints E0 per position and length (um) and, with --mpe, the
verdict against the MPE line per ISO 14253-1 with the test uncertainty U; --plot draws the
certificate picture, --html writes the certificate.  Definitions and the sign convention:
volerr.uncertainty.iso10360.
"""

from __future__ import annotations


from ._common import (add_error_arguments, add_html, add_identification, add_json, add_plot,
                      add_vector, error_functions_from_args, finite_option,
                      identification_from_args, inputs_of)
from ..fileio import Outputs, json_text, write_text


def register(sub) -> None:
    p = sub.add_parser("iso10360", help="simulated ISO 10360-2 length measuring test (E0)",
                       description=__doc__.split("\n\n")[1].replace("``", ""))
    p.add_argument("layout", help="layout name (volerr layouts) or layout file")
    add_error_arguments(p)
    add_vector(p, "--probe", default=(0.0, 0.0, 0.0),
               help="probe offset XP YP ZP, mm (X Y Z or X,Y,Z; E0 is tested with 0 0 0)")
    p.add_argument("--volume", choices=("travel", "measured"), default="travel",
                   help="box of the test: the layout's travel or the part of it the error "
                        "tables cover")
    p.add_argument("--mpe", metavar="'E0=A+L/K'",
                   help="MPE line to judge against (A um, or with a length unit: E0=1.5 um+L/333; "
                        "L mm): verdict per ISO 14253-1")
    p.add_argument("--noise-um", type=float, default=0.0, metavar="S",
                   help="probing noise per point, standard deviation, um")
    p.add_argument("--seed", type=int, default=0, metavar="K", help="seed of the probing noise")
    g = p.add_argument_group("test uncertainty U(L), k = 2 (ISO 10360-2 / ISO 14253-5)")
    g.add_argument("--artefact-u", default="0.1+L/2000", metavar="'A+L/K'",
                   help="expanded calibration uncertainty of the reference lengths, um (L mm)")
    g.add_argument("--artefact-cte-ppm-per-K", type=float, default=11.5, metavar="A",
                   help="expansion coefficient of the artefact, ppm/K")
    g.add_argument("--artefact-cte-u-ppm-per-K", type=float, default=1.0, metavar="U",
                   help="standard uncertainty of that coefficient, ppm/K")
    g.add_argument("--temperature-C", type=float, default=20.0, metavar="T",
                   help="artefact temperature during the test, degC")
    g.add_argument("--temperature-u-K", type=float, default=0.2, metavar="U",
                   help="standard uncertainty of the artefact temperature, K")
    add_json(p, "E0 values, U, verdicts")
    add_plot(p, "E0 against L with the MPE, the undecided zone and the marked values")
    add_html(p, "the certificate (identification, verdict, plot, every E0)")
    add_identification(p, "the artefact (step gauge, gauge blocks)")
    p.set_defaults(func=run)


def _test_uncertainty(args):
    """:class:`volerr.uncertainty.iso10360.TestUncertainty` of the artefact options."""
    from ..uncertainty import iso10360

    a, k = iso10360.parse_calibration(args.artefact_u)
    finite_option(args.artefact_cte_ppm_per_K, "--artefact-cte-ppm-per-K", -100.0, 100.0)
    finite_option(args.artefact_cte_u_ppm_per_K, "--artefact-cte-u-ppm-per-K", 0.0, 100.0)
    finite_option(args.temperature_C, "--temperature-C", -50.0, 100.0)
    finite_option(args.temperature_u_K, "--temperature-u-K", 0.0, 100.0)
    return iso10360.TestUncertainty(a, k, args.artefact_cte_ppm_per_K,
                                    args.artefact_cte_u_ppm_per_K, args.temperature_C,
                                    args.temperature_u_K)


def run(args) -> int:
    import numpy as np

    from ..cmm.volmap import volume  # the capability: when the command runs
    from ..machine.model import load
    from ..uncertainty import iso10360
    from ..units import num

    model = load(args.layout)
    funcs = error_functions_from_args(args, model)
    inputs = inputs_of(args)
    outs = Outputs(inputs).file("--json", args.json).plot("--plot", args.plot) \
        .file("--html", args.html).check()
    spec = iso10360.parse_spec(args.mpe, "--mpe") if args.mpe is not None else None
    tu = _test_uncertainty(args)
    ident = identification_from_args(args, {
        "artefact temperature": f"{args.temperature_C:g} \u00b0C (u = {args.temperature_u_K:g} K)",
        "artefact expansion coefficient": f"{args.artefact_cte_ppm_per_K:g} ppm/K (u = "
                                          f"{args.artefact_cte_u_ppm_per_K:g} ppm/K)"})
    res = iso10360.simulate(model, funcs, tuple(args.probe),
                            volume(model, funcs, args.volume), noise_um=args.noise_um,
                            seed=args.seed, spec=spec, uncertainty=tu)
    print(f"{model.name}: simulated ISO 10360-2 length test, E0 = measured - true length, um")
    for i, name in enumerate(res.names):
        cells = "  ".join(f"L={L:7.1f}: " + " ".join(num(e, "+7.3f") for e in res.E_um[i, j])
                          for j, L in enumerate(res.lengths[i]))
        print(f"  {name:16s} {cells}")
    d = res.as_dict()
    print(f"  max |E0| = {num(d['max_abs_E_um'], '.3f')} um; test uncertainty U <= "
          f"{num(d['uncertainty_um']['E0'], '.3f')} um (k = 2)")
    if spec is not None:
        c = d["verdict_counts"]
        print(f"  MPE {spec.text()}: max |E0| / MPE = {num(d['max_ratio_to_mpe'], '.3f')} -> "
              f"{d['verdict'].upper()} (ISO 14253-1: {c['pass']} pass, {c['undecided']} "
              f"undecided, {c['fail']} fail)")
    doc = {"layout": model.name, "errors": str(args.errors),
           "probe_mm": [float(v) for v in args.probe], "repetitions": int(res.E_um.shape[-1]),
           **d, "identification": ident.as_dict()}
    title = f"{model.name}: simulated ISO 10360-2" + (f", {d['verdict']}" if spec else "")
    with outs:
        if args.json:
            write_text(outs.path("--json"), json_text(doc), inputs)
        png = None
        if args.plot or args.html:
            png = iso10360.plot_png(res, title)
            if args.plot:
                from ..fileio import write_bytes
                write_bytes(outs.path("--plot"), png, inputs)
        if args.html:
            from .. import __version__
            from ..uncertainty.iso10360_report import report_html
            write_text(outs.path("--html"), report_html(
                doc, png, ident, f"Evaluated with volerr {__version__}."), inputs)
    return 0 if np.isfinite(d["max_abs_E_um"]) else 1

