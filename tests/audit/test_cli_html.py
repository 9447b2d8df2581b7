"""``volerr audit --html``: output paths checked before computing; the page (MathML, one section
per document, no network)."""

from __future__ import annotations

import json
import re
from collections import Counter
from importlib import resources

import pytest
from helpers.in_process import volerr as volerr_command


CATS = ("identical", "printing_error", "extraction", "convention", "simplification",
        "undecidable")


def run(*args):
    """``volerr audit ARGS`` as ``python -m volerr`` runs it (exit code, stdout, stderr), in this
    process (``helpers.in_process.volerr``: ``main``'s exit code and lines; a warning a process
    would print counts as a line of stderr), without an interpreter importing sympy again."""
    return volerr_command("audit", *args)


def test_html_equal_to_json_refused_before_computing(tmp_path):
    f = tmp_path / "same.out"
    r = run("MB1", "--json", str(f), "--html", str(f))
    assert r.returncode == 2 and "same file" in r.stderr
    assert "Traceback" not in r.stderr and not f.exists()


def test_html_onto_an_input_refused(tmp_path):
    data = resources.files("volerr.derive.audit") / "data" / "printed_pahk.toml"
    before = data.read_bytes()
    r = run("MB1", "--html", str(data))
    assert r.returncode == 2 and "input" in r.stderr
    assert data.read_bytes() == before


def test_html_page_mb1(tmp_path, capsys):
    from volerr.cli import main

    out, js = tmp_path / "a.html", tmp_path / "a.json"
    capsys.readouterr()
    code = main(["audit", "MB1", "--html", str(out), "--json", str(js)])  # in this process
    r = capsys.readouterr()
    assert code == 0, r.err
    page = out.read_text("utf-8")
    entries = json.loads(js.read_text("utf-8"))
    assert page.count("<math") >= len(entries)              # printed and derived rendered
    assert not re.search(r"(src|href)=\"(https?:)?//", page)  # nothing fetched from a network
    assert all(h.startswith("#") for h in re.findall(r'href="([^"]*)"', page))
    assert '<h2 id="pahk-1995">' in page
    # the summary line counts per category, matching the JSON
    line = r.out.strip().splitlines()[-1]
    for cat in ("identical", "simplification", "undecidable"):
        n = sum(e["category"] == cat for e in entries)
        assert f"{n} {cat}" in line
    for e in entries:
        assert {"source", "equation", "layout", "component", "category", "printed",
                "derived", "evidence"} <= set(e)


@pytest.mark.slow
@pytest.mark.xdist_group("full_audit")
def test_html_every_document(full_audit):
    r, entries, page = full_audit
    assert '<h2 id="pahk-1995">' in page and '<h2 id="ellingsdalen-2021">' in page
    # summary at the top: per document and per category, before the first document section
    top = page[:page.index('<h2 id="pahk-1995">')]
    assert '<h2 id="summary">' in top and "How a category is chosen" in top
    for src in ("Pahk 1995", "Ellingsdalen 2021"):
        counts = Counter(e["category"] for e in entries if e["source"] == src)
        row = top[top.index(f">{src}</a></td>"):]
        row = row[:row.index("</tr>")]
        assert re.findall(r"<td>(\d+)</td>", row) == [str(counts.get(c, 0)) for c in CATS]
    # every non-identical verdict shows its readings
    assert page.count("<b>readings tried:</b>") >= sum(e["category"] != "identical"
                                                        for e in entries)


def test_html_fits_1400px_and_wraps(tmp_path):
    """The page's layout cannot scroll sideways at 1400 px: a fixed table layout of 100 %
    width inside a body of at most 1360 px + padding, every cell breaking long words, no
    overflow-x anywhere, and long sums rendered as inline math pieces that wrap."""
    from volerr.audit import render_html

    long_sum = " + ".join(f"a{i}*Ez(X)*Yo" for i in range(60))
    entries = [{"source": "S", "equation": "1", "layout": "L", "component": "c",
                "category": "convention", "verdict": "differs", "erratum": "e",
                "printed": long_sum, "derived": long_sum, "evidence": "x" * 3000,
                "readings_tried": ["r1: exact", "r2: 2 term(s) differ"],
                "readings_used": ["table_origin"], "alternative": long_sum}]
    page = render_html(entries)
    style = page[page.index("<style>"):page.index("</style>")]
    assert "table-layout:fixed" in style and "width:100%" in style
    assert "overflow-x" not in style and "overflow:auto" not in style
    assert re.search(r"max-width:(\d+)px", style)
    assert int(re.search(r"max-width:(\d+)px", style).group(1)) <= 1380
    assert "overflow-wrap:anywhere" in style and "white-space:pre-wrap" in style
    assert page.count('class="mwrap"') == 3                  # printed, derived, alternative
    assert page.count('<math display="inline">') == 3 * 60
    assert "<li>r1: exact</li>" in page and "<code>table_origin</code>" in page
