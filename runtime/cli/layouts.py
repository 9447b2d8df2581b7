"""``volerr layouts``: list the shipped layouts."""

from volerr.machine.layout import layout_names, read_layout


def register(sub) -> None:
    p = sub.add_parser("layouts", help="list the shipped machine layouts")
    p.add_argument("--long", action="store_true", help="with axes and description")
    p.set_defaults(func=run)


def run(args) -> int:
    for name in layout_names():
        if args.long:
            lay = read_layout(name)
            text = " ".join(lay.description.split())  # the first sentence, on one line
            first = text.split(". ")[0].rstrip(".") + "." if text else ""
            print(f"{name:8s} {' '.join(lay.axis_names):12s} {first}")
        else:
            print(name)
    return 0
