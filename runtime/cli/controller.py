"""``volerr controller export|import``: controller compensation tables; see ``volerr
controller export --help`` and :mod:`volerr.fiveaxis.controller_api`."""

from __future__ import annotations

from ..choices import CONTROLLER_AXIS_FORMATS as AXIS_FORMATS
from ..choices import CONTROLLER_TEMP_FORMATS as TEMP_FORMATS
from ._common import (add_accept_implausible, add_errors_out, add_force, command_parser,
                      options_of, parse_at)


def register(sub) -> None:
    p, _ = command_parser(sub, "controller")
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    e, H = command_parser(s, "export", "controller-export")
    e.add_argument("layout", help="layout name or file")
    e.add_argument("--errors", metavar="DIR", help=H["--errors"])
    e.add_argument("--format", choices=("isg", "etalon") + AXIS_FORMATS + TEMP_FORMATS,
                   required=True, help=H["--format"])
    e.add_argument("--out", required=True, help=H["--out"])
    e.add_argument("--loop-json", metavar="F", help=H["--loop-json"])
    e.add_argument("--temperatures", metavar="LOG.csv", help=H["--temperatures"])
    e.add_argument("--sensors", metavar="T_a,T_b", help=H["--sensors"])
    e.add_argument("--comp-file-type", type=int, choices=(0, 1), default=None,
                   help=H["--comp-file-type"])
    e.add_argument("--negate", action="store_true", help=H["--negate"])
    e.add_argument("--force", action="store_true", help=H["--force"])
    e.add_argument("--points", type=int, default=None, metavar="N", help=H["--points"])
    e.add_argument("--json", metavar="F", help=H["--json"])
    e.add_argument("--plot", metavar="PNG", help=H["--plot"])
    e.add_argument("--grid", type=int, default=9, metavar="N", help=H["--grid"])
    e.add_argument("--at", action="append", default=[], metavar="AXIS=DEG", help=H["--at"])
    add_accept_implausible(e)
    e.set_defaults(func=run)
    i, H = command_parser(s, "import", "controller-import")
    i.add_argument("layout", help="layout name or file")
    i.add_argument("file", help=H["file"])
    i.add_argument("--format", choices=("auto", "isg", "etalon") + AXIS_FORMATS,
                   default="auto", help="the file's format (auto: isg or etalon)")
    add_errors_out(i, "the imported tables", "--out", required=True)
    add_force(i)
    add_accept_implausible(i)
    i.add_argument("--negate", action="store_true", help=H["--negate"])
    i.set_defaults(func=run)


def run(args):
    from ..fiveaxis.controller_api import controller_export, controller_import

    if args.action == "export":
        return controller_export(args.layout, args.errors, at=parse_at(args.at), **options_of(
            args, "format out json plot loop_json temperatures sensors comp_file_type negate "
                  "force points grid accept_implausible"))
    return controller_import(args.layout, args.file, out=args.errors_out, **options_of(
        args, "format negate force accept_implausible"))
