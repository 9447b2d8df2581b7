"""``volerr probe-cal``: probe calibration or a probing plan (:func:`volerr.probe_cal`)."""

from __future__ import annotations

import sys

from ._common import (add_force, add_identification_arguments, add_vector, command_parser,
                      options_of)


def register(sub) -> None:
    p, H = command_parser(sub, "probe-cal")
    a = p.add_argument
    a("data", nargs="?", metavar="DATA.csv", help=H["data"])
    a("--sphere-radius", type=float, required=True, metavar="R", help=H["--sphere-radius"])
    a("--out", metavar="MAP.csv", help=H["--out"])
    a("--json", metavar="F", help="summary: r_eff_mm, center_mm, probe_error_um")
    a("--tilt-deg", type=float, default=0.0, metavar="A", help=H["--tilt-deg"])
    a("--roll-deg", type=float, default=0.0, metavar="B", help=H["--roll-deg"])
    a("--degree", type=int, metavar="L", help=H["--degree"])
    a("--outlier-k", type=float, default=5.0, metavar="K", help=H["--outlier-k"])
    a("--exclude-outliers", action="store_true", help=H["--exclude-outliers"])
    a("--plot", metavar="F.png", help=H["--plot"])
    a("--plots", metavar="DIR", help=H["--plots"])
    add_force(p)
    plan = p.add_argument_group("plan generation (--plan)")
    g = plan.add_argument
    g("--plan", metavar="PLAN.csv", help=H["--plan"])
    a("--ball-radius", type=float, metavar="r", help=H["--ball-radius"])
    add_vector(plan, "--center", default=(0.0, 0.0, 0.0), help=H["--center"])
    g("--step-deg", type=float, default=18.0, help=H["--step-deg"])
    g("--circles", type=int, default=5, help=H["--circles"])
    g("--phis", metavar="P1,P2,...", help=H["--phis"])
    g("--per-circle", type=int, metavar="N", help="custom plan: points per circle")
    g("--no-pole", action="store_true", help="leave out the pole point")
    add_identification_arguments(p, "the reference sphere (its calibration)")
    p.set_defaults(func=run)


def _run_plan(args) -> int:
    from ..fileio import Outputs
    from ..probe.api import probe_plan

    with Outputs().file("--plan", args.plan) as outs:
        res = probe_plan(**options_of(args, "sphere_radius ball_radius center tilt_deg "
                                            "roll_deg step_deg circles phis per_circle",
                                      pole=not args.no_pole))
        res.write_csv(outs.path("--plan"))
    print(f"{res.summary()} -> {args.plan}")
    return 0


def run(args) -> int:
    from ..probe.api import command_form, probe_cal
    from ..results import run_command

    command_form(args.data, args.plan, args.out)
    if args.plan:
        return _run_plan(args)
    res = run_command(vars(args), [args.data], lambda *_: probe_cal(**options_of(
        args, "data sphere_radius tilt_deg roll_deg degree outlier_k exclude_outliers "
              "ball_radius")), **{"--out": args.out, "--plots": (
        args.plots, ("probe_map_3d.png", "probe_map_2d.png"))})
    for note in res.calibration.notes:
        print(f"volerr probe-cal: warning: {note}", file=sys.stderr)
    print(f"{res.summary()}\nmap: {args.out}")
    return 0
