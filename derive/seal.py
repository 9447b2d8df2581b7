"""A text that says whether it is still as written: its last line a tag and the sha256 of the
text above it.  Every module the generator writes is sealed (:data:`GENERATED_TAG`:
``volerr derive`` replaces a file only while its seal holds, an edited one with ``--force``);
the derivation cache seals its entries with its own tag.  hashlib only (no sympy): the
runtime reads seals without deriving."""

from __future__ import annotations

import hashlib

#: the last line of every file ``volerr derive`` writes: the sha256 of the text above it
GENERATED_TAG = "# volerr derive sha256 "


def seal(text: str, tag: str = GENERATED_TAG) -> str:
    """``text`` (its trailing newlines dropped) and a last line ``tag`` + the sha256 of that
    text (UTF-8)."""
    body = text.rstrip("\n")
    return f"{body}\n{tag}{hashlib.sha256(body.encode('utf-8')).hexdigest()}\n"


def unseal(text: str, tag: str = GENERATED_TAG) -> str | None:
    """The text a :func:`seal` was put on (without its last line and final newline), or
    None when the last line is not ``tag`` with the sha256 of the text above it (edited,
    cut short, never sealed)."""
    body, _, last = text.rstrip("\n").rpartition("\n")
    if not last.startswith(tag):
        return None
    if hashlib.sha256(body.encode("utf-8")).hexdigest() != last[len(tag):]:
        return None
    return body
