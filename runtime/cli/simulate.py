"""``volerr simulate LAYOUT --out DATA.csv``: a virtual machine's measured deviations.

The machine of LAYOUT (exact chain, random smooth error functions by seed) measured at
random points with several probe/tool offsets, Gaussian noise, an unknown instrument
placement, and optionally undeclared effects (``--effect``).  Writes the measured-deviation
CSV of INTERFACE.md.  See :mod:`volerr.loop.simulate`.
"""

from __future__ import annotations

from volerr.errors import InputError, require


def _effect(text: str) -> dict:
    """``kind[:key=value,...]`` -> effect dict (numbers where they parse)."""
    kind, _, rest = text.partition(":")
    out: dict = {"kind": kind.strip()}
    for item in filter(None, (s.strip() for s in rest.split(","))):
        key, eq, value = item.partition("=")
        require(eq == "=", f"--effect {text!r}: write key=value pairs after the kind")
        try:
            out[key.strip()] = float(value)
        except ValueError:
            out[key.strip()] = value.strip()
    return out


def _probe(text: str) -> tuple:
    try:
        v = tuple(float(x) for x in text.split(","))
    except ValueError:
        raise InputError(f"--probe {text!r}: write x,y,z in mm") from None
    require(len(v) == 3, f"--probe {text!r}: write x,y,z in mm")
    return v


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
                    "setup:um=8,urad=15 (needs --rounds 2 or more).")
    p.add_argument("layout", help="layout name or layout file")
    p.add_argument("--out", required=True, help="measured-deviation CSV to write")
    p.add_argument("--points", type=int, default=600, help="number of points (default 600)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--probe", action="append", metavar="X,Y,Z",
                   help="probe/tool offset in mm (repeat for several; default: a plan of five)")
    p.add_argument("--rounds", type=int, default=1, help="measurement rounds (set-ups)")
    p.add_argument("--effect", action="append", default=[], metavar="KIND[:K=V,...]",
                   help="an undeclared effect (repeatable)")
    p.add_argument("--noise-um", type=float, default=0.3, help="instrument noise, um (1 sigma)")
    p.add_argument("--magnitude-um", type=float, default=5.0,
                   help="size of the random error functions, um")
    p.set_defaults(func=run)


def run(args) -> int:
    from volerr.machine.model import load
    from volerr.loop.simulate import demo_probes, simulate

    require(10 <= args.points <= 10_000_000, "--points must be between 10 and 10^7")
    require(args.noise_um >= 0 and args.magnitude_um >= 0, "noise and magnitude must be >= 0")
    from volerr.cli._common import layout_inputs
    from volerr.fileio import Outputs

    model = load(args.layout)
    inputs = layout_inputs(args.layout)
    outs = Outputs(inputs).file("--out", args.out).check()
    probes = [_probe(t) for t in args.probe] if args.probe else demo_probes(model)
    camp = simulate(args.layout, n_points=args.points, seed=args.seed, probes=probes,
                    rounds=args.rounds, effects=[_effect(e) for e in args.effect],
                    noise_um=args.noise_um, magnitude_um=args.magnitude_um)
    with outs:
        camp.write_csv(outs.path("--out"), inputs=inputs)
    print(f"{camp.n_points} points of {model.name} -> {args.out}")
    return 0
