"""``volerr identify LAYOUT --axis A FILE... --out F``: three-point laser-tracker identification.

Reads tracker point data (``round,point,position,x,y,z`` CSV, or the thesis' raw export with
``--format thesis --positions start:stop:count``), identifies the six error motions of axis A
at every commanded position of every round (weighted least squares by default, ``--method
closed`` for the Zhang & Hu closed form), averages the rounds and writes the error table
(with n rounds: ``_s`` = the standard deviation s of one round and ``_std`` = s / sqrt(n), the
uncertainty of the mean; ``_u95`` with ``--tracker``).  See ``volerr.identify.solve``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ._common import (add_accept_implausible, add_accept_residual, add_force,
                      add_identification_arguments, add_json, add_plot, add_vector,
                      identification_from_args, write_certificates)


def register(sub) -> None:
    p = sub.add_parser(
        "identify", help="three-point laser-tracker identification of an axis' error motions",
        description="Identify the six error motions of one axis from laser-tracker "
                    "measurements of three or more points fixed on the moving component. The "
                    "first position of each round is the reference (errors zero).")
    p.add_argument("layout", help="layout name or layout file")
    p.add_argument("files", nargs="+", metavar="FILE", help="tracker data file(s)")
    p.add_argument("--axis", required=True, help="the measured axis (X, Y, Z, B, C ...)")
    out = p.add_mutually_exclusive_group(required=True)
    out.add_argument("--errors-out", metavar="DIR",
                     help="write the error table as DIR/<axis>.csv of an error directory (for "
                          "'volerr squareness', 'map', 'uncertainty'); DIR is created when "
                          "missing, its parent must exist")
    out.add_argument("--out", metavar="F.csv",
                     help="write the error table to this file instead (name it after the axis "
                          "inside an error directory: DIR/X.csv ...)")
    p.add_argument("--format", choices=("csv", "thesis"), default="csv",
                   help="csv: round,point,position,x,y,z (default); thesis: the raw export of "
                        "the thesis, blocks of label,x,y,z rows, one file per round")
    p.add_argument("--positions", help="thesis format: commanded positions, start:stop:count "
                                       "or a comma list")
    p.add_argument("--labels", dest="points",
                   help="thesis format: labels of the point blocks in file order, e.g. K,P,Q "
                        "(default: the first label of each block)")
    p.add_argument("--points", dest="points", help=argparse.SUPPRESS)  # old name of --labels
    p.add_argument("--method", choices=("lsq", "closed"), default="lsq",
                   help="lsq: weighted least squares over all points (default); closed: Zhang "
                        "& Hu closed form of six selected equations")
    add_vector(p, "--tracker",
               help="tracker position X Y Z in the measurement frame, mm (X Y Z or X,Y,Z): "
                    "weights the points with the AT960 uncertainty model and writes _u95 "
                    "columns (not given: unweighted, no _u95)")
    add_vector(p, "--direction", help="axis direction X Y Z in the measurement frame (not "
                                      "given: the layout's)")
    p.add_argument("--origin", nargs="+", metavar="X",
                   help="a point X Y Z on a rotary axis in the measurement frame, mm (X Y Z or "
                        "X,Y,Z; not given: 0 0 0), or 'layout': the axis point of the layout")
    p.add_argument("--sense", choices=("auto", "+", "-"), default="auto",
                   help="sense of the nominal motion of the points; auto: from the data")
    p.add_argument("--max-cond", type=float, default=1e4,
                   help="refuse point geometry with a larger condition number")
    p.add_argument("--outlier-k", type=float, default=5.0,
                   help="flag points whose residual exceeds k times the noise (default 5)")
    p.add_argument("--fit", choices=("poly", "smooth", "linear", "cubic"),
                   help="fit error functions (poly: degree by cross-validation; smooth: "
                        "smoothing spline by GCV) and report their residuals (JSON, plot)")
    p.add_argument("--residuals", help="write per-position, per-point residuals (CSV, um)")
    p.add_argument("--signs", choices=("component", "model"), default="component",
                   help="component (as the thesis; 'volerr formats tracker'): the error motions "
                        "of the moving component that carries the points; model: the volerr "
                        "model's tool-relative convention (for a table axis of LAYOUT: negated "
                        "and re-referenced to the tool point; a linear axis measured from a "
                        "reference position q0 != 0: re-referenced to q = 0; measurement frame = "
                        "machine frame), ready for map / compensate")
    add_accept_implausible(p)
    add_json(p, "a summary")
    add_plot(p, "a plot of the error motions")
    add_force(p)
    add_accept_residual(p)
    add_identification_arguments(p, "the laser tracker")
    p.set_defaults(func=run)


def _vec(text, what):
    from ._common import parse_vector

    return list(parse_vector(text, what))


def run(args) -> int:
    from ..fileio import Outputs, json_text, write_text
    from ..identify.api import identify
    from ..identify.inputs import refuse_repeated_files
    from ..identify.report import outlier_warnings, residual_csv, summary_lines
    from ..tables.table import table_to_csv

    from ._common import layout_inputs

    inputs = list(args.files) + layout_inputs(args.layout)
    refuse_repeated_files(args.files)
    axis = args.axis.strip().upper()
    outs = Outputs(inputs, force=args.force).file("--out", args.out) \
        .folder("--errors-out", args.errors_out, files=[f"{axis}.csv"]) \
        .file("--residuals", args.residuals) \
        .file("--json", args.json).plot("--plot", args.plot).file("--pdf", args.pdf).check()
    ident = identification_from_args(args, inputs)
    res = identify(
        args.layout, args.axis, args.files, format=args.format, positions=args.positions,
        points=args.points, method=args.method,
        tracker=_vec(args.tracker, "--tracker") if args.tracker else None,
        direction=_vec(args.direction, "--direction") if args.direction else None,
        origin=("layout" if args.origin == ["layout"] else
                _vec(args.origin, "--origin") if args.origin else None),
        sense=args.sense, max_cond=args.max_cond, outlier_k=args.outlier_k, signs=args.signs,
        accept_implausible=args.accept_implausible, accept_residual=args.accept_residual)
    result, table = res.identification, res.errors
    text = table_to_csv(table)
    if res.data.get("forced"):
        text = f"# {res.data['forced']}\n" + text
    summary = dict(res.data)        # --fit adds its entry to the JSON, not to the result
    fits = None
    if args.fit:
        from ..tables.errorfit import fit_table
        fits = fit_table(table, args.fit, weighted=table.std != {})
        summary["fit"] = [f.report() for f in fits.values()]
    with outs:
        if args.plot:
            from ..identify.plots import plot_identification
            plot_identification(result, outs.path("--plot"), fits)
        table_path = (outs.path("--out") if args.out else
                      outs.path("--errors-out") / f"{axis}.csv")
        write_text(table_path, text, inputs=inputs)
        if args.residuals:
            write_text(outs.path("--residuals"), residual_csv(result), inputs=inputs)
        if args.json:
            write_text(outs.path("--json"), json_text(summary), inputs=inputs)
        write_certificates(outs, res, ident, inputs)
    written = args.out or str(Path(args.errors_out) / f"{axis}.csv")
    print("\n".join(summary_lines(args.axis, summary, written) + ["  " + res.quality.line()]))
    for line in outlier_warnings(summary):
        print(line, file=sys.stderr)
    return 0
