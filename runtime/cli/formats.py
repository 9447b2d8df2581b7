"""``volerr formats [NAME]``: the file formats, printed from the text shipped in the package
(:mod:`volerr.formats_doc`)."""

from __future__ import annotations

from ._common import command_parser


def __getattr__(name):
    # text() and sections() by their former place, imported only when asked (--help imports
    # no capability)
    if name in ("text", "sections"):
        from .. import formats_doc

        return getattr(formats_doc, name)
    raise AttributeError(name)


def register(sub) -> None:
    p, H = command_parser(sub, "formats")
    p.add_argument("name", nargs="?", metavar="NAME", help=H["name"])
    p.set_defaults(func=run)


def run(args) -> int:
    from ..formats_doc import listing, section

    print(listing() if args.name is None else section(args.name), end="" if args.name else "\n")
    return 0
