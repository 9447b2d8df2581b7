"""``volerr controller export|import``: error parameters for controllers -- ISG CSV and Etalon
(volumetric compensation, :mod:`volerr.tables.controller`) and the axis compensation tables of
SINUMERIK (LEC, CEC), Heidenhain (``.CMA`` / ``.COM``) and Fanuc (pitch error compensation)
(:mod:`volerr.tables.controller_tables`).

``volerr controller export LAYOUT --errors DIR --format FORMAT --out F [--json F] [--plot P]``
    writes the tables and constants of an error directory; for the axis compensation formats
    it compares what compensating with the tables leaves (the model's volumetric error over
    the working volume after their correction, max and rms) with the uncompensated error, on
    the console and in ``--json``, and refuses (exit 2) tables that leave more than none
    unless ``--force``; ``--plot`` maps both.  ``--format linuxcnc``: ``--out`` is a folder
    (one ``COMP_FILE`` per joint and the ini lines).
``volerr controller export LAYOUT_aug.toml --format sinumerik-temp|isg-temp --loop-json F
--temperatures LOG.csv --out DIR``
    the temperature compensation a controller runs (per axis offset and gradient, linear in
    the temperatures it reads) fitted to an augmented layout's thermal effects on a logged
    series, with what it leaves against the full model (:mod:`volerr.tables.thermal_comp`).
``volerr controller import LAYOUT FILE --out DIR [--format ...]``
    reads such a file back into an error directory (``X.csv`` ... ``constants.csv``).
"""

from __future__ import annotations

from pathlib import Path

from ..errors import require

AXIS_FORMATS = ("sinumerik-lec", "sinumerik-cec", "heidenhain", "fanuc", "linuxcnc")
TEMP_FORMATS = ("sinumerik-temp", "isg-temp")


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
    e.set_defaults(func=run)
    i = s.add_parser("import", help="controller file -> error directory")
    i.add_argument("layout", help="layout name or file")
    i.add_argument("file", help="controller file (heidenhain: the .cma, its .com tables next "
                                "to it; linuxcnc: the ini naming the COMP_FILEs)")
    i.add_argument("--format", choices=("auto", "isg", "etalon") + AXIS_FORMATS,
                   default="auto", help="the file's format (auto: isg or etalon)")
    from ._common import add_errors_out, add_force

    add_errors_out(i, "the imported tables", "--out", required=True)
    add_force(i)
    i.add_argument("--negate", action="store_true",
                   help="isg / etalon: the file holds compensation values: reverse their sign")
    i.set_defaults(func=run)


def run(args) -> int:
    from ..machine.model import load

    model = load(args.layout)
    if args.action == "export":
        if args.format in TEMP_FORMATS:
            return _export_temperature(args, model)
        for flag in ("loop_json", "temperatures", "sensors"):
            require(getattr(args, flag) is None, f"--{flag.replace('_', '-')} is for "
                                                 f"{' / '.join(TEMP_FORMATS)}")
        require(args.errors is not None, f"--errors DIR is needed for --format {args.format}")
        require(not Path(args.errors).is_file(), f"{args.errors} is a file, not an error "
                                                  f"directory (the folder holding X.csv ...)")
        require(Path(args.errors).is_dir(), f"error directory not found: {args.errors}")
        if args.format in AXIS_FORMATS:
            return _export_axis_tables(args, model)
        return _export_volumetric(args, model)
    if args.format in AXIS_FORMATS:
        return _import_axis_tables(args, model)
    return _import_volumetric(args, model)


def _export_volumetric(args, model) -> int:
    from ..tables import controller as ct
    from ..tables.table import read_error_dir
    from ._common import layout_inputs
    from ..fileio import Outputs, json_text, write_text

    for flag in ("plot", "points", "comp_file_type"):
        require(getattr(args, flag) is None, f"--{flag.replace('_', '-')} is for the axis "
                                             f"compensation formats ({' '.join(AXIS_FORMATS)})")
    tables, (consts, _, _) = read_error_dir(args.errors, model.axes)
    ct.check_against_model(model, tables, consts, args.errors)
    require(tables or consts, f"{args.errors}: no error tables or constants to export")
    if args.negate:
        tables, consts = ct.negated(tables, consts)
    writer = ct.write_isg if args.format == "isg" else ct.write_etalon
    inputs = list(Path(args.errors).glob("*.csv")) + layout_inputs(args.layout)
    outs = Outputs(inputs).file("--out", args.out).file("--json", args.json).check()
    s = _volumetric_left(args, model)
    require(not worse_than_none(s) or args.force,
            f"{model.name}: a volumetric compensation with these parameters leaves more than "
            f"none (max {_change(s, 'max')}, rms {_change(s, 'rms')}); nothing written "
            "(--force writes it anyway)")
    with outs:
        write_text(outs.path("--out"), writer(model.name, tables, consts), inputs)
        if args.json:
            write_text(outs.path("--json"), json_text(
                {"layout": model.name, "format": args.format, **s,
                 "worse_than_none": worse_than_none(s)}), inputs)
    n = sum(len(t.values) for t in tables.values())
    print(f"{model.name}: wrote {n} component errors ({len(tables)} axes) and "
          f"{len(consts)} position errors to {args.out} ({args.format}"
          f"{', negated: compensation values' if args.negate else ''})")
    print(f"  volumetric error over the working volume ({s['points']} points): max "
          f"{_change(s, 'max')}, rms {_change(s, 'rms')} left by a volumetric compensation "
          "with every parameter by the first-order model (its second-order remainder)")
    return 0


