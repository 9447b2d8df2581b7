"""``volerr iso230-3``: ISO 230-3 evaluation of a thermal drift test.

    volerr iso230-3 FILE [--json F] [--html H] [--plot P] [--stage-column NAME]
                    [--machine T --instrument T --operator T --date D] [--force]

Parses arguments, reads the drift file (:mod:`volerr.instruments.drift`) and calls
:mod:`volerr.positioning.iso230_3`.
"""

from __future__ import annotations

from ..errors import require
from ._common import (add_force, add_html, add_identification, add_json, add_plot,
                      identification_from_args, write_certificates)

EPILOG = """\
input: a drift file (volerr formats drift): t_s | t_min | t_h, channels d_<label>_um with
  '# channel d_<label>: DIR [at z=<mm>]' header lines, temperatures T_*, spindle speed S_rpm.
  A logger's file as saved is read with the mapping of 'volerr drift convert'.

evaluation (ISO 230-3:2020, clauses 5 ETVE, 6 rotating spindle, 7 moving linear axes):
  drift d(t) = reading(t) - first reading, um; per channel max, min (and their times), range
  = max - min (the ETVE in an environmental test, the thermal drift in a spindle test);
  tilts from two channels of one direction at two heights z1 < z2:
  about Y = +(sX(z2) - sX(z1)) / (z2 - z1), about X = -(sY(z2) - sY(z1)) / (z2 - z1), urad;
  stages: maximal stretches where the stage column (stage, else S_rpm, or --stage-column)
  stays within 2 % of its largest magnitude of the stage's first value; per stage the change
  and range of every channel and tilt.

outputs:
  --json: {"standard", "file", "test", "n_readings", "duration_s",
    "channels": {LABEL: {"direction", "z_mm", "range_um", "max_um", "min_um", "t_max_s",
    "t_min_s"}}, "tilts": {NAME: {"channels", "about", "lever_mm", "range_urad", ...}},
    "stage_column", "stages": [{"index", "t_start_s", "t_end_s", "value", "channels": {LABEL:
    {"start_um", "end_um", "change_um", "range_um", ...}}, "tilts": {...}}],
    "temperatures": {T_*: {"min_C", "max_C", "range_K"}}, "notes"};
    a file of several runs: {"standard", "runs": [...]}.
  --plot: drift, tilts, spindle speed and temperatures against time (PNG; one per run,
    _<run> added to the name when the file holds several).
  --html: the test report with the plot embedded.
"""


def register(sub) -> None:
    p = sub.add_parser(
        "iso230-3", help="ISO 230-3 evaluation of a thermal drift test",
        description="Evaluate a thermal drift test by ISO 230-3:2020 (environmental "
                    "temperature variation, rotating spindle, moving linear axes): drift range, "
                    "largest and smallest value per channel, tilts from sensor pairs at two "
                    "heights, per stage of the spindle programme, plotted against time.",
        epilog=EPILOG)
    p.add_argument("file", metavar="FILE", help="the drift file (volerr formats drift)")
    add_json(p, "the results")
    add_plot(p, "drift, tilts, speed and temperatures against time")
    add_html(p, "the test report (identification, drift per channel and stage, the plot)")
    p.add_argument("--stage-column", metavar="NAME",
                   help="the logged column whose changes make the stages (default: stage, "
                        "else S_rpm)")
    add_force(p)
    add_identification(p, "the displacement sensors")
    p.set_defaults(func=run)


def _plot_paths(path, runs) -> list:
    from pathlib import Path

    if path is None:
        return []
    p = Path(path)
    if len(runs) == 1:
        return [p]
    return [p.with_name(f"{p.stem}_{r.run}{p.suffix}") for r in runs]


def run(args) -> int:
    import datetime

    from .. import __version__ as ver
    from ..fileio import Outputs, json_text, write_bytes, write_text
    from ..instruments import drift
    from ..positioning import iso230_3

    ident = identification_from_args(args)     # --date checked before anything is read
    runs = drift.read_runs(args.file)
    plots = _plot_paths(args.plot, runs)
    outs = Outputs([args.file], force=args.force).file("--json", args.json) \
        .file("--html", args.html).file("--pdf", args.pdf)
    if len(plots) == 1:
        outs.plot("--plot", plots[0])
    else:
        require(not plots or plots[0].suffix.lower() == ".png",
                f"plot file must end in .png, got {args.plot}")
        outs.group("--plot", plots)
    outs.check()
    ident = identification_from_args(args, [args.file])
    evals = [iso230_3.evaluate(r, args.stage_column) for r in runs]
    report = iso230_3.report_dict(evals)
    pngs = [iso230_3.plot(ev) for ev in evals] if (args.plot or args.html) else []
    html_text = None
    if args.html:
        html_text = iso230_3.report_html(
            evals, pngs, f"Evaluated with volerr {ver} on {datetime.date.today().isoformat()}.",
            identification=ident)
    with outs:
        if args.json:
            write_text(outs.path("--json"), json_text(report), inputs=[args.file])
        for k, _ in enumerate(plots):
            role = "--plot" if len(plots) == 1 else outs.group_role("--plot", plots, k)
            write_bytes(outs.path(role), pngs[k], inputs=[args.file])
        if html_text is not None:
            write_text(outs.path("--html"), html_text, inputs=[args.file])
        write_certificates(outs, report, ident, [args.file])
    for ev in evals:
        print("\n".join(ev.summary_lines()))
    return 0
