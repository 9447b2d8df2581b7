"""``volerr iso230-2``: ISO 230-2 evaluation of laser-interferometer positioning runs.

    volerr iso230-2 RUN.csv [RUN2.csv ...] [--axis X] [--json F] [--plot P] [--html F]
                    [--errors-out DIR] [--tolerance "A=..,E=..,M=..,R=..,B=.."]
                    [--machine T --instrument T --operator T --date D]
                    [--cte-ppm-per-K A [--material-temp-C T] [--cte-reference-mm P]]

Parses arguments and calls :mod:`volerr.positioning`; formats are described there and in
``--help``.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import require
from ._common import (add_errors_out, add_force, add_html, add_identification, add_json,
                      add_plot, finite_option, identification_from_args,
                      write_certificates)

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
  axis, n_cycles, temperature_correction; uncertainty_um {A, E, M, R, B: U (k = 2)} and
  uncertainty_budget (ISO/TR 230-9); with --tolerance: tolerance_um, verdicts {Q: pass |
  fail | undecided}, verdict, decision_rule (ISO 14253-1); identification.  Several RUN
  files: {"runs": [...]}, same keys per run, and the overall verdict.
  E is bidirectional: max - min of the mean deviations of BOTH directions (not max(E_fwd,
  E_bwd)); B = max |B_i|, B_avg = mean of B_i = forward minus backward.
  --errors-out DIR: DIR/<axis>.csv with <axis>,EXX_um,EXX_std_um,EXX_s_um,RV_X_um (axis X):
  EXX = mean bidirectional deviation x_i; EXX_std = its standard uncertainty (Type A)
  S_i / sqrt(2 n), n cycles per direction (2 n readings per target); EXX_s = the pooled
  single-reading repeatability S_i = sqrt((S_fwd^2 + S_bwd^2)/2); RV_X = reversal B_i.
  Readable by 'volerr map --errors DIR' and 'volerr uncertainty --errors DIR' (_std: the
  uncertainty of the error function at each node; _s with --repeatability).

measurement uncertainty (ISO/TR 230-9; contributors of ISO 230-2 Annex A), k = 2:
  instrument u = ppm L / sqrt 3; alignment e = D^2 / (2 L), u = e / sqrt 12; temperature
  (with --cte-ppm-per-K) u = L cte u(T) and L |T - 20| u(cte); environment u = EVE /
  (2 sqrt 3); repeatability from the run: E S sqrt(2/n), M S/sqrt(n), B S sqrt(2/n),
  R 4 S/sqrt(2(n-1)), A sqrt(2 S^2/n + 8 S^2/(2(n-1))).  R and B: environment and
  repeatability only (the rest cancels at one target).
verdict (ISO 14253-1, --tolerance): pass when value <= tolerance - U, fail when value >
  tolerance + U, undecided in between; the plot rings the readings that decide a quantity
  that fails or is undecided.
"""