def _volumetric_left(args, model) -> dict:
    """What a volumetric compensation with the whole error directory leaves (summary)."""
    from ..fiveaxis.tables_left import volumetric_left
    from ..tables.functions import ErrorFunctions
    from ._common import parse_at

    funcs = ErrorFunctions.from_dir(args.errors, model)
    return volumetric_left(model, funcs, args.grid, parse_at(args.at)).summary()


def _export_axis_tables(args, model) -> int:
    from ..fileio import Outputs, json_text, write_text
    from ..fiveaxis.tables_left import left
    from ..tables import controller_tables as ctl
    from ..tables.functions import ErrorFunctions
    from ._common import layout_inputs, parse_at

    require(not args.negate, "--negate is for isg / etalon (the axis formats have their own "
                             "sign conventions, volerr formats controller)")
    require(args.comp_file_type is None or args.format == "linuxcnc",
            "--comp-file-type is for --format linuxcnc")
    funcs = ErrorFunctions.from_dir(args.errors, model)
    tables = ctl.build(funcs, args.format, args.points)
    inputs = list(Path(args.errors).glob("*.csv")) + layout_inputs(args.layout)
    outs = Outputs(inputs, force=args.force)
    files = ctl.write(model, tables, args.format, Path(args.out), args.comp_file_type or 0)
    roles = _declare_tables(outs, args, files)
    outs.file("--json", args.json).plot("--plot", args.plot).check()
    result = left(model, funcs, tables, args.grid, parse_at(args.at))
    s = result.summary()
    worse = worse_than_none(s)
    require(not worse or args.force,
            f"{model.name}: these {args.format} tables leave more than no compensation "
            f"(max {_change(s, 'max')}, rms {_change(s, 'rms')}); nothing written "
            "(--force writes them anyway)")
    with outs:
        for path, text in files.items():
            write_text(_staged(outs, roles[path]), text, inputs)
        if args.json:
            write_text(outs.path("--json"), json_text(
                {"layout": model.name, "format": args.format, **s,
                 "worse_than_none": worse,
                 "tables": [{"parameter": t.parameter, "input": t.input, "output": t.output,
                             "points": len(t.values), "start": t.start, "step": t.step,
                             "modulo": t.modulo, "direction": t.direction}
                            for t in tables]}), inputs)
        if args.plot:
            ctl.plot_left(result, outs.path("--plot"),
                          f"{model.name}: what {args.format} tables leave")
    print(f"{model.name}: wrote {len(tables)} {args.format} tables "
          f"({', '.join(sorted({t.parameter for t in tables}))}) to {args.out}")
    print(f"  volumetric error over the working volume ({s['points']} points): max "
          f"{_change(s, 'max')}, rms {_change(s, 'rms')} left after the tables' correction")
    print("  WORSE than no compensation: written because of --force" if worse else
          "  better than no compensation (max and rms)")
    return 0


def worse_than_none(summary: dict) -> bool:
    """Tables that leave a larger max or rms of the volumetric error than no compensation
    (compared at 1 nm, below which a difference is the rounding of the tables' values)."""
    b, a = summary["before_um"], summary["left_um"]
    return a["max"] > b["max"] + 1e-3 or a["rms"] > b["rms"] + 1e-3


def _change(s: dict, key: str) -> str:
    return f"{s['before_um'][key]:.2f} -> {s['left_um'][key]:.2f} um"


def _declare_tables(outs, args, files: dict) -> dict:
    """Declare the table files on ``outs``; {path: its role}.  One file: ``--out``; Heidenhain
    (.cma + .com): a group, nothing replaced without --force; LinuxCNC: the folder --out."""
    if args.format == "linuxcnc":
        outs.folder("--out", args.out, files=[Path(p).name for p in files])
        return {path: ("--out", Path(path).name) for path in files}
    from ..fileio import Outputs

    roles = {path: Outputs.group_role("--out", files, k) for k, path in enumerate(files)}
    if len(files) > 1:
        outs.group("--out", files)
    else:
        outs.file("--out", args.out)
    return roles


def _staged(outs, role):
    """Where to write a table file now: a file role, or (folder role, name in it)."""
    if isinstance(role, tuple):
        return outs.path(role[0]) / role[1]
    return outs.path(role)


