"""The demo's ``index.html``: a section per step with its figures, captions, the headline
and links to every report page and file."""

from __future__ import annotations

from pathlib import Path

from ..fileio import write_text
from ..report.page import document
from .text import ABOUT, CAPTIONS


def index_html(out: Path, results: list) -> None:
    """index.html: a section per step with its figures (each shown at its own pixel width,
    :func:`volerr.plotstyle.img_tag`), captions, the result line, a link to every report page
    (HTML) the step wrote and to every file."""
    from html import escape

    from ..plotstyle import img_tag, png_size

    parts = []
    toc = []
    pages = []
    for i, r in enumerate(results, start=1):
        sid = f"s{i}"
        toc.append(f'<li><a href="#{sid}">{escape(r["title"])}</a></li>')
        files = " ".join(f'<a href="{escape(f)}">{escape(f)}</a>' for f in r["files"])
        reports = [f for f in r["files"] if f.endswith(".html")]
        pages += reports
        figs = []
        for f in r["files"]:
            if f.endswith(".png"):
                cap = CAPTIONS.get(f, f)
                width = png_size((out / f).read_bytes()[:32])[0]
                figs.append(f'<figure>{img_tag(f, cap, width=width, link=f)}'
                            f'<figcaption>{escape(cap)} <span class="file">({escape(f)})'
                            f'</span></figcaption></figure>')
        report_links = (f'<p class="pages">Report page{"s" if len(reports) > 1 else ""}: '
                        + " ".join(f'<a href="{escape(f)}">{escape(f)}</a>' for f in reports)
                        + "</p>") if reports else ""
        parts.append(
            f'<section id="{sid}"><h2>{i}. {escape(r["title"])}</h2>'
            f'<p>{escape(ABOUT.get(r.get("section", ""), ""))}</p>'
            f'<p class="result"><strong>Result:</strong> {escape(r["value"])} '
            f'<span class="file">[{r.get("seconds", 0)} s]</span></p>'
            + report_links + "".join(figs) + f'<p class="files">Files: {files}</p></section>')
    page_list = ", ".join(f'<a href="{escape(f)}">{escape(f)}</a>' for f in pages)
    # the shared page style (volerr.report.page), then the index's own few rules
    css = ("body{line-height:1.5}h2{border-bottom:2px solid #ddd;padding-bottom:.2em;"
           "margin-top:2em}img{border:1px solid #eee}.file{color:#777;font-size:.9em}"
           ".result{background:#f5f7fa;padding:.6em .9em;border-left:4px solid #4a7}"
           ".files a{margin-right:.8em}")
    html = document("volerr demo", "<h1>volerr demo</h1><p>Every step below ran a real "
                    "<code>volerr</code> command on built-in data; units µm and µrad unless "
                    "stated.  Click a figure for full size; the files next to this page hold "
                    f"every number.  Report pages: {page_list}.</p>"
                    f"<ol>{''.join(toc)}</ol>{''.join(parts)}", css=css)
    write_text(out / "index.html", html)
