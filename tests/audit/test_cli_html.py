"""``volerr audit --html``: output paths checked before computing; the page (MathML, one section
per document, no network)."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from importlib import resources

import pytest


def run(*args):
    return subprocess.run([sys.executable, "-m", "volerr", "audit", *args],
                          capture_output=True, text=True, timeout=600)


def test_html_equal_to_json_refused_before_computing(tmp_path):
    f = tmp_path / "same.out"
    r = run("MB1", "--json", str(f), "--html", str(f))
    assert r.returncode == 2 and "same file" in r.stderr
    assert "Traceback" not in r.stderr and not f.exists()


def test_html_onto_an_input_refused(tmp_path):
    data = resources.files("volerr") / "data" / "printed_pahk.toml"
    before = data.read_bytes()
    r = run("MB1", "--html", str(data))
    assert r.returncode == 2 and "input" in r.stderr
    assert data.read_bytes() == before


def test_html_page_mb1(tmp_path):
    out, js = tmp_path / "a.html", tmp_path / "a.json"
    r = run("MB1", "--html", str(out), "--json", str(js))
    assert r.returncode == 0, r.stderr
    page = out.read_text("utf-8")
    entries = json.loads(js.read_text("utf-8"))
    assert page.count("<math") >= len(entries)              # printed and derived rendered
    assert not re.search(r"(src|href)=\"(https?:)?//", page)  # nothing fetched from a network
    assert all(h.startswith("#") for h in re.findall(r'href="([^"]*)"', page))
    assert '<h2 id="pahk-1995">' in page
    # the summary line counts per category, matching the JSON
    line = r.stdout.strip().splitlines()[-1]
    for cat in ("identical", "simplification", "undecidable"):
        n = sum(e["category"] == cat for e in entries)
        assert f"{n} {cat}" in line
    for e in entries:
        assert {"source", "equation", "layout", "component", "category", "printed",
                "derived", "evidence"} <= set(e)


@pytest.mark.slow
@pytest.mark.xdist_group("full_audit")
def test_html_every_document(full_audit):
    r, _, page = full_audit
    assert '<h2 id="pahk-1995">' in page and '<h2 id="ellingsdalen-2021">' in page
