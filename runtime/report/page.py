"""One page style for every report (HTML): every page is built by :func:`document` (the
shared head with :data:`STYLE`, the page's own few rules after it, units in words, tables
aligned), so the calibrate, ballbar, plan, loop (3-D and drift), check, history, ISO 230-2 /
230-3, uncertainty, ISO 10360-2, audit pages and the demo's index look alike: tables whose
cells never break a word (they wrap between words only: ``word-break: keep-all``, no
hyphens; ``white-space: nowrap`` on every header was tried and made the uncertainty page's
result table wider than a 1100 px window, clipped), words left and numbers right
(:func:`aligned`), units in µm and µrad (:func:`units_in_words`), a print stylesheet (A4,
the report id and "page x of y" on every printed page: :func:`print_ids`), and the
identification block put on a command's page that does not carry it itself
(:func:`stamp_html`)."""

from __future__ import annotations

import html
import re

#: the one stylesheet of every page (screen and print): words left, numbers right (``th.l``,
#: ``td.l`` for text), no word broken in a table cell (``word-break: keep-all``, no hyphens,
#: ``overflow-wrap: normal``: a cell wraps between words only), figures never wider than the
#: window, a print stylesheet (A4, "page x of y" at the foot of every printed page;
#: :func:`print_ids` adds the report id at the head and foot); ``volerr-certificate`` marks a
#: page that carries it
STYLE = """
/* volerr-certificate: the shared page style */
body { font-family: Helvetica, Arial, "DejaVu Sans", sans-serif; max-width: 1200px;
  margin: 1.5em auto; padding: 0 1em; color: #1a1a1a; line-height: 1.4; }
h1 { font-size: 1.5em; border-bottom: 2px solid #333; padding-bottom: .3em; }
h2 { font-size: 1.25em; margin-top: 1.5em; } h3 { font-size: 1.05em; }
table { border-collapse: collapse; margin: .5em 0 1em 0; font-size: .92em; }
th, td { border: 1px solid #bbb; padding: .2em .6em; text-align: right; vertical-align: top; }
th { background: #eef1f5; }
th.l, td.l { text-align: left; }
table th { word-break: keep-all; hyphens: none; overflow-wrap: normal; }
table td { word-break: keep-all; hyphens: none; overflow-wrap: normal; }
img { max-width: 100%; height: auto; }
figure { margin: 1em 0; } figcaption { color: #444; font-size: .95em; }
pre { background: #f6f6f6; padding: .6em; white-space: pre-wrap; font-size: .85em; }
.s { color: #555; font-size: .85em; } .verdict, .headline { font-size: 1.15em; }
table.ident { border-collapse: collapse; margin: 0.4em 0 0.8em 0; }
table.ident th, table.ident td { text-align: left; padding: 2px 10px 2px 4px;
  vertical-align: top; border: none; border-bottom: 1px solid #ddd; background: none; }
table.ident td { white-space: normal; }
table.budget { border-collapse: collapse; margin: 0.3em 0 0.8em 0; }
table.budget th, table.budget td { padding: 2px 8px; border: none; border-bottom: 1px solid #ddd;
  text-align: right; } table.budget td.l, table.budget th.l { text-align: left; }
p.warn { color: #b26a00; font-weight: bold; } span.nw { white-space: nowrap; }
div.report-id { font-size: 12px; color: #555; text-align: right; }
@page { size: A4; margin: 16mm 14mm 18mm 14mm;
  @bottom-right { content: "page " counter(page) " of " counter(pages);
    font: 8pt sans-serif; color: #555; } }
@media print { body { max-width: none; margin: 0; padding: 0; font-size: 10pt; }
  div.report-id { display: none; }
  table.budget, table.ident { page-break-inside: avoid; }
  img { max-width: 100%; page-break-inside: avoid; }
  table { page-break-inside: auto; } tr { page-break-inside: avoid; }
  tr:first-child, tr:nth-child(2) { break-after: avoid; }
  tr:last-child { break-before: avoid; }
  h1, h2, h3 { page-break-after: avoid; break-after: avoid; } }
"""
#: the shared style as it was named before the one stylesheet (kept for its importers)
CSS = "<style>" + STYLE + "</style>\n"


