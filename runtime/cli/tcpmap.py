"""``volerr tcpmap LAYOUT --errors DIR --point X Y Z --plot F.png``: tool-tip error over the
range of the two rotary axes of a five-axis machine for one workpiece point.

For every pair of rotary positions the linear axes follow the nominal inverse kinematics so
that the tool tip stays on the point (x, y, z) of the workpiece frame (mm); the map shows the
predicted error there (length and dx, dy, dz in um).  Grey: the linear axes leave their travel
or a position leaves an error table's measured range.  ``--csv`` writes the grid:
``<R1>_deg,<R2>_deg,X_mm,Y_mm,Z_mm,dx_um,dy_um,dz_um,e_um`` (empty error cells where invalid).
"""

from __future__ import annotations

from pathlib import Path

from ._common import add_error_arguments, add_vector
from ..errors import require
from ._common import layout_inputs
from ..fileio import Outputs, write_text


def register(sub) -> None:

    p = sub.add_parser("tcpmap", help="five-axis tool-tip error over the rotary range (PNG)",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("layout", help="five-axis layout name or file")
    add_error_arguments(p)
    add_vector(p, "--point", required=True,
               help="workpiece point X Y Z, mm, workpiece frame (X Y Z or X,Y,Z)")
    add_vector(p, "--tool", default=(0.0, 0.0, 0.0),
               help="tool-tip offset XT YT ZT in the tool frame, mm (X Y Z or X,Y,Z)")
    p.add_argument("--steps", type=int, default=73, help="grid steps per rotary axis")
    from ._common import add_plot

    add_plot(p, "the map", "--out", required=True)
    p.add_argument("--csv", metavar="F.csv", help="write the grid (CSV)")
    p.add_argument("--approach", default=None, metavar="DIRS",
                   help="approach direction of linear axes whose tables carry a reversal "
                        "column RV_<axis>_um: X+,Y- per axis, + / - for all, or sweep (the "
                        "grid run row by row with the first rotary axis rising, each axis "
                        "approaching in the direction it moves; not given: the bidirectional "
                        "mean)")
    p.set_defaults(func=run)


def run(args) -> int:
    import math
    import sys

    import numpy as np

    from ..fiveaxis.compensate import error_functions
    from ..machine.model import load
    from ..fiveaxis.plots import plot_tcp_error_map
    from ..fiveaxis.tcpmap import tcp_map

    model = load(args.layout)
    require(len(model.rotary_axes) == 2, f"{model.name}: tcpmap needs a five-axis layout")
    require(all(math.isfinite(v) for v in (*args.point, *args.tool)), "point/tool must be finite")
    require(3 <= args.steps <= 1000, "--steps must be 3..1000")
    require(not Path(args.errors).is_file(), f"{args.errors} is a file, not an error "
                                              f"directory (the folder holding X.csv ...)")
    require(Path(args.errors).is_dir(), f"error directory not found: {args.errors}")
    funcs, notes = error_functions(args.errors, model, args.method, args.degree,
                                   args.extrapolate)
    inputs = [*Path(args.errors).glob("*.csv"), *layout_inputs(args.layout)]
    outs = Outputs(inputs).plot("--plot", args.plot).file("--csv", args.csv).check()
    from ..tables.functions import parse_approach
    from ._common import progress_bar

    approach = "sweep" if args.approach == "sweep" else \
        parse_approach(args.approach, model, funcs)
    with progress_bar(None, "tcpmap", total=args.steps * args.steps, unit="points") as tick:
        tmap = tcp_map(model, funcs, args.point, args.tool, args.steps, args.steps,
                       approach=approach, progress=tick)
    a1, a2, q1, q2, err, valid = tmap.axis1, tmap.axis2, tmap.q1, tmap.q2, tmap.err, tmap.valid
    require(valid.any(), f"{model.name}: the point is outside the travel or the error tables "
                         "for every rotary position")
    with outs:
        plot_tcp_error_map(tmap, outs.path("--plot"))
        if args.csv:
            write_text(outs.path("--csv"), _grid_csv(tmap), inputs)
    mag = np.linalg.norm(err, axis=2) * 1e3
    print(f"{model.name}: tool-tip error at ({', '.join(f'{v:g}' for v in args.point)}) mm over "
          f"{a1} {q1[0]:g}..{q1[-1]:g} deg, {a2} {q2[0]:g}..{q2[-1]:g} deg: max "
          f"{np.nanmax(mag):.3f} um, min {np.nanmin(mag):.3f} um "
          f"({int(valid.sum())} of {valid.size} grid points valid); wrote {args.plot}")
    # notes only after success: bad input gets exactly one line on stderr
    for note in notes:
        print(f"note: {note}", file=sys.stderr)
    return 0


def _grid_csv(tmap) -> str:
    """The ``--csv`` text: one row per grid point, empty error cells where invalid."""
    import numpy as np

    g1, g2 = np.meshgrid(tmap.q1, tmap.q2)
    lin = tmap.linear.reshape(-1, 3)
    e = tmap.err.reshape(-1, 3) * 1e3
    m = np.linalg.norm(tmap.err, axis=2).ravel() * 1e3
    rows = [f"{tmap.axis1}_deg,{tmap.axis2}_deg,X_mm,Y_mm,Z_mm,dx_um,dy_um,dz_um,e_um"]
    for i in range(g1.size):
        cells = [f"{g1.ravel()[i]:.10g}", f"{g2.ravel()[i]:.10g}"] + \
            [f"{lin[i, k]:.10g}" for k in range(3)]
        cells += [("" if not np.isfinite(v) else f"{v:.6g}") for v in (*e[i], m[i])]
        rows.append(",".join(cells))
    return "\n".join(rows) + "\n"
