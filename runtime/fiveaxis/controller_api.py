"""``volerr.controller_export(...)`` / ``volerr.controller_import(...)``: the Python API of
``volerr controller export|import`` (:mod:`volerr.results`).

The capability: an error directory as a controller's compensation -- ISG CSV and Etalon
(volumetric compensation, :mod:`volerr.tables.controller`), the axis compensation tables of
SINUMERIK (LEC, CEC), Heidenhain (``.CMA`` / ``.COM``), Fanuc (pitch error compensation) and
LinuxCNC (:mod:`volerr.tables.controller_tables`), the temperature compensation a controller
runs (:mod:`volerr.tables.thermal_comp`) -- with what the compensation leaves of the model's
volumetric error over the working volume (:mod:`volerr.fiveaxis.tables_left`; compared with
no compensation by :func:`volerr.tables.controller_tables.worse_than_none`), and such files
read back into an error directory.

Here, in the five-axis room, because what the tables leave needs the volume of the error
tables (:mod:`volerr.cmm.volmap`) and the chain's nominal Jacobian; the formats themselves
stay in :mod:`volerr.tables`.  Units: mm / deg positions, mm / rad errors inside; what is left
in um (max and rms of the length of the 3-D volumetric error).
"""

from __future__ import annotations

from ..choices import CONTROLLER_AXIS_FORMATS, CONTROLLER_TEMP_FORMATS

from dataclasses import dataclass, field
from pathlib import Path

from ..errors import require
from ..fileio import layout_inputs
from ..results import ResultMixin, Row
from ..tables.controller_tables import worse_than_none

#: the axis compensation formats (tables of one error against one axis)
AXIS_FORMATS = CONTROLLER_AXIS_FORMATS
#: the temperature compensation formats (fitted to an augmented layout's thermal effects)
TEMP_FORMATS = CONTROLLER_TEMP_FORMATS
#: the volumetric compensation formats (every parameter of the error directory)
VOLUMETRIC_FORMATS = ("isg", "etalon")


@dataclass(repr=False)
class ControllerExport(ResultMixin):
    """Result of :func:`controller_export`.

    Attributes
    ----------
    data : dict
        The ``--json`` document: ``format``, ``before_um`` / ``left_um`` ``{max, rms}`` (um:
        the length of the model's volumetric error over the working volume without and with
        the compensation), ``points``, ``worse_than_none`` (and ``layout``, ``tables`` ...
        as the format has them).
    files : dict
        Path -> text of every controller file (written when ``out`` was given).
    lines : list of str
        What ``volerr controller export`` prints (:meth:`summary`).
    left : object
        What the compensation leaves on the grid (:class:`volerr.fiveaxis.tables_left.Left`,
        or the :class:`volerr.tables.thermal_comp.TempComp` of a temperature format).
    tables : list
        The axis tables (:class:`volerr.tables.comp_tables` tables; empty for the other
        formats).
    """

    data: dict
    files: dict
    lines: list
    left: object = None
    tables: list = field(default_factory=list)

    def _rows(self) -> list:
        # what is left against no compensation: exact figures of the grid, no uncertainty
        d = self.data
        return [Row(f"{which}_{stat}", float(d[key][stat]), None, "um", 1.0)
                for which, key in (("before", "before_um"), ("left", "left_um"))
                for stat in ("max", "rms")]

    def figures(self) -> dict:
        """``{"left"}``: ``|e|`` before and after the axis tables' correction on three levels of
        the last linear axis (axis formats only; none for the others)."""
        if not self.tables or self.left is None:
            return {}
        from ..tables.controller_tables import left_figure

        return {"left": left_figure(self.left, f"{self.data['layout']}: what "
                                               f"{self.data['format']} tables leave")}


@dataclass(repr=False)
class ControllerImport(ResultMixin):
    """Result of :func:`controller_import`: ``tables`` axis ->
    :class:`volerr.tables.table.ErrorTable` (positions mm / deg, errors mm / rad),
    ``constants`` ISO name -> value (mm / rad), ``data`` what was read (counts),
    ``lines`` what ``volerr controller import`` prints."""

    data: dict
    tables: dict
    constants: dict
    lines: list

    def _rows(self) -> list:
        out = [Row(n, v * (1e6 if n[1] in "ABC" else 1e3), None,
                   "urad" if n[1] in "ABC" else "um", 1.0)
               for n, v in self.constants.items()]
        for axis, t in self.tables.items():
            for name, values in t.values.items():
                f, unit = (1e6, "urad") if name[1] in "ABC" else (1e3, "um")
                out += [Row(f"{name}({q:g})", f * float(v), None, unit, 1.0)
                        for q, v in zip(t.positions, values)]
        return out


