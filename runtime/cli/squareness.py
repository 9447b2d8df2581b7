"""``volerr squareness LAYOUT DIR --errors-out DIR2``: squareness from straightness reference lines.

Reads the error tables of DIR (``X.csv``, ``Y.csv``, ``Z.csv`` ..., e.g. written by ``volerr
identify``), fits the least-squares reference straight line of every straightness, writes the
squareness errors ``EC0Y EB0Z EA0Z`` (those whose two straightness tables exist) to
``DIR2/constants.csv`` (with the other constants of DIR) and the tables with the slopes removed
to DIR2.  Sign convention: ``volerr.cmm.squareness``.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import require
from ._common import add_accept_implausible, add_errors_out, add_force, add_json


def register(sub) -> None:
    p = sub.add_parser("squareness", help="squareness of linear axes from straightness tables",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("layout", help="layout name or layout file")
    p.add_argument("directory", help="error directory with the straightness tables")
    add_errors_out(p, "the squareness with the slope-free tables (must differ from DIR)",
                   "--out", required=True)
    add_force(p)
    add_accept_implausible(p)
    p.add_argument("--tables-are", choices=("carrier", "component"), default="carrier",
                   help="carrier: motions of the component carrying the points, as written by "
                        "'volerr identify' (default); component: ISO component errors (tool "
                        "relative to workpiece)")
    add_json(p, "the squareness and the slopes (urad)")
    p.set_defaults(func=run)


def run(args) -> int:
    from ._common import layout_inputs
    from ..cmm.api import squareness
    from ..fileio import Outputs

    src, out = Path(args.directory), Path(args.errors_out)
    require(not (out.exists() and out.resolve() == src.resolve()),
            "--errors-out must differ from the input directory (inputs are never overwritten)")
    res = squareness(args.layout, src, tables_are=args.tables_are,
                     accept_implausible=args.accept_implausible)
    inputs = [p for p in src.iterdir() if p.is_file()] + layout_inputs(args.layout)
    outs = Outputs(inputs, force=args.force) \
        .folder("--errors-out", out, files=[*res.texts, "constants.csv"]) \
        .file("--json", args.json).check()
    with outs:
        res.write_dir(outs.path("--errors-out"), inputs)
        if args.json:
            res.write_json(outs.path("--json"), inputs)
    print(res.summary())
    print(f"-> {out}")
    return 0
