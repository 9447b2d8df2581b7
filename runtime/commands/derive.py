"""``volerr derive LAYOUT [--out DIR]``: derive a layout and generate its numpy module."""

from pathlib import Path

from volerr.fileio import write_text
from volerr.layout import layout_names, read_layout


def register(sub) -> None:
    p = sub.add_parser("derive", help="derive and generate one layout (or --all)")
    p.add_argument("layout", nargs="*", help="layout name or layout file")
    p.add_argument("--all", action="store_true", help="every shipped layout")
    p.add_argument("--out", help="output folder (default: the package's generated/)")
    p.set_defaults(func=run)


def generated_dir() -> Path:
    import volerr.generated

    return Path(volerr.generated.__file__).parent


def run(args) -> int:
    from volerr.derive.generate import generate_module, module_name
    from volerr.errors import require

    names = list(args.layout) + (layout_names() if args.all else [])
    require(names, "name a layout (see 'volerr layouts') or use --all")
    out = Path(args.out) if args.out else generated_dir()
    for name in names:
        layout = read_layout(name)
        path = out / f"{module_name(layout.name)}.py"
        write_text(path, generate_module(layout), inputs=[name])
        print(f"{layout.name}: {path}")
    return 0