def controller_export(layout, errors=None, *, format: str, out=None, json=None, plot=None,
                      loop_json=None, temperatures=None, sensors=None, comp_file_type=None,
                      negate: bool = False, force: bool = False, points=None,
                      grid: int = 9, at=None,
                      accept_implausible: bool = False) -> ControllerExport:
    """An error directory as a controller's compensation, with what it leaves of the
    volumetric error (``volerr controller export``).

    Parameters
    ----------
    layout : str or path
        Layout name or file (for the ``-temp`` formats the augmented layout of a loop run).
    errors : str or path, optional
        Error directory (``X.csv`` ... ``constants.csv``: mm / um, rad / urad as their
        columns say); needed by every format but the ``-temp`` ones.
    format : str
        ``isg`` / ``etalon`` (volumetric compensation parameters), ``sinumerik-lec``,
        ``sinumerik-cec``, ``heidenhain``, ``fanuc``, ``linuxcnc`` (axis compensation
        tables), ``sinumerik-temp`` / ``isg-temp`` (temperature compensation).
    out : str or path, optional
        The controller file to write (heidenhain: the ``.cma``, its ``.com`` tables next to
        it; linuxcnc and the ``-temp`` formats: a folder).  None: nothing written; the texts
        are in ``files``.
    json, plot : str or path, optional
        The ``--json`` document and (axis formats) the PNG map of before / after.
    loop_json, temperatures, sensors
        ``-temp`` formats: the loop report with the effects' fitted values, the logged
        temperature series (``t_s`` / ``t_min`` / ``t_h``, ``T_*`` in degC) and the sensors
        the controller reads (``"T_a,T_b"``; default those of the thermal effects).
    comp_file_type : {0, 1}, optional
        linuxcnc: ``COMP_FILE_TYPE`` (default 0).
    negate : bool
        isg / etalon: write compensation values (the errors with reversed sign).
    force : bool
        Write a compensation that leaves more than none (refused otherwise); heidenhain /
        linuxcnc / -temp: let the export replace existing files.
    points : int, optional
        Axis tables: at most this many equally spaced points per table.
    grid : int
        Grid points per linear axis of what the export leaves (2 .. 60).
    at : dict, optional
        Rotary axis -> position (deg) for what the export leaves (default 0).
    accept_implausible : bool
        ``--accept-implausible``: error values beyond what a machine of the layout's travel
        can have (:mod:`volerr.tables.plausible`) used instead of refused (by default
        refused naming the file, the column and the likely unit).

    Returns
    -------
    ControllerExport
        ``to_dict()`` is ``--json`` (um); ``summary()`` the console text.

    Raises
    ------
    volerr.InputError
        Bad input, or a compensation that leaves more than none without ``force``
        (one line; nothing written).
    """
    from ..machine.model import load

    model = load(layout)
    o = _Options(layout, errors, format, out, json, plot, loop_json, temperatures, sensors,
                 comp_file_type, negate, force, points, grid, dict(at or {}),
                 accept_implausible)
    if format in TEMP_FORMATS:
        return _export_temperature(o, model)
    for flag in ("loop_json", "temperatures", "sensors"):
        require(getattr(o, flag) is None, f"--{flag.replace('_', '-')} is for "
                                          f"{' / '.join(TEMP_FORMATS)}")
    require(errors is not None, f"--errors DIR is needed for --format {format}")
    require(not Path(errors).is_file(), f"{errors} is a file, not an error "
                                        f"directory (the folder holding X.csv ...)")
    require(Path(errors).is_dir(), f"error directory not found: {errors}")
    if format in AXIS_FORMATS:
        return _export_axis_tables(o, model)
    require(format in VOLUMETRIC_FORMATS, f"--format {format!r}: one of "
            f"{', '.join(VOLUMETRIC_FORMATS + AXIS_FORMATS + TEMP_FORMATS)}")
    return _export_volumetric(o, model)


