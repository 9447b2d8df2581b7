"""``volerr drift convert``: a logger's file -> a drift file (``drift_test.drift_convert``)."""

from __future__ import annotations

from ._common import command_parser


def register(sub) -> None:
    p, _ = command_parser(sub, "drift")
    steps = p.add_subparsers(dest="step", metavar="STEP", required=True)
    c, H = command_parser(steps, "convert", "drift-convert")
    a = c.add_argument
    a("raw", metavar="RAW.csv", help="the logger's file (CSV, UTF-8)")
    a("--out", required=True, metavar="F", help="the drift file to write")
    a("--map", metavar="'RAW=NAME,...'", help=H["--map"])
    a("--time-unit", choices=("s", "min", "h"), help=H["--time-unit"])
    a("--channel", action="append", metavar="'LABEL=DIR [at z=MM]'", help=H["--channel"])
    a("--force", action="store_true",
      help="accepted for uniformity with the other commands; a file named by --out is "
           "replaced either way (only output folders need --force), and never when the "
           "input is refused")
    c.set_defaults(func=run)


def run(args) -> int:
    from ..fileio import Outputs
    from ..instruments.drift_test import drift_convert

    with Outputs([args.raw], force=args.force).file("--out", args.out).check() as outs:
        res = drift_convert(args.raw, mapping=args.map, time_unit=args.time_unit,
                            channels=args.channel)
        res.write(outs.path("--out"), inputs=[args.raw])
    print(res.summary(args.out))
    return 0
