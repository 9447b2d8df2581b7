"""``volerr iso10360 LAYOUT --errors DIR``: simulated ISO 10360-2 length measuring test.

7 positions (4 space diagonals, lines along X, Y, Z through the centre), 5 lengths, 3
repetitions, bidirectional; prints E0 per position and length (um) and, with --mpe, the
verdict against the MPE line; --plot draws the certificate picture.  Definitions and the sign
convention: volerr.uncertainty.iso10360.
"""

from __future__ import annotations

import json

import numpy as np

from ._common import add_error_arguments, error_functions_from_args, inputs_of
from ..fileio import Outputs, write_text
from ..machine.model import load
from ..uncertainty import iso10360
from ..uncertainty.report import num
from ..cmm.volmap import volume


def register(sub) -> None:
    p = sub.add_parser("iso10360", help="simulated ISO 10360-2 length measuring test (E0)",
                       description=__doc__.split("\n\n")[1].replace("``", ""))
    p.add_argument("layout", help="layout name (volerr layouts) or layout file")
    add_error_arguments(p)
    p.add_argument("--probe", nargs=3, type=float, metavar=("XP", "YP", "ZP"),
                   default=(0.0, 0.0, 0.0), help="probe offset, mm (E0: 0 0 0)")
    p.add_argument("--volume", choices=("travel", "measured"), default="travel")
    p.add_argument("--mpe", metavar="'E0=A+L/K'", help="MPE line to judge against")
    p.add_argument("--noise-um", type=float, default=0.0, help="probing noise per point, um")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", metavar="F")
    p.add_argument("--plot", metavar="PNG")
    p.set_defaults(func=run)


def run(args) -> int:
    model = load(args.layout)
    funcs = error_functions_from_args(args, model)
    inputs = inputs_of(args)
    outs = Outputs(inputs).file("--json", args.json).plot("--plot", args.plot).check()
    spec = iso10360.parse_spec(args.mpe, "--mpe") if args.mpe else None
    res = iso10360.simulate(model, funcs, args.probe, volume(model, funcs, args.volume),
                            noise_um=args.noise_um, seed=args.seed, spec=spec)
    print(f"{model.name}: simulated ISO 10360-2 length test, E0 = measured - true length, um")
    for i, name in enumerate(res.names):
        cells = "  ".join(f"L={L:7.1f}: " + " ".join(num(e, "+7.3f") for e in res.E_um[i, j])
                          for j, L in enumerate(res.lengths[i]))
        print(f"  {name:16s} {cells}")
    d = res.as_dict()
    print(f"  max |E0| = {num(d['max_abs_E_um'], '.3f')} um")
    if spec is not None:
        print(f"  MPE {spec.text()}: max |E0| / MPE = {num(d['max_ratio_to_mpe'], '.3f')} -> "
              f"{'PASS' if d['passes'] else 'FAIL'}")
    with outs:
        if args.json:
            doc = {"layout": model.name, "errors": str(args.errors),
                   "probe_mm": list(args.probe), "repetitions": int(res.E_um.shape[-1]), **d}
            write_text(outs.path("--json"), json.dumps(doc, indent=2) + "\n", inputs)
        if args.plot:
            iso10360.plot(res, outs.path("--plot"),
                          f"{model.name}: simulated ISO 10360-2 ({args.errors})", inputs)
    return 0 if np.isfinite(d["max_abs_E_um"]) else 1
