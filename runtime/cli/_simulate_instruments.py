"""``volerr simulate --instrument sphere|ballbar``: the options and the run (argument parsing
only; the files come from :mod:`volerr.instruments.simulated_files`)."""

from __future__ import annotations

from ..errors import require

#: options of ``simulate`` that only the deviations campaign uses: (attribute, default)
DEVIATION_ONLY = (("probe", None), ("rounds", 1), ("effect", []), ("magnitude_um", 5.0))


def add_arguments(p) -> None:
    """The options of the instrument files (an argument group of ``simulate``)."""
    from ..instruments.simulated_files import INSTRUMENTS

    g = p.add_argument_group(
        "instrument files (--instrument sphere | ballbar): the layout's model with planted "
        "errors, for a calibration of known truth ('volerr calibrate LAYOUT FILE')")
    g.add_argument("--instrument", choices=INSTRUMENTS, default="deviations",
                   help="the file to write: deviations (3-D measured deviations of the "
                        "virtual machine, the options above), sphere (touch probe on spheres "
                        "/ R-test: two placements, the rotary axes over their travel; 'volerr "
                        "formats sphere') or ballbar (three ISO 230-4 circles XY, YZ, ZX about "
                        "the middle of the travel, both directions, 180 readings each, one "
                        "file with a placement column; 'volerr formats ballbar')")
    from ..instruments.simulated_files import DEFAULT_PLANTED

    shown = {k: ", ".join(f"{n}={v:g}" for n, v in d.items())
             for k, d in DEFAULT_PLANTED.items()}
    g.add_argument("--plant", metavar="NAME=V,...",
                   help="sphere / ballbar: the planted errors, in the units calibrate reports: "
                        "constants (EX0C=15 um, EA0C=25 urad, EC0Y=20 urad) and slopes of "
                        "component errors (EXX@slope=0.01 um/mm, zero at mid-travel); every "
                        "other error 0 (default: sphere the location errors of the rotary "
                        f"axes the layout has among {shown['sphere']}; ballbar squareness "
                        f"and scales {shown['ballbar']})")
    g.add_argument("--errors", metavar="DIR",
                   help="sphere / ballbar: plant the errors of an error directory instead "
                        "(tables and constants, 'volerr formats tables')")
    from ._common import add_accept_implausible

    add_accept_implausible(g)
    g.add_argument("--steps", type=int, default=None,
                   help="sphere: positions of each rotary axis over its travel (at most 320 "
                        "deg), every combination (default 9)")
    g.add_argument("--radius", type=float, default=None, metavar="MM",
                   help="ballbar: circle radius = bar length, mm (default 100, at most 40 %% of "
                        "the shortest linear travel)")


#: options of the instrument files: (attribute, the instruments that use it)
INSTRUMENT_ONLY = (("plant", ("sphere", "ballbar")), ("errors", ("sphere", "ballbar")),
                   ("steps", ("sphere",)), ("radius", ("ballbar",)))


def refuse_unused(args) -> None:
    """An option the chosen --instrument does not use is refused, never silently ignored."""
    for attr, users in INSTRUMENT_ONLY:
        require(getattr(args, attr, None) is None or args.instrument in users,
                f"--{attr} is for --instrument {' / '.join(users)}")


def run(args) -> int:
    """Write the sphere or ballbar file of ``args`` (the options checked first)."""
    import math
    from pathlib import Path

    from ..fileio import Outputs, write_text
    from ..instruments import simulated_files as sim
    from ..machine.model import load
    from ._common import layout_inputs

    for attr, default in DEVIATION_ONLY:
        require(getattr(args, attr) in (default, None) or getattr(args, attr) == default,
                f"--{attr.replace('_', '-')} is for --instrument deviations")
    refuse_unused(args)
    require(not (args.plant and args.errors), "give --plant or --errors, not both")
    require(math.isfinite(args.noise_um) and 0 <= args.noise_um <= 1e3,
            "--noise-um must be finite, between 0 and 1000 um")
    model = load(args.layout)
    inputs = layout_inputs(args.layout) + ([args.errors] if args.errors else [])
    if args.errors:
        require(Path(args.errors).is_dir(), f"error directory not found: {args.errors}")
    outs = Outputs(inputs).file("--out", args.out).check()
    if args.errors:
        from ..tables.functions import ErrorFunctions

        planted, funcs = None, ErrorFunctions.from_dir(
            args.errors, model, accept_implausible=args.accept_implausible)
    else:
        planted = (sim.parse_planted(args.plant, model) if args.plant is not None
                   else sim.default_planted(model, args.instrument))
        funcs = sim.planted_functions(model, planted)
    if args.instrument == "sphere":
        cols = sim.sphere_columns(model, funcs, steps=args.steps or 9, noise_um=args.noise_um,
                                  seed=args.seed)
    else:
        cols = sim.ballbar_columns(model, funcs, args.radius, args.noise_um, args.seed)
    text = sim.header_line(model, planted, args.errors) + sim.csv_text(cols)
    with outs:
        write_text(outs.path("--out"), text, inputs=inputs)
    n = len(next(iter(cols.values())))
    what = ", ".join(f"{k}={v:g}" for k, v in planted.items()) if planted is not None \
        else f"the errors of {args.errors}"
    print(f"{n} {args.instrument} readings of {model.name} ({what}; noise "
          f"{args.noise_um:g} um) -> {args.out}")
    return 0