@dataclass
class _Options:
    """The export's options (the command's, by name)."""

    layout: object
    errors: object
    format: str
    out: object
    json: object
    plot: object
    loop_json: object
    temperatures: object
    sensors: object
    comp_file_type: object
    negate: bool
    force: bool
    points: object
    grid: int
    at: dict
    accept_implausible: bool = False


def _dest(out, tail: str = "") -> str:
    """Where the console text says the output went: ``out`` (a folder with ``tail`` "/"), or
    "(not written)" when the API call wrote nothing."""
    return "(not written)" if out is None else f"{Path(str(out)) if tail else out}{tail}"


def _refuse_worse(s: dict, force: bool, head: str, it: str = "it") -> bool:
    """Whether the compensation summarised by ``s`` leaves more than none
    (:func:`worse_than_none`); refused (one line starting with ``head``) unless ``force``."""
    worse = worse_than_none(s)
    require(not worse or force, f"{head} (max {_change(s, 'max')}, rms {_change(s, 'rms')}); "
                                f"nothing written (--force writes {it} anyway)")
    return worse


def _change(s: dict, key: str) -> str:
    return f"{s['before_um'][key]:.2f} -> {s['left_um'][key]:.2f} um"


def _export_volumetric(o: _Options, model) -> ControllerExport:
    from ..fileio import Outputs, json_text, write_text
    from ..tables import controller as ct
    from ..tables.functions import ErrorFunctions
    from ..tables.table import read_error_dir
    from .tables_left import volumetric_left

    for flag in ("plot", "points", "comp_file_type"):
        require(getattr(o, flag) is None, f"--{flag.replace('_', '-')} is for the axis "
                                          f"compensation formats ({' '.join(AXIS_FORMATS)})")
    tables, (consts, _, _) = read_error_dir(o.errors, model.axes, machine=model,
                                            accept_implausible=o.accept_implausible)
    ct.check_against_model(model, tables, consts, o.errors)
    require(tables or consts, f"{o.errors}: no error tables or constants to export")
    if o.negate:
        tables, consts = ct.negated(tables, consts)
    writer = ct.write_isg if o.format == "isg" else ct.write_etalon
    inputs = list(Path(o.errors).glob("*.csv")) + layout_inputs(o.layout)
    outs = Outputs(inputs).file("--out", o.out).file("--json", o.json).check()
    res = volumetric_left(model, ErrorFunctions.from_dir(
        o.errors, model, accept_implausible=o.accept_implausible), o.grid, o.at)
    s = res.summary()
    worse = _refuse_worse(s, o.force, f"{model.name}: a volumetric compensation with these "
                                      "parameters leaves more than none")
    doc = {"layout": model.name, "format": o.format, **s, "worse_than_none": worse}
    text = writer(model.name, tables, consts)
    with outs:
        if o.out is not None:
            write_text(outs.path("--out"), text, inputs)
        if o.json:
            write_text(outs.path("--json"), json_text(doc), inputs)
    n = sum(len(t.values) for t in tables.values())
    lines = [f"{model.name}: wrote {n} component errors ({len(tables)} axes) and "
             f"{len(consts)} position errors to {_dest(o.out)} ({o.format}"
             f"{', negated: compensation values' if o.negate else ''})",
             f"  volumetric error over the working volume ({s['points']} points): max "
             f"{_change(s, 'max')}, rms {_change(s, 'rms')} left by a volumetric compensation "
             "with every parameter by the first-order model (its second-order remainder)"]
    key = str(o.out) if o.out is not None else f"{model.name}_{o.format}"
    return ControllerExport(doc, {key: text}, lines, res)


