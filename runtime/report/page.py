"""One page style for every report (HTML): tables whose headers never break a word (they wrap
between words only: ``word-break: keep-all``, no hyphens; ``white-space: nowrap`` on every
header was tried and made the uncertainty page's result table wider than a 1100 px window,
clipped), units in
µm and µrad, a print stylesheet (A4, the report id and "page x of y" on every printed page),
and the identification block put on a command's page that does not carry it itself
(:func:`stamp_html`)."""

from __future__ import annotations

import html
import re

#: the shared style, added once to a page's <head> (class ``volerr-certificate``)
CSS = """
<style>
/* volerr-certificate: the shared page style */
body { font-family: Helvetica, Arial, "DejaVu Sans", sans-serif; }
table th { word-break: keep-all; hyphens: none; overflow-wrap: normal; }
table td { word-break: keep-all; hyphens: none; overflow-wrap: normal; }
table.ident { border-collapse: collapse; margin: 0.4em 0 0.8em 0; }
table.ident th, table.ident td { text-align: left; padding: 2px 10px 2px 0;
  vertical-align: top; border-bottom: 1px solid #ddd; }
table.ident td { white-space: normal; }
table.budget { border-collapse: collapse; margin: 0.3em 0 0.8em 0; }
table.budget th, table.budget td { padding: 2px 8px; border-bottom: 1px solid #ddd;
  text-align: right; } table.budget td.l { text-align: left; }
p.warn { color: #b26a00; font-weight: bold; }
div.report-id { font: 12px sans-serif; color: #555; text-align: right; }
@page { size: A4; margin: 16mm 14mm 18mm 14mm;
  @bottom-right { content: "REPORT_ID  page " counter(page) " of " counter(pages);
    font: 8pt sans-serif; color: #555; }
  @top-right { content: "REPORT_ID"; font: 8pt sans-serif; color: #555; } }
@media print { body { max-width: none; margin: 0; font-size: 10pt; }
  div.report-id { display: none; }
  table.budget, table.ident { page-break-inside: avoid; }
  h3 { page-break-after: avoid; }
  img { max-width: 100%; page-break-inside: avoid; }
  table { page-break-inside: auto; } tr { page-break-inside: avoid; }
  h2 { page-break-after: avoid; } }
</style>
"""

#: the ASCII spellings of units that every page shows as µm and µrad
_UNITS = [(re.compile(r"(?<![A-Za-z_\-.])um(?=[ )/,.;:<\]]|$)"), "\u00b5m"),
          (re.compile(r"(?<![A-Za-z_\-.])urad(?=[ )/,.;:<\]]|$)"), "\u00b5rad")]


def units_in_words(text: str) -> str:
    """``um`` -> ``µm``, ``urad`` -> ``µrad`` in visible text (never inside a tag or a name
    such as ``A_um``)."""
    parts = re.split(r"(<[^>]*>)", text)
    out = []
    for i, part in enumerate(parts):
        if i % 2 == 0 and part:
            for pattern, unit in _UNITS:
                part = pattern.sub(unit, part)
        out.append(part)
    return "".join(out)


def conditions_table(cond: dict) -> str:
    """The test conditions (label -> text) as a two-column table."""
    e = html.escape
    return ("<h2>Test conditions</h2><table class='ident'>" + "".join(
        f"<tr><th class='l'>{e(str(k))}</th><td class='l'>{e(str(v))}</td></tr>"
        for k, v in cond.items()) + "</table>")


def budgets_html(budgets: list) -> str:
    """The uncertainty budgets (:mod:`volerr.report.budget`), one table per quantity, the
    same rows as the PDF (:func:`volerr.report.content.budget_rows`)."""
    from .content import budget_rows

    e = html.escape
    out = []
    for b in budgets:
        rows = budget_rows(b)
        head = "".join(f"<th>{e(c)}</th>" for c in rows[0])
        body = "".join("<tr>" + "".join(f"<td class='l'>{e(c)}</td>" if i == 0 else
                                        f"<td>{e(c)}</td>" for i, c in enumerate(r))
                       + "</tr>" for r in rows[1:])
        out.append(f"<h3>Uncertainty budget: {e(b['quantity'])}</h3>"
                   f"<table class='budget'><tr>{head}</tr>{body}</table>"
                   + "".join(f"<p>{e(n)}</p>" for n in b.get("notes") or ()))
    return "".join(out)


def stamp_html(text: str, ident, conditions: dict | None = None, budgets=()) -> str:
    """The page ``text`` with the shared style, the report id at the top and, when the page
    has no identification table of its own, :func:`volerr.certificate.html_table` after its
    first heading, then the test ``conditions`` (label -> text) when given."""
    from ..certificate import html_table

    rid = html.escape(ident.report_id or "")
    css = CSS.replace("REPORT_ID", f"report {rid}" if rid else "")
    if "volerr-certificate" not in text:
        text = (text.replace("</head>", css + "</head>", 1) if "</head>" in text
                else css + text)
    block = f"<div class='report-id'>report {rid}</div>" if rid else ""
    own = re.search(r"<table class=.ident.>.*?</table>(<p class='warn'>.*?</p>)*", text, re.S)
    if own is None:
        block += "<h2>Identification</h2>" + html_table(ident)
    if conditions and "<h2>Test conditions</h2>" not in text:
        if own is None:
            block += conditions_table(conditions)
        else:   # after the page's own identification
            text = text[:own.end()] + conditions_table(conditions) + text[own.end():]
    m = re.search(r"</h1>", text) or re.search(r"<body[^>]*>", text)
    at = m.end() if m else 0
    text = text[:at] + block + text[at:]
    if budgets and "Uncertainty budget:" not in text:
        tail = ("<h2>Uncertainty budgets (GUM, ISO/TR 230-9)</h2><p>u(x_i): standard "
                "uncertainty of the source in its unit; c_i: sensitivity; contribution "
                "|c_i| u(x_i); combined u: root sum of squares; U = k u.</p>"
                + budgets_html(budgets))
        at = text.rfind("</body>")
        text = text[:at] + tail + text[at:] if at >= 0 else text + tail
    if "<body" in text:
        head, body = text.split("<body", 1)
        text = head + "<body" + units_in_words(body)
    return text
