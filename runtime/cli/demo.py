"""``volerr demo [--out DIR]``: the whole pipeline on built-in data; writes a report.

Argument parsing only: the run is :func:`volerr.demo` (:mod:`volerr.demo`)."""

from __future__ import annotations

from ..choices import DEMO_SECTIONS as SECTIONS
from ._common import add_force


def register(sub) -> None:
    p = sub.add_parser("demo", help="the whole pipeline on built-in data; writes a report",
                       description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default="volerr-demo", help="output folder (default volerr-demo)")
    p.add_argument("--only", nargs="+", choices=SECTIONS, help="run only these sections")
    p.add_argument("--jobs", type=int, default=None, metavar="N",
                   help="worker processes for the sections (default: one per core, at most "
                        "2; 1: all in one process); the files do not depend on it")
    add_force(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..demo import demo

    print(demo(args.out, only=args.only, force=args.force, jobs=args.jobs).summary())
    return 0
