"""``volerr derive LAYOUT [--out DIR]``: derive a layout and generate its numpy module.

``volerr derive --all`` regenerates every file of ``generated/``: one module per shipped layout
plus the layout-independent modules listed in :data:`EXTRA_MODULES`.
"""

import importlib
from pathlib import Path

from volerr.errors import require
from volerr.fileio import write_text
from volerr.layout import layout_names, read_layout

#: generated file name -> "module:function" returning that file's text (no arguments).
#: Layout-independent derivations (identification solves, probe frame) register here.
EXTRA_MODULES = {
    "three_point.py": "volerr.derive.three_point:generate_module",
    "probe.py": "volerr.derive.probe:generate_module",
}


def register(sub) -> None:
    p = sub.add_parser("derive", help="derive and generate one layout (or --all)")
    p.add_argument("layout", nargs="*", help="layout name or layout file")
    p.add_argument("--all", action="store_true",
                   help="every shipped layout and every layout-independent module")
    p.add_argument("--out", help="output folder (default: the package's generated/)")
    p.set_defaults(func=run)


def generated_dir() -> Path:
    import volerr.generated

    return Path(volerr.generated.__file__).parent


def all_generated() -> dict:
    """File name -> text of every file ``volerr derive --all`` writes (imports sympy)."""
    from volerr.derive.generate import generate_module, module_name

    out = {f"{module_name(n)}.py": generate_module(read_layout(n)) for n in layout_names()}
    for filename, target in EXTRA_MODULES.items():
        mod_name, func = target.split(":")
        try:
            mod = importlib.import_module(mod_name)
        except ModuleNotFoundError as exc:
            if exc.name == mod_name:
                continue  # that derivation is not part of this build
            raise
        out[filename] = getattr(mod, func)()
    return out


def run(args) -> int:
    from volerr.derive.generate import generate_module, module_name

    require(args.layout or args.all, "name a layout (see 'volerr layouts') or use --all")
    out = Path(args.out) if args.out else generated_dir()
    texts = {}
    for name in args.layout:
        layout = read_layout(name)
        texts[f"{module_name(layout.name)}.py"] = generate_module(layout)
    if args.all:
        texts.update(all_generated())
    for filename, text in texts.items():
        path = write_text(out / filename, text, inputs=list(args.layout))
        print(f"{filename[:-3]}: {path}")
    return 0
