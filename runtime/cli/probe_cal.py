"""``volerr probe-cal``: probe (lobing) calibration on a master sphere (Pahk sec. 3.2, eq. 13).

    volerr probe-cal DATA.csv --sphere-radius R --out MAP.csv [--json F] [--plots DIR]
    volerr probe-cal --plan PLAN.csv --sphere-radius R --ball-radius r [--center X,Y,Z]

The first form fits the sphere of the recorded ball centres, reports the effective ball radius
R_eff and Probe(phi, theta) at every point (MAP.csv) and fits the smooth map.  The second writes
a probing plan (Pahk's 101 points by default) as nominal ball centres in the same CSV format.
Conventions: see :mod:`volerr.probe.calibration`.
"""

from __future__ import annotations

import math
import sys

from ._common import (add_force, add_identification_arguments, add_vector,
                      identification_from_args, write_certificates)
from ..errors import require
from ..fileio import json_text, write_text
from ..units import parse_number


def register(sub) -> None:
    p = sub.add_parser(
        "probe-cal", help="probe lobing calibration on a master sphere (Pahk eq. 13)",
        description="Master-sphere probe calibration (Pahk 1995 sec. 3): least-squares sphere "
                    "of the recorded stylus-ball centres, effective ball radius R_eff and the "
                    "probe error Probe(phi, theta) = R_eff - (R_m - R_s) at every point, plus a "
                    "smooth spherical-harmonic map. Directions: outward normal at the contact "
                    "(sphere centre -> ball centre), phi from the probe axis, theta azimuth, in "
                    "the probe frame of tilt A / roll B. With --plan: write a probing plan.")
    p.add_argument("data", nargs="?", metavar="DATA.csv",
                   help="CSV x,y,z (ball centres, mm) [,phi_deg,theta_deg (probe frame)]")
    p.add_argument("--sphere-radius", type=float, required=True, metavar="R",
                   help="master-sphere radius, mm (calibrated value)")
    p.add_argument("--out", metavar="MAP.csv",
                   help="output map: phi_deg,theta_deg,probe_um (+ map_um, residual_um, "
                        "r_m_mm, outlier)")
    p.add_argument("--json", metavar="F", help="summary: r_eff_mm, center_mm, probe_error_um")
    p.add_argument("--tilt-deg", type=float, default=0.0, metavar="A",
                   help="probe-head tilt A, deg (default 0: vertical probe)")
    p.add_argument("--roll-deg", type=float, default=0.0, metavar="B",
                   help="probe-head roll B, deg (default 0)")
    p.add_argument("--degree", type=int, metavar="L",
                   help="spherical-harmonic degree of the smooth map (default: by "
                        "cross-validation)")
    p.add_argument("--outlier-k", type=float, default=5.0, metavar="K",
                   help="flag points whose leave-one-out map residual exceeds K x 1.4826 MAD "
                        "(default 5)")
    p.add_argument("--exclude-outliers", action="store_true",
                   help="refit without the flagged points (they stay in MAP.csv, flagged)")
    p.add_argument("--plot", metavar="F.png",
                   help="one PNG with the 3-D lobing map (Fig. 3a) and the (phi, theta) map "
                        "(Fig. 3b)")
    p.add_argument("--plots", metavar="DIR",
                   help="write probe_map_3d.png (Fig. 3a) and probe_map_2d.png (Fig. 3b) into "
                        "DIR (created when missing, its parent must exist)")
    add_force(p)
    g = p.add_argument_group("plan generation (--plan)")
    g.add_argument("--plan", metavar="PLAN.csv",
                   help="write a probing plan (nominal ball centres x,y,z,phi_deg,theta_deg) "
                        "instead of calibrating")
    p.add_argument("--ball-radius", type=float, metavar="r",
                   help="stylus-ball radius, mm (nominal): needed with --plan; when "
                        "calibrating, the effective radius the data give must match it within "
                        "the pretravel (0.1 mm), else --sphere-radius is refused")
    add_vector(g, "--center", default=(0.0, 0.0, 0.0),
               help="sphere centre X Y Z, mm (X Y Z or X,Y,Z)")
    g.add_argument("--step-deg", type=float, default=18.0,
                   help="Pahk plan: latitude and azimuth step, deg (default 18)")
    g.add_argument("--circles", type=int, default=5,
                   help="Pahk plan: number of latitude circles (default 5)")
    g.add_argument("--phis", metavar="P1,P2,...",
                   help="custom plan: circle latitudes phi, deg (with --per-circle)")
    g.add_argument("--per-circle", type=int, metavar="N", help="custom plan: points per circle")
    g.add_argument("--no-pole", action="store_true", help="leave out the pole point")
    add_identification_arguments(p, "the reference sphere (its calibration)")
    p.set_defaults(func=run)


