"""``volerr simulate --instrument sphere|ballbar``: the options and the run (argument parsing
only; the files come from :mod:`volerr.instruments.simulated_files`)."""

from __future__ import annotations

from ..errors import require

#: options of ``simulate`` that only the deviations campaign uses: (attribute, default)
DEVIATION_ONLY = (("probe", None), ("rounds", 1), ("effect", []), ("magnitude_um", 5.0))


def add_arguments(p) -> None:
    """The options of the instrument files (an argument group of ``simulate``)."""
    from ..choices import SIMULATED_INSTRUMENTS as INSTRUMENTS

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
    from ..fileio import Outputs, write_text
    from ..instruments.simulated_files import instrument_file
    from ._common import layout_inputs

    for attr, default in DEVIATION_ONLY:
        require(getattr(args, attr) in (default, None) or getattr(args, attr) == default,
                f"--{attr.replace('_', '-')} is for --instrument deviations")
    refuse_unused(args)
    inputs = layout_inputs(args.layout) + ([args.errors] if args.errors else [])
    outs = Outputs(inputs).file("--out", args.out).check()
    text, line = instrument_file(args.layout, args.instrument, plant=args.plant,
                                 errors=args.errors, steps=args.steps, radius=args.radius,
                                 noise_um=args.noise_um, seed=args.seed,
                                 accept_implausible=args.accept_implausible)

    with outs:
        write_text(outs.path("--out"), text, inputs=inputs)
    print(f"{line} -> {args.out}")
    return 0
