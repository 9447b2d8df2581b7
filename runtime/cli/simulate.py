"""``volerr simulate LAYOUT --out DATA.csv``: a virtual machine's measured deviations.

The machine of LAYOUT (exact chain, random smooth error functions by seed) measured at
random points with several probe/tool offsets, Gaussian noise, an unknown instrument
placement, and optionally undeclared effects (``--effect``).  Writes the measured-deviation
CSV ('volerr formats deviations').  See volerr.loop.simulate.
"""

from __future__ import annotations

from ._common import add_vector


def register(sub) -> None:
    p = sub.add_parser(
        "simulate", help="simulate measured deviations of a virtual machine (CSV)",
        description="Simulate a measurement campaign on a virtual machine of LAYOUT: exact "
                    "chain, smooth random error functions (by --seed), probe/tool offsets, "
                    "noise, instrument placement and undeclared effects.  Effects: "
                    "thermal:axis=X,ppm_per_K=11.5  drift:direction=x,um_per_h=3  "
                    "reversal:axis=X,um=4  coupling:component=EZX,axis=Y,um=6  "
                    "periodic:component=EXX,period_mm=25,um=2  "
                    "higher_order:component=EYZ,um=3,degree=10  probe_direction:um=2  "
                    "setup:um=8,urad=15 (needs --rounds 2 or more)  "
                    "thermal_lag:sensor=T_motorX,tau_min=40,axis=X,ppm_per_K=2 (the scale of X "
                    "follows a logged sensor through a first-order lag; or component=EYX,"
                    "um_per_K=0.5; needs --sensors).")
    p.add_argument("layout", help="layout name or layout file")
    p.add_argument("--out", required=True, help="measured-deviation CSV to write")
    p.add_argument("--points", type=int, default=600, help="number of points (default 600)")
    p.add_argument("--seed", type=int, default=0,
                   help="seed of the machine's error functions, points and noise")
    add_vector(p, "--probe", append=True,
               help="probe/tool offset X Y Z in mm (X Y Z or X,Y,Z; repeat for several; "
                    "default: a plan of five)")
    p.add_argument("--rounds", type=int, default=1, help="measurement rounds (set-ups)")
    p.add_argument("--effect", action="append", default=[], metavar="KIND[:K=V,...]",
                   help="an undeclared effect (repeatable)")
    p.add_argument("--noise-um", type=float, default=0.3, help="instrument noise, um (1 sigma)")
    p.add_argument("--magnitude-um", type=float, default=5.0,
                   help="size of the random error functions, um")
    p.add_argument("--sensors", metavar="N|NAMES",
                   help="log temperatures in place of T_C: a number (the first N of T_spindle "
                        "T_motorX T_column T_bed T_coolant T_air1 T_air2 T_hydraulics T_motorY "
                        "T_motorZ T_table T_cabinet) or comma-separated names (default: none, "
                        "one column T_C)")
    p.add_argument("--duty", metavar="SPEC",
                   help="duty cycle of the heat sources, e.g. on:6h,off:4h (the drives; the "
                        "coolant pump follows) or drives=on:2h,off:2h,on:6h;coolant=on:10h "
                        "(default with --sensors: on:6h,off:4h)")
    p.add_argument("--hours", type=float, default=8.0,
                   help="duration of the campaign, h (the points in time order; default 8)")
    from . import _simulate_instruments

    _simulate_instruments.add_arguments(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from . import _simulate_instruments

    if getattr(args, "instrument", "deviations") != "deviations":
        return _simulate_instruments.run(args)
    _simulate_instruments.refuse_unused(args)
    from ._common import layout_inputs
    from ..fileio import Outputs
    from ..loop.simulate import check_options, simulate_options

    check_options(args.points, args.noise_um, args.magnitude_um)
    inputs = layout_inputs(args.layout)
    outs = Outputs(inputs).file("--out", args.out).check()
    camp, name = simulate_options(args.layout, points=args.points, seed=args.seed,
                                  probes=args.probe, rounds=args.rounds, effects=args.effect,
                                  noise_um=args.noise_um, magnitude_um=args.magnitude_um,
                                  hours=args.hours, sensors=args.sensors, duty=args.duty)
    with outs:
        camp.write_csv(outs.path("--out"), inputs=inputs)
    print(f"{camp.n_points} points of {name} -> {args.out}")
    return 0
