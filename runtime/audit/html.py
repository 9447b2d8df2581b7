"""``volerr audit --html F``: one self-contained page, one section per source document.

Every verdict shows the printed form, the derived form (and, for a convention or a
simplification, the alternative derivation that reproduces the print), its category, the
evidence and the readings tried.  The top of the page summarises the verdicts per document and
per category and states the rule that picks a category.  Expressions are rendered as
presentation MathML (sympy's MathML printer; browsers render it natively: no script, no
network, no CDN); a long sum is rendered term by term as inline math that wraps like text, so
the table fits a 1400 px page without horizontal scrolling (fixed table layout, long words
broken); text that is no expression (matrices as lists, code, prose) is shown as wrapped
preformatted text.  All links are relative (``#anchors``).  sympy is imported inside
:func:`math_html` only.
"""

from __future__ import annotations

import functools
import html
import re

from ._summary import CATEGORIES, category_counts

_COLOURS = {"identical": "#2e7d32", "printing_error": "#c62828", "extraction": "#6a1b9a",
            "convention": "#1565c0", "simplification": "#00838f", "undecidable": "#ef6c00"}
_MAX_MATH = 3000          # characters: longer expressions are shown as text
_ONE_LINE = 40            # characters: longer sums are rendered term by term (they wrap;
#                           at 90 an 80-character sum overflowed its 20 % column, seen)
_PLAIN = re.compile(r"^[\w\s\(\)\*\+\-/\.\^,]+$")


def _anchor(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "-", text).strip("-").lower() or "x"


@functools.lru_cache(maxsize=4096)
def math_html(text: str) -> str:
    """Presentation MathML of an expression string, or escaped preformatted text (once per
    text: verdicts repeat their printed and derived forms)."""
    if not text:
        return ""
    if len(text) <= _MAX_MATH and _PLAIN.match(text):
        try:
            import sympy as sp
            from sympy.parsing.sympy_parser import parse_expr

            src = re.sub(r"\b(R?(?:dx|dy|dz|Ex|Ey|Ez))\((\w+)\)", r"\1__\2", text)
            names = {}
            for n in set(re.findall(r"[A-Za-z_]\w*", src)):
                if n in ("sin", "cos", "tan", "sqrt", "atan2", "acos", "atan", "pi"):
                    continue
                # paper notation dx(X), Ey(Yo): one symbol printed with its argument
                names[n] = sp.Symbol(n.replace("__", "(") + ")" if "__" in n else n)
            expr = parse_expr(src, local_dict=names, evaluate=False)
            if len(text) > _ONE_LINE and isinstance(expr, sp.Add):
                parts = []
                for i, term in enumerate(sp.Add.make_args(expr)):
                    c, rest = term.as_coeff_Mul()
                    neg = c.is_number and c < 0
                    body = -term if neg else term
                    ml = sp.mathml(body, printer="presentation", order="none")
                    sign = "<mo>-</mo>" if neg else ("<mo>+</mo>" if i else "")
                    parts.append(f'<math display="inline"><mrow>{sign}{ml}</mrow></math>')
                return '<div class="mwrap">' + " ".join(parts) + "</div>"
            ml = sp.mathml(expr, printer="presentation", order="none")
            return f'<math display="block">{ml}</math>'
        except Exception:  # noqa: BLE001 - anything unparsable is shown as text
            pass
    return f"<pre>{html.escape(text)}</pre>"


def _badge(cat: str) -> str:
    return (f'<span class="cat" style="background:{_COLOURS.get(cat, "#555")}">'
            f"{html.escape(cat)}</span>")


def _row(e: dict) -> str:
    cells = [f"<td>{html.escape(str(e.get('equation', '')))}<br><small>"
             f"{html.escape(str(e.get('component', '')))}</small></td>",
             f"<td>{_badge(e['category'])}<br><small>{html.escape(e.get('erratum', ''))}"
             f"</small></td>",
             f"<td>{math_html(e.get('printed', ''))}</td>",
             f"<td>{math_html(e.get('derived', ''))}</td>"]
    extra = []
    if e.get("alternative"):
        exact = e.get("dropped") or e["category"] in ("convention", "simplification")
        label = ("alternative that reproduces the print" if exact else
                 "alternative reading (the evidence says what it reproduces or leaves)")
        extra.append(f"<p><b>{label}:</b></p>{math_html(e['alternative'])}")
    if e.get("statement"):
        extra.append(f"<p><b>statement / convention:</b> {html.escape(e['statement'])}</p>")
    if e.get("dropped"):
        extra.append(f"<p><b>terms by which it differs:</b></p>{math_html(e['dropped'])}")
    if e.get("dropped_um") is not None:
        extra.append(f"<p><b>size on a typical machine:</b> {e['dropped_um']:.3g} um</p>")
    extra.append(f"<p>{html.escape(e.get('evidence', ''))}</p>")
    if e.get("readings_tried"):
        items = "".join(f"<li>{html.escape(str(r))}</li>" for r in e["readings_tried"])
        extra.append(f"<p><b>readings tried:</b></p><ul class=\"tried\">{items}</ul>")
    if e.get("readings_used"):
        extra.append("<p><b>rests on:</b> " + ", ".join(
            f"<code>{html.escape(str(k))}</code>" for k in e["readings_used"]) + "</p>")
    cells.append(f"<td>{''.join(extra)}</td>")
    return "<tr>" + "".join(cells) + "</tr>"


