"""``volerr derive LAYOUT [--out DIR]``: derive a layout and generate its numpy module.

Writes ``<name>.py`` into ``--out`` (default: ``./generated/`` of the working directory), never
into the installed package.  ``volerr derive --all`` regenerates every file of ``generated/``
(one module per shipped layout plus the layout-independent modules); run from a source checkout
it writes the committed ``generated/`` folder (that is ``./generated/`` there), elsewhere give
``--out DIR`` or, as a developer, ``--in-package`` to regenerate the installed package's folder.
"""

from pathlib import Path

from ..errors import require
from ..fileio import Outputs, is_package_file, write_text
from ..machine import derivation
from ..machine.layout import read_layout


def register(sub) -> None:
    p = sub.add_parser("derive", help="derive and generate one layout (or --all)",
                       description=__doc__.split("\n\n")[1])
    p.add_argument("layout", nargs="*", help="layout name or layout file")
    p.add_argument("--all", action="store_true",
                   help="every shipped layout and every layout-independent module")
    p.add_argument("--out", metavar="DIR", default=None,
                   help="output folder (default: ./generated of the working directory)")
    p.add_argument("--in-package", action="store_true",
                   help="developers: with --all, regenerate the installed package's generated/ "
                        "folder")
    p.set_defaults(func=run)


def run(args) -> int:
    require(args.layout or args.all, "name a layout (see 'volerr layouts') or use --all")
    require(not (args.in_package and args.out), "give either --out DIR or --in-package")
    out = derivation.package_generated_dir() if args.in_package else \
        Path(args.out if args.out else "generated")
    # the committed generated/ folder may be rewritten only as a whole, by --all
    in_package = is_package_file(out)
    if in_package:
        require(out.resolve() == derivation.package_generated_dir().resolve(),
                f"--out {out}: refusing to write into the installed volerr package")
        require(args.all and not args.layout,
                f"{out} is the installed package's generated/ folder: only 'volerr derive "
                f"--all' rewrites it; give --out DIR for a layout")
    require(not args.in_package or args.all, "--in-package regenerates everything: add --all")
    layouts = [read_layout(name) for name in args.layout]
    names = [derivation.module_filename(lay) for lay in layouts]
    if args.all:
        from ..machine.layout import layout_names
        names += [derivation.module_filename(read_layout(n)) for n in layout_names()]
    dup = sorted({n for n in names if names.count(n) > 1})
    require(not dup, f"two layouts generate the same module {dup[0] if dup else ''}: give them "
                     f"different names or derive them one at a time")
    inputs = [p for p in (Path(n) for n in args.layout) if p.is_file()]
    # rewriting generated modules is what derive is for: its files may be replaced
    outs = Outputs(inputs, allow_package=in_package).folder("--out", out, replace=True).check()
    texts = {}
    from ._common import progress

    for layout in progress(layouts, desc="derive", unit="layout"):
        texts[derivation.module_filename(layout)] = derivation.generate_source(layout)
    if args.all:
        texts.update(derivation.all_sources(
            lambda names: progress(names, desc="derive --all", unit="layout")))
    with outs:
        for filename, text in texts.items():
            write_text(outs.path("--out") / filename, text, inputs=inputs)
    for filename in texts:
        print(f"{filename[:-3]}: {out / filename}")
    return 0
