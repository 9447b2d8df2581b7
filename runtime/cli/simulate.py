"""``volerr simulate LAYOUT --out F``: a virtual machine's deviations or instrument file."""

from __future__ import annotations

from ..choices import SIMULATED_INSTRUMENTS as INSTRUMENTS, SIMULATED_PLANTED as PLANTED
from ._common import add_accept_implausible, add_vector, command_parser, options_of


def register(sub) -> None:
    p, H = command_parser(sub, "simulate")
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
    g = p.add_argument_group(H["instrument files"])
    g.add_argument("--instrument", choices=INSTRUMENTS, default="deviations",
                   help=H["--instrument"])
    shown = {k: ", ".join(f"{n}={v:g}" for n, v in d.items()) for k, d in PLANTED.items()}
    g.add_argument("--plant", metavar="NAME=V,...", help=H["--plant"].format(**shown))
    g.add_argument("--errors", metavar="DIR", help=H["--errors"])
    add_accept_implausible(g)
    g.add_argument("--steps", type=int, default=None, help=H["--steps"])
    g.add_argument("--radius", type=float, default=None, metavar="MM", help=H["--radius"])
    p.set_defaults(func=run)


def run(args) -> int:
    from ..fileio import planned_outputs, write_text
    from ..fileio import layout_inputs
    from ..instruments.simulated_files import refuse_unused
    from ..loop.simulate import simulated_file

    refuse_unused(args.instrument, vars(args))
    inputs = layout_inputs(args.layout) + ([args.errors] if args.errors else [])
    with planned_outputs(vars(args), inputs, **{"--out": args.out}) as outs:
        text, line = simulated_file(args.layout, args.instrument, **options_of(
            args, "probe effect points seed rounds noise_um magnitude_um hours sensors duty "
                  "plant errors steps radius accept_implausible"))
        write_text(outs.path("--out"), text, inputs=inputs)
    print(f"{line} -> {args.out}")
    return 0
