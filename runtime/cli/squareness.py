"""``volerr squareness``: squareness of straightness tables (:func:`volerr.cmm.api.squareness`)."""

from __future__ import annotations

from pathlib import Path

from ..errors import require
from ..fileio import planned_outputs
from ._common import (add_accept_implausible, add_errors_out, add_force, add_json, command_parser,
                      options_of)


def register(sub) -> None:
    p, H = command_parser(sub, "squareness")
    p.add_argument("layout", help="layout name or layout file")
    p.add_argument("directory", help="error directory with the straightness tables")
    add_errors_out(p, H["--errors-out"], "--out", required=True)
    add_force(p)
    add_accept_implausible(p)
    p.add_argument("--tables-are", choices=("carrier", "component"), default="carrier",
                   help=H["--tables-are"])
    add_json(p, "the squareness and the slopes (urad)")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..cmm.api import squareness
    from ..fileio import layout_inputs

    src, out = Path(args.directory), Path(args.errors_out)
    require(not (out.exists() and out.resolve() == src.resolve()),
            "--errors-out must differ from the input directory (inputs are never overwritten)")
    res = squareness(args.layout, src, **options_of(args, "tables_are accept_implausible"))
    inputs = [p for p in src.iterdir() if p.is_file()] + layout_inputs(args.layout)
    files = [*res.texts, "constants.csv"]
    with planned_outputs(vars(args), inputs, **{"--errors-out": (out, files)}) as outs:
        res.write_dir(outs.path("--errors-out"), inputs)
        res.write_files(outs, vars(args), inputs, ("json",))
    print(f"{res.summary()}\n-> {out}")
    return 0
