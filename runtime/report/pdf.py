"""The PDF certificate of a result (``--pdf F``, ``result.write_pdf(F)``): A4, every page
headed by the report id and footed by "report id, page x of y"; the identification, the test
conditions of the standard, each result with its standard uncertainty u, the coverage factor
k and the expanded uncertainty U = k u, the verdicts and the decision rule where a tolerance
was given, the uncertainty budgets, the notes and the figures as vector graphics.

Built with fpdf2 (pure Python, installs with pip alone, no system library; LGPL; maintained,
releases every few months): it embeds a TrueType font (DejaVu Sans, shipped with matplotlib,
so µ, ±, ° and every Unicode letter print and the text reads back) and imports matplotlib's
SVG as vector paths.  reportlab needs its own SVG bridge (svglib, which pulls in a C
library for some installs) for vector figures.

Tables never break a word: a column is at least as wide as its longest word (header or
cell), the rest of the line is shared in proportion to the text, and a table too wide for
the page is set in a smaller type (down to 6.5 pt) before any word could be split."""

from __future__ import annotations

import io
import math
from pathlib import Path

FONT = "DejaVu"
#: A4 with 15 mm side margins: the usable width, mm
TEXT_WIDTH_MM = 180.0
#: body and table type sizes, pt; the smallest a wide table may shrink to
BODY_PT, TABLE_PT, MIN_TABLE_PT = 10.0, 8.5, 6.5
#: left and right padding of a table cell, mm; a column's width beyond its text (both
#: paddings, the rule's width and 1 mm against rounding of the glyph widths)
CELL_PAD_MM = 1.0
#: the tallest a figure is set, mm (two figures and a table share a page), and where the
#: text stops above the footer, mm from the top of the A4 page
FIGURE_MAX_MM, PAGE_BOTTOM_MM = 115.0, 279.0
#: a tall figure (height over width above TALL) may fill a page up to FULL_PAGE_MM high: at
#: FIGURE_MAX_MM the loop's 14-row residual figure was 40 mm wide, its text about 1.5 pt
TALL, FULL_PAGE_MM = 1.0, 240.0
#: a figure of more SVG elements (markers, paths) than this is set as a PNG of RASTER_DPI
#: instead: fpdf2 imports about 500 elements a second (3000 markers: 6 s measured), so a
#: scatter of tens of thousands of readings would take minutes as vectors
MAX_SVG_ELEMENTS, RASTER_DPI = 2500, 200
#: a table up to this height (mm) is kept on one page
KEEP_TOGETHER_MM = 80.0
PAD_MM = 2 * CELL_PAD_MM + 1.0


def _font_files() -> dict:
    import matplotlib

    ttf = Path(matplotlib.get_data_path()) / "fonts" / "ttf"
    return {"": ttf / "DejaVuSans.ttf", "B": ttf / "DejaVuSans-Bold.ttf",
            "I": ttf / "DejaVuSans-Oblique.ttf"}


def _document(report_id: str, title: str):
    from fpdf import FPDF

    class Certificate(FPDF):
        def header(self):
            self.set_font(FONT, "", 8)
            self.set_text_color(90)
            self.cell(TEXT_WIDTH_MM * 0.7, 5, _fit(self, title, TEXT_WIDTH_MM * 0.68),
                      align="L")
            self.cell(TEXT_WIDTH_MM * 0.3, 5, f"report {report_id}", align="R",
                      new_x="LMARGIN", new_y="NEXT")
            self.ln(3)
            self.set_text_color(0)

        def footer(self):
            self.set_y(-13)
            self.set_font(FONT, "", 8)
            self.set_text_color(90)
            self.cell(0, 5, f"report {report_id}, page {self.page_no()} of {{nb}}", align="C")
            self.set_text_color(0)

    pdf = Certificate(format="A4", unit="mm")
    pdf.set_margins(15, 14, 15)
    pdf.set_auto_page_break(True, margin=18)
    for style, path in _font_files().items():
        pdf.add_font(FONT, style, str(path))
    pdf.alias_nb_pages()
    pdf.set_title(f"{title} {report_id}")
    pdf.set_creator("volerr")
    return pdf


