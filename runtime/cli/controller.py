"""``volerr controller export|import``: error parameters for controllers -- ISG CSV and Etalon
(volumetric compensation, :mod:`volerr.tables.controller`) and the axis compensation tables of
SINUMERIK (LEC, CEC), Heidenhain (``.CMA`` / ``.COM``) and Fanuc (pitch error compensation)
(:mod:`volerr.tables.controller_tables`).

See ``volerr controller export --help``, :func:`volerr.controller_export` /
:func:`volerr.controller_import` (:mod:`volerr.fiveaxis.controller_api`).
"""

from __future__ import annotations

from ..choices import CONTROLLER_AXIS_FORMATS as AXIS_FORMATS
from ..choices import CONTROLLER_TEMP_FORMATS as TEMP_FORMATS
from ._common import add_accept_implausible, add_errors_out, add_force, parse_at


def register(sub) -> None:
    p = sub.add_parser("controller", help="export/import controller compensation tables",
                       description=__doc__.split("\n\n")[0])
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    e = s.add_parser("export", help="error directory -> controller file")
    e.add_argument("layout", help="layout name or file")
    e.add_argument("--errors", metavar="DIR", help="error directory (not for the -temp "
                                                   "formats)")
    e.add_argument("--format", choices=("isg", "etalon") + AXIS_FORMATS + TEMP_FORMATS,
                   required=True,
                   help="isg / etalon: volumetric compensation parameters; sinumerik-lec "
                        "(positioning), sinumerik-cec (straightness), heidenhain (.CMA with "
                        ".COM tables next to it), fanuc (pitch error compensation tape): axis "
                        "compensation tables, within each controller's documented limits; "
                        "linuxcnc: [JOINT_n] COMP_FILE tables; sinumerik-temp / isg-temp: "
                        "temperature compensation from an augmented layout's thermal effects "
                        "(volerr formats axis-tables, thermal-comp)")
    e.add_argument("--out", required=True,
                   help="controller file to write (heidenhain: the .cma; its .com tables "
                        "are written next to it; linuxcnc: a folder for <axis>.comp and "
                        "compensation.ini)")
    e.add_argument("--loop-json", metavar="F",
                   help="-temp formats: the report (volerr loop --json) of the run that wrote "
                        "the augmented layout: its effects' fitted parameters")
    e.add_argument("--temperatures", metavar="LOG.csv",
                   help="-temp formats: a logged series (time column t_s / t_min / t_h, the "
                        "temperatures T_*) on which the controller's model is fitted and "
                        "judged against the full one")
    e.add_argument("--sensors", metavar="T_a,T_b",
                   help="-temp formats: the temperatures the controller reads (default: "
                        "those the thermal effects read)")
    e.add_argument("--comp-file-type", type=int, choices=(0, 1), default=None,
                   help="linuxcnc: COMP_FILE_TYPE 0 (nominal, actual forward, actual "
                        "reverse; default) or 1 (nominal, forward trim, reverse trim)")
    e.add_argument("--negate", action="store_true",
                   help="isg / etalon: write compensation values (the errors with reversed "
                        "sign) for a controller that expects them")
    e.add_argument("--force", action="store_true",
                   help="axis tables: write tables that leave more of the volumetric error "
                        "than no compensation (refused without it); heidenhain / linuxcnc: "
                        "let the export replace existing files")
    e.add_argument("--points", type=int, default=None, metavar="N",
                   help="axis tables: at most N equally spaced points per table (default: "
                        "the finest spacing of the error table, up to the format's limit)")
    e.add_argument("--json", metavar="F",
                   help="JSON {format, left_um: {max, rms}, before_um, "
                        "worse_than_none, tables}: what compensating with the tables leaves "
                        "of the model's volumetric error over the working volume")
    e.add_argument("--plot", metavar="PNG",
                   help="axis tables: map of the volumetric error before and after the "
                        "tables' correction (three levels of the last linear axis)")
    e.add_argument("--grid", type=int, default=9, metavar="N",
                   help="grid points per linear axis of what the export leaves (console, "
                        "--json, --plot): over the part of the travel the error tables cover "
                        "(-temp formats: the travel; default 9)")
    e.add_argument("--at", action="append", default=[], metavar="AXIS=DEG",
                   help="position of a rotary axis for what the export leaves, "
                        "repeatable (default 0 deg)")
    add_accept_implausible(e)
    e.set_defaults(func=run)
    i = s.add_parser("import", help="controller file -> error directory")
    i.add_argument("layout", help="layout name or file")
    i.add_argument("file", help="controller file (heidenhain: the .cma, its .com tables next "
                                "to it; linuxcnc: the ini naming the COMP_FILEs)")
    i.add_argument("--format", choices=("auto", "isg", "etalon") + AXIS_FORMATS,
                   default="auto", help="the file's format (auto: isg or etalon)")
    add_errors_out(i, "the imported tables", "--out", required=True)
    add_force(i)
    add_accept_implausible(i)
    i.add_argument("--negate", action="store_true",
                   help="isg / etalon: the file holds compensation values: reverse their sign")
    i.set_defaults(func=run)


def run(args) -> int:
    from ..fiveaxis.controller_api import controller_export, controller_import

    if args.action == "export":
        result = controller_export(
            args.layout, args.errors, format=args.format, out=args.out, json=args.json,
            plot=args.plot, loop_json=args.loop_json, temperatures=args.temperatures,
            sensors=args.sensors, comp_file_type=args.comp_file_type, negate=args.negate,
            force=args.force, points=args.points, grid=args.grid, at=parse_at(args.at),
            accept_implausible=args.accept_implausible)
    else:
        result = controller_import(args.layout, args.file, out=args.errors_out,
                                   format=args.format, negate=args.negate, force=args.force,
                                   accept_implausible=args.accept_implausible)
    print(result.summary())
    return 0
