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
from ..units import URAD_PER_RAD
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
    from ..fileio import Outputs, json_text, write_text
    from ..machine.layout import read_layout
    from ..cmm.squareness import squareness
    from ..tables.table import read_error_dir, table_to_csv, write_constants

    layout = read_layout(args.layout)
    src, out = Path(args.directory), Path(args.errors_out)
    require(src.exists(), f"error directory {src} does not exist")
    require(src.is_dir(), f"{src} is a file: give the error directory (X.csv, Y.csv ...)")
    require(not (out.exists() and out.resolve() == src.resolve()),
            "--errors-out must differ from the input directory (inputs are never overwritten)")
    tables, (consts, cstd, _) = read_error_dir(src, axes=layout.axis_names, machine=layout,
                                               accept_implausible=args.accept_implausible)
    require(tables, f"{src}: no error tables")
    values, std, corrected, slopes = squareness(tables, layout, args.tables_are)
    require(values, f"{src}: no pair of straightness tables for a squareness (EC0Y needs EYX "
                    f"in X.csv and EXY in Y.csv, EB0Z EZX and EXZ, EA0Z EZY and EYZ)")
    inputs = [p for p in src.iterdir() if p.is_file()] + layout_inputs(args.layout)
    texts = {f"{ax}.csv": table_to_csv(t) for ax, t in corrected.items()}
    outs = Outputs(inputs, force=args.force) \
        .folder("--errors-out", out, files=[*texts, "constants.csv"]) \
        .file("--json", args.json).check()
    merged = {k: v for k, v in consts.items() if k not in values}
    merged_std = {k: v for k, v in cstd.items() if k in merged}
    merged.update(values)
    merged_std.update(std)
    with outs:
        staged = outs.path("--errors-out")
        for name, text in texts.items():
            write_text(staged / name, text, inputs=inputs)
        write_constants(staged / "constants.csv", merged, inputs=inputs, std=merged_std,
                        machine=layout, accept_implausible=args.accept_implausible)
        if args.json:
            doc = {"squareness_urad": {k: v * URAD_PER_RAD for k, v in values.items()},
                   "u_urad": {k: v * URAD_PER_RAD for k, v in std.items()},
                   "slopes_urad": {k: v * URAD_PER_RAD for k, v in slopes.items()},
                   "tables_are": args.tables_are}
            write_text(outs.path("--json"), json_text(doc), inputs=inputs)
    for sq, v in values.items():
        print(f"{sq} = {v * URAD_PER_RAD:.3f} urad (u = {std[sq] * URAD_PER_RAD:.3f} urad)")
    print(f"-> {out}")
    return 0
