"""``volerr compensate LAYOUT --errors DIR PROGRAM --out F``: compensated NC program.

Reads an NC program (ISO G-code or Heidenhain plain language; axis positions, arcs G2/G3,
TCPM), predicts the tool-tip error of every motion block from the layout's model and the error
tables (by each block's approach direction where they carry a reversal), and writes a copy
whose positions make the actual tool tip land on the nominal one (see
:mod:`volerr.fiveaxis.compensate` for the method, :mod:`volerr.nc.gcode`,
:mod:`volerr.nc.arcs`, :mod:`volerr.nc.tcpm` and :mod:`volerr.nc.heidenhain`
for what is supported; ``volerr formats gcode``).  Only position numbers change; the input is
never overwritten.

Outputs: ``--out`` (the program, same bytes except the compensated numbers), ``--report``
(CSV, one row per motion block: ``line,status``, the programmed and written axis positions
``<axis>_nominal_mm|deg``, ``<axis>_out_mm|deg``, the predicted tool-tip error before and after
``dx_before_um, dy_before_um, dz_before_um, e_before_um, dx_after_um, ..., e_after_um``, the
tool-axis error ``orientation_before_urad, orientation_after_urad``, ``iterations`` and the
standard uncertainty of the remaining error ``ux_after_um, uy_after_um, uz_after_um`` from the
tables' std columns, empty without them),
``--json`` (summary) and ``--plot`` (PNG: error along the program before and after).
With ``--datum`` the report's errors are relative to the work datum and three more columns
``dx_datum_um, dy_datum_um, dz_datum_um`` give the error at the datum (the same on every row:
what the work offset absorbed).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ._common import (add_error_arguments, add_identification_arguments, add_vector,
                      identification_from_args, progress_bar, write_certificates)
from ..errors import InputError, require
from ._common import layout_inputs
from ..fileio import Outputs, write_text


def register(sub) -> None:

    p = sub.add_parser("compensate", help="rewrite an NC program with compensated coordinates",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("layout", help="layout name (see 'volerr layouts') or layout file")
    p.add_argument("program", help="G-code program in machine axis coordinates")
    p.add_argument("--out", required=True, help="compensated program (never the input)")
    add_error_arguments(p)
    p.add_argument("--strategy", choices=("full", "thesis"), default="full",
                   help="full: iterate the inverse on the complete model (default); thesis: "
                        "Ellingsdalen 2021 sec. 3.5 (rotary, then linear; angular errors of the "
                        "linear axes neglected), for comparison")
    p.add_argument("--orientation", action="store_true",
                   help="also correct the tool orientation with the rotary axes (FOR)")
    p.add_argument("--types", default=None,
                   help="ISO/TR 16907 compensation types to apply, comma separated: L-POS "
                        "L-STR L-SQU L-ANG R-POS R-RAX R-POR R-ANG, or L-VOL R-VOL (default: "
                        "all); the report still predicts the full model's error")
    add_vector(p, "--tool", default=(0.0, 0.0, 0.0),
               help="tool-tip offset XT YT ZT in the tool frame, mm (X Y Z or X,Y,Z), beyond "
                    "the point the axis positions refer to (0 0 0: the program positions the "
                    "tip)")
    p.add_argument("--tol-um", type=float, default=0.1,
                   help="stop iterating when the correction changes by less than this (um)")
    p.add_argument("--decimals", type=int, default=4,
                   help="decimals of the written numbers (at least those of the input)")
    p.add_argument("--initial", default=None,
                   help="axis positions at program start, e.g. 'B=0,C=0' (otherwise an axis "
                        "is unknown until programmed; a rotary axis the program never commands "
                        "is taken at 0 deg)")
    p.add_argument("--ignore-travel", action="store_true",
                   help="accept positions outside the layout's travel")
    p.add_argument("--arc-tolerance-um", type=float, default=1.0, metavar="T",
                   help="arcs G2/G3: the actual tool path stays within T um of the nominal "
                        "arc: an arc is kept (end point and centre corrected) where the "
                        "correction varies less than T along it, else linearised into G1 "
                        "moves (default 1)")
    p.add_argument("--tool-length", type=float, default=None, metavar="MM",
                   help="TCPM programs (G43.4/G43.5, M128, FUNCTION TCPM, TRAORI): the tool "
                        "length the controller uses, mm (the tip lies this far from the point "
                        "the axes refer to, against the tool axis); with --tool-table, "
                        "the length of the tools the table does not hold (a tool it holds "
                        "with another length is refused)")
    p.add_argument("--tool-table", default=None, metavar="CSV",
                   help="TCPM programs: tool lengths by tool number, CSV tool,length_mm, "
                        "looked up at the program's H word (Fanuc), else T (Siemens, "
                        "Heidenhain TOOL CALL), else D")
    p.add_argument("--dialect", choices=("auto", "iso", "heidenhain"), default="auto",
                   help="program language: ISO G-code (Fanuc, Siemens, Heidenhain ISO) or "
                        "Heidenhain plain language (auto: detected from the first lines)")
    p.add_argument("--datum", default="none", metavar="X,Y,Z[,B,C]",
                   help="the work datum: the axis positions (layout order, mm / deg; rotary "
                        "axes not given: 0) where the part zero was probed or the work offset "
                        "set.  The work offset has absorbed the tool-tip error there, so only "
                        "the error relative to it is compensated and the report's before / "
                        "after errors are relative to it.  'none' (the default): the full "
                        "volumetric error, relative to the machine's reference (the error "
                        "tables' zero), is compensated -- right when the work offset comes "
                        "from the machine's reference (a calibrated fixture or pallet), and "
                        "volerr cannot know where a part was probed; after probing the part, "
                        "give the probing position or the error there is compensated twice")
    p.add_argument("--report", help="per-block CSV report")
    p.add_argument("--json", help="summary as JSON")
    p.add_argument("--plot", help="PNG: predicted tool-tip error along the program")
    add_identification_arguments(p)
    p.set_defaults(func=run)


def _initial(text: str) -> dict:
    out = {}
    for part in filter(None, (s.strip() for s in text.replace(";", ",").split(","))):
        require("=" in part, f"--initial: expected AXIS=VALUE, got {part!r}")
        a, v = part.split("=", 1)
        try:
            val = float(v)
        except ValueError:
            raise InputError(f"--initial: {v!r} is not a number") from None
        require(math.isfinite(val), f"--initial: {a} is not finite")
        out[a.strip().upper()] = val
    return out


def _datum(text: str, model) -> tuple | None:
    """``--datum``: None for 'none', else the axis positions (layout order; rotary axes not
    given are at 0 deg), inside the travel."""
    if text.strip().lower() == "none":
        return None
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


def _datum_lines(model, funcs, tool, datum) -> tuple[str, dict | None]:
    """The console sentence on the datum and its JSON entry (the error there, um)."""
    from ..fiveaxis.compensate import ErrorModel

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


def _positions(model, q) -> str:
    return " ".join(f"{a}={v:g}" for a, v in zip(model.axes, q))


def run(args) -> int:
    import sys

    from ..fiveaxis import program
    from ..fiveaxis.compensate import error_functions
    from ..machine.model import load

    model = load(args.layout)
    require(not Path(args.errors).is_file(), f"{args.errors} is a file, not an error "
                                              f"directory (the folder holding X.csv ...)")
    require(Path(args.errors).is_dir(), f"error directory not found: {args.errors}")
    funcs, notes = error_functions(args.errors, model, args.method, args.degree,
                                   args.extrapolate)
    open_source = program.open_program(args.program)
    table = None
    if args.tool_table:
        from ..nc.tcpm import read_tool_table
        table = read_tool_table(args.tool_table)
    inputs = [args.program, *Path(args.errors).glob("*.csv"), *layout_inputs(args.layout),
              *([args.tool_table] if args.tool_table else [])]
    outs = Outputs(inputs).file("--out", args.out).file("--report", args.report) \
        .file("--json", args.json).plot("--plot", args.plot).file("--pdf", args.pdf).check()
    ident = identification_from_args(args, inputs)
    datum = _datum(args.datum, model)
    datum_text, datum_doc = _datum_lines(model, funcs, tuple(args.tool), datum)
    opts = program.Options(
        tuple(args.tool), args.orientation, args.strategy, args.tol_um, args.decimals,
        _initial(args.initial or ""), not args.ignore_travel, 50,
        None if args.types is None else tuple(t for t in args.types.split(",") if t.strip()),
        args.arc_tolerance_um, args.tool_length, table, args.dialect, datum)
    with outs:  # all or nothing: staged outputs are put in place at the end
        # streamed: the program and the report are written chunk by chunk
        sink = program.FileSink(model, outs.path("--out"),
                                outs.path("--report") if args.report else None, inputs,
                                keep_errors=bool(args.plot))
        if datum_doc is not None:   # the report shows the datum's error on every row
            sink.constant_columns = {f"{c}_datum_um": f"{v:.6f}" for c, v in
                                     zip(("dx", "dy", "dz"), datum_doc["error_um"])}
        try:
            with progress_bar(Path(args.program), "compensate") as tick:
                s, assumed_zero = program.run(open_source, model, funcs, opts, sink,
                                              progress=tick)
            require(s["motion_blocks"] > 0, f"{args.program}: no motion block to compensate "
                                            "(an empty program or one without axis words)")
            if args.json:
                write_text(outs.path("--json"), json.dumps(
                    {"layout": model.name, "strategy": args.strategy,
                     "orientation": bool(args.orientation), "types": args.types or "L-VOL,R-VOL",
                     "datum": datum_doc, **s}, indent=2) + "\n", inputs)
            if args.plot:
                from ..fiveaxis.plots import plot_program_errors

                plot_program_errors(sink.program_errors(), outs.path("--plot"),
                                    title=f"{model.name}: {args.program}")
            write_certificates(outs, {"layout": model.name, **s}, ident, inputs)
            sink.commit()
        except BaseException:
            sink.discard()
            raise
    print(f"{model.name}: {s['compensated']} of {s['motion_blocks']} motion blocks compensated "
          f"({args.strategy}{', orientation' if args.orientation else ''}"
          f"{', types ' + args.types if args.types else ''}); predicted tool-tip "
          f"error max {s['max_before_um']:.3f} -> {s['max_after_um']:.3f} um, rms "
          f"{s['rms_before_um']:.3f} -> {s['rms_after_um']:.3f} um; wrote {args.out}")
    print(datum_text)
    _print_arcs(s["arcs"], args.arc_tolerance_um)
    if s["max_u_after_um"] > 0:
        print(f"standard uncertainty of the remaining error (tables' _std and _s, k = 1): max "
              f"{s['max_u_after_um']:.3f} um")
    # notes only after success: bad input gets exactly one line on stderr
    if assumed_zero:
        notes.append(f"axes {' '.join(assumed_zero)} are never programmed: taken at 0 deg "
                     f"(give --initial to state other positions)")
    for note in notes:
        print(f"note: {note}", file=sys.stderr)
    if model.rotary_axes:
        print(f"tool-axis error max {s['max_orientation_before_urad']:.2f} -> "
              f"{s['max_orientation_after_urad']:.2f} urad")
    for nc in s["not_compensated"][:5]:
        print(f"warning: line {nc['line']}: {nc['reason']}", file=sys.stderr)
    if len(s["not_compensated"]) > 5:
        print(f"warning: {len(s['not_compensated']) - 5} more blocks not compensated",
              file=sys.stderr)
    return 0


def _print_arcs(arcs: dict, tol_um: float) -> None:
    """The console line on the program's arcs: how many were kept, how many linearised into
    how many G1 lines."""
    if arcs["linearised"]:
        print(f"arcs: {arcs['linearised']} linearised into {arcs['segments']} G1 lines "
              f"(predicted path within {tol_um:g} um of the arc, max "
              f"{arcs['max_path_deviation_um']:.3g} um); {arcs['kept']} kept as arcs")
    elif arcs["kept"]:
        print(f"arcs: {arcs['kept']} kept as arcs (end point and centre corrected)")
