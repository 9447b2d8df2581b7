"""``volerr iso10360``: the simulated ISO 10360-2 length test (:func:`volerr.iso10360`)."""

from __future__ import annotations

from ._common import (add_error_arguments, add_html, add_identification_arguments, add_json,
                      add_plot, add_vector, command_parser, options_of)


def register(sub) -> None:
    p, H = command_parser(sub, "iso10360")
    a = p.add_argument
    a("layout", help="layout name (volerr layouts) or layout file")
    add_error_arguments(p)
    add_vector(p, "--probe", default=(0.0, 0.0, 0.0), help=H["--probe"])
    a("--volume", choices=("travel", "measured"), default="travel", help=H["--volume"])
    a("--mpe", metavar="'E0=A+L/K'", help=H["--mpe"])
    a("--noise-um", type=float, default=0.0, metavar="S", help=H["--noise-um"])
    a("--seed", type=int, default=0, metavar="K", help="seed of the probing noise")
    g = p.add_argument_group("test uncertainty U(L), k = 2 (ISO 10360-2 / ISO 14253-5)")
    g = g.add_argument
    g("--artefact-u", default="0.1+L/2000", metavar="'A+L/K'", help=H["--artefact-u"])
    g("--artefact-cte-ppm-per-K", type=float, default=11.5, metavar="A",
      help=H["--artefact-cte-ppm-per-K"])
    g("--artefact-cte-u-ppm-per-K", type=float, default=1.0, metavar="U",
      help=H["--artefact-cte-u-ppm-per-K"])
    g("--temperature-C", type=float, default=20.0, metavar="T", help=H["--temperature-C"])
    g("--temperature-u-K", type=float, default=0.2, metavar="U", help=H["--temperature-u-K"])
    add_json(p, "E0 values, U, verdicts")
    add_plot(p, H["--plot"])
    add_html(p, "the certificate (identification, verdict, plot, every E0)")
    add_identification_arguments(p, "the artefact (step gauge, gauge blocks)")
    p.set_defaults(func=run)


def run(args) -> int:
    import math

    from ..cmm.volmap import map_inputs
    from ..results import run_command
    from ..uncertainty.api import iso10360

    res = run_command(vars(args), map_inputs(args.layout, args.errors), lambda _, ident: iso10360(
        **options_of(args, "layout errors method degree extrapolate probe volume mpe noise_um "
                           "seed artefact_u artefact_cte_ppm_per_K artefact_cte_u_ppm_per_K "
                           "temperature_C temperature_u_K accept_implausible",
                     identification=ident)))
    print(res.summary())
    return 0 if math.isfinite(res.data["max_abs_E_um"]) else 1
