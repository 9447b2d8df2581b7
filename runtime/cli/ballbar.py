"""``volerr ballbar simulate|evaluate``: ballbar traces, ISO 230-4 (``ballbar.api``)."""

from __future__ import annotations

from ._common import (add_error_arguments, add_fit_switches, add_force, add_html,
                      add_identification_arguments, add_json, add_plot, add_vector, command_parser,
                      options_of)


def register(sub) -> None:
    p, _ = command_parser(sub, "ballbar")
    s = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    sim, H_sim = command_parser(s, "simulate", text="ballbar-simulate")
    sim.add_argument("layout", help="layout name or layout file")
    add_error_arguments(sim)
    sim.add_argument("--plane", choices=("XY", "YZ", "ZX"), required=True, help=H_sim["--plane"])
    sim.add_argument("--radius", type=float, required=True, help="bar length, mm")
    add_vector(sim, "--centre", required=True, help=H_sim["--centre"])
    add_vector(sim, "--tool", default=(0.0, 0.0, 0.0), help=H_sim["--tool"])
    sim.add_argument("--rotary", default=None, metavar="A=DEG,...", help=H_sim["--rotary"])
    sim.add_argument("--points", type=int, default=360, help="readings per direction")
    sim.add_argument("--noise-um", type=float, default=0.0, help=H_sim["--noise-um"])
    sim.add_argument("--direction", choices=("both", "ccw", "cw"), default="both",
                     help=H_sim["--direction"])
    sim.add_argument("--seed", type=int, default=0, help="seed of the noise")
    sim.add_argument("--out", required=True, metavar="TRACE.csv", help="the trace to write")
    add_force(sim)
    sim.set_defaults(func=run_simulate)
    ev, H_ev = command_parser(s, "evaluate", text="ballbar-evaluate")
    ev.add_argument("files", nargs="+", metavar="TRACE.csv", help="ballbar files")
    ev.add_argument("--layout", help=H_ev["--layout"])
    add_json(ev, "the evaluation (G, H, F per trace; diagnosis)")
    add_plot(ev, "the polar plot")
    add_html(ev, "the report page (polar plot, ISO 230-4 table, diagnosis)")
    add_identification_arguments(ev, "the ballbar (its calibration length and certificate)")
    add_fit_switches(ev, implausible=False)
    ev.set_defaults(func=run_evaluate)


def run_simulate(args) -> int:
    from ..cmm.volmap import map_inputs
    from ..fileio import planned_outputs
    from ..instruments.ballbar import simulated_trace
    from ..machine.model import load

    model = load(args.layout)
    inputs = map_inputs(args.layout, args.errors)
    with planned_outputs(vars(args), inputs, **{"--out": args.out}) as outs:
        trace = simulated_trace(model, args.errors, args.plane, args.radius, args.centre,
                                **options_of(args, "tool rotary points noise_um direction seed "
                                                   "method degree extrapolate accept_implausible"))
        trace.write_csv(outs.path("--out"), inputs=inputs)
    print(trace.summary(args.out))
    return 0


def run_evaluate(args):
    from ..ballbar.api import ballbar_evaluate
    from ..fileio import layout_inputs
    from ..results import run_command

    return run_command(vars(args), list(args.files) + layout_inputs(args.layout), lambda *_: (
        ballbar_evaluate(args.files, args.layout, accept_residual=args.accept_residual)))
