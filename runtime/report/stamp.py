"""A command's report outputs finished with its identification (:func:`finish`, called by
:meth:`volerr.results.ResultMixin.write_outputs` inside ``with outs:``, after the command's
own writes, so everything stays all or nothing): the written ``--json`` gets
``"identification"``, the written ``--html`` the shared style, the report id and the
identification block (:func:`volerr.report.page.stamp_html`), and ``--pdf`` the certificate
(:mod:`volerr.report.pdf`)."""

from __future__ import annotations

import json
from pathlib import Path


def document_of(result) -> dict:
    """The JSON document of a result object (``to_dict()``) or of a dict."""
    return result.to_dict() if hasattr(result, "to_dict") else dict(result or {})


def rows_of_result(result) -> list:
    """The reported rows of a result (its ``_rows()``; none for a plain document)."""
    return list(result._rows()) if hasattr(result, "_rows") else []


def figures_of(result) -> dict:
    """The result's matplotlib figures (none for a plain document)."""
    try:
        return dict(result.figures()) if hasattr(result, "figures") else {}
    except Exception:   # a figure that cannot be drawn must not cost the certificate
        return {}


def finish(outs, result, ident, inputs=(), title: str | None = None) -> None:
    """Inside ``with outs:`` (:class:`volerr.fileio.Outputs`): stamp ``--json`` (when written
    and the user stated an identification, or the document carries one of its own) and
    ``--html`` (when written) with ``ident`` (:class:`volerr.certificate.Identification`);
    write ``--pdf`` (when given).  ``result``: a result object (a bare JSON document, or a
    result without rows: as :class:`volerr.report.document.Document`)."""
    from ..fileio import json_text, write_text
    from .page import stamp_html

    json_path, html_path = outs.path("--json"), outs.path("--html")
    if json_path is not None and Path(json_path).is_file():
        doc = json.loads(Path(json_path).read_text(encoding="utf-8"))
        if isinstance(doc, dict) and (ident.stated or "identification" in doc):
            doc["identification"] = ident.as_dict()
            write_text(json_path, json_text(doc), inputs=inputs)
    if html_path is not None and Path(html_path).is_file():
        from . import conditions

        doc = dict(document_of(result), identification=ident.as_dict())
        cond = conditions.of(doc, {**ident.conditions, **ident.test_conditions}) \
            or ident.test_conditions
        from .content import budgets_of

        text = Path(html_path).read_text(encoding="utf-8")
        write_text(html_path, stamp_html(text, ident, cond, budgets_of(doc)), inputs=inputs)
    pdf_path = outs.path("--pdf")
    if pdf_path is not None:
        write_pdf(pdf_path, result, ident, inputs=inputs, title=title)


def write_pdf(path, result, ident=None, inputs=(), title: str | None = None,
              figures: bool = True) -> Path:
    """The PDF certificate of ``result`` (a result object or its JSON document);
    ``figures=False``: without the figures (they come last: the pages before are the same;
    the manual's gallery of certificates, built quickly)."""
    from . import content, pdf

    doc = document_of(result)
    ident = content.identification_of(doc, ident)
    doc["identification"] = ident.as_dict()
    title = title or _title(result, doc)
    secs = content.sections(doc, rows_of_result(result),
                            figures_of(result) if figures else {}, ident)
    return pdf.write(path, secs, ident.report_id or "not stated", title, inputs=inputs)


def _title(result, doc: dict) -> str:
    """The command (from the method) or the result's kind, and the standard it follows."""
    std = doc.get("standard")
    method = (doc.get("identification") or {}).get("method") or {}
    name = method.get("command") or f"volerr {type(result).__name__.lower()}"
    return f"{name}: {std}" if isinstance(std, str) else name
