"""Numbers and units as every page and certificate prints them."""

from __future__ import annotations


def unit(u: str) -> str:
    """A unit as printed on a page (``um`` -> ``µm``, ``urad`` -> ``µrad``, ``um/mm`` ->
    ``µm/mm``, ``deg`` -> ``°``)."""
    import re

    text = re.sub(r"\bu(m|rad)\b", "\u00b5\\1", str(u or ""))
    return "\u00b0" if text == "deg" else text


def number(v, digits: int = 4) -> str:
    """A value with ``digits`` significant digits, no negative zero, "-" when missing."""
    if v is None:
        return "\u2013"
    try:
        x = float(v)
    except (TypeError, ValueError):
        return str(v)
    text = f"{x:.{digits}g}"
    return text[1:] if text.startswith("-") and float(text) == 0 else text
