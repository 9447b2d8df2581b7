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
    import sys

    from ..fiveaxis.api import tcpmap
    from ._common import progress_bar

    inputs = [*Path(args.errors).glob("*.csv"), *layout_inputs(args.layout)]
    outs = Outputs(inputs).plot("--plot", args.plot).file("--csv", args.csv).check()
    with progress_bar(None, "tcpmap", total=args.steps * args.steps, unit="points") as tick:
        res = tcpmap(args.layout, args.errors, tuple(args.point), tool=tuple(args.tool),
                     steps=args.steps, approach=args.approach, method=args.method,
                     degree=args.degree, extrapolate=args.extrapolate, plot_name=args.plot,
                     progress=tick, accept_implausible=args.accept_implausible)
    with outs:
        res.write_plot(outs.path("--plot"))
        if args.csv:
            write_text(outs.path("--csv"), res.csv_text(), inputs)
    print(res.summary())
    # notes only after success: bad input gets exactly one line on stderr
    for note in res.notes:
        print(note, file=sys.stderr)
    return 0
