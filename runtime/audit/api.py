"""``volerr audit`` as one call: :func:`audit` returns an :class:`Audit` result (the verdicts,
their text table, ``--json`` and ``--html``); the steps are :mod:`volerr.audit.run`."""

from __future__ import annotations

from dataclasses import dataclass

from ..results import ResultMixin


@dataclass(repr=False)
class Audit(ResultMixin):
    """Result of :func:`audit`: ``data`` the verdicts as dicts (the ``--json`` list, with
    their evidence), ``table_text`` the text table (a row per printed item, or per
    component), ``totals`` the line of totals, ``numeric`` the numeric spot check's table
    (None when not asked for) and ``inputs`` the printed material read (data files)."""

    data: list
    table_text: str
    totals: str
    numeric: str | None
    inputs: list

    def summary(self, evidence=()) -> str:
        """What ``volerr audit`` prints; ``evidence``: the files written (``--json``,
        ``--html``) that the last line names."""
        from ._summary import summary_line

        given = [str(p) for p in evidence if p]
        tail = f" Evidence: {', '.join(given)}" if given else " Evidence: --json F, --html F"
        text = f"{self.table_text}\n\n{self.totals}\n{summary_line(self.data)}.{tail}"
        return text if self.numeric is None else f"{text}\n\n{self.numeric}"

    def write_json(self, path, inputs=()):
        """The verdicts with their evidence (``--json``: a list, one dict per verdict)."""
        from ..fileio import json_text, write_text

        return write_text(path, json_text(self.data, indent=1, ensure_ascii=False),
                          inputs=[*self.inputs, *inputs])

    def write_html(self, path, inputs=()):
        """One page, a section per source document (rendered math, category, evidence)."""
        from ..fileio import write_text
        from .html import render_html

        return write_text(path, render_html(self.data), inputs=[*self.inputs, *inputs])

    def _rows(self) -> list:
        return []

    def __repr__(self) -> str:
        return f"<volerr Audit: {self.totals}>"


def audit(layouts=None, *, detail: bool = False, numeric: bool = False,
          points: int = 200, progress=None) -> Audit:
    """The printed equations of every source document against the engine's derivation
    (``volerr audit``; imports sympy).

    Parameters
    ----------
    layouts : sequence of str, optional
        Layout names or layout files to restrict the audit to (default: every audited
        equation).
    detail : bool
        One table row per component (dX, RY2, the rule of dx(X) ...) instead of per item.
    numeric : bool
        Also spot-check the generated models against the printed equations (no sympy;
        differences in um).
    points : int
        Random points of the numeric spot check (at least 1).
    progress : callable, optional
        ``progress(iterable, desc=..., unit=...)`` (:func:`volerr.progress.progress`).

    Returns
    -------
    Audit
        The verdicts (``to_dict()``/``--json``), the table, the totals.
    """
    from ..errors import require
    from . import run

    require(points >= 1, "--points must be at least 1")
    names = run.resolve_layouts([str(x) for x in ([layouts] if isinstance(layouts, str)
                                                  else layouts or [])])
    mods, verdicts = run.collect(names, progress=progress)
    rows = run.detail_rows(verdicts) if detail else run.group(verdicts)
    return Audit([v.as_dict() for v in verdicts], run.table(rows), run.totals_line(verdicts),
                 run.numeric_table(names or None, points) if numeric else None,
                 run.data_paths(mods))
