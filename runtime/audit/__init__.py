"""Audit in the runtime (no sympy): the verdicts of ``volerr audit`` counted per category and
rendered as HTML, and the printed equations evaluated numerically against the generated models
(:mod:`volerr.audit.numeric`).

The verdicts themselves are computed by :mod:`volerr.derive.audit` (sympy); this package
collects, groups and formats them (:mod:`volerr.audit.run`, the steps of ``volerr audit``) and
renders them (plain dicts, as in ``volerr audit --json``).
"""

from ._summary import CATEGORIES, category_counts, summary_line
from .html import render_html

__all__ = ["CATEGORIES", "category_counts", "render_html", "summary_line"]
