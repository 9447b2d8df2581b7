"""``volerr simulate LAYOUT --out DATA.csv``: a virtual machine's measured deviations, or a
sphere / ballbar file of the layout's model with planted errors; see ``volerr simulate
--help``."""

from __future__ import annotations

from ..errors import require
from ._common import (add_accept_implausible, add_vector, command_parser, layout_inputs,
                      option_help, planned_outputs)

#: options of ``simulate`` that only the deviations campaign uses: (attribute, default)
DEVIATION_ONLY = (("probe", None), ("rounds", 1), ("effect", []), ("magnitude_um", 5.0))
#: options of the instrument files: (attribute, the instruments that use it)
INSTRUMENT_ONLY = (("plant", ("sphere", "ballbar")), ("errors", ("sphere", "ballbar")),
                   ("steps", ("sphere",)), ("radius", ("ballbar",)))


def register(sub) -> None:
    H = option_help("simulate")
    p = command_parser(sub, "simulate", "simulate measured deviations of a virtual machine "
                                        "(CSV)")
    p.add_argument("layout", help="layout name or layout file")
    p.add_argument("--out", required=True, help="measured-deviation CSV to write")
    p.add_argument("--points", type=int, default=600, help="number of points (default 600)")
    p.add_argument("--seed", type=int, default=0, help=H["--seed"])
    add_vector(p, "--probe", append=True, help=H["--probe"])
    p.add_argument("--rounds", type=int, default=1, help="measurement rounds (set-ups)")
    p.add_argument("--effect", action="append", default=[], metavar="KIND[:K=V,...]",
                   help=H["--effect"])
    p.add_argument("--noise-um", type=float, default=0.3, help="instrument noise, um (1 sigma)")
    p.add_argument("--magnitude-um", type=float, default=5.0, help=H["--magnitude-um"])
    p.add_argument("--sensors", metavar="N|NAMES", help=H["--sensors"])
    p.add_argument("--duty", metavar="SPEC", help=H["--duty"])
    p.add_argument("--hours", type=float, default=8.0, help=H["--hours"])
    from ..choices import SIMULATED_INSTRUMENTS as INSTRUMENTS

    g = p.add_argument_group(
        "instrument files (--instrument sphere | ballbar): the layout's model with planted "
        "errors, for a calibration of known truth ('volerr calibrate LAYOUT FILE')")
    g.add_argument("--instrument", choices=INSTRUMENTS, default="deviations",
                   help=H["--instrument"])
    from ..choices import SIMULATED_PLANTED as DEFAULT_PLANTED

    shown = {k: ", ".join(f"{n}={v:g}" for n, v in d.items())
             for k, d in DEFAULT_PLANTED.items()}
    g.add_argument("--plant", metavar="NAME=V,...",
                   help="sphere / ballbar: the planted errors, in the units calibrate reports: "
                        "constants (EX0C=15 um, EA0C=25 urad, EC0Y=20 urad) and slopes of "
                        "component errors (EXX@slope=0.01 um/mm, zero at mid-travel); every "
                        "other error 0 (default: sphere the location errors of the rotary "
                        f"axes the layout has among {shown['sphere']}; ballbar squareness "
                        f"and scales {shown['ballbar']})")
    g.add_argument("--errors", metavar="DIR", help=H["--errors"])
    add_accept_implausible(g)
    g.add_argument("--steps", type=int, default=None, help=H["--steps"])
    g.add_argument("--radius", type=float, default=None, metavar="MM", help=H["--radius"])


    p.set_defaults(func=run)


def run(args) -> int:
    """An option the chosen --instrument does not use is refused, never silently ignored;
    then the file is simulated and written."""
    from ..fileio import write_text
    from ..instruments.simulated_files import instrument_file
    from ..loop.simulate import simulate_options

    deviations = args.instrument == "deviations"
    for attr, default in () if deviations else DEVIATION_ONLY:
        require(getattr(args, attr) in (default, None),
                f"--{attr.replace('_', '-')} is for --instrument deviations")
    for attr, users in INSTRUMENT_ONLY:
        require(getattr(args, attr) is None or args.instrument in users,
                f"--{attr} is for --instrument {' / '.join(users)}")
    inputs = layout_inputs(args.layout) + ([args.errors] if args.errors else [])
    outs = planned_outputs(args, inputs, **{"--out": args.out})
    with outs:
        if deviations:
            camp, name = simulate_options(
                args.layout, points=args.points, seed=args.seed, probes=args.probe,
                rounds=args.rounds, effects=args.effect, noise_um=args.noise_um,
                magnitude_um=args.magnitude_um, hours=args.hours, sensors=args.sensors,
                duty=args.duty)
            camp.write_csv(outs.path("--out"), inputs=inputs)
            line = f"{camp.n_points} points of {name}"
        else:
            text, line = instrument_file(
                args.layout, args.instrument, plant=args.plant, errors=args.errors,
                steps=args.steps, radius=args.radius, noise_um=args.noise_um, seed=args.seed,
                accept_implausible=args.accept_implausible)
            write_text(outs.path("--out"), text, inputs=inputs)
    print(f"{line} -> {args.out}")
    return 0
