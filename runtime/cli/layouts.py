"""``volerr layouts [--long]``: list the shipped layouts (with --long: axes, travel, rotary axis
points, parameters and the description)."""

from ..machine.layout import describe, layout_names, read_layout


def register(sub) -> None:
    p = sub.add_parser("layouts", help="list the shipped machine layouts",
                       description=__doc__.split(":", 1)[1].strip())
    p.add_argument("--long", action="store_true",
                   help="with axes, travel, rotary axis points, parameters and description")
    p.set_defaults(func=run)


def run(args) -> int:
    for name in layout_names():
        print(f"{describe(read_layout(name))}\n" if args.long else name)
    return 0
