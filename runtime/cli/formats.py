"""``volerr formats [NAME]``: the file formats, printed from the text shipped in the package.

Without NAME: the list of sections.  The text is ``volerr/data/formats.md`` (identical to
``docs/formats.md`` of the source tree).
"""

from __future__ import annotations

import re
from importlib import resources

from ..errors import require


def register(sub) -> None:
    p = sub.add_parser("formats", help="the file formats (error tables, tracker CSV, layout "
                                       "TOML, G-code ...)",
                       description="Print the file formats volerr reads and writes: all "
                                   "section names, or one section.")
    p.add_argument("name", nargs="?", metavar="NAME",
                   help="section: tables, tracker, probe-sphere, deviations, ballbar, sphere, "
                        "artifact, interferometer, distances, drift, iso230-3, calibrate-json, loop-json, "
                        "layout, gcode, tools, controller, axis-tables, uncertainty, iso230-2, "
                        "outputs, audit, or 'all'")
    p.set_defaults(func=run)


def text() -> str:
    """The whole formats document."""
    return (resources.files("volerr") / "data" / "formats.md").read_text(encoding="utf-8")


def sections() -> dict:
    """NAME -> (title, section text); NAME is the word in brackets of a ``##`` heading, for
    the ISO 230-2 section ``iso230-2``."""
    out = {}
    parts = re.split(r"(?m)^## ", text())
    for part in parts[1:]:
        title = part.splitlines()[0].strip()
        m = re.search(r"\(([a-z0-9-]+)\)\s*$", title)
        name = m.group(1) if m else ("iso230-2" if "230-2" in title else
                                     title.split()[0].lower())
        out[name] = (title, "## " + part.rstrip() + "\n")
    return out


def run(args) -> int:
    secs = sections()
    if args.name is None:
        print("File formats (volerr formats NAME; docs/formats.md):")
        for name, (title, _) in secs.items():
            short = re.sub(r"\s*\([a-z0-9-]+\)$", "", title)
            print(f"  {name:15s} {short}")
        return 0
    if args.name == "all":
        print(text(), end="")
        return 0
    require(args.name in secs, f"no format section {args.name!r}; sections: "
                               f"{' '.join(secs)}")
    print(secs[args.name][1], end="")
    return 0
