"""``volerr demo [--out DIR]``: argument parsing only, the run is :func:`volerr.demo`."""

from __future__ import annotations

from ..choices import DEMO_SECTIONS as SECTIONS
from ._common import add_force, command_parser


def register(sub) -> None:
    p, H = command_parser(sub, "demo")
    p.add_argument("--out", default="volerr-demo", help="output folder (default volerr-demo)")
    p.add_argument("--only", nargs="+", choices=SECTIONS, help="run only these sections")
    p.add_argument("--jobs", type=int, default=None, metavar="N", help=H["--jobs"])
    add_force(p)
    p.set_defaults(func=run)


def run(args):
    from ..demo import demo

    return demo(args.out, only=args.only, force=args.force, jobs=args.jobs)