def register(sub) -> None:
    p = sub.add_parser(
        "iso230-2", help="ISO 230-2 evaluation of laser-interferometer positioning runs",
        description="Evaluate positioning runs of one linear axis (targets x cycles x both "
                    "directions) by ISO 230-2:2014: mean unidirectional and bidirectional "
                    "deviations, reversal B, repeatability R, systematic error E, M and "
                    "accuracy A; the standard's plot, an HTML certificate and an error table "
                    "with reversal for --errors DIR.",
        epilog=EPILOG)
    p.add_argument("runs", nargs="+", metavar="RUN.csv", help="positioning run(s), long or "
                                                               "wide format (below)")
    p.add_argument("--axis", default="X",
                   help="axis letter of the runs (X Y Z U V W; default X), or a comma list with "
                        "one letter per RUN file")
    add_json(p, "the results")
    add_plot(p, "the ISO 230-2 plot")
    add_html(p, "the certificate (identification, results with U, verdicts, plot, budget)")
    add_errors_out(p, "DIR/<axis>.csv: mean bidirectional deviation, its standard "
                      "uncertainty S/sqrt(2n) (_std), the single-reading repeatability S (_s) "
                      "and the reversal (RV_<axis>_um),", "--table-out")
    add_force(p)
    p.add_argument("--tolerance", metavar="'A=..,E=..'",
                   help="tolerances in um (or with a length unit: A=0.012 mm) of any of "
                        "A E M R B: verdicts per ISO 14253-1 (tolerance reduced / widened by U)")
    u = p.add_argument_group("measurement uncertainty (ISO/TR 230-9)")
    u.add_argument("--instrument-ppm", type=float, default=0.5, metavar="P",
                   help="accuracy of the interferometer with its environmental compensation, "
                        "ppm of the length (a maximum error, rectangular)")
    u.add_argument("--alignment-mm", type=float, default=0.1, metavar="D",
                   help="lateral offset of the beam over the travel after alignment, mm "
                        "(cosine error D^2 / 2L)")
    u.add_argument("--temperature-u-K", type=float, default=0.2, metavar="U",
                   help="standard uncertainty of the material temperature, K")
    u.add_argument("--cte-u-ppm-per-K", type=float, default=1.0, metavar="U",
                   help="standard uncertainty of the expansion coefficient, ppm/K")
    u.add_argument("--eve-um", type=float, metavar="V",
                   help="environmental variation error of a drift test, um (not given: not "
                        "included, noted)")
    add_identification(p, "the laser interferometer")
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
    from ..fileio import Outputs, json_text, write_bytes, write_text

    inputs = list(args.runs)
    require(len({Path(f).resolve() for f in inputs}) == len(inputs), "the same RUN file is given "
                                                                      "twice")
    require(args.material_temp_C is None or args.cte_ppm_per_K is not None,
            "--material-temp-C is used only with --cte-ppm-per-K")
    axes = _axes(args.axis, len(inputs))
    dup = sorted({a for a in axes if axes.count(a) > 1})
    require(not args.errors_out or not dup,
            f"--errors-out writes one table per axis: {len(inputs)} runs of axis "
            f"{dup[0] if dup else ''}; evaluate them one at a time")
    for opt in ("instrument_ppm", "alignment_mm", "temperature_u_K", "cte_u_ppm_per_K",
                "eve_um"):
        finite_option(getattr(args, opt), "--" + opt.replace("_", "-"), 0.0, 1e3)
    from .. import conformance
    from ..positioning.api import iso230_2
    if args.tolerance is not None:   # checked before any output is planned
        conformance.parse_tolerances(args.tolerance, ("A", "E", "M", "R", "B"))
    outs = Outputs(inputs, force=args.force).file("--json", args.json) \
        .plot("--plot", args.plot).file("--html", args.html).file("--pdf", args.pdf) \
        .folder("--errors-out", args.errors_out, files=[f"{a}.csv" for a in axes]).check()

    conditions = {}
    if args.cte_ppm_per_K is not None:
        conditions["expansion coefficient"] = f"{args.cte_ppm_per_K:g} ppm/K (corrected to " \
                                              f"20 \u00b0C)"
    if args.material_temp_C is not None:
        conditions["material temperature"] = f"{args.material_temp_C:g} \u00b0C"
    ident = identification_from_args(args, inputs, conditions)
    res = iso230_2(inputs, ",".join(axes), tolerance=args.tolerance,
                   instrument_ppm=args.instrument_ppm, alignment_mm=args.alignment_mm,
                   temperature_u_K=args.temperature_u_K, cte_u_ppm_per_K=args.cte_u_ppm_per_K,
                   eve_um=args.eve_um, cte_ppm_per_K=args.cte_ppm_per_K,
                   material_temp_C=args.material_temp_C, cte_reference_mm=args.cte_reference_mm,
                   identification=ident)
    report, evaluations = res.data, res.evaluations
    table_texts = [pos.error_table_csv(ev) for ev in evaluations] if args.errors_out else []
    per_run = report["runs"] if "runs" in report else [report]
    png = res.png() if args.plot else None

    # all outputs at the end, all or nothing
    with outs:
        if args.json:   # every output optional: without any, the result is on the console
            write_text(outs.path("--json"), json_text(report), inputs=inputs)
        if args.plot:
            write_bytes(outs.path("--plot"), png, inputs=inputs)
        if args.html:
            res.write_html(outs.path("--html"), inputs=inputs)
        for a, text in zip(axes, table_texts):
            write_text(outs.path("--errors-out") / f"{a}.csv", text, inputs=inputs)
        write_certificates(outs, res, ident, inputs)

    print(res.summary())
    notes = pos.summary_lines(report)[1]
    notes += [f"{r['file']}: {n}" for r in per_run for n in r["uncertainty_budget"]["notes"]]
    for n in notes:
        print(f"volerr iso230-2: note: {n}", file=sys.stderr)
    return 0
