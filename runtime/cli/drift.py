"""``volerr drift convert``: a thermal logger's file as saved -> a ``drift`` file.

    volerr drift convert RAW.csv --out drift.csv [--map "ch1(um)=d_ch1_um,..."]
                         [--time-unit s|min|h] [--channel "ch1=X at z=120" ...] [--force]

Parses arguments and calls :func:`volerr.instruments.drift.convert` (the header mapping is
:mod:`volerr.instruments._drift_logger`; ``volerr formats drift``).
"""

from __future__ import annotations

EPILOG = """\
header mapping (each cell, the first rule that fits; --map overrides any):
  Time(s) 時間(s) time_s -> t_s; Time(min) -> t_s (x 60); Time(h) -> t_s (x 3600);
    a time without a unit needs --time-unit; clock times (14:05:30, 2024-03-01 14:05:30,
    01.03.2024 14:05:30; a Date column beside) -> t_s from the first reading
  ch1(um) ch1 [µm] -> d_ch1_um;  ch1(mm) -> d_ch1_um (x 1000)
  t1(°C) -> T_1;  motor(degC) -> T_motor
  spindle(RPM) S(rpm) speed(rpm) -> S_rpm;  other NAME(rpm) -> NAME_rpm
  other NAME(unit) -> NAME_unit;  names already in the drift format are kept.
--channel LABEL=DIR [at z=<mm>]: the channel's direction (X Y Z -X -Y -Z ?) and the sensor's
  height on the mandrel, written as '# channel d_LABEL: ...' header lines.
The converted file is read back before it is written: a file that converts is a file that
'volerr loop LAYOUT drift:FILE' and 'volerr iso230-3 FILE' read.
"""


def register(sub) -> None:
    p = sub.add_parser("drift", help="thermal drift files (ISO 230-3): convert a logger's file",
                       description="Thermal drift files: 'convert' turns a logger's file as "
                                   "saved (Time(min), ch1(um), t1(°C), spindle(RPM) ...) into "
                                   "the drift format (volerr formats drift).")
    steps = p.add_subparsers(dest="step", metavar="STEP", required=True)
    c = steps.add_parser("convert", help="a logger's CSV -> a drift file", epilog=EPILOG,
                         description="Rename the columns of a logger's CSV to the drift format "
                                     "(time in seconds, displacements in um), add the channels' "
                                     "directions, check the result and write it.")
    c.add_argument("raw", metavar="RAW.csv", help="the logger's file (CSV, UTF-8)")
    c.add_argument("--out", required=True, metavar="F", help="the drift file to write")
    c.add_argument("--map", metavar="'RAW=NAME,...'",
                   help="column names: RAW header cell = drift name (over the default rules)")
    c.add_argument("--time-unit", choices=("s", "min", "h"),
                   help="the unit of a time column whose header gives none")
    c.add_argument("--channel", action="append", metavar="'LABEL=DIR [at z=MM]'",
                   help="a channel's direction and height (repeatable)")
    c.add_argument("--force", action="store_true", help="replace an existing --out file")
    c.set_defaults(func=run)


def run(args) -> int:
    from ..fileio import Outputs, write_text
    from ..instruments import _drift_logger as logger
    from ..instruments import drift

    outs = Outputs([args.raw], force=args.force).file("--out", args.out).check()
    text, runs = drift.convert(args.raw, logger.parse_map(args.map), args.time_unit,
                               logger.parse_channels(args.channel))
    with outs:
        write_text(outs.path("--out"), text, inputs=[args.raw])
    for r in runs:
        span = r.t_s[-1] - r.t_s[0]
        head = args.out if len(runs) == 1 else f"{args.out}[{r.run}]"
        print(f"{head}: {r.n} readings over {span:g} s; channels "
              f"{', '.join(f'{k} ({r.directions[k]})' for k in r.channels)}; inputs "
              f"{', '.join(r.inputs) or 'none'}")
    return 0
