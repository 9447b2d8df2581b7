"""``volerr plan LAYOUT --instrument SPEC ... --readings N --out DIR``: design a measurement
campaign before the machine time is spent (:mod:`volerr.plan`)."""

from __future__ import annotations

from pathlib import Path

from ..errors import require
from ..fileio import Outputs
from ._common import (add_force, add_html, add_identification_arguments, add_json,
                      identification_from_args, write_certificates)


def register(sub) -> None:
    p = sub.add_parser(
        "plan", help="design a measurement campaign (optimal set-ups, files, NC programs)",
        description="Design a calibration campaign for LAYOUT with the instruments named: "
                    "from candidate set-ups inside the travel (ballbar circles, sphere / "
                    "R-test placements, tracking-interferometer stations, laser-interferometer "
                    "lines, ball-plate placements) choose the set-ups "
                    "and readings that minimise the predicted standard uncertainty of the "
                    "volumetric error over the working volume (I-optimal; --criterion D) "
                    "while every requested parameter stays determined (greedy design, "
                    "Fedorov exchange, on calibrate's own normal equations).  Writes into "
                    "DIR one instrument file per set-up group with EMPTY reading columns, an "
                    "NC program beside each (the layout's axes, --dialect; safe along its "
                    "whole path: ballbar circles as arcs with run-in and run-out, balls "
                    "probed from outside, ISO 230-2 overshoots), and "
                    "plan.html (the set-up sheet); predicts what 'volerr calibrate LAYOUT "
                    "FILES' (no options) will report once the files are filled, and the same "
                    "for the instrument's conventional plan at the same number of readings "
                    "(the baseline).  SPEC grammar, files, NC contract and the time model: "
                    "'volerr formats plan'.")
    p.add_argument("layout", help="layout name (volerr layouts) or layout file")
    p.add_argument("--instrument", action="append", required=True, metavar="SPEC",
                   help="an instrument: KIND[:key=value[,value...]]... with KIND ballbar "
                        "(lengths=100,150,250 length_u_um=U), sphere (places=K tool_u_um=U "
                        "frame=work|machine), distances (stations=K), interferometer "
                        "(optics=linear,straightness,angular, the default all three; "
                        "u_urad=U), artifact (a ball plate: balls=5x5 pitch=100 "
                        "cal_u_um=0.5 places=4); every kind takes "
                        "u_um=U and tool=L or tool=X,Y,Z (mm); repeat for a mixed campaign")
    p.add_argument("--readings", type=int, required=True, metavar="N",
                   help="readings in all (rows of the plan files)")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="folder of the plan files (created when missing, its parent must "
                        "exist; an existing folder must hold no .csv, .nc or .html file "
                        "unless --force)")
    add_json(p, "the plan: predicted standard uncertainties, files, baseline")
    add_html(p, "the set-up sheet (default: DIR/plan.html)")
    add_identification_arguments(p)
    p.add_argument("--parameters", metavar="SPEC",
                   help="parameters the campaign must determine (as calibrate --parameters; "
                        "written into the files' header); default: what calibrate fits for "
                        "these instruments")
    p.add_argument("--minutes", type=float, metavar="M",
                   help="time budget in minutes (set-up changes and readings, the time "
                        "model of 'volerr formats plan'); default: no limit")
    p.add_argument("--criterion", choices=("I", "D"), default="I",
                   help="I: mean predicted variance of the volumetric error over the working "
                        "volume; D: determinant of the information matrix")
    p.add_argument("--dialect", default="iso", metavar="NAME",
                   help="controller dialect of the NC programs: iso (default; ISO 6983 / "
                        "RS274NGC, read by LinuxCNC), linuxcnc, fanuc (G4 P in ms, G31 "
                        "probing), sinumerik (.mpf: G4 F, MEAS=1, ; comments), heidenhain (.h "
                        "plain language: CYCL DEF 9 dwell, TCH PROBE 0); every program safe "
                        "along its whole path: 'volerr formats plan'")
    p.add_argument("--seed", type=int, default=0,
                   help="seed of the random starts of the exchange (the same seed, the same "
                        "plan)")
    add_force(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..plan import plan
    from ._common import layout_inputs

    require(1 <= args.readings <= 10 ** 7, "--readings must be between 1 and 10000000")
    require(args.minutes is None or args.minutes > 0, "--minutes must be positive")
    from ..plan._dialect import NAMES

    require(args.dialect in NAMES, f"--dialect {args.dialect}: not a dialect; give one of "
                                   f"{', '.join(NAMES)}")
    require(args.parameters is None or args.parameters.strip(),
            "--parameters: empty; give names, axes or groups")
    inputs = layout_inputs(args.layout)
    out = Path(args.out)
    require(not out.exists() or out.is_dir(), f"--out {out}: a file, not a folder")
    outs = Outputs(inputs, force=args.force).folder("--out", out) \
        .file("--json", args.json).file("--html", args.html).file("--pdf", args.pdf).check()
    ident = identification_from_args(args, inputs)
    if out.is_dir() and not args.force:
        taken = sorted(p.name for p in out.iterdir()
                       if p.suffix in (".csv", ".nc", ".html", ".h", ".mpf"))
        require(not taken, f"--out {out}: holds {taken[0] if taken else ''} already; give "
                           f"--force to replace plan files there, or another folder")
    with outs:
        result = plan(args.layout, args.instrument, args.readings, args.parameters,
                      args.minutes, args.criterion, args.seed)
        folder = outs.path("--out")
        result.write(folder, outs.path("--json") if args.json else None,
                     outs.path("--html") if args.html else None, inputs, args.dialect)
        write_certificates(outs, result, ident, inputs)
    print(result.summary())
    return 0