def _fit(pdf, text: str, width_mm: float) -> str:
    """``text`` shortened with an ellipsis to ``width_mm`` in the current font."""
    if pdf.get_string_width(text) <= width_mm:
        return text
    while text and pdf.get_string_width(text + "\u2026") > width_mm:
        text = text[:-1]
    return text.rstrip() + "\u2026"


def _heading(pdf, text: str) -> None:
    if pdf.get_y() > 255:
        pdf.add_page()
    pdf.ln(2)
    pdf.set_font(FONT, "B", 11.5)
    pdf.cell(0, 7, text, new_x="LMARGIN", new_y="NEXT")
    pdf.set_font(FONT, "", BODY_PT)


def _paragraph(pdf, text: str, style: str = "", colour=(0, 0, 0)) -> None:
    pdf.set_font(FONT, style, BODY_PT)
    pdf.set_text_color(*colour)
    pdf.multi_cell(0, 5, text, align="L", new_x="LMARGIN", new_y="NEXT")
    pdf.set_text_color(0)


def _widths(pdf, rows: list, size: float, header: bool) -> list | None:
    """Column widths (mm) that break no word at ``size`` pt (the header in bold), or None
    when none fit the text width."""
    n = max(len(r) for r in rows)
    low = [PAD_MM] * n
    want = [PAD_MM] * n
    for j, r in enumerate(rows):
        pdf.set_font(FONT, "B" if header and j == 0 else "", size)
        for i, cell in enumerate(r):
            text = str(cell)
            words = text.split() or [""]
            low[i] = max(low[i], max(pdf.get_string_width(w) for w in words) + PAD_MM)
            want[i] = max(want[i], pdf.get_string_width(text) + PAD_MM)
    if sum(low) > TEXT_WIDTH_MM:
        return None
    if sum(want) <= TEXT_WIDTH_MM:
        return want
    spare = TEXT_WIDTH_MM - sum(low)
    extra = [w - lo for w, lo in zip(want, low)]
    return [lo + spare * e / sum(extra) for lo, e in zip(low, extra)]


def _layout(pdf, rows: list, header: bool) -> tuple:
    """Type size (pt), column widths (mm) and the estimated height (mm) of a table."""
    size = TABLE_PT
    widths = _widths(pdf, rows, size, header)
    while widths is None and size > MIN_TABLE_PT:
        size -= 0.5
        widths = _widths(pdf, rows, size, header)
    widths = widths or [TEXT_WIDTH_MM / len(rows[0])] * len(rows[0])
    pdf.set_font(FONT, "", size)
    height = 0.0
    for r in rows:
        lines = max(math.ceil((pdf.get_string_width(c) + PAD_MM) / w) for c, w in zip(r, widths))
        height += lines * size * 0.5 + 1.2
    return size, widths, height


def _aligns(rows: list, header: bool) -> tuple:
    """Per column: "RIGHT" when every data cell reads as a number (as on the HTML pages,
    :func:`volerr.report.page.aligned`), else "LEFT"."""
    from .page import _NUMERIC

    n = max(len(r) for r in rows)
    data = rows[1:] if header else rows
    return tuple("RIGHT" if any(len(r) > i and r[i].strip() for r in data) and all(
        len(r) <= i or _NUMERIC.match(r[i]) for r in data) else "LEFT" for i in range(n))