def print_ids(report_id: str | None) -> str:
    """The ``<style>`` that prints ``report_id`` at the head and beside "page x of y" at the
    foot of every printed page (empty without an id)."""
    if not report_id:
        return ""
    rid = re.sub(r"[^A-Za-z0-9 ._:/-]", "", str(report_id))   # a CSS string, no escapes
    return ("<style>@page { @top-right { content: \"report " + rid + "\"; font: 8pt "
            "sans-serif; color: #555; } @bottom-right { content: \"report " + rid +
            "   page \" counter(page) \" of \" counter(pages); font: 8pt sans-serif; "
            "color: #555; } }</style>\n")


def document(title: str, body: str, css: str = "", report_id: str | None = None) -> str:
    """A whole page: the shared head (:data:`STYLE`, then the page's own rules ``css``, then
    :func:`print_ids`), the ``title``, and ``body`` (HTML, its units written as µm and µrad:
    :func:`units_in_words`)."""
    extra = f"/* the page's own rules */\n{css}\n" if css else ""
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            f"<title>{html.escape(title)}</title>\n<style>{STYLE}{extra}</style>\n"
            f"{print_ids(report_id)}</head>\n<body>\n{aligned(units_in_words(body))}\n"
            "</body></html>\n")


def finish(text: str) -> str:
    """A whole page made elsewhere (a template) finished as :func:`document` finishes its
    body: units in words and tables aligned, in the ``<body>`` only."""
    if "<body" not in text:
        return aligned(units_in_words(text))
    head, body = text.split("<body", 1)
    return head + "<body" + aligned(units_in_words(body))


#: a cell that reads as a number (or numbers: "4.29, -12.03", "3.08 → 0.52", "23 %", "–")
_NUMERIC = re.compile(r"^[\s+\-\u2212\u2013\u00b10-9.,eE%\u2192()/*]*$")
_TABLE = re.compile(r"<table\b.*?</table>", re.S | re.I)
_ROW = re.compile(r"<tr\b[^>]*>(.*?)</tr>", re.S | re.I)
_CELL = re.compile(r"<(t[dh])(\s[^>]*)?>(.*?)</\1>", re.S | re.I)


def aligned(body: str) -> str:
    """Every table of ``body`` with words left and numbers right: a column whose data cells
    all read as numbers (one at least) stays right-aligned (the style's default), any other
    column (words, or empty) gets ``class="l"`` on its plain cells (header included); a cell
    with a class or a ``colspan`` keeps its own."""
    return _TABLE.sub(lambda m: _align_table(_DATA.sub(_joints, _HEADER.sub(
        _keep_k, m.group(0)))), body)


#: a data cell, and a long name in it (``setup:sphere_DMU50.csv#2.centre_dz``): it may wrap
#: after its ":" and "#" joints, never inside a word (at 800 px such names made the
#: calibrate page's table wider than the window)
_DATA = re.compile(r"(<td\b[^>]*>)(.*?)(</td>)", re.S | re.I)
_LONG_NAME = re.compile(r"[^\s<>]{24,}")
#: kept on one line: a number with an exponent ("6.16e-" over "15" was seen, printed) and
#: a command's option ("--" over "artefact-u" in the method line of the ISO 10360-2 page)
_EXPONENT = re.compile(r"(?<![\w.])[-+\u2212]?\d+(?:\.\d+)?e[-+]\d+\b|(?<!\S)--\w[\w-]*")
_JOINT = re.compile(r"(?<!&)([:#])(?=\w)")   # not the "#" of an entity (&#8593;)


def _joints(m) -> str:
    parts = re.split(r"(<[^>]*>)", m.group(2))
    for i in range(0, len(parts), 2):
        parts[i] = _EXPONENT.sub(lambda w: f'<span class="nw">{w.group(0)}</span>',
                                 _LONG_NAME.sub(lambda w: _JOINT.sub(r"\1<wbr>", w.group(0)),
                                                parts[i]))
    return m.group(1) + "".join(parts) + m.group(3)


#: a table header, and in it what stays on one line: a coverage factor ("U (k" over "= 2)"
#: was seen in the uncertainty page's headers at 800 px) and a hyphenated word ("set-" over
#: "up" in the plan sheet's)
_HEADER = re.compile(r"(<th\b[^>]*>)(.*?)(</th>)", re.S | re.I)
_K = re.compile(r"\bk = (\d)")
_HYPHENATED = re.compile(r"\b\w+(?:-\w+)+\b")


