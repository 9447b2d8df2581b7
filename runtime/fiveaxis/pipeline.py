"""The one compensation pipeline of ``volerr compensate`` and :func:`volerr.compensate`.

:func:`prepare` validates every input once -- the layout, the error directory, the program,
the tool (``tool`` offset, ``tool_length``, ``tool_table``), the work datum (travel and
finiteness), the options -- and returns a :class:`Job`; :func:`execute` streams the program
through :func:`volerr.fiveaxis.program.run` chunk by chunk into a sink (files for the command,
memory for the Python API: the same chunks, so the same bytes, line endings kept) and returns
what both print and write: the ``--json`` document, the console lines, the notes.

The tool offset (mm, in the tool frame, the frame the layout's chain ends in) is the vector
from the point the axis positions refer to (the spindle gauge point) to the tool tip.  A tool
of length ``L`` points its tip against the tool axis: offset ``(0, 0, -L)``
(:func:`volerr.nc.tcpm.tool_offset`; the tool axis points from the tip towards the spindle,
``docs/conventions.md``).  ``tool_length`` applies to every block: under TCPM it is the
controller's tool length, in axis positions it is this offset (the model's error at the tip
changes with ``L`` wherever an angular error turns the tool: rotary axes tilting it, the
angular errors of the linear axes through their Abbe arms).  Given with a ``tool`` offset that
is not ``(0, 0, -L)`` it is refused (which one is meant cannot be told); a ``tool_table``
gives the lengths of TCPM blocks only and is refused for a program without TCPM.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, require


@dataclass
class Job:
    """Validated inputs of one compensation: the ``model``, its error functions ``funcs`` (and
    the ``notes`` on them), ``open_source()`` a fresh iterator over the program's lines with
    their endings, the validated :class:`volerr.fiveaxis.program.Options`, the work datum's
    console sentence and JSON entry, and ``inputs`` (files no output may overwrite)."""

    model: object
    funcs: object
    notes: list
    open_source: object
    program_name: str
    opts: object
    datum_text: str
    datum_doc: dict | None
    inputs: list = field(default_factory=list)
    types_text: str | None = None


def _initial(initial) -> dict:
    """``initial`` as ``{AXIS: value}``: a dict, or the option's text ``'B=0,C=0'``."""
    if initial is None:
        return {}
    if isinstance(initial, dict):
        items = list(initial.items())
    else:
        items = []
        for part in filter(None, (s.strip() for s in str(initial).replace(";", ",")
                                  .split(","))):
            require("=" in part, f"--initial: expected AXIS=VALUE, got {part!r}")
            items.append(tuple(part.split("=", 1)))
    out = {}
    for a, v in items:
        try:
            val = float(v)
        except (TypeError, ValueError):
            raise InputError(f"--initial: {v!r} is not a number") from None
        require(math.isfinite(val), f"--initial: {a} is not finite")
        out[str(a).strip().upper()] = val
    return out


def parse_datum(datum, model) -> tuple | None:
    """``--datum``: None for None / 'none', else the axis positions (layout order; rotary axes
    not given are at 0 deg), finite and inside the travel.  ``datum``: the option's text
    ``'X,Y,Z[,B,C]'`` or a sequence of numbers."""
    if datum is None or (isinstance(datum, str) and datum.strip().lower() == "none"):
        return None
    text = datum if isinstance(datum, str) else ",".join(str(v) for v in datum)
    parts = [c.strip() for c in text.replace(";", ",").split(",") if c.strip()]
    n_lin = len(model.axes) - len(model.rotary_axes)
    require(n_lin <= len(parts) <= len(model.axes),
            f"--datum: give {n_lin} to {len(model.axes)} numbers "
            f"({','.join(model.axes)}, mm / deg) or 'none', got {text!r}")
    try:
        values = [float(c) for c in parts]
    except ValueError:
        raise InputError(f"--datum: {text!r} is not a list of numbers "
                         f"({','.join(model.axes)}) or 'none'") from None
    values += [0.0] * (len(model.axes) - len(values))
    for a, v in zip(model.axes, values):
        lo, hi = model.travel[a]
        require(math.isfinite(v) and lo <= v <= hi,
                f"--datum: {a} = {v:g} is outside the travel of {model.name} ({lo:g} .. {hi:g})")
    return tuple(values)


def _positions(model, q) -> str:
    return " ".join(f"{a}={v:g}" for a, v in zip(model.axes, q))


def datum_lines(model, funcs, tool, datum) -> tuple[str, dict | None]:
    """The console sentence on the datum and its JSON entry (the error there, um, with the
    run's tool offset ``tool`` mm)."""
    from .compensate import ErrorModel

    if datum is None:
        return ("datum: none -- every block is moved by its full volumetric error, relative to "
                "the machine's reference (the error tables' zero); if the work offset was set "
                "by probing the part, give --datum with the probing position"), None
    em = ErrorModel(model, funcs, tool).relative_to(datum)
    require(bool(em.admissible(em.datum)[0]),
            f"--datum: {_positions(model, datum)} lies outside the range of the error tables")
    e = 1e3 * em.datum_error()
    where = _positions(model, datum)
    return (f"datum {where}: tool-tip error there dx {e[0]:+.3f} dy {e[1]:+.3f} dz {e[2]:+.3f} "
            f"um (|e| {np.linalg.norm(e):.3f} um), absorbed by the work offset; compensated: "
            f"the error relative to it"), {
        "positions": dict(zip(model.axes, datum)), "error_um": [round(float(v), 6) for v in e]}