def _export_axis_tables(o: _Options, model) -> ControllerExport:
    from ..fileio import Outputs, json_text, write_text
    from ..tables import controller_tables as ctl
    from ..tables.functions import ErrorFunctions
    from .tables_left import left

    require(not o.negate, "--negate is for isg / etalon (the axis formats have their own "
                          "sign conventions, volerr formats controller)")
    require(o.comp_file_type is None or o.format == "linuxcnc",
            "--comp-file-type is for --format linuxcnc")
    funcs = ErrorFunctions.from_dir(o.errors, model, accept_implausible=o.accept_implausible)
    tables = ctl.build(funcs, o.format, o.points)
    inputs = list(Path(o.errors).glob("*.csv")) + layout_inputs(o.layout)
    outs = Outputs(inputs, force=o.force)
    files = ctl.write(model, tables, o.format, Path(o.out if o.out is not None else
                                                    f"{model.name}_{o.format}"),
                      o.comp_file_type or 0)
    roles = _declare_tables(outs, o, files) if o.out is not None else {}
    outs.file("--json", o.json).plot("--plot", o.plot).check()
    result = left(model, funcs, tables, o.grid, o.at)
    s = result.summary()
    worse = _refuse_worse(s, o.force, f"{model.name}: these {o.format} tables leave more "
                                      "than no compensation", "them")
    doc = {"layout": model.name, "format": o.format, **s, "worse_than_none": worse,
           "tables": [{"parameter": t.parameter, "input": t.input, "output": t.output,
                       "points": len(t.values), "start": t.start, "step": t.step,
                       "modulo": t.modulo, "direction": t.direction} for t in tables]}
    with outs:
        for path, text in files.items():
            if path in roles:
                write_text(_staged(outs, roles[path]), text, inputs)
        if o.json:
            write_text(outs.path("--json"), json_text(doc), inputs)
        if o.plot:
            ctl.plot_left(result, outs.path("--plot"),
                          f"{model.name}: what {o.format} tables leave")
    lines = [f"{model.name}: wrote {len(tables)} {o.format} tables "
             f"({', '.join(sorted({t.parameter for t in tables}))}) to {_dest(o.out)}",
             f"  volumetric error over the working volume ({s['points']} points): max "
             f"{_change(s, 'max')}, rms {_change(s, 'rms')} left after the tables' correction",
             "  WORSE than no compensation: written because of --force" if worse else
             "  better than no compensation (max and rms)"]
    return ControllerExport(doc, files, lines, result, tables)


def _declare_tables(outs, o: _Options, files: dict) -> dict:
    """Declare the table files on ``outs``; {path: its role}.  One file: ``--out``; Heidenhain
    (.cma + .com): a group, nothing replaced without force; LinuxCNC: the folder ``out``."""
    if o.format == "linuxcnc":
        outs.folder("--out", o.out, files=[Path(p).name for p in files])
        return {path: ("--out", Path(path).name) for path in files}
    from ..fileio import Outputs

    roles = {path: Outputs.group_role("--out", files, k) for k, path in enumerate(files)}
    if len(files) > 1:
        outs.group("--out", files)
    else:
        outs.file("--out", o.out)
    return roles


def _staged(outs, role):
    """Where to write a table file now: a file role, or (folder role, name in it)."""
    if isinstance(role, tuple):
        return outs.path(role[0]) / role[1]
    return outs.path(role)


def _export_temperature(o: _Options, model) -> ControllerExport:
    from ..fileio import Outputs, json_text, write_text
    from ..tables import thermal_comp as tc

    require(o.errors is None, f"--errors is not for {o.format} (the augmented "
                              "layout's thermal effects and --loop-json give the model)")
    for flag in ("negate", "comp_file_type", "points", "plot"):
        require(getattr(o, flag) in (None, False),
                f"--{flag.replace('_', '-')} is not for {o.format}")
    require(o.loop_json is not None, f"--loop-json F is needed for {o.format} (the "
                                     "loop report with the effects' fitted values)")
    require(o.temperatures is not None, f"--temperatures LOG.csv is needed for "
                                        f"{o.format}")
    name = "temp_comp.spf" if o.format == "sinumerik-temp" else "temp_comp.lis"
    inputs = [o.loop_json, o.temperatures] + layout_inputs(o.layout)
    outs = Outputs(inputs, force=o.force)
    if o.out is not None:
        outs.folder("--out", o.out, files=[name])
    outs.file("--json", o.json).check()
    values = tc.effect_values(model, o.loop_json)
    log = tc.read_log(o.temperatures)
    sensors = [s.strip() for s in o.sensors.split(",")] if o.sensors else None
    res = tc.fit(model, values, log, sensors, o.grid, o.at)
    s = res.summary()
    worse = _refuse_worse(s, o.force, f"{model.name}: this {o.format} model leaves more of "
                                      "the thermal error than no compensation")
    text = tc.write_sinumerik(res) if o.format == "sinumerik-temp" else \
        tc.write_isg(res, model.axes)
    doc = {"format": o.format, **s, "worse_than_none": worse}
    with outs:
        if o.out is not None:
            write_text(outs.path("--out") / name, text, inputs)
        if o.json:
            write_text(outs.path("--json"), json_text(doc), inputs)
    where = Path(o.out) / name if o.out is not None else "(not written)"
    return ControllerExport(doc, {str(where) if o.out is not None else name: text},
                            _temperature_lines(model, o, res, s, worse, where), res)


