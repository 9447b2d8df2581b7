"""``volerr formats [NAME]``: the file formats, printed from the text shipped in the package
(:mod:`volerr.formats_doc`)."""

from __future__ import annotations


def __getattr__(name):
    # text() and sections() by their former place, imported only when asked (--help imports
    # no capability)
    if name in ("text", "sections"):
        from .. import formats_doc

        return getattr(formats_doc, name)
    raise AttributeError(name)


def register(sub) -> None:
    p = sub.add_parser("formats", help="the file formats (error tables, tracker CSV, layout "
                                       "TOML, G-code ...)",
                       description="Print the file formats volerr reads and writes: all "
                                   "section names, or one section.")
    p.add_argument("name", nargs="?", metavar="NAME",
                   help="section: tables, tracker, probe-sphere, deviations, ballbar, sphere, "
                        "artifact, interferometer, distances, drift, iso230-3, calibrate-json, "
                        "check, loop-json, history, layout, gcode, tools, controller, "
                        "axis-tables, uncertainty, iso230-2, outputs, audit, or 'all'")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..formats_doc import listing, section

    print(listing() if args.name is None else section(args.name), end="" if args.name else "\n")
    return 0
