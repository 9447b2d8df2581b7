"""``volerr history add|show``: a machine's results over time (:mod:`volerr.history`)."""

from __future__ import annotations

from ._common import add_html, add_identification_arguments, add_json, command_parser, help_text


def register(sub) -> None:
    p, H = command_parser(sub, "history")
    s = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    a, _ = command_parser(s, "add", "history-add", epilog=help_text("history"))
    sh, _ = command_parser(s, "show", "history-show", epilog=help_text("history"))
    for q in (a, sh):
        q.add_argument("--db", required=True, metavar="DB", help=H["--db"])
        q.add_argument("--machine", required=True, metavar="ID", help="the machine's id")
        q.add_argument("--wait", type=float, default=10.0, metavar="S", help=H["--wait"])
    a.add_argument("--date", metavar="YYYY-MM-DD", help=H["--date"])
    a.add_argument("results", nargs="+", metavar="RESULT.json", help="result files")
    a.set_defaults(func=run_add)
    sh.add_argument("--tolerance", metavar="'NAME=V UNIT,map=V um'", help=H["--tolerance"])
    add_json(sh, H["--json"])
    add_html(sh, "the history page (one chart per parameter)")
    add_identification_arguments(sh)
    sh.set_defaults(func=run_show)


def run_add(args) -> int:
    from ..history.run import add, added_lines

    done = add(args.db, args.machine, args.results, args.date, args.wait)
    if done:
        print(added_lines(done, args.machine))
    return 0


def run_show(args):
    from ..history.run import show
    from ..results import run_command

    def call(_, ident):     # the report's machine: --machine, unless the file states one
        ident.machine = ident.machine or (None if ident.machine_details else args.machine)
        return show(args.db, args.machine, args.tolerance, args.wait)
    return run_command(vars(args), [] if "://" in args.db else [args.db], call)
