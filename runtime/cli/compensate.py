"""``volerr compensate LAYOUT PROGRAM --errors DIR --out F``: compensated NC program; see
``volerr compensate --help`` and :func:`volerr.compensate`."""

from __future__ import annotations

from pathlib import Path

from ._common import (add_error_arguments, add_identification_arguments, add_vector, help_text,
                      identification_from_args, layout_inputs, planned_outputs, progress_bar,
                      write_certificates)


def register(sub) -> None:

    p = sub.add_parser("compensate", help="rewrite an NC program with compensated coordinates",
                       description=help_text("compensate-description"))
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
               help="tool-tip offset XT YT ZT in the tool frame, mm (X Y Z or X,Y,Z), from "
                    "the point the axis positions refer to to the tool tip (0 0 0: the "
                    "program positions the tip; a tool L long: 0 0 -L, as --tool-length L)")
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
                   help="the tool length, mm: the tip lies this far from the point the axes "
                        "refer to, against the tool axis (tool offset 0 0 -L in the tool "
                        "frame), for every block: the tool-tip error of axis-position blocks "
                        "is predicted and compensated at that tip, and TCPM programs "
                        "(G43.4/G43.5, M128, FUNCTION TCPM, TRAORI) use it as the "
                        "controller's tool length; with --tool-table, the length of the "
                        "tools the table does not hold (a tool it holds with another length "
                        "is refused); a --tool other than 0 0 -L is refused")
    p.add_argument("--tool-table", default=None, metavar="CSV",
                   help="TCPM programs: tool lengths by tool number, CSV tool,length_mm, "
                        "looked up at the program's H word (Fanuc), else T (Siemens, "
                        "Heidenhain TOOL CALL), else D (refused for a program without TCPM)")
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


def run(args) -> int:
    import sys

    from ..fiveaxis.api import compensate

    inputs = [args.program, *Path(args.errors).glob("*.csv"), *layout_inputs(args.layout),
              *([args.tool_table] if args.tool_table else [])]
    outs = planned_outputs(args, inputs, first={"--out": args.out, "--report": args.report})
    ident = identification_from_args(args, inputs)
    with outs:  # all or nothing: staged outputs are put in place at the end
        with progress_bar(Path(args.program), "compensate") as tick:
            res = compensate(
                args.layout, Path(args.program), args.errors, datum=args.datum,
                tool=tuple(args.tool), tool_length=args.tool_length,
                tool_table=args.tool_table, orientation=args.orientation,
                strategy=args.strategy, types=args.types, tol_um=args.tol_um,
                decimals=args.decimals, method=args.method, degree=args.degree,
                extrapolate=args.extrapolate, initial=args.initial or "",
                check_travel=not args.ignore_travel, arc_tol_um=args.arc_tolerance_um,
                dialect=args.dialect, out=outs.path("--out"),
                report=outs.path("--report") if args.report else None, inputs=inputs,
                out_name=args.out, keep_errors=bool(args.plot), progress=tick,
                accept_implausible=args.accept_implausible)
        if args.json:
            res.write_json(outs.path("--json"), inputs)
        if args.plot:
            res.write_plot(outs.path("--plot"), title=f"{res.layout}: {args.program}")
        write_certificates(outs, res.to_dict(), ident, inputs)   # the summary's certificate
    print(res.summary())
    for note in res.notes:   # only after success: bad input gets one line on stderr
        print(note, file=sys.stderr)
    return 0
