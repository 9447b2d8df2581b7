"""``volerr iso230-3``: ISO 230-3 evaluation of a thermal drift test (:func:`volerr.iso230_3`)."""

from __future__ import annotations

from ._common import (add_force, add_html, add_identification_arguments, add_json, add_plot,
                      command_parser)


def register(sub) -> None:
    p, H = command_parser(sub, "iso230-3")
    p.add_argument("file", metavar="FILE", help="the drift file (volerr formats drift)")
    add_json(p, "the results")
    add_plot(p, "drift, tilts, speed and temperatures against time")
    add_html(p, "the test report (identification, drift per channel and stage, the plot)")
    p.add_argument("--stage-column", metavar="NAME", help=H["--stage-column"])
    add_force(p)
    add_identification_arguments(p, "the displacement sensors")
    p.set_defaults(func=run)


def run(args):
    from ..certificate import from_options
    from ..fileio import planned_outputs
    from ..instruments.drift_test import iso230_3

    inputs = [args.file]
    ident = from_options(vars(args), inputs)     # --date checked before reading
    res = iso230_3(args.file, stage_column=args.stage_column, identification=ident)
    plots = res.plot_paths(args.plot)      # one PNG per run of the file
    with planned_outputs(vars(args), inputs, **{"--plot": plots[0] if len(plots) == 1
                                                else plots}) as outs:
        res.write_outputs(outs, vars(args), ident, inputs, roles=("json", "html"))
    return res