def _export_temperature(args, model) -> int:
    from ..fileio import Outputs, json_text, write_text
    from ..tables import thermal_comp as tc
    from ._common import layout_inputs, parse_at

    require(args.errors is None, f"--errors is not for {args.format} (the augmented "
                                 "layout's thermal effects and --loop-json give the model)")
    for flag in ("negate", "comp_file_type", "points", "plot"):
        require(getattr(args, flag) in (None, False),
                f"--{flag.replace('_', '-')} is not for {args.format}")
    require(args.loop_json is not None, f"--loop-json F is needed for {args.format} (the "
                                        "loop report with the effects' fitted values)")
    require(args.temperatures is not None, f"--temperatures LOG.csv is needed for "
                                           f"{args.format}")
    name = "temp_comp.spf" if args.format == "sinumerik-temp" else "temp_comp.lis"
    inputs = [args.loop_json, args.temperatures] + layout_inputs(args.layout)
    outs = Outputs(inputs, force=args.force).folder("--out", args.out, files=[name])
    outs.file("--json", args.json).check()
    values = tc.effect_values(model, args.loop_json)
    log = tc.read_log(args.temperatures)
    sensors = [s.strip() for s in args.sensors.split(",")] if args.sensors else None
    res = tc.fit(model, values, log, sensors, args.grid, parse_at(args.at))
    s = res.summary()
    worse = worse_than_none(s)
    require(not worse or args.force,
            f"{model.name}: this {args.format} model leaves more of the thermal error than "
            f"no compensation (max {_change(s, 'max')}, rms {_change(s, 'rms')}); nothing "
            "written (--force writes it anyway)")
    text = tc.write_sinumerik(res) if args.format == "sinumerik-temp" else \
        tc.write_isg(res, model.axes)
    with outs:
        write_text(outs.path("--out") / name, text, inputs)
        if args.json:
            write_text(outs.path("--json"), json_text(
                {"format": args.format, **s, "worse_than_none": worse}), inputs)
    _print_temperature(model, args, res, s, worse, name)
    return 0


def _print_temperature(model, args, res, s, worse, name) -> None:
    print(f"{model.name}: wrote {args.format} ({', '.join(a.axis for a in res.axes)}; "
          f"reading {', '.join(res.sensors)}) to {Path(args.out) / name}")
    print(f"  thermal error of the full model on {s['samples']} readings of the log x "
          f"{s['points']} points: max {s['before_um']['max']:.2f} um, rms "
          f"{s['before_um']['rms']:.2f} um; left by the controller's model (static, linear in "
          f"position and in the sensors): max {s['left_um']['max']:.2f} um, rms "
          f"{s['left_um']['rms']:.2f} um")
    if res.lags:
        lg = s["left_with_lagged_sensors_um"]
        print("  the effects act through lags the controller's model does not compute ("
              + ", ".join(f"{c}: {tau:g} s" for c, tau in res.lags) + f"); with the sensors "
              f"filtered by those lags (in the PLC) it would leave max {lg['max']:.2f} um, rms "
              f"{lg['rms']:.2f} um")
    print("  WORSE than no compensation: written because of --force" if worse else
          "  better than no compensation (max and rms)")


def _import_volumetric(args, model) -> int:
    from ..tables import controller as ct
    from ._common import layout_inputs
    from ..fileio import Outputs
    from ..tables.table import write_error_dir

    inputs = [args.file] + layout_inputs(args.layout)
    outs = Outputs(inputs, force=args.force).folder("--errors-out", args.errors_out,
                                  files=[f"{a}.csv" for a in model.axes] + ["constants.csv"])
    outs.check()
    tables, consts = ct.read_controller_file(args.file, model, args.format)
    if args.negate:
        tables, consts = ct.negated(tables, consts)
    with outs:
        write_error_dir(outs.path("--errors-out"), tables, consts or None, inputs=inputs)
    n = sum(len(t.values) for t in tables.values())
    print(f"{model.name}: read {n} component errors ({len(tables)} axes) and {len(consts)} "
          f"position errors from {args.file}; wrote {Path(args.errors_out)}/")
    return 0


def _import_axis_tables(args, model) -> int:
    from ..fileio import Outputs
    from ..tables import controller_tables as ctl
    from ..tables.table import write_error_dir
    from ._common import layout_inputs

    require(not args.negate, "--negate is for isg / etalon")
    inputs = [args.file] + layout_inputs(args.layout)
    outs = Outputs(inputs, force=args.force).folder(
        "--errors-out", args.errors_out,
        files=[f"{a}.csv" for a in model.axes] + ["constants.csv"])
    outs.check()
    tables = ctl.import_tables(model, args.file, args.format)
    with outs:
        write_error_dir(outs.path("--errors-out"), tables, None, inputs=inputs)
    n = sum(len(t.values) for t in tables.values())
    print(f"{model.name}: read {n} component errors ({len(tables)} axes) from {args.file} "
          f"({args.format}); wrote {Path(args.errors_out)}/")
    return 0
