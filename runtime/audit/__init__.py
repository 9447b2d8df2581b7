"""Audit reports: the verdicts of ``volerr audit`` counted per category and rendered as HTML.

The verdicts themselves are computed by :mod:`volerr.derive.audit` (sympy); this package only
reads them (plain dicts, as in ``volerr audit --json``).  Public names: :func:`category_counts`,
:func:`summary_line`, :func:`render_html`.
"""

from ._summary import CATEGORIES, category_counts, summary_line
from .html import render_html

__all__ = ["CATEGORIES", "category_counts", "render_html", "summary_line"]
