"""``volerr derive LAYOUT [--out DIR]``: derive a layout and generate its numpy module; see
``volerr derive --help``."""

from pathlib import Path

from ._common import command_parser


def register(sub) -> None:
    p, H = command_parser(sub, "derive")
    p.add_argument("layout", nargs="*", help="layout name or layout file")
    p.add_argument("--all", action="store_true", help=H["--all"])
    p.add_argument("--out", metavar="DIR", default=None, help=H["--out"])
    p.add_argument("--in-package", action="store_true", help=H["--in-package"])
    p.add_argument("--force", action="store_true", help=H["--force"])
    p.set_defaults(func=run)


def run(args) -> int:
    from ..fileio import Outputs, write_text
    from ..machine import derivation
    from ..progress import progress

    out, in_package, layouts = derivation.derive_request(
        args.layout, all_layouts=args.all, out=args.out, in_package=args.in_package)
    inputs = [p for p in (Path(n) for n in args.layout) if p.is_file()]
    # rewriting generated modules is what derive is for: a file is replaced while it is as
    # volerr derive wrote it (stale or not), an edited one only with --force
    outs = Outputs(inputs, allow_package=in_package, force=args.force).folder(
        "--out", out, derivation.target_names(layouts, args.all),
        replace=derivation.not_replaceable).check()
    texts = derivation.derived_sources(layouts, args.all, progress)
    with outs:
        for filename, text in texts.items():
            write_text(outs.path("--out") / filename, text, inputs=inputs)
    for filename in texts:
        print(f"{filename[:-3]}: {out / filename}")
    return 0