def _keep_k(m) -> str:
    parts = re.split(r"(<[^>]*>)", m.group(2))
    for i in range(0, len(parts), 2):
        parts[i] = _HYPHENATED.sub(lambda w: f'<span class="nw">{w.group(0)}</span>',
                                   _K.sub("k&nbsp;=&nbsp;\\1", parts[i]))
    return m.group(1) + "".join(parts) + m.group(3)


def _align_table(table: str) -> str:
    rows = [[(c.group(1).lower(), c.group(2) or "", c.group(3)) for c in _CELL.finditer(r)]
            for r in _ROW.findall(table)]
    text_cols, numbers = set(), set()
    for cells in rows:
        if any("colspan" in a for _, a, _ in cells):
            continue
        for i, (tag, _, inner) in enumerate(cells):
            words = html.unescape(re.sub(r"<[^>]*>", "", inner)).strip()
            if tag == "td" and words:
                (numbers if _NUMERIC.match(words) else text_cols).add(i)
    width = max((len(c) for c in rows), default=0)
    text_cols |= set(range(width)) - numbers

    def row(m):
        cells = list(_CELL.finditer(m.group(1)))
        if any("colspan" in (c.group(2) or "") for c in cells):
            return m.group(0)
        out, at = [], 0
        for i, c in enumerate(cells):
            plain = not (c.group(2) or "").strip()
            out.append(m.group(1)[at:c.start()])
            out.append(f"<{c.group(1)} class=\"l\">{c.group(3)}</{c.group(1)}>"
                       if plain and i in text_cols else c.group(0))
            at = c.end()
        out.append(m.group(1)[at:])
        return m.group(0).replace(m.group(1), "".join(out), 1)

    return _ROW.sub(row, table) if text_cols else table


#: the ASCII spellings of units that every page shows as µm and µrad
_UNITS = [(re.compile(r"(?<![A-Za-z_\-.])um(?=[ )/,.;:<\]]|$)"), "\u00b5m"),
          (re.compile(r"(?<![A-Za-z_\-.])urad(?=[ )/,.;:<\]]|$)"), "\u00b5rad")]


def units_in_words(text: str) -> str:
    """``um`` -> ``µm``, ``urad`` -> ``µrad`` in visible text (never inside a tag or a name
    such as ``A_um``, nor what a user types: ``<code>`` and a command line with its
    options, ``volerr check ... --tolerance EX0C=30 um``, stay as written).  A ``<span>``
    (:func:`aligned` keeps an option on one line with one) does not split the text."""
    parts = re.split(r"(<(?!/?span[ >])[^>]*>)", text)
    out, code = [], 0
    for i, part in enumerate(parts):
        if i % 2:
            tag = re.match(r"<(/?)code\b", part, re.I)
            code += (-1 if tag.group(1) else 1) if tag else 0
        elif part and code <= 0 and not _COMMAND.search(part):
            for pattern, unit in _UNITS:
                part = pattern.sub(unit, part)
        out.append(part)
    return "".join(out)


#: a command line in a page's text (the identification's method): its options as typed
_COMMAND = re.compile(r"\bvolerr [a-z0-9-]+ .*--[a-z]")


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
        head = "".join(f"<th class='l'>{e(c)}</th>" if i == 0 else f"<th>{e(c)}</th>"
                       for i, c in enumerate(rows[0]))
        body = "".join("<tr>" + "".join(f"<td class='l'>{e(c)}</td>" if i == 0 else
                                        f"<td>{e(c)}</td>" for i, c in enumerate(r))
                       + "</tr>" for r in rows[1:])
        out.append(f"<h3>Uncertainty budget: {e(b['quantity'])}</h3>"
                   f"<table class='budget'><tr>{head}</tr>{body}</table>"
                   + "".join(f"<p>{e(n)}</p>" for n in b.get("notes") or ()))
    return aligned("".join(out))


def stamp_html(text: str, ident, conditions: dict | None = None, budgets=()) -> str:
    """The page ``text`` with the shared style, the report id at the top and, when the page
    has no identification table of its own, :func:`volerr.certificate.html_table` after its
    first heading, then the test ``conditions`` (label -> text) when given."""
    from ..certificate import html_table

    rid = html.escape(ident.report_id or "")
    css = ("" if "volerr-certificate" in text else CSS) + print_ids(ident.report_id)
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
    text = text[:at] + aligned(block) + text[at:]
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
