"""``volerr check``: the interim check between two calibrations (:mod:`volerr.check`).

    volerr check plan LAYOUT --reference CAL.json --instrument SPEC [--minutes M]
                      [--readings N] [--detect-um D] --out DIR [--json F] [--html H]
    volerr check LAYOUT --reference CAL.json FILE... [--tolerance T] [--date D]
                 [--json F] [--html H]

Parses arguments and calls :func:`volerr.check.plan_check` or :func:`volerr.check.check`.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import InputError, require
from ..fileio import Outputs
from ._common import (add_accept_residual, add_force, add_html, add_identification_arguments,
                      add_json, add_max_change, identification_from_args, write_certificates)

USAGE = ("volerr check plan LAYOUT --reference CAL.json --instrument SPEC [--minutes M] "
         "[--readings N] [--detect-um D] --out DIR [--json F] [--html H]\n"
         "       volerr check LAYOUT --reference CAL.json FILE... [--tolerance T] "
         "[--date YYYY-MM-DD] [--json F] [--html H]")
#: options of one form only
PLAN_ONLY = ("instrument", "minutes", "readings", "detect_um", "out")
CHECK_ONLY = ("tolerance", "date", "max_change")


def register(sub) -> None:
    p = sub.add_parser(
        "check", usage=USAGE,
        help="between calibrations: plan an interim check, or say what changed since the "
             "reference",
        description="'volerr check plan': from a reference calibration (the JSON of "
                    "'volerr calibrate --json', values and covariance) the shortest check "
                    "with the instruments named that detects a change of the volumetric "
                    "error by D um anywhere in the working volume (--detect-um) with 95 % "
                    "probability, false alarms below 5 %; files, NC programs and set-up "
                    "sheet as 'volerr plan' writes them.  'volerr check': the check's filled "
                    "files against the reference: which parameters changed, by how much, "
                    "with uncertainties that hold the reference's covariance (the smallest "
                    "set that explains the readings: forward selection, BIC and "
                    "cross-validation), the verdict unchanged | changed, the volumetric "
                    "change, the parameters the check cannot tell apart, and --tolerance by "
                    "the ISO 14253-1 decision rule.  Formats: 'volerr formats check'.")
    p.add_argument("words", nargs="+", metavar="LAYOUT FILE",
                   help="'plan LAYOUT', or LAYOUT and the check's filled files")
    p.add_argument("--reference", required=True, nargs="+", metavar=("CAL.json", "FILE"),
                   help="the reference: the JSON of 'volerr calibrate --json' (or of an "
                        "earlier 'volerr check --json'); the check's files may follow it")
    p.add_argument("--instrument", action="append", metavar="SPEC",
                   help="check plan: an instrument, as 'volerr plan --instrument' (repeat)")
    p.add_argument("--minutes", type=float, metavar="M",
                   help="check plan: time budget, minutes (the time model of 'volerr formats "
                        "plan')")
    p.add_argument("--readings", type=int, metavar="N",
                   help="check plan: at most N readings (rows of the files)")
    p.add_argument("--detect-um", type=float, metavar="D",
                   help="check plan: the change of the volumetric error to detect, um "
                        "(default 5)")
    p.add_argument("--out", metavar="DIR", help="check plan: folder of the check's files")
    p.add_argument("--tolerance", metavar="T",
                   help="check: \"NAME=VALUE UNIT,...,map=VALUE um\": each parameter's "
                        "|value| and the largest volumetric error after the check against "
                        "its limit (ISO 14253-1, U = 2 u); every VALUE needs its unit "
                        "(converted to the parameter's)")
    p.add_argument("--date", metavar="YYYY-MM-DD", help="check: the date of the check, not "
                                                        "after today (carried into the JSON)")
    add_json(p, "the check plan or the check's result")
    add_html(p, "the set-up sheet (check plan) or the check's page")
    add_identification_arguments(p)
    add_force(p)
    add_accept_residual(p)
    add_max_change(p, reference=False)
    p.set_defaults(func=run)


def run(args) -> int:
    from ._common import layout_inputs

    args.words = args.words + args.reference[1:]      # the files after --reference CAL.json
    args.reference = args.reference[0]
    if args.words[0] == "plan":
        require(len(args.words) == 2, "check plan: give one LAYOUT (usage: " + USAGE.split(
            "\n")[0].strip() + ")")
        _only(args, CHECK_ONLY, "volerr check LAYOUT FILE...")
        return _plan(args, layout_inputs(args.words[1]))
    require(len(args.words) >= 2, "give LAYOUT and the check's files (or 'check plan "
                                  "LAYOUT ...' to plan one)")
    _only(args, PLAN_ONLY, "volerr check plan")
    return _check(args, layout_inputs(args.words[0]))


def _only(args, names, form) -> None:
    for name in names:
        if getattr(args, name) is not None:
            raise InputError(f"--{name.replace('_', '-')} belongs to '{form}'")


def _plan(args, inputs) -> int:
    from ..check import plan_check

    layout = args.words[1]
    require(args.instrument, "check plan: give at least one --instrument")
    require(args.out, "check plan: give --out DIR")
    require(args.readings is None or 1 <= args.readings <= 10 ** 5,
            "--readings must be between 1 and 100000")
    require(args.minutes is None or args.minutes > 0, "--minutes must be positive")
    require(args.detect_um is None or args.detect_um > 0, "--detect-um must be positive")
    inputs = inputs + [Path(args.reference)]
    out = Path(args.out)
    require(not out.exists() or out.is_dir(), f"--out {out}: a file, not a folder")
    outs = Outputs(inputs, force=args.force).folder("--out", out) \
        .file("--json", args.json).file("--html", args.html).file("--pdf", args.pdf).check()
    ident = identification_from_args(args, inputs[-1:] + inputs[:-1])
    if out.is_dir() and not args.force:
        taken = sorted(p.name for p in out.iterdir() if p.suffix in (".csv", ".nc", ".html"))
        require(not taken, f"--out {out}: holds {taken[0] if taken else ''} already; give "
                           f"--force to replace check files there, or another folder")
    with outs:
        kw = {} if args.detect_um is None else {"detect_um": args.detect_um}
        result = plan_check(layout, args.reference, args.instrument, minutes=args.minutes,
                            readings=args.readings, **kw)
        result.write(outs.path("--out"), outs.path("--json") if args.json else None,
                     outs.path("--html") if args.html else None, inputs)
        write_certificates(outs, result, ident, inputs)
    print(result.summary())
    return 0


def _check(args, inputs) -> int:
    from ..check import check
    from ..instruments import split_spec

    layout, files = args.words[0], args.words[1:]
    inputs = inputs + [Path(args.reference)] + [Path(split_spec(f)[1]) for f in files]
    outs = Outputs(inputs, force=args.force).file("--json", args.json) \
        .file("--html", args.html).file("--pdf", args.pdf).check()
    ident = identification_from_args(args, [Path(split_spec(f)[1]) for f in files] + inputs)
    with outs:
        result = check(layout, files, reference=args.reference, tolerance=args.tolerance,
                       date=args.date, accept_residual=args.accept_residual,
                       max_change=args.max_change, accept_change=args.accept_change)
        if args.json:
            result.write_json(outs.path("--json"), inputs=inputs)
        if args.html:
            result.write_html(outs.path("--html"), inputs=inputs)
        write_certificates(outs, result, ident, inputs)
    print(result.summary())
    return 0
