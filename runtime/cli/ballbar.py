"""``volerr ballbar simulate|evaluate``: ballbar traces of a layout's model, and the ISO 230-4
evaluation of measured traces with a diagnosis in ISO 230-1 parameters.  See
:mod:`volerr.ballbar`."""

from __future__ import annotations

from ..errors import InputError, require
from ..fileio import Outputs
from ._common import (add_accept_residual, add_error_arguments, add_force, add_html,
                      add_identification_arguments, add_json, add_plot, add_vector,
                      error_functions_from_args, identification_from_args, layout_inputs,
                      write_certificates)


def register(sub) -> None:
    p = sub.add_parser("ballbar", help="ballbar traces: simulate (ISO 230-4 / 10791-6) and "
                                       "evaluate (G, H, polar plot, diagnosis)",
                       description="Ballbar tests: 'simulate' writes a trace of LAYOUT's model "
                                   "with an error directory; 'evaluate' gives the ISO 230-4 "
                                   "circular deviation G, circular hysteresis H, radial "
                                   "deviations and a diagnosis in ISO 230-1 parameters with "
                                   "standard uncertainties.  Format: 'volerr formats ballbar'.")
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    sim = s.add_parser("simulate", help="a ballbar trace of the layout's model (CSV)",
                       description="A circle of the tool ball about the pivot in a plane of "
                                   "the workpiece frame (rotary axes fixed with --rotary AXIS=DEG, "
                                   "or one swept with --rotary AXIS=START:STOP), readings of the "
                                   "layout's first-order model with the error directory.")
    sim.add_argument("layout", help="layout name or layout file")
    add_error_arguments(sim)
    sim.add_argument("--plane", choices=("XY", "YZ", "ZX"), required=True,
                     help="plane of the circle in the workpiece frame")
    sim.add_argument("--radius", type=float, required=True, help="bar length, mm")
    add_vector(sim, "--centre", required=True, help="pivot ball centre in the workpiece frame, "
                                                    "mm (X Y Z or X,Y,Z)")
    add_vector(sim, "--tool", default=(0.0, 0.0, 0.0),
               help="offset of the tool-side ball centre from the tool point, mm")
    sim.add_argument("--rotary", default=None, metavar="A=DEG,...",
                     help="rotary axes: AXIS=DEG fixed, AXIS=START:STOP swept (comma list)")
    sim.add_argument("--points", type=int, default=360, help="readings per direction")
    sim.add_argument("--noise-um", type=float, default=0.0,
                     help="standard deviation of Gaussian noise added to each reading, um")
    sim.add_argument("--direction", choices=("both", "ccw", "cw"), default="both",
                     help="counter-clockwise, clockwise or both (CCW first)")
    sim.add_argument("--seed", type=int, default=0, help="seed of the noise")
    sim.add_argument("--out", required=True, metavar="TRACE.csv", help="the trace to write")
    add_force(sim)
    sim.set_defaults(func=run_simulate)
    ev = s.add_parser("evaluate", help="ISO 230-4 G, H, F of traces and a diagnosis",
                      description="Evaluate ballbar traces (one trace per placement and "
                                  "direction; a file without a placement column is cut into "
                                  "its circles by plane, pivot, radius and direction): G, H, "
                                  "F and the least-squares centre (ISO 230-4), a polar plot, "
                                  "and a diagnosis in ISO 230-1 parameters from the layout's "
                                  "observation model.  A trace with fewer than 8 readings at "
                                  "distinct angles or less than half a circle, and the same "
                                  "file given twice, are refused ('volerr formats ballbar').")
    ev.add_argument("files", nargs="+", metavar="TRACE.csv", help="ballbar files")
    ev.add_argument("--layout", help="the machine's layout (needed for traces with rotary "
                                     "axes; default: a generic Cartesian layout, MB1)")
    add_json(ev, "the evaluation (G, H, F per trace; diagnosis)")
    add_plot(ev, "the polar plot")
    add_html(ev, "the report page (polar plot, ISO 230-4 table, diagnosis)")
    add_identification_arguments(ev, "the ballbar (its calibration length and certificate)")
    add_force(ev)
    add_accept_residual(ev)
    ev.set_defaults(func=run_evaluate)


def _rotary(text: str) -> dict:
    out = {}
    for item in [t.strip() for t in text.split(",") if t.strip()]:
        name, sep, value = item.partition("=")
        require(sep == "=" and name.strip(), f"--rotary expects AXIS=DEG or AXIS=START:STOP, "
                                             f"got {item!r}")
        try:
            parts = [float(v) for v in value.split(":")]
        except ValueError:
            raise InputError(f"--rotary {item!r}: not a number") from None
        require(len(parts) in (1, 2), f"--rotary {item!r}: AXIS=DEG or AXIS=START:STOP")
        out[name.strip().upper()] = parts[0] if len(parts) == 1 else tuple(parts)
    return out


def run_simulate(args) -> int:
    from ..instruments.ballbar import simulate, write_csv
    from ..cmm.volmap import error_dir_inputs
    from ..machine.model import load

    model = load(args.layout)
    inputs = error_dir_inputs(args.errors) + layout_inputs(args.layout)
    outs = Outputs(inputs, force=args.force).file("--out", args.out).check()
    require(args.noise_um >= 0, "--noise-um must not be negative")
    require(0 < args.radius <= 1e5, f"--radius must be a positive length of at most 1e5 mm, "
                                    f"got {args.radius:g}")
    require(8 <= args.points <= 10 ** 6, f"--points must be between 8 and 10^6 readings per "
                                         f"direction, got {args.points}")
    funcs = error_functions_from_args(args, model)
    cols = simulate(model, funcs, args.plane, args.radius, args.centre, args.tool,
                    _rotary(args.rotary or ""), args.points, args.noise_um, args.direction, args.seed)
    with outs:
        write_csv(outs.path("--out"), cols, inputs=inputs)
    n = len(cols["dr_um"])
    print(f"{model.name}: ballbar trace {args.plane}, radius {args.radius:g} mm, {n} readings "
          f"-> {args.out} (dr {cols['dr_um'].min():.3f} .. {cols['dr_um'].max():.3f} um)")
    return 0


def run_evaluate(args) -> int:
    from ..ballbar.api import ballbar_evaluate

    inputs = list(args.files) + layout_inputs(args.layout)
    outs = Outputs(inputs, force=args.force).file("--json", args.json).plot("--plot", args.plot) \
        .file("--html", args.html).file("--pdf", args.pdf).check()
    ident = identification_from_args(args, inputs)
    ev = ballbar_evaluate(args.files, args.layout, accept_residual=args.accept_residual)
    with outs:
        if args.json:
            ev.write_json(outs.path("--json"), inputs=inputs)
        if args.plot:
            from ..ballbar.plots import polar_plot

            polar_plot(ev.traces, ev.results, outs.path("--plot"), inputs=inputs)
        if args.html:
            from ..ballbar.report import write_html

            write_html(outs.path("--html"), ev, inputs=inputs)
        write_certificates(outs, ev, ident, inputs)
    print(ev.summary())
    return 0
