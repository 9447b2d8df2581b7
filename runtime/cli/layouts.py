"""``volerr layouts [--long]``: list the shipped layouts; see ``volerr layouts --help``."""

from ..machine.layout import describe, layout_names, read_layout
from ._common import command_parser


def register(sub) -> None:
    p, H = command_parser(sub, "layouts")
    p.add_argument("--long", action="store_true", help=H["--long"])
    p.set_defaults(func=run)


def run(args) -> int:
    for name in layout_names():
        print(f"{describe(read_layout(name))}\n" if args.long else name)
    return 0