def _counts_table(entries, sources) -> str:
    head = "".join(f"<th>{_badge(c)}</th>" for c in CATEGORIES)
    rows = []
    for s in sources:
        counts = category_counts([e for e in entries if e["source"] == s])
        rows.append(f'<tr><td><a href="#{_anchor(s)}">{html.escape(s)}</a></td>'
                    + "".join(f"<td>{counts[c]}</td>" for c in CATEGORIES) + "</tr>")
    total = category_counts(entries)
    rows.append("<tr><td><b>all</b></td>" + "".join(f"<td><b>{total[c]}</b></td>"
                                                     for c in CATEGORIES) + "</tr>")
    return f"<table><tr><th>document</th>{head}</tr>{''.join(rows)}</table>"


_RULE = (
    "Every combination of the named readings is tried (conventions and simplifications, each "
    "with its own evidence; every axis stacking the text allows; repairs of text-extraction "
    "damage; unstated assumptions). The category is, in this order of preference: "
    "<b>identical</b> (the derivation reproduces the print); <b>convention</b> / "
    "<b>simplification</b> (a combination of stated conventions and approximations reproduces "
    "it exactly; the fewest readings are reported); <b>extraction</b> (only a repair of "
    "extraction damage reproduces it, and the evidence tells that damage from the print); "
    "<b>printing_error</b> (no reading reproduces it, and the text itself decides it is not "
    "extraction damage); <b>undecidable</b> (otherwise: only an unstated assumption reproduces "
    "it, or a glyph-level defect that the print and the extraction explain equally; both "
    "are named).")


def _category_summary(entries) -> str:
    total = category_counts(entries)
    items = "".join(f'<li>{_badge(c)} {total[c]}</li>' for c in CATEGORIES)
    return (f"<p><b>{len(entries)} verdicts</b> in {len({e['source'] for e in entries})} "
            f"documents:</p><ul class=\"cats\">{items}</ul>")


def render_html(entries: list[dict], title: str = "volerr audit") -> str:
    """The audit page for ``entries`` (dicts as written by ``volerr audit --json``)."""
    sources = list(dict.fromkeys(e["source"] for e in entries))
    parts = [f"<h1>{html.escape(title)}</h1>",
             "<p>Printed equations, numbers and code of the source documents against volerr's "
             "own derivations. Categories: <b>identical</b>; <b>printing_error</b> (a typo, "
             "wrong symbol, sign or lost row no consistent convention explains); "
             "<b>extraction</b> (damage of the OCR text of the seed); <b>convention</b> "
             "(reproduced exactly under the named convention); <b>simplification</b> (the "
             "author's stated approximation, with the size of what it drops); "
             "<b>undecidable</b> (the evidence says what is missing).</p>",
             '<h2 id="summary">Summary</h2>', _category_summary(entries),
             _counts_table(entries, sources),
             f"<p><b>How a category is chosen.</b> {_RULE}</p>"]
    for s in sources:
        mine = [e for e in entries if e["source"] == s]
        counts = category_counts(mine)
        parts.append(f'<h2 id="{_anchor(s)}">{html.escape(s)}</h2><p>'
                     + ", ".join(f'<a href="#{_anchor(s + "-" + c)}">{counts[c]} {c}</a>'
                                 if counts[c] else f"0 {c}" for c in CATEGORIES) + "</p>")
        for c in CATEGORIES:
            rows = [e for e in mine if e["category"] == c]
            if not rows:
                continue
            parts.append(f'<h3 id="{_anchor(s + "-" + c)}">{_badge(c)} {len(rows)}</h3>'
                         "<table><colgroup><col class=\"c1\"><col class=\"c2\">"
                         "<col class=\"c3\"><col class=\"c4\"><col class=\"c5\"></colgroup>"
                         "<tr><th>equation</th><th>category</th><th>printed</th>"
                         "<th>derived</th><th>evidence and readings</th></tr>"
                         + "".join(_row(e) for e in rows) + "</table>")
    # the shared page style (volerr.report.page), then the audit's own: fixed columns; an
    # expression (MathML, code) may wrap anywhere; a word of the text only when it is wider
    # than its whole fixed column (break-word; else it would run over the next column)
    style = ("body{max-width:1360px}"
             "table{width:100%;table-layout:fixed}"
             "col.c1{width:9%}col.c2{width:10%}col.c3{width:20%}col.c4{width:20%}"
             "col.c5{width:41%}"
             "td,th{padding:4px;font-size:90%}td{overflow-wrap:break-word}"
             "math{max-width:100%;overflow-wrap:anywhere}"
             "math[display=block]{overflow-wrap:anywhere}"
             ".mwrap{white-space:normal;line-height:1.9}.mwrap math{display:inline}"
             "pre{white-space:pre-wrap;overflow-wrap:anywhere;word-break:break-all;margin:0}"
             "ul.tried{margin:0 0 0 1.2em;padding:0;font-size:92%}ul.cats{list-style:none;"
             "padding:0}ul.cats li{display:inline;margin-right:1.5em}"
             ".cat{color:#fff;border-radius:3px;padding:1px 5px;font-size:85%}")
    from ..report.page import document

    return document(title, "\n".join(parts), css=style)
