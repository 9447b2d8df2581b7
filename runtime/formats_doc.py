"""The file formats document shipped in the package (``volerr/data/formats.md``, identical to
``docs/formats.md`` of the source tree), whole or by section (``volerr formats [NAME]``)."""

from __future__ import annotations

import re
from importlib import resources

from .errors import require


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


def listing() -> str:
    """What ``volerr formats`` prints: every section's NAME and title."""
    rows = [f"  {name:15s} " + re.sub(r"\s*\([a-z0-9-]+\)$", "", title)
            for name, (title, _) in sections().items()]
    return "\n".join(["File formats (volerr formats NAME; docs/formats.md):", *rows])


def section(name: str) -> str:
    """The section NAME (``"all"``: the whole document); an unknown NAME is refused naming
    the sections."""
    if name == "all":
        return text()
    secs = sections()
    require(name in secs, f"no format section {name!r}; sections: {' '.join(secs)}")
    return secs[name][1]
