"""``volerr iso230-2``: ISO 230-2 evaluation of laser-interferometer positioning runs.

    volerr iso230-2 RUN.csv [RUN2.csv ...] [--axis X] --json F [--plot P] [--table-out DIR]
                    [--html F] [--cte-ppm-per-K A [--material-temp-C T] [--cte-reference-mm P]]

Parses arguments and calls :mod:`volerr.positioning`; formats are described there and in
``--help``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..errors import require

EPILOG = """\
input formats (CSV; ';' or tab separated exports are read too; names case-insensitive):

  long, one row per reading:
    target_mm,cycle,direction,deviation_um[,T_C]
    0,1,+1,0.4
    0,1,-1,2.1
  direction +1 = forward (approach in the positive direction), -1 = backward
  (+ - fwd bwd forward backward up down accepted); deviation = actual minus target,
  the interferometer reading after environmental (air) compensation; deviation_mm accepted.

  wide, one row per target (interferometer software export):
    target_mm,fwd_1_um,bwd_1_um,fwd_2_um,bwd_2_um,...[,T_C]
  variants: fwd1, Fwd 1, forward_1, run1_fwd, 1+, 1-, up_1, down_1, b_2 ...; unit suffix
  _um, _mm, (um), (mm), [um], [mm]; no unit means um.
  target column (both formats): target_mm, target, target_position, position, with the same
  unit spellings (Target (mm), Target [mm], position_mm); no unit means mm.  cycle: an integer
  (or a text label); 1.5 is refused.

  T_C (or material_T_C): material temperature, degC, used by --cte-ppm-per-K; other *_C
  columns are reported as conditions; other columns are ignored.  Every target needs both
  directions in every cycle exactly once; at least 2 targets and 2 cycles.

correction to 20 degC (ISO 1), with --cte-ppm-per-K:
  x_20 = x - cte * (T - 20 C) * (P - P_ref)   (warm steel scale reads short: x > 0 before)

outputs:
  --json: ISO 230-2:2014 clause 3 figures in um: A_um A_fwd_um A_bwd_um B_um B_avg_um R_um
  R_fwd_um R_bwd_um E_um E_fwd_um E_bwd_um M_um, per-target arrays (targets_mm, mean_fwd_um,
  mean_bwd_um, mean_um, reversal_um, s_fwd_um, s_bwd_um, R_i_fwd_um, R_i_bwd_um, R_i_um),
  axis, n_cycles, temperature_correction.  Several RUN files: {"runs": [...]}, same keys per run.
  E is bidirectional: max - min of the mean deviations of BOTH directions (not max(E_fwd,
  E_bwd)); B = max |B_i|, B_avg = mean of B_i = forward minus backward.
  --table-out DIR: DIR/<axis>.csv with <axis>,EXX_um,EXX_std_um,RV_X_um,S_X_um (axis X):
  EXX = mean bidirectional deviation x_i; EXX_std = its standard uncertainty (Type A)
  S_i / sqrt(2 n), n cycles per direction (2 n readings per target); RV_X = reversal B_i;
  S_X = pooled single-reading repeatability S_i = sqrt((S_fwd^2 + S_bwd^2)/2) (ignored by
  the table reader).  Readable by 'volerr map --errors DIR' and 'volerr uncertainty --errors
  DIR' with its default --table-std systematic (EXX_std is the uncertainty of the error
  function at each node).  Not with --table-std repeatability: that wants a single-reading
  scatter per probing point, and EXX_std is sqrt(2 n) times smaller than S_X.
