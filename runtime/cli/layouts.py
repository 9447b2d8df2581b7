"""``volerr layouts [--long]``: list the shipped layouts (with --long: axes, travel, rotary axis
points, parameters and the description)."""

import textwrap

from volerr.machine.layout import layout_names, read_layout


def register(sub) -> None:
    p = sub.add_parser("layouts", help="list the shipped machine layouts",
                       description=__doc__.split(":", 1)[1].strip())
    p.add_argument("--long", action="store_true",
                   help="with axes, travel, rotary axis points, parameters and description")
    p.set_defaults(func=run)


def _num(v) -> str:
    return f"{v:g}" if isinstance(v, (int, float)) else str(v)


def describe(lay) -> str:
    """Several lines on one layout: axes with travel (mm / deg), points on rotary axes,
    parameters, the description."""
    lines = [f"{lay.name}  ({lay.kind})"]
    for a in lay.axis_names:
        ax = lay.axes[a]
        unit = "deg" if ax.kind == "rotary" else "mm"
        text = (f"  {a}: {ax.kind:6s} travel {_num(ax.travel[0])} .. {_num(ax.travel[1])} "
                f"{unit}, direction ({', '.join(_num(c) for c in ax.direction)})")
        if ax.kind == "rotary":
            text += f", through ({', '.join(_num(c) for c in ax.point)}) mm"
        lines.append(text)
    if lay.parameters:
        lines.append("  parameters: " + ", ".join(f"{k} = {_num(v)} mm"
                                                  for k, v in sorted(lay.parameters.items())))
    desc = " ".join(lay.description.split())
    if desc:
        lines.extend(textwrap.wrap(desc, width=94, initial_indent="  ",
                                   subsequent_indent="  "))
    return "\n".join(lines)


def run(args) -> int:
    for name in layout_names():
        if args.long:
            print(describe(read_layout(name)))
            print()
        else:
            print(name)
    return 0