def _program_source(program):
    """(opener, name, input path or None) of ``program``: a file (path), or the program text
    itself (a string holding a line ending)."""
    import io

    from .program import open_program

    if isinstance(program, str) and ("\n" in program or "\r" in program):
        return (lambda: io.StringIO(program, newline="")), "<program text>", None
    return open_program(program), str(program), Path(program)


def _tool_table(tool_table):
    """The tool table: None, a CSV path (:func:`volerr.nc.tcpm.read_tool_table`) or a dict
    tool number -> length mm (checked as the file's entries are)."""
    from ..nc.tcpm import read_tool_table

    if tool_table is None:
        return None, None
    if not isinstance(tool_table, dict):
        return read_tool_table(tool_table), Path(tool_table)
    out = {}
    for k, v in tool_table.items():
        number, length = _number(k, f"tool table: tool {k!r}"), _number(v, f"tool table: "
                                                                          f"tool {k}: length")
        require(0 <= length <= 2000,
                f"tool table: tool {k}: length {v!r} is not plausible (0 .. 2000 mm)")
        out[int(number) if number.is_integer() else number] = length   # as the CSV's keys
    require(out, "tool table: no tools in the tool table")
    return out, None


def _number(value, what: str) -> float:
    """``value`` as a finite float, else :class:`InputError` naming ``what``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what}: {value!r} is not a number") from None
    require(math.isfinite(v), f"{what}: {value!r} is not finite")
    return v


def _types(types):
    """``types`` as a tuple of names (``'L-VOL,R-VOL'`` or a sequence), or None."""
    if types is None:
        return None
    if isinstance(types, str):
        return tuple(t for t in types.split(",") if t.strip())
    return tuple(types)


def prepare(layout, program, errors, *, datum=None, tool=(0.0, 0.0, 0.0),
            tool_length=None, tool_table=None, orientation=False, strategy="full",
            types=None, tol_um=0.1, decimals=4, method="linear", degree=None,
            extrapolate=False, initial=None, check_travel=True, arc_tol_um=1.0,
            dialect="auto", accept_implausible=False, decimal_less="auto") -> Job:
    """Every input of a compensation validated once -> :class:`Job` (the arguments are those
    of :func:`volerr.fiveaxis.api.compensate`)."""
    from ..machine.model import load
    from .compensate import error_functions
    from .program import Options

    model = load(layout)
    linear = [a for a in model.axes if a not in model.rotary_axes]
    require(sorted(linear) == ["X", "Y", "Z"],
            f"{model.name}: compensate needs the linear axes X, Y and Z (this layout has "
            f"{' '.join(linear)}: its tool tip has an error component no axis word corrects)")
    require(not Path(errors).is_file(), f"{errors} is a file, not an error "
                                        f"directory (the folder holding X.csv ...)")
    require(Path(errors).is_dir(), f"error directory not found: {errors}")
    funcs, notes = error_functions(errors, model, method, degree, extrapolate,
                                   accept_implausible)
    opener, name, path = _program_source(program)
    table, table_path = _tool_table(tool_table)
    types = _types(types)
    if tool_length is not None:
        tool_length = _number(tool_length, "--tool-length")
    opts = Options(tuple(tool), orientation, strategy, tol_um, decimals, _initial(initial),
                   check_travel, 50, types, arc_tol_um, tool_length, table, dialect,
                   None, decimal_less).validated(model)
    d = parse_datum(datum, model)
    text, doc = datum_lines(model, funcs, opts.tool, d)
    import dataclasses

    opts = dataclasses.replace(opts, datum=d)
    inputs = [p for p in (path, *Path(errors).glob("*.csv"), table_path) if p is not None]
    if Path(str(layout)).is_file():
        inputs.append(Path(str(layout)))
    return Job(model, funcs, notes, opener, name, opts, text, doc, inputs,
               ",".join(types) if types else None)


def tool_sentence(opts, tcpm_blocks: int) -> str:
    """The console sentence on the tool offset the run assumed (mm, tool frame)."""
    off = "(" + ", ".join(f"{v:g}" for v in np.asarray(opts.tool) + 0.0) + ") mm"
    if opts.tool_length is not None:
        s = (f"tool: length {opts.tool_length:g} mm, offset {off} in the tool frame (the tip "
             f"{opts.tool_length:g} mm from the point the axes refer to, against the tool axis)")
    elif any(opts.tool):
        s = f"tool: offset {off} in the tool frame (--tool)"
    else:
        s = (f"tool: offset {off} -- the axis positions place the tool tip (give "
             f"--tool-length L for a tool L mm from the point the layout's axes refer to)")
    if tcpm_blocks:
        s += (f"; {tcpm_blocks} TCPM blocks: the tool length of each block "
              f"({'the tool table' if opts.tool_table else '--tool-length'})")
    return s


@dataclass(frozen=True)
class Outcome:
    """What a run gives both the command and the API: the ``--json`` document, the console
    lines (stdout), the notes and warnings (stderr) and the corrections per axis (max and
    rms of written minus programmed position, mm / deg, over the compensated blocks)."""

    data: dict
    lines: tuple
    notes: tuple
    corrections: dict


def execute(job: Job, sink, progress=None, wrote=None) -> Outcome:
    """Stream ``job``'s program through :func:`volerr.fiveaxis.program.run` into ``sink``
    (``start()``, ``add(chunk)``); ``wrote``: the name of the written program the console
    line gives (None: no such clause).  Raises :class:`InputError` for a program without a
    motion block and for a tool table no block uses, before the caller commits anything."""
    from .program import run

    if job.datum_doc is not None:   # the report shows the datum's error on every row
        sink.constant_columns = {f"{c}_datum_um": f"{v:.6f}" for c, v in
                                 zip(("dx", "dy", "dz"), job.datum_doc["error_um"])}
    s, assumed_zero, corrections = run(job.open_source, job.model, job.funcs, job.opts, sink,
                                       progress=progress, corrections=True)
    require(s["motion_blocks"] > 0, f"{job.program_name}: no motion block to compensate "
                                    "(an empty program or one without axis words)")
    require(not (job.opts.tool_table and not s["tcpm_blocks"]),
            f"--tool-table: {job.program_name} has no TCPM block (G43.4 / G43.5, M128, "
            f"FUNCTION TCPM, TRAORI): the table's lengths would not be used; give the tool "
            f"of a program in axis positions with --tool-length L")
    o = job.opts
    data = {"layout": job.model.name, "strategy": o.strategy, "orientation": o.orientation,
            "types": job.types_text or "L-VOL,R-VOL", "datum": job.datum_doc, **s,
            "tool_offset_mm": [float(v) + 0.0 for v in o.tool],
            "tool_length_mm": o.tool_length}
    notes = [f"note: {n}" for n in job.notes]
    if assumed_zero:
        notes.append(f"note: axes {' '.join(assumed_zero)} are never programmed: taken at 0 "
                     f"deg (give --initial to state other positions)")
    notes += [f"warning: line {nc['line']}: {nc['reason']}" for nc in s["not_compensated"][:5]]
    if len(s["not_compensated"]) > 5:
        notes.append(f"warning: {len(s['not_compensated']) - 5} more blocks not compensated")
    return Outcome(data, tuple(console_lines(data, job, wrote)), tuple(notes), corrections)


def console_lines(data: dict, job: Job, wrote=None) -> list:
    """The lines ``volerr compensate`` prints (stdout) for the summary ``data``."""
    s, o = data, job.opts
    lines = [f"{s['layout']}: {s['compensated']} of {s['motion_blocks']} motion blocks "
             f"compensated ({o.strategy}{', orientation' if o.orientation else ''}"
             f"{', types ' + job.types_text if job.types_text else ''}); predicted tool-tip "
             f"error max {s['max_before_um']:.3f} -> {s['max_after_um']:.3f} um, rms "
             f"{s['rms_before_um']:.3f} -> {s['rms_after_um']:.3f} um"
             f"; wrote {wrote if wrote is not None else '(not written)'}",
             job.datum_text, tool_sentence(o, s["tcpm_blocks"])]
    arcs = s["arcs"]
    if arcs["linearised"]:
        lines.append(f"arcs: {arcs['linearised']} linearised into {arcs['segments']} G1 lines "
                     f"(predicted path within {o.arc_tol_um:g} um of the arc, max "
                     f"{arcs['max_path_deviation_um']:.3g} um); {arcs['kept']} kept as arcs")
    elif arcs["kept"]:
        lines.append(f"arcs: {arcs['kept']} kept as arcs (end point and centre corrected)")
    ln = s["lines"]
    if ln["sampled"]:
        lines.append(f"G1 moves: predicted path within {ln['max_path_deviation_um']:.3g} um of "
                     f"the nominal line (max at line {ln['line']}; {ln['sampled']} moves "
                     "sampled between their corrected ends; G0 rapids not: not cut)")
    if ln["tcpm_not_sampled"]:
        lines.append(f"G1 moves under TCPM not sampled ({ln['tcpm_not_sampled']}): the "
                     "controller interpolates the tool tip")
    if s["max_u_after_um"] > 0:
        lines.append(f"standard uncertainty of the remaining error (tables' _std and _s, "
                     f"k = 1): max {s['max_u_after_um']:.3f} um")
    if job.model.rotary_axes:
        lines.append(f"tool-axis error max {s['max_orientation_before_urad']:.2f} -> "
                     f"{s['max_orientation_after_urad']:.2f} urad")
    return lines
