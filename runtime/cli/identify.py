"""``volerr identify LAYOUT --axis A FILE... --out F``: three-point laser-tracker identification.

Reads tracker point data (``round,point,position,x,y,z`` CSV, or the thesis' raw export with
``--format thesis --positions start:stop:count``), identifies the six error motions of axis A
at every commanded position of every round (weighted least squares by default, ``--method
closed`` for the Zhang & Hu closed form), averages the rounds and writes the error table
(``_std`` columns with several rounds, ``_u95`` with ``--tracker``).  See ``volerr.identify.solve``.
"""

from __future__ import annotations

import argparse
import json
import sys

from volerr.cli._common import add_vector
from volerr.errors import require


def register(sub) -> None:
    p = sub.add_parser(
        "identify", help="three-point laser-tracker identification of an axis' error motions",
        description="Identify the six error motions of one axis from laser-tracker "
                    "measurements of three or more points fixed on the moving component. The "
                    "first position of each round is the reference (errors zero).")
    p.add_argument("layout", help="layout name or layout file")
    p.add_argument("files", nargs="+", metavar="FILE", help="tracker data file(s)")
    p.add_argument("--axis", required=True, help="the measured axis (X, Y, Z, B, C ...)")
    p.add_argument("--out", required=True, metavar="DIR/A.csv",
                   help="output error table (CSV).  For 'volerr squareness' and 'volerr map' "
                        "name it after the axis inside an error directory: DIR/X.csv, "
                        "DIR/Y.csv ... (add constants.csv there for squareness / location "
                        "errors)")
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
                   help="sense of the nominal motion of the points (default: from the data)")
    p.add_argument("--max-cond", type=float, default=1e4,
                   help="refuse point geometry with a larger condition number (default 1e4)")
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
    p.add_argument("--json", help="write a summary (JSON)")
    p.add_argument("--plot", help="write a plot of the error motions (PNG)")
    p.set_defaults(func=run)


def _vec(text, what):
    from volerr.cli._common import parse_vector

    return list(parse_vector(text, what))


def _refuse_repeated_files(files) -> None:
    """The same tracker file given twice would count its rounds twice (understated Type A
    uncertainty)."""
    import os
    from pathlib import Path

    seen = []
    for f in files:
        p = Path(f)
        for q in seen:
            same = p.resolve() == q.resolve() or (
                p.exists() and q.exists() and os.path.samefile(p, q))
            require(not same, f"tracker file {f} is given twice (its rounds would be counted "
                              f"twice)")
        seen.append(p)


def read_rounds(files, fmt="csv", positions=None, points=None):
    """Rounds from the input files (both formats)."""
    from volerr.identify.tracker_io import parse_positions, read_thesis_export, read_tracker_csv

    rounds = []
    if fmt == "thesis":
        require(positions is not None, "--format thesis needs --positions start:stop:count")
        pos = parse_positions(positions)
        labels = None
        if points:
            labels = [s.strip() for s in points.split(",") if s.strip()]
        for f in files:
            rounds.append(read_thesis_export(f, pos, labels))
    else:
        require(positions is None and points is None,
                "--positions and --labels apply to --format thesis only")
        for f in files:
            rounds.extend(read_tracker_csv(f))
    return rounds


def residual_csv(result) -> str:
    """Per-position, per-point residuals of every round (um) with the outlier flag."""
    flagged = {(o[0], o[1], o[2]) for o in result.outliers()}
    lines = ["round,point,position,rx_um,ry_um,rz_um,norm_um,outlier"]
    for r in result.rounds:
        for k, pos in enumerate(r.positions):
            for i, lab in enumerate(r.labels):
                v = r.residuals[k, i] * 1e3
                n = float((v ** 2).sum()) ** 0.5
                flag = int((r.name, float(pos), lab) in flagged)
                lines.append(f"{r.name},{lab},{pos:.10g},{v[0]:.6g},{v[1]:.6g},{v[2]:.6g},"
                             f"{n:.6g},{flag}")
    return "\n".join(lines) + "\n"


def run(args) -> int:
    from volerr.fileio import Outputs, write_text
    from volerr.identify.solve import identify, to_model_signs
    from volerr.machine.layout import read_layout
    from volerr.tables.table import table_to_csv

    from volerr.cli._common import layout_inputs

    inputs = list(args.files) + layout_inputs(args.layout)
    _refuse_repeated_files(args.files)
    outs = Outputs(inputs).file("--out", args.out).file("--residuals", args.residuals) \
        .file("--json", args.json).plot("--plot", args.plot).check()
    layout = read_layout(args.layout)
    rounds = read_rounds(args.files, args.format, args.positions, args.points)
    sense = {"auto": "auto", "+": 1, "-": -1}[args.sense]
    result = identify(
        rounds, layout, args.axis, method=args.method,
        tracker=_vec(args.tracker, "--tracker") if args.tracker else None,
        direction=_vec(args.direction, "--direction") if args.direction else None,
        origin=("layout" if args.origin == ["layout"] else
                _vec(args.origin, "--origin") if args.origin else None),
        sense=sense, max_cond=args.max_cond, outlier_k=args.outlier_k)
    table = result.table()
    if args.signs == "model":
        table = to_model_signs(table, layout, reference=result.rounds[0].positions[0])
    text = table_to_csv(table)
    summary = result.summary()
    fits = None
    if args.fit:
        from volerr.tables.errorfit import fit_table
        fits = fit_table(table, args.fit, weighted=table.std != {})
        summary["fit"] = [f.report() for f in fits.values()]
    with outs:
        if args.plot:
            from volerr.identify.plots import plot_identification
            plot_identification(result, outs.path("--plot"), fits)
        write_text(outs.path("--out"), text, inputs=inputs)
        if args.residuals:
            write_text(outs.path("--residuals"), residual_csv(result), inputs=inputs)
        if args.json:
            write_text(outs.path("--json"), json.dumps(summary, indent=2) + "\n", inputs=inputs)
    s = summary
    print(f"{args.axis}: {s['n_positions']} positions x {len(s['points'])} points x "
          f"{s['n_rounds']} round(s), method {s['method']}, condition {s['condition']:.3g}, "
          f"residual RMS {s['residual_rms_um']:.3g} um -> {args.out}")
    if "closed_form" in s:
        cf = s["closed_form"]
        d = list(cf["vs_lsq_max"].values())
        g = [v for v in cf["noise_gain_vs_lsq"].values() if v is not None and v == v]
        roles = "; ".join(f"P={r['P']} Q={r['Q']} K={r['K']}" for r in cf["roles"])
        print(f"closed form (Zhang & Hu selection {cf['selection']}, {roles}): equals least "
              f"squares on consistent data to {cf['consistency_max']:.1g}; on these data it "
              f"differs by up to {max(d[:3]):.3g} um / {max(d[3:]):.3g} urad"
              + (f", noise gain {min(g):.2g}-{max(g):.2g} x least squares" if g else ""))
    for f in s.get("fit", []):
        deg = f" degree {f['degree']}" if f["degree"] is not None else ""
        loo = f", leave-one-out {f['loo_rms']:.3g}" if f["loo_rms"] is not None else ""
        print(f"fit {f['name']}: {f['method']}{deg}, residual RMS {f['rms_residual']:.3g} "
              f"max {f['max_residual']:.3g}{loo} {f['unit']}")
    for o in s["outliers"]:
        print(f"warning: round {o['round']} position {o['position']:g} point {o['point']}: "
              f"residual {o['residual_um']:.3g} um = {o['ratio']:.1f} x noise", file=sys.stderr)
    return 0
