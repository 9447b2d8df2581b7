"""``volerr.compensate(...)``: the Python API of ``volerr compensate`` (:mod:`volerr.results`).

The command and this function run one pipeline (:mod:`volerr.fiveaxis.pipeline`): the same
validation, the same chunks, the same summary; the command streams the program into its
``--out`` file, the function keeps it in memory (or streams it into ``out``), so
:meth:`Compensation.write_program` writes the bytes the command writes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from ..results import ResultMixin, Row

#: urad per deg (the corrections of rotary axes in the table)
URAD_PER_DEG = math.pi / 180.0 * 1e6


@dataclass(frozen=True, repr=False)
class Compensation(ResultMixin):
    """Result of :func:`compensate`.

    ``data``: the ``--json`` summary (predicted tool-tip error before / after in um, the
    tool-axis error in urad, the tool offset assumed in mm); ``lines`` the console lines,
    ``notes`` the notes and warnings the command prints on stderr; ``text`` the compensated
    program (None when it was streamed into a file, ``out``); ``blocks`` the per-block
    reports (:class:`volerr.fiveaxis.program.LineReport`; empty when streamed);
    ``corrections`` axis -> (max ``|correction|``, rms correction), mm / deg.  Sign: a
    correction is the written minus the programmed position, about minus the predicted error
    (actual minus nominal tool tip) turned into axis motion."""

    data: dict
    lines: tuple
    notes: tuple
    corrections: dict
    text: str | None = None
    blocks: list = field(default_factory=list)
    axes: tuple = ()
    rotary_axes: tuple = ()
    #: per-block errors for the plot when streamed with ``keep_errors``
    #: (:class:`volerr.fiveaxis.program.ProgramErrors`), else None
    errors: object = None

    def program_errors(self):
        """Per compensated block its line and the tool-tip / tool-axis errors before and
        after (um / urad): :class:`volerr.fiveaxis.program.ProgramErrors`."""
        from ..errors import require
        from .program import ProgramErrors

        if self.errors is not None:
            return self.errors
        require(self.text is not None, "the program was streamed into a file without "
                                       "keep_errors=True: no per-block errors kept")
        return ProgramErrors.from_reports(self.blocks)

    def figures(self) -> dict:
        """``{"program_errors": Figure}``: the predicted tool-tip and tool-axis errors per
        block before and after (what ``--plot`` draws); none when the program was streamed
        into a file without ``keep_errors``."""
        from .plots import draw_program_errors, unsaved

        if self.errors is None and self.text is None:
            return {}
        return {"program_errors": unsaved(draw_program_errors, self.program_errors(),
                                          f"{self.data['layout']}: program")}

    def write_plot(self, path, inputs=(), title: str | None = None) -> Path:
        """The ``--plot`` PNG: the predicted tool-tip error (um) and tool-axis error (urad)
        per block, before and after (:func:`volerr.fiveaxis.plots.plot_program_errors`);
        ``title`` default ``"LAYOUT: program"``."""
        from .plots import plot_program_errors

        return plot_program_errors(self.program_errors(), path,
                                   title=title or f"{self.data['layout']}: program")

    def write_outputs(self, outs, options: dict, ident, inputs=(), title=None, roles=()) -> None:
        """``volerr compensate``'s ``--json``, ``--plot`` (titled ``LAYOUT: PROGRAM``) and the
        certificate of the summary (:func:`volerr.report.stamp.finish` of :meth:`to_dict`),
        inside ``with outs:`` (the program and ``--report`` are streamed by the call)."""
        from ..report.document import Document
        from ..report.stamp import finish

        if options.get("json"):
            self.write_json(outs.path("--json"), inputs)
        if options.get("plot"):
            self.write_plot(outs.path("--plot"), title=f"{self.layout}: {options['program']}")
        finish(outs, Document(self.to_dict()), ident, list(inputs))

    def write_program(self, path, inputs=()) -> Path:
        """Write the compensated program, the bytes ``volerr compensate --out`` writes
        (latin-1, line endings as read); never over an input."""
        from ..errors import require
        from ..fileio import write_bytes

        require(self.text is not None, "the compensated program was streamed into a file "
                                       "(out=...); there is no text to write again")
        return write_bytes(path, self.text.encode("latin-1"), inputs=list(inputs))

    def _rows(self) -> list:
        """Counts, tool-tip error before / after (um), tool-axis error (urad), the
        remaining error's standard uncertainty, the datum's error, the tool offset (mm) and
        the corrections per axis (um / urad): value, std (k = 1) where known, unit, k."""
        s = self.data
        rows = [Row("motion_blocks", float(s["motion_blocks"]), None, "blocks"),
                Row("compensated", float(s["compensated"]), None, "blocks")]
        u = s["max_u_after_um"] or None
        for when in ("before", "after"):
            rows += [Row(f"max_{when}", s[f"max_{when}_um"], u if when == "after" else None,
                         "um"),
                     Row(f"rms_{when}", s[f"rms_{when}_um"], None, "um")]
        rows += [Row("max_orientation_before", s["max_orientation_before_urad"], None, "urad"),
                 Row("max_orientation_after", s["max_orientation_after_urad"], None, "urad"),
                 Row("max_u_after", s["max_u_after_um"], None, "um")]
        if s["datum"] is not None:
            rows += [Row(f"datum_{c}", v, None, "um")
                     for c, v in zip(("dx", "dy", "dz"), s["datum"]["error_um"])]
        rows += [Row(f"tool_offset_{c}", v, None, "mm")
                 for c, v in zip("xyz", s["tool_offset_mm"])]
        for a, (mx, rms) in self.corrections.items():
            f, unit = (URAD_PER_DEG, "urad") if a in self.rotary_axes else (1e3, "um")
            rows += [Row(f"max_correction_{a}", mx * f, None, unit),
                     Row(f"rms_correction_{a}", rms * f, None, unit)]
        return rows

    def __repr__(self) -> str:
        s = self.data
        return (f"<volerr Compensation: {s['layout']}, {s['compensated']} of "
                f"{s['motion_blocks']} blocks, max {s['max_before_um']:.3f} -> "
                f"{s['max_after_um']:.3f} um>")


def compensate(layout, program, errors, *, datum=None, tool=(0.0, 0.0, 0.0),
               tool_length: float | None = None, tool_table=None,
               orientation: bool = False, strategy: str = "full", types=None,
               tol_um: float = 0.1, decimals: int = 4, method: str = "linear", degree=None,
               extrapolate: bool = False, initial=None, check_travel: bool = True,
               arc_tol_um: float = 1.0, dialect: str = "auto", out=None, report=None,
               inputs=(), out_name=None, keep_errors: bool = False,
               progress=None, accept_implausible: bool = False,
               decimal_less: str = "auto") -> Compensation:
    """Rewrite an NC program with compensated coordinates (``volerr compensate``).

    Parameters
    ----------
    layout : str or path
        Layout name or file.
    program : str or path
        A program file, or the program text itself (a string holding a line ending; G-code
        or Heidenhain plain language in machine axis coordinates: mm, rotary axes in deg;
        'volerr formats gcode').
    errors : str or path
        Error directory (``X.csv`` ... ``constants.csv``; 'volerr formats error-table').
    datum : sequence of float or str, optional
        The work datum: axis positions (layout order, mm / deg; rotary axes not given at 0
        deg), or the option's text ``'X,Y,Z[,B,C]'`` / ``'none'``, where the work offset was
        set by probing the part; inside the travel.  The corrections are then relative to
        the error at the datum (which the work offset absorbs); None: every block moves by
        its full volumetric error.
    tool : (3,) mm
        Tool offset in the tool frame: from the point the axis positions refer to (the
        spindle gauge point) to the tool tip.
    tool_length : float, optional
        Tool length L, mm: the tool offset ``(0, 0, -L)`` (the tip L from the point the axes
        refer to, against the tool axis) of every block -- axis positions and TCPM alike;
        refused with a different non-zero ``tool``.
    tool_table : path or dict, optional
        TCPM tool lengths by tool number (CSV ``tool,length_mm`` or ``{number: mm}``), looked
        up at the H, else T, else D word; refused for a program without TCPM.
    orientation, strategy, types, tol_um, decimals, method, degree, extrapolate, initial,
    check_travel, arc_tol_um, dialect, decimal_less
        As the command's options (``volerr compensate --help``); ``types`` a sequence or the
        option's text ``'L-VOL,R-VOL'``, ``initial`` a dict or ``'B=0,C=0'``.
    out, report : path, optional
        Stream the program (and the per-block CSV report) into these files instead of
        keeping the text (for programs of millions of lines); written all or nothing, never
        over ``inputs`` or an input of the run.
    out_name : str, optional
        The name the summary's first line gives the written program (default ``out``).
    keep_errors : bool
        With ``out``: keep the per-block errors for :meth:`Compensation.program_errors`.
    progress : callable, optional
        ``progress(n_lines)`` after every chunk.
    accept_implausible : bool
        ``--accept-implausible``: use error values beyond what a machine of the layout's
        travel can have (:mod:`volerr.tables.plausible`); by default they are refused naming
        the file, the column and the likely unit.

    Returns
    -------
    Compensation
        ``text``: the compensated program; ``to_dict()``: the ``--json`` summary;
        ``summary()``: the console text; ``table()``: before / after errors (um), tool-axis
        errors (urad), corrections per axis (um / urad).
    """
    from .pipeline import execute, prepare
    from .program import FileSink, _Collect

    job = prepare(layout, program, errors, datum=datum, tool=tool, tool_length=tool_length,
                  tool_table=tool_table, orientation=orientation, strategy=strategy,
                  types=types, tol_um=tol_um, decimals=decimals, method=method, degree=degree,
                  extrapolate=extrapolate, initial=initial, check_travel=check_travel,
                  arc_tol_um=arc_tol_um, dialect=dialect,
                  accept_implausible=accept_implausible, decimal_less=decimal_less)
    axes = (tuple(job.model.axes), tuple(job.model.rotary_axes))
    if out is None:
        sink = _Collect(job.model)
        res = execute(job, sink, progress)
        return Compensation(res.data, res.lines, res.notes, res.corrections,
                            "".join(sink.text), sink.reports, *axes)
    sink = FileSink(job.model, out, report, [*job.inputs, *inputs], keep_errors)
    try:
        res = execute(job, sink, progress, out_name if out_name is not None else out)
        sink.commit()
    except BaseException:
        sink.discard()
        raise
    return Compensation(res.data, res.lines, res.notes, res.corrections, None, [], *axes,
                        sink.program_errors() if keep_errors else None)


@dataclass(frozen=True, repr=False)
class ToolTipMap(ResultMixin):
    """Result of :func:`tcpmap`: ``map`` the :class:`volerr.fiveaxis.tcpmap.TcpMap` (grid,
    axis positions, tool-tip error in mm, workpiece frame, actual minus nominal), ``data``
    its summary (:meth:`to_dict`: tool-tip error ``|e|`` max / min / rms over the valid grid
    points, um), ``lines`` / ``notes`` what ``volerr tcpmap`` prints on stdout / stderr."""

    map: object
    data: dict
    lines: tuple
    notes: tuple

    def _rows(self) -> list:
        s = self.data
        return [Row("max_error", s["max_um"], None, "um"),
                Row("min_error", s["min_um"], None, "um"),
                Row("rms_error", s["rms_um"], None, "um"),
                Row("valid_points", float(s["valid_points"]), None, "points")]

    def csv_text(self) -> str:
        """The ``--csv`` grid: ``<R1>_deg,<R2>_deg,X_mm,Y_mm,Z_mm,dx_um,dy_um,dz_um,e_um``, one
        row per grid point, empty error cells where invalid."""
        import numpy as np

        t = self.map
        g1, g2 = np.meshgrid(t.q1, t.q2)
        lin = t.linear.reshape(-1, 3)
        e = t.err.reshape(-1, 3) * 1e3
        m = np.linalg.norm(t.err, axis=2).ravel() * 1e3
        rows = [f"{t.axis1}_deg,{t.axis2}_deg,X_mm,Y_mm,Z_mm,dx_um,dy_um,dz_um,e_um"]
        for i in range(g1.size):
            cells = [f"{g1.ravel()[i]:.10g}", f"{g2.ravel()[i]:.10g}"] + \
                [f"{lin[i, k]:.10g}" for k in range(3)]
            cells += [("" if not np.isfinite(v) else f"{v:.6g}") for v in (*e[i], m[i])]
            rows.append(",".join(cells))
        return "\n".join(rows) + "\n"

    def figures(self) -> dict:
        """``{"map": Figure}``: the map ``--plot`` draws."""
        from .plots import draw_tcp_error_map, unsaved

        return {"map": unsaved(draw_tcp_error_map, self.map)}

    def write_plot(self, path, inputs=()) -> Path:
        """The map as PNG (:func:`volerr.fiveaxis.plots.plot_tcp_error_map`); ``inputs``:
        files it must not replace."""
        from ..fileio import check_plot
        from .plots import plot_tcp_error_map

        return plot_tcp_error_map(self.map, check_plot(path, list(inputs)))

    def write_csv(self, path, inputs=()) -> Path:
        """Write :meth:`csv_text` (``--csv``); returns its path."""
        from ..fileio import write_text

        return write_text(path, self.csv_text(), inputs=list(inputs))

    def __repr__(self) -> str:
        s = self.data
        return (f"<volerr ToolTipMap: {s['layout']} at {tuple(s['point_mm'])} mm, max "
                f"{s['max_um']:.3f} um>")


def tcpmap(layout, errors, point, *, tool=(0.0, 0.0, 0.0), steps: int = 73, approach=None,
           method: str = "linear", degree=None, extrapolate: bool = False, plot_name=None,
           progress=None, accept_implausible: bool = False) -> ToolTipMap:
    """Tool-tip error of a five-axis machine over the range of its two rotary axes for one
    workpiece point (``volerr tcpmap``).

    Parameters
    ----------
    layout : str or path
        Five-axis layout name or file.
    errors : str or path
        Error directory.
    point : (3,) mm
        The workpiece point (workpiece frame); at every pair of rotary positions the linear
        axes follow the nominal inverse that keeps the tool tip on it.
    tool : (3,) mm
        Tool offset in the tool frame (a tool L long: ``(0, 0, -L)``).
    steps : int
        Grid steps per rotary axis, 3 .. 1000.
    approach : str or dict, optional
        Approach directions of axes whose tables carry a reversal: ``'X+,Y-'``, ``'+'``,
        ``'-'``, ``'sweep'`` or ``{axis: +1 | -1}`` (default: the bidirectional mean).
    method, degree, extrapolate
        Error functions from the tables (as ``--method`` ``--degree`` ``--extrapolate``).
    plot_name : str, optional
        The name of the written plot the summary line gives ("; wrote NAME").
    progress : callable, optional
        ``progress(n_points)`` block by block.
    accept_implausible : bool
        ``--accept-implausible``: use error values beyond what a machine of the layout's
        travel can have (:mod:`volerr.tables.plausible`); by default refused.

    Returns
    -------
    ToolTipMap
        ``map`` the grid and errors (mm), ``summary()`` the console line, ``table()`` the
        error's max / min / rms (um), ``csv_text()``, ``write_plot(path)``.
    """
    import numpy as np

    from ..errors import require
    from ..machine.model import load
    from ..tables.functions import parse_approach
    from .compensate import error_functions
    from .tcpmap import tcp_map

    model = load(layout)
    require(len(model.rotary_axes) == 2, f"{model.name}: tcpmap needs a five-axis layout")
    require(all(math.isfinite(float(v)) for v in (*point, *tool)), "point/tool must be finite")
    require(3 <= steps <= 1000, "--steps must be 3..1000")
    require(not Path(errors).is_file(), f"{errors} is a file, not an error "
                                        f"directory (the folder holding X.csv ...)")
    require(Path(errors).is_dir(), f"error directory not found: {errors}")
    funcs, notes = error_functions(errors, model, method, degree, extrapolate,
                                   accept_implausible)
    if approach != "sweep" and not isinstance(approach, dict):
        approach = parse_approach(approach, model, funcs)
    tmap = tcp_map(model, funcs, point, tool, steps, steps, approach=approach,
                   progress=progress)
    require(tmap.valid.any(), f"{model.name}: the point is outside the travel or the error "
                              "tables for every rotary position")
    mag = np.linalg.norm(tmap.err, axis=2) * 1e3
    ok = mag[tmap.valid]
    data = {"layout": model.name, "point_mm": [float(v) for v in point],
            "tool_mm": [float(v) + 0.0 for v in tool], "axes": [tmap.axis1, tmap.axis2],
            "range_deg": [[float(tmap.q1[0]), float(tmap.q1[-1])],
                          [float(tmap.q2[0]), float(tmap.q2[-1])]],
            "max_um": float(np.nanmax(mag)), "min_um": float(np.nanmin(mag)),
            "rms_um": float(np.sqrt(np.mean(ok ** 2))), "valid_points": int(tmap.valid.sum()),
            "grid_points": int(tmap.valid.size)}
    q1, q2 = tmap.q1, tmap.q2
    line = (f"{model.name}: tool-tip error at ({', '.join(f'{v:g}' for v in point)}) mm over "
            f"{tmap.axis1} {q1[0]:g}..{q1[-1]:g} deg, {tmap.axis2} {q2[0]:g}..{q2[-1]:g} deg: "
            f"max {data['max_um']:.3f} um, min {data['min_um']:.3f} um "
            f"({data['valid_points']} of {data['grid_points']} grid points valid)"
            f"{'; wrote ' + str(plot_name) if plot_name is not None else ''}")
    return ToolTipMap(tmap, data, (line,), tuple(f"note: {n}" for n in notes))