def _temperature_lines(model, o: _Options, res, s, worse, where) -> list:
    out = [f"{model.name}: wrote {o.format} ({', '.join(a.axis for a in res.axes)}; "
           f"reading {', '.join(res.sensors)}) to {where}",
           f"  thermal error of the full model on {s['samples']} readings of the log x "
           f"{s['points']} points: max {s['before_um']['max']:.2f} um, rms "
           f"{s['before_um']['rms']:.2f} um; left by the controller's model (static, linear in "
           f"position and in the sensors): max {s['left_um']['max']:.2f} um, rms "
           f"{s['left_um']['rms']:.2f} um"]
    if res.lags:
        lg = s["left_with_lagged_sensors_um"]
        out.append("  the effects act through lags the controller's model does not compute ("
                   + ", ".join(f"{c}: {tau:g} s" for c, tau in res.lags) + f"); with the "
                   f"sensors filtered by those lags (in the PLC) it would leave max "
                   f"{lg['max']:.2f} um, rms {lg['rms']:.2f} um")
    out.append("  WORSE than no compensation: written because of --force" if worse else
               "  better than no compensation (max and rms)")
    return out


def controller_import(layout, file, *, out=None, format: str = "auto", negate: bool = False,
                      force: bool = False,
                      accept_implausible: bool = False) -> ControllerImport:
    """A controller's compensation file read back into error tables (``volerr controller
    import``).

    Parameters
    ----------
    layout : str or path
        Layout name or file.
    file : str or path
        The controller file (heidenhain: the ``.cma``, its ``.com`` tables next to it;
        linuxcnc: the ini naming the ``COMP_FILE``\\ s).
    out : str or path, optional
        Error directory to write (``X.csv`` ... ``constants.csv``, um / urad); None: not
        written (the tables are in the result).
    format : str
        ``auto`` (isg or etalon, told from the text), ``isg``, ``etalon`` or one of the axis
        formats (``sinumerik-lec`` ... ``linuxcnc``).
    negate : bool
        isg / etalon: the file holds compensation values; reverse their sign.
    force : bool
        Let the import replace files in ``out``.
    accept_implausible : bool
        ``--accept-implausible``: error values beyond what a machine of the layout's travel
        can have (:mod:`volerr.tables.plausible`) used instead of refused (by default
        refused naming the file, the column and the likely unit).

    Returns
    -------
    ControllerImport
        ``tables`` (mm / rad), ``constants``; ``summary()`` the console text.
    """
    from ..fileio import Outputs
    from ..machine.model import load
    from ..tables import controller as ct
    from ..tables import controller_tables as ctl
    from ..tables.table import write_error_dir

    model = load(layout)
    axis = format in AXIS_FORMATS
    if axis:
        require(not negate, "--negate is for isg / etalon")
    inputs = [file] + layout_inputs(layout)
    outs = Outputs(inputs, force=force)
    if out is not None:
        outs.folder("--errors-out", out,
                    files=[f"{a}.csv" for a in model.axes] + ["constants.csv"])
    outs.check()
    if axis:
        tables, consts = ctl.import_tables(model, file, format), {}
    else:
        tables, consts = ct.read_controller_file(file, model, format)
        if negate:
            tables, consts = ct.negated(tables, consts)
    with outs:
        if out is not None:
            write_error_dir(outs.path("--errors-out"), tables,
                            None if axis else (consts or None), inputs=inputs,
                            machine=model, accept_implausible=accept_implausible,
                            shown=out)
    n = sum(len(t.values) for t in tables.values())
    line = (f"{model.name}: read {n} component errors ({len(tables)} axes) from {file} "
            f"({format}); wrote {_dest(out, '/')}" if axis else
            f"{model.name}: read {n} component errors ({len(tables)} axes) and {len(consts)} "
            f"position errors from {file}; wrote {_dest(out, '/')}")
    doc = {"layout": model.name, "file": str(file), "format": format,
           "component_errors": n, "axes": sorted(tables), "constants": len(consts)}
    return ControllerImport(doc, tables, consts, [line])
