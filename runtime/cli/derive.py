"""``volerr derive LAYOUT [--out DIR]``: derive a layout and generate its numpy module.

``volerr derive --all`` regenerates every file of ``generated/``: one module per shipped layout
plus the layout-independent modules (identification solves, probe frame).
"""

from pathlib import Path

from volerr.errors import require
from volerr.fileio import write_text
from volerr.machine import derivation
from volerr.machine.layout import read_layout


def register(sub) -> None:
    p = sub.add_parser("derive", help="derive and generate one layout (or --all)")
    p.add_argument("layout", nargs="*", help="layout name or layout file")
    p.add_argument("--all", action="store_true",
                   help="every shipped layout and every layout-independent module")
    p.add_argument("--out", help="output folder (default: the package's generated/)")
    p.set_defaults(func=run)


def run(args) -> int:
    require(args.layout or args.all, "name a layout (see 'volerr layouts') or use --all")
    out = Path(args.out) if args.out else derivation.package_generated_dir()
    texts = {}
    for name in args.layout:
        layout = read_layout(name)
        texts[derivation.module_filename(layout)] = derivation.generate_source(layout)
    if args.all:
        texts.update(derivation.all_sources())
    for filename, text in texts.items():
        path = write_text(out / filename, text, inputs=list(args.layout))
        print(f"{filename[:-3]}: {path}")
    return 0