def _floats(text: str, what: str) -> list[float]:
    """Comma-separated finite numbers (``30,60,90``)."""
    return [parse_number(v, what=what) for v in text.split(",") if v.strip()]


def _run_plan(args) -> int:
    from ..probe import plans as pp

    require(args.data is None, "give either DATA.csv (calibrate) or --plan (write a plan)")
    require(args.ball_radius is not None and args.ball_radius > 0,
            "--plan needs --ball-radius (stylus-ball radius, mm, > 0)")
    require(args.sphere_radius > 0, "--sphere-radius must be > 0 mm")
    center = list(args.center)
    if args.phis or args.per_circle:
        require(args.phis and args.per_circle, "a custom plan needs both --phis and --per-circle")
        plan = pp.circles_plan(_floats(args.phis, "--phis"), args.per_circle, not args.no_pole)
    else:
        plan = pp.pahk_plan(args.step_deg, args.circles, not args.no_pole)
    pts = pp.nominal_points(plan, center, args.sphere_radius, args.ball_radius,
                            args.tilt_deg, args.roll_deg)
    from ..fileio import Outputs

    with Outputs().file("--plan", args.plan) as outs:
        write_text(outs.path("--plan"), pp.plan_csv_text(plan, pts))
    print(f"plan: {len(plan)} points -> {args.plan}")
    return 0


def run(args) -> int:
    if args.plan:
        return _run_plan(args)
    from ..probe import calibration as probe
    from ..probe.api import probe_cal

    require(args.data, "name the probing data DATA.csv (or use --plan to write a plan)")
    require(args.out, "--out MAP.csv is required")
    require(math.isfinite(args.sphere_radius) and args.sphere_radius > 0,
            f"--sphere-radius must be a positive length in mm, got {args.sphere_radius}")
    require(args.ball_radius is None or (math.isfinite(args.ball_radius) and
                                         args.ball_radius > 0),
            f"--ball-radius must be a positive length in mm, got {args.ball_radius}")
    from ..fileio import Outputs

    inputs = [args.data]
    outs = Outputs(inputs, force=args.force).file("--out", args.out) \
        .file("--json", args.json).file("--pdf", args.pdf) \
        .plot("--plot", args.plot) \
        .folder("--plots", args.plots, files=("probe_map_3d.png", "probe_map_2d.png")).check()
    require(args.degree is None or 0 <= args.degree <= 20,
            f"--degree must be between 0 and 20, got {args.degree}")
    ident = identification_from_args(args, inputs)
    res = probe_cal(args.data, args.sphere_radius, tilt_deg=args.tilt_deg,
                    roll_deg=args.roll_deg, degree=args.degree, outlier_k=args.outlier_k,
                    exclude_outliers=args.exclude_outliers, ball_radius=args.ball_radius)
    cal, summary = res.calibration, res.data
    with outs:
        write_text(outs.path("--out"), probe.map_csv_text(cal), inputs=inputs)
        if args.json:
            write_text(outs.path("--json"), json_text(summary), inputs=inputs)
        if args.plot:
            from ..probe.plots import plot_probe_calibration

            plot_probe_calibration(cal, outs.path("--plot"))
        if args.plots:
            from ..probe.plots import plot_probe_map_2d, plot_probe_map_3d

            d = outs.path("--plots")
            plot_probe_map_3d(cal, d / "probe_map_3d.png")
            plot_probe_map_2d(cal, d / "probe_map_2d.png")
        write_certificates(outs, res, ident, inputs)
    for note in cal.notes:
        print(f"volerr probe-cal: warning: {note}", file=sys.stderr)
    print(res.summary())
    print(f"map: {args.out}")
    return 0