"""


def register(sub) -> None:
    p = sub.add_parser(
        "iso230-2", help="ISO 230-2 evaluation of laser-interferometer positioning runs",
        description="Evaluate positioning runs of one linear axis (targets x cycles x both "
                    "directions) by ISO 230-2:2014: mean unidirectional and bidirectional "
                    "deviations, reversal B, repeatability R, systematic error E, M and "
                    "accuracy A; the standard's plot, an HTML certificate and an error table "
                    "with reversal for --errors DIR.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("runs", nargs="+", metavar="RUN.csv", help="positioning run(s), long or "
                                                               "wide format (below)")
    p.add_argument("--axis", default="X",
                   help="axis letter of the runs (X Y Z U V W; default X), or a comma list with "
                        "one letter per RUN file")
    p.add_argument("--json", required=True, metavar="F", help="write the results (JSON)")
    p.add_argument("--plot", metavar="P.png", help="write the ISO 230-2 plot (PNG)")
    p.add_argument("--html", metavar="F", help="write a one-page report (HTML, plot embedded)")
    p.add_argument("--table-out", metavar="DIR",
                   help="write DIR/<axis>.csv for --errors DIR: mean bidirectional deviation, "
                        "its standard uncertainty S/sqrt(2n) (_std; fits 'volerr uncertainty "
                        "--table-std systematic', the default), reversal (RV_<axis>_um) and "
                        "the single-reading repeatability S (S_<axis>_um)")
    g = p.add_argument_group("correction to 20 degC")
    g.add_argument("--cte-ppm-per-K", type=float, metavar="A",
                   help="coefficient of expansion of the scale / material, ppm/K (um/m/K); "
                        "needs a T_C column or --material-temp-C")
    g.add_argument("--material-temp-C", type=float, metavar="T",
                   help="material temperature for the whole run, degC (when the file has no "
                        "T_C column)")
    g.add_argument("--cte-reference-mm", type=float, default=0.0, metavar="P",
                   help="position where the expansion is zero (scale fixed point or where the "
                        "interferometer was zeroed), mm (default 0)")
    p.set_defaults(func=run)


def _axes(text: str, n: int) -> list[str]:
    axes = [a.strip().upper() for a in text.split(",")]
    require(len(axes) in (1, n), f"--axis: give one axis or one per RUN file ({n}), got "
                                 f"{len(axes)}")
    return axes * n if len(axes) == 1 else axes


def run(args) -> int:
    import sys

    from .. import positioning as pos
    from ..fileio import Outputs, write_bytes, write_text

    inputs = list(args.runs)
    require(len({Path(f).resolve() for f in inputs}) == len(inputs), "the same RUN file is given "
                                                                      "twice")
    require(args.material_temp_C is None or args.cte_ppm_per_K is not None,
            "--material-temp-C is used only with --cte-ppm-per-K")
    axes = _axes(args.axis, len(inputs))
    dup = sorted({a for a in axes if axes.count(a) > 1})
    require(not args.table_out or not dup,
            f"--table-out writes one table per axis: {len(inputs)} runs of axis "
            f"{dup[0] if dup else ''}; evaluate them one at a time")
    outs = Outputs(inputs).file("--json", args.json).plot("--plot", args.plot) \
        .file("--html", args.html) \
        .folder("--table-out", args.table_out, files=[f"{a}.csv" for a in axes]).check()

    runs = pos.evaluate_files(inputs, axes, args.cte_ppm_per_K, args.material_temp_C,
                              args.cte_reference_mm)
    evaluations = runs.evaluations
    report = runs.report()
    table_texts = [pos.error_table_csv(ev) for ev in evaluations] if args.table_out else []
    png = pos.plot_runs(evaluations) if (args.plot or args.html) else None
    html_text = None
    if args.html:
        from .. import __version__ as ver
        import datetime
        html_text = pos.report_html(report, png, inputs, f"Evaluated with volerr {ver} on "
                                                         f"{datetime.date.today().isoformat()}.")

    # all outputs at the end, all or nothing
    with outs:
        write_text(outs.path("--json"), json.dumps(report, indent=2) + "\n", inputs=inputs)
        if args.plot:
            write_bytes(outs.path("--plot"), png, inputs=inputs)
        if html_text is not None:
            write_text(outs.path("--html"), html_text, inputs=inputs)
        for a, text in zip(axes, table_texts):
            write_text(outs.path("--table-out") / f"{a}.csv", text, inputs=inputs)

    lines, notes = pos.summary_lines(report)
    print("\n".join(lines))
    for n in notes:
        print(f"volerr iso230-2: note: {n}", file=sys.stderr)
    return 0
