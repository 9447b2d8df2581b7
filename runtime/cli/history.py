"""``volerr history``: a machine's calibrations and checks over time.

    volerr history add --db DB --machine ID [--date YYYY-MM-DD] [--wait S] RESULT.json...
    volerr history show --db DB --machine ID [--tolerance "NAME=VALUE UNIT,...,map=VALUE um"]
                        [--json F] [--html H] [--wait S]

Parses arguments and calls :mod:`volerr.history`; the rules are stated there and in
``volerr formats history``.
"""

from __future__ import annotations

from ._common import (add_html, add_identification_arguments, add_json,
                      identification_from_args, write_certificates)

EPILOG = """\
DB: a file (SQLite, created by the first add) or a postgresql:// URL (a server; needs
'pip install volerr[postgresql]').  RESULT.json: 'volerr calibrate --json' or 'volerr check
--json' results.  Machine ids: 1 to 64 letters, digits, spaces and . _ - : / + #.
A result added twice to the same machine and date is stored once; on another machine or
date it is refused.  Several adds at once lose nothing (a new SQLite file appears only when
its first entries are committed; a failing add removes nothing but its own staging
folder).  A date (YYYY-MM-DD) after today is refused; a check needs its reference
calibration in the machine's history.  A locked database (another writer): exit 2 after
--wait seconds, nothing written.  show --tolerance: every value with its unit (22 um,
5 urad, 0.02 mm, 3 arcsec; um/m for a small angle).

show --json: {"machine", "layout", "entries": [...], "events": [{"date", "parameter",
"change", "unit", "std"}], "trends": {NAME: {"slope_per_day", "unit", "std", "since", "n"}},
"forecast": {NAME: {"date", "interval": [lo, hi], "tolerance", "unit"}}, "control": {NAME:
{"centre", "shewhart": [...], "ewma": [...]}}}; slope_per_day in the parameter's unit per
day; a null date or interval end: not reached (or open).  'volerr formats history'.
"""


def _common(p) -> None:
    p.add_argument("--db", required=True, metavar="DB",
                   help="the history: a file (SQLite) or a postgresql:// URL")
    p.add_argument("--machine", required=True, metavar="ID", help="the machine's id")
    p.add_argument("--wait", type=float, default=10.0, metavar="S",
                   help="seconds to wait for another writer's lock")


def register(sub) -> None:
    p = sub.add_parser("history", help="a machine's calibrations and checks over time: "
                                       "events, trends, forecast",
                       description="Store calibration and check results per machine (SQLite "
                                   "file or PostgreSQL) and show each parameter over time: "
                                   "control charts (ISO 7870-2 Shewhart, ISO 7870-6 EWMA), "
                                   "change points, trends and the date a tolerance is left.",
                       epilog=EPILOG)
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    a = s.add_parser("add", help="store results (calibrate / check JSON) of a machine",
                     epilog=EPILOG)
    _common(a)
    a.add_argument("--date", metavar="YYYY-MM-DD",
                   help="the date of the results, not after today (default: the date a "
                        "result states, else today, UTC)")
    a.add_argument("results", nargs="+", metavar="RESULT.json", help="result files")
    a.set_defaults(func=run_add)
    sh = s.add_parser("show", help="events, trends, forecast of a machine's history",
                      epilog=EPILOG)
    _common(sh)
    sh.add_argument("--tolerance", metavar="'NAME=V UNIT,map=V um'",
                    help="tolerances |value| <= V of parameters (or of the volumetric error, "
                         "map=), each with its unit (22 um, 5 urad, 0.02 mm, 3 arcsec): the "
                         "date each is left, with a 95 %% interval")
    add_json(sh, "the history (entries, events, trends, forecast, control charts)")
    add_html(sh, "the history page (one chart per parameter)")
    add_identification_arguments(sh)
    sh.set_defaults(func=run_show)


def _wait(args) -> float:
    from ..errors import require

    require(0 <= args.wait <= 3600, f"--wait {args.wait:g}: 0 to 3600 s")
    return args.wait


def run_add(args) -> int:
    from .. import history

    done = history.add(args.db, args.machine, args.results, args.date, _wait(args))
    for entry, what in done:
        print(f"{entry.source}: {entry.kind} of {entry.layout} on {entry.date} for machine "
              f"{args.machine}: {what}")
    return 0


def run_show(args) -> int:
    from .. import history
    from ..fileio import Outputs, write_text

    wait = _wait(args)
    inputs = [] if "://" in args.db else [args.db]
    outs = Outputs(inputs, force=False).file("--json", args.json).file("--html", args.html) \
        .file("--pdf", args.pdf).check()
    ident = identification_from_args(args, inputs)
    ident.machine = ident.machine or (None if ident.machine_details else args.machine)
    h = history.show(args.db, args.machine, args.tolerance, wait)
    text = h.html() if args.html else None
    with outs:
        if args.json:
            h.write_json(outs.path("--json"))
        if text is not None:
            write_text(outs.path("--html"), text)
        write_certificates(outs, h, ident, inputs)
    print(h.summary())
    return 0
