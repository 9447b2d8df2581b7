"""``volerr controller export|import``: error parameters for controllers with built-in
volumetric compensation (ISG CSV, Etalon exchange format; see :mod:`volerr.tables.controller`).

``volerr controller export LAYOUT --errors DIR --format isg|etalon --out F``
    writes the tables and constants of an error directory (component errors as grid points,
    position errors as values; mm and rad, arguments mm and deg).
``volerr controller import LAYOUT FILE --out DIR [--format auto|isg|etalon]``
    reads such a file back into an error directory (``X.csv`` ... ``constants.csv``, um and urad).
"""

from __future__ import annotations

from pathlib import Path

from ..errors import require


def register(sub) -> None:
    p = sub.add_parser("controller", help="export/import ISG CSV and Etalon controller tables",
                       description=__doc__.split("\n\n")[0])
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    e = s.add_parser("export", help="error directory -> controller file")
    e.add_argument("layout", help="layout name or file")
    e.add_argument("--errors", required=True, metavar="DIR", help="error directory")
    e.add_argument("--format", choices=("isg", "etalon"), required=True,
                   help="isg: ISG CSV; etalon: Etalon exchange format")
    e.add_argument("--out", required=True, help="controller file to write")
    e.add_argument("--negate", action="store_true",
                   help="write compensation values (the errors with reversed sign) for a "
                        "controller that expects them")
    e.set_defaults(func=run)
    i = s.add_parser("import", help="controller file -> error directory")
    i.add_argument("layout", help="layout name or file")
    i.add_argument("file", help="ISG CSV or Etalon file")
    i.add_argument("--format", choices=("auto", "isg", "etalon"), default="auto",
                   help="format of FILE: auto (from its content), isg or etalon")
    from ._common import add_errors_out, add_force

    add_errors_out(i, "the imported tables", "--out", required=True)
    add_force(i)
    i.add_argument("--negate", action="store_true",
                   help="the file holds compensation values: reverse their sign")
    i.set_defaults(func=run)


def run(args) -> int:
    from ..tables import controller as ct
    from ._common import layout_inputs
    from ..fileio import Outputs, write_text
    from ..machine.model import load
    from ..tables.table import read_error_dir, write_error_dir

    model = load(args.layout)
    if args.action == "export":
        require(not Path(args.errors).is_file(), f"{args.errors} is a file, not an error "
                                                  f"directory (the folder holding X.csv ...)")
        require(Path(args.errors).is_dir(), f"error directory not found: {args.errors}")
        tables, (consts, _, _) = read_error_dir(args.errors, model.axes)
        ct.check_against_model(model, tables, consts, args.errors)
        require(tables or consts, f"{args.errors}: no error tables or constants to export")
        if args.negate:
            tables, consts = ct.negated(tables, consts)
        writer = ct.write_isg if args.format == "isg" else ct.write_etalon
        inputs = list(Path(args.errors).glob("*.csv")) + layout_inputs(args.layout)
        with Outputs(inputs).file("--out", args.out) as outs:
            write_text(outs.path("--out"), writer(model.name, tables, consts), inputs)
        n = sum(len(t.values) for t in tables.values())
        print(f"{model.name}: wrote {n} component errors ({len(tables)} axes) and "
              f"{len(consts)} position errors to {args.out} ({args.format}"
              f"{', negated: compensation values' if args.negate else ''})")
        return 0
    inputs = [args.file] + layout_inputs(args.layout)
    outs = Outputs(inputs, force=args.force).folder("--errors-out", args.errors_out,
                                  files=[f"{a}.csv" for a in model.axes] + ["constants.csv"])
    outs.check()
    tables, consts = ct.read_controller_file(args.file, model, args.format)
    if args.negate:
        tables, consts = ct.negated(tables, consts)
    out = Path(args.errors_out)
    with outs:
        write_error_dir(outs.path("--errors-out"), tables, consts or None, inputs=inputs)
    n = sum(len(t.values) for t in tables.values())
    print(f"{model.name}: read {n} component errors ({len(tables)} axes) and {len(consts)} "
          f"position errors from {args.file}; wrote {out}/")
    return 0
