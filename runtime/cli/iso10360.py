"""``volerr iso10360 LAYOUT --errors DIR``: the simulated ISO 10360-2 length measuring test (see
``volerr iso10360 --help``; the Python API :func:`volerr.iso10360`)."""

from __future__ import annotations

from ._common import (add_error_arguments, add_html, add_identification, add_json, add_plot,
                      add_vector, command_parser, identification_from_args, inputs_of,
                      planned_outputs, write_document_outputs)


def register(sub) -> None:
    p = command_parser(sub, "iso10360", "simulated ISO 10360-2 length measuring test (E0)")
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


def run(args) -> int:
    import math

    from ..uncertainty.api import iso10360

    inputs = inputs_of(args)
    outs = planned_outputs(args, inputs)
    res = iso10360(
        args.layout, args.errors, method=args.method, degree=args.degree,
        extrapolate=args.extrapolate, probe=args.probe, volume=args.volume, mpe=args.mpe,
        noise_um=args.noise_um, seed=args.seed, artefact_u=args.artefact_u,
        artefact_cte_ppm_per_K=args.artefact_cte_ppm_per_K,
        artefact_cte_u_ppm_per_K=args.artefact_cte_u_ppm_per_K,
        temperature_C=args.temperature_C, temperature_u_K=args.temperature_u_K,
        identification=identification_from_args(args, inputs),
        accept_implausible=args.accept_implausible)
    print(res.summary())
    with outs:
        write_document_outputs(args, outs, res, res.identification, inputs, res.title)
    return 0 if math.isfinite(res.data["max_abs_E_um"]) else 1
