"""Counting verdicts per category (no sympy)."""

from __future__ import annotations

from collections import Counter

#: verdict categories in report order (the same tuple as
#: volerr.derive.audit.framework.CATEGORIES)
CATEGORIES = ("identical", "printing_error", "extraction", "convention", "simplification",
              "undecidable")


def category_counts(entries) -> dict:
    """{category: number of verdicts} over ``entries`` (dicts with a ``category`` key), every
    category present (0 when none)."""
    c = Counter(e["category"] for e in entries)
    unknown = set(c) - set(CATEGORIES)
    if unknown:
        raise ValueError(f"unknown verdict categories {sorted(unknown)}")
    return {k: c.get(k, 0) for k in CATEGORIES}


def summary_line(entries) -> str:
    """One line: the number of verdicts per category."""
    counts = category_counts(entries)
    return (f"{len(entries)} verdicts: " +
            ", ".join(f"{counts[k]} {k}" for k in CATEGORIES))