def table(pdf, rows: list, header: bool = True, align: str | None = None,
          heading: str = "") -> None:
    """``rows`` (first the header when ``header``) as a table that breaks no word, under
    ``heading``; words left and numbers right (``align`` one alignment for every column
    instead); a table of at most :data:`KEEP_TOGETHER_MM` starts on a new page rather
    than break (a longer one breaks, its header repeated)."""
    rows = [[str(c) for c in r] for r in rows]
    align = align or _aligns(rows, header)
    size, widths, height = _layout(pdf, rows, header)
    if pdf.get_y() + min(height, KEEP_TOGETHER_MM) + (9 if heading else 0) > PAGE_BOTTOM_MM:
        pdf.add_page()
    if heading:
        _heading(pdf, heading)
    pdf.set_font(FONT, "", size)
    with pdf.table(col_widths=widths, width=sum(widths), align="LEFT", text_align=align,
                   first_row_as_headings=header, line_height=size * 0.5,
                   padding=(0.6, CELL_PAD_MM),
                   headings_style=_heading_style(), wrapmode=_word_wrap()) as t:
        for r in rows:
            row = t.row()
            for cell in r:
                row.cell(cell)
    pdf.set_font(FONT, "", BODY_PT)
    pdf.ln(1.5)


def _heading_style():
    from fpdf.fonts import FontFace

    return FontFace(emphasis="BOLD", fill_color=(232, 236, 242))


def _word_wrap():
    from fpdf.enums import WrapMode

    return WrapMode.WORD


def figure(pdf, fig, heading: str = "") -> None:
    """A matplotlib figure as vector graphics (SVG; a PNG beyond :data:`MAX_SVG_ELEMENTS`)
    under ``heading``, at most
    :data:`FIGURE_MAX_MM` high, on a new page when it does not fit below (with its heading)."""
    import re

    raw = io.StringIO()
    fig.savefig(raw, format="svg", bbox_inches="tight")
    # fpdf2 reads no <metadata> (and says so on stderr): the figure's metadata is not drawn
    svg = re.sub(r"<metadata>.*?</metadata>", "", raw.getvalue(), flags=re.S)
    buf = io.BytesIO(svg.encode("utf-8"))
    if svg.count("<use ") + svg.count("<path ") > MAX_SVG_ELEMENTS:   # a raster, print dpi
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=RASTER_DPI, bbox_inches="tight")
        buf.seek(0)
    w_in, h_in = fig.get_size_inches()
    tallest = FULL_PAGE_MM if h_in / w_in > TALL else FIGURE_MAX_MM
    width = min(TEXT_WIDTH_MM, tallest * w_in / h_in)
    height = width * h_in / w_in
    if pdf.get_y() + height + 12 > PAGE_BOTTOM_MM:
        pdf.add_page()
    if heading:
        _heading(pdf, heading)
    pdf.image(buf, x=pdf.l_margin + (TEXT_WIDTH_MM - width) / 2, w=width)


def write(path, sections: list, report_id: str, title: str, inputs=()) -> Path:
    """Write the certificate of ``sections`` (:func:`volerr.report.content.sections`) to
    ``path`` (A4); returns the path."""
    from ..fileio import write_bytes

    return write_bytes(path, render(sections, report_id, title), inputs=list(inputs))


def render(sections: list, report_id: str, title: str) -> bytes:
    """The PDF bytes of ``sections``: (heading, kind, payload) with kind ``table`` (rows,
    header first), ``pairs`` (label, text rows), ``text``, ``warn`` or ``figure``."""
    pdf = _document(report_id, title)
    pdf.add_page()
    pdf.set_font(FONT, "B", 15)
    pdf.multi_cell(0, 8, title, align="L", new_x="LMARGIN", new_y="NEXT")
    pdf.set_font(FONT, "", BODY_PT)
    for heading, kind, payload in sections:
        if heading and kind not in ("figure", "table", "pairs"):
            _heading(pdf, heading)
        if kind == "table":
            table(pdf, payload, heading=heading)
        elif kind == "pairs":
            table(pdf, payload, header=False, heading=heading)
        elif kind == "text":
            _paragraph(pdf, payload)
        elif kind == "warn":
            _paragraph(pdf, payload, "B", (178, 106, 0))
        elif kind == "figure":
            figure(pdf, payload[0], heading)
    return bytes(pdf.output())
