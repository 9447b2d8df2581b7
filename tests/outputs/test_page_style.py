"""Issue 45 item 4: one page style for every report page.  Every page is built from the same
head (:func:`volerr.report.page.document`: the shared stylesheet with its print rules), units
read µm and µrad (never "um" / "urad" in the text a reader sees), tables break no word and put
words left and numbers right, labels are words (no raw JSON keys), and every PDF page carries
"page x of y" and the report id with no word of a table split over two lines."""

from __future__ import annotations

import html as htmllib
import re
from pathlib import Path

import pytest

import volerr
from volerr.report import fmt, page

RUNTIME = Path(volerr.__file__).parent

#: spellings that split a word in a table cell (CSS)
BREAKING = ("overflow-wrap:anywhere", "overflow-wrap: anywhere", "word-break:break-all",
            "word-break: break-all", "word-break:break-word", "word-break: break-word",
            "hyphens:auto", "hyphens: auto")


def _visible(text: str) -> str:
    """The text of a page's body as a reader sees it (no tags, no style, entities decoded)."""
    body = text.split("<body", 1)[1]
    body = re.sub(r"<style>.*?</style>|<[^>]*>", " ", body, flags=re.S)
    return re.sub(r"[ \t\n]+", " ", htmllib.unescape(body))


def test_document_writes_units_in_words_but_leaves_names_and_tags():
    text = page.document("t", "<p class='um'>3 um, 2 urad (4 um/m); EXX_um, sum, urad.</p>")
    seen = _visible(text)
    assert "3 \u00b5m, 2 \u00b5rad (4 \u00b5m/m)" in seen
    assert "EXX_um" in seen and "sum" in seen and seen.strip().endswith("\u00b5rad.")
    assert "class='um'" in text                      # inside a tag: untouched
    assert not re.search(r"(?<![\w\u00b5])u(m|rad)\b", seen.replace("EXX_um", ""))


def test_the_shared_stylesheet_holds_the_print_rules_and_breaks_no_word():
    text = page.document("t", "<p>x</p>", report_id="VE-0123456789ab")
    for rule in ("volerr-certificate", "size: A4", "counter(page)", "counter(pages)",
                 "word-break: keep-all", "hyphens: none", "report VE-0123456789ab"):
        assert rule in text, rule
    for bad in BREAKING:
        assert bad not in text, bad


def test_tables_put_words_left_and_numbers_right():
    body = ("<table><tr><th>file</th><th>G / um</th><th>offset / um</th></tr>"
            "<tr><td>ballbar_XY.csv</td><td>5.389</td><td>4.29, -12.03</td></tr>"
            "<tr><td>ballbar_YZ.csv</td><td>-</td><td>\u2013</td></tr>"
            "<tr><td colspan=3>none</td></tr></table>")
    out = page.aligned(body)
    assert out.count('class="l"') == 3                # file: header and its two cells
    assert '<th class="l">file</th>' in out and "<th>G / um</th>" in out
    assert "<td>5.389</td>" in out and "<td>4.29, -12.03</td>" in out
    assert "<td colspan=3>none</td>" in out           # a spanning cell keeps its own


def test_no_page_builds_its_own_head_or_breaks_words():
    """Every HTML page of volerr comes from report.page.document (or the loop's templates,
    which include the same stylesheet): no other module writes a doctype or a <style>."""
    own = []
    for path in RUNTIME.rglob("*.py"):
        if path.parent.name == "report" or "derive" in path.parts:
            continue
        text = path.read_text(encoding="utf-8")
        if re.search(r"<!doctype html|<style", text, re.I):
            own.append(str(path.relative_to(RUNTIME)))
        # a formula (the audit's MathML and code) may wrap anywhere; the words of a table not
        text = re.sub(r"(math|pre)[^{}\"]*\{[^}]*\}", "", text)
        for bad in BREAKING:
            assert bad not in text, f"{path.name}: {bad}"
    assert own == [], own
    for tpl in (RUNTIME / "loop" / "templates").glob("*.html.j2"):
        text = tpl.read_text(encoding="utf-8")
        assert "style.html.j2" in text or "page_style" in text, tpl.name
        assert "<style>{{ page_style|safe }}</style>" in \
            (RUNTIME / "loop" / "templates" / "style.html.j2").read_text(encoding="utf-8")


def test_demo_index_uses_the_shared_stylesheet(tmp_path):
    from volerr.demo.page import index_html

    index_html(tmp_path, [{"title": "a step", "files": ["a.html", "a.json"],
                           "value": "max 3.5 um, 20 urad", "section": ""}])
    text = (tmp_path / "index.html").read_text(encoding="utf-8")
    assert page.STYLE.strip()[:60] in text and "size: A4" in text
    assert "3.5 \u00b5m, 20 \u00b5rad" in _visible(text)


@pytest.mark.parametrize("key", ["delta_bic", "rss_reduction_fraction", "cv_rms_before_um",
                                 "cv_rms_after_um", "cv_paired_t", "step",
                                 "indistinguishable_from", "delta_bic_given_others",
                                 "contribution_rms_um", "contribution_max_um", "same_cause_as",
                                 "delta_bic_vs_replaced", "cv_rms_um"])
def test_loop_evidence_keys_read_as_words(key):
    label = fmt.words(key)
    assert "_" not in label and label != key.replace("_", " ")
    assert not re.search(r"\bum\b", label)
    if key.endswith("_um"):
        assert label.endswith(" / \u00b5m")


def test_words_spells_out_an_unlisted_key_with_its_unit():
    assert fmt.words("rms_after_um") == "RMS after / \u00b5m"
    assert fmt.words("tilt_urad") == "tilt / \u00b5rad"
    assert fmt.words("lag_s") == "lag / s"


def test_api_page_of_a_result_has_worded_headers_and_units(tmp_path):
    from volerr.results import Row, html_page

    text = html_page("Result", "summary", [Row("EXX", 1.5, 0.1, "um/m"),
                                           Row("EC0Y", 20.0, 2.0, "urad")])
    headers = re.findall(r"<th[^>]*>(.*?)</th>", text)
    assert "std" not in headers and "standard uncertainty u" in headers
    assert "\u00b5m/m" in _visible(text) and "\u00b5rad" in _visible(text)


LONG_WORDS = ("identifiable", "parameter", "sphere_DMU50.csv", "multilateration",
              "confounded", "setup:sphere_DMU50.csv.tool_dz")


def test_every_pdf_page_is_numbered_with_the_report_id_and_no_word_is_split():
    """A table of 9 narrow-ish columns of long words, long enough to run over three pages:
    each page reads "page i of n" and the report id; every long word reads back whole (a word
    split over two lines of a cell would read back as two pieces)."""
    pypdf = pytest.importorskip("pypdf")
    import io

    from volerr.report import pdf

    header = ["parameter", "identifiable", "seen by", "not seen by", "confounded with",
              "value / \u00b5m", "u / \u00b5m", "file", "multilateration"]
    rows = [header] + [[f"EX{i}B", "yes", "sphere_DMU50.csv", "", "setup:sphere_DMU50.csv."
                        "tool_dz", "1.5", "0.25", "sphere_DMU50.csv", "confounded"]
                       for i in range(160)]
    data = pdf.render([("Identification", "pairs", [["report id", "VE-0123456789ab"]]),
                       ("What the campaign determines", "table", rows)],
                      "VE-0123456789ab", "volerr calibrate: a test")
    reader = pypdf.PdfReader(io.BytesIO(data))
    n = len(reader.pages)
    assert n >= 3
    for i, p in enumerate(reader.pages, start=1):
        text = p.extract_text()
        assert f"page {i} of {n}" in text and "VE-0123456789ab" in text
        for w in LONG_WORDS:
            assert w in text, (i, w)


def test_a_coverage_factor_and_a_hyphenated_word_in_a_header_stay_on_one_line():
    out = page.aligned("<table><tr><th>U (k = 2) / um</th><th>set-up</th></tr>"
                       "<tr><td>1.5</td><td>S3</td></tr></table>")
    assert "U (k&nbsp;=&nbsp;2) / um" in out
    assert '<span class="nw">set-up</span>' in out and "span.nw { white-space: nowrap; }" \
        in page.STYLE


def test_certificate_rows_name_json_keys_in_words_and_keep_parameter_names():
    from volerr.report.content import row_name

    assert row_name("x1:mae_before") == "x1: MAE before"
    assert row_name("KH_EXZ_S_rpm_0:tau") == "KH_EXZ_S_rpm_0: time constant"
    assert row_name("max_abs_dx") == "largest |dx|"            # volerr map's rows
    assert "_" not in row_name("rms_length") and "_" not in row_name("random_max_z")
    for kept in ("EXX@slope", "KT_EXZ_T_spindle_0", "X:A", "EY0B + EY0C"):
        assert row_name(kept) == kept


def test_what_a_user_types_keeps_its_units_as_typed():
    """A command line (the identification's method) and <code> are not rewritten: a user
    copying "--tolerance EX0C=30 um" must get what volerr reads."""
    text = page.document("t", "<table><tr><td>volerr check (volerr 0.1.0) --tolerance "
                              "EX0C=30 um DMU50</td></tr></table><p>give <code>--detect-um "
                              "5 um</code>; changed by 5 um</p>")
    seen = _visible(text)
    assert "--tolerance EX0C=30 um DMU50" in seen and "--detect-um 5 um" in seen
    assert "changed by 5 \u00b5m" in seen


def test_a_certificate_value_shows_what_its_uncertainty_resolves():
    """399.999965 mm with u = 0.00133 mm: 4 significant digits ("400") would hide the
    -0.035 um the Monte Carlo found; the value is printed to u's second significant digit
    (0.0001 mm), and never with fewer digits than before."""
    from volerr.report.content import result_rows
    from volerr.results import Row

    rows = result_rows([Row("distance", 399.999965, 0.00133, "mm"),
                        Row("A", 9.4123, 0.58, "um"), Row("r", 5.0, None, "mm")])
    assert rows[1][1] == "400.0000" and rows[2][1] == "9.412" and rows[3][1] == "5"
    assert rows[2][5] == "\u00b5m"


def test_a_long_name_in_a_cell_may_wrap_at_its_joints_only():
    out = page.aligned("<table><tr><td>EY0C, setup:sphere_example_DMU50.csv#2.centre_dz, "
                       "a:b &#8593;</td></tr></table>")
    assert "setup:<wbr>sphere_example_DMU50.csv#<wbr>2.centre_dz," in out
    assert "a:b &#8593;" in out                     # short names and entities untouched
    assert re.sub(r"<wbr>", "", out).count("sphere_example_DMU50.csv#2.centre_dz") == 1


def test_a_number_with_an_exponent_is_kept_on_one_line():
    out = page.aligned("<table><tr><th>u</th></tr><tr><td>6.16e-15</td></tr></table>")
    assert '<span class="nw">6.16e-15</span>' in out
    # a source in its own unit (a budget's own-unit rounding noise prints as 0:
    # tests/outputs/test_budget_noise.py)
    budget = {"quantity": "EC0Y", "unit": "urad", "u": 0.5, "k": 2.0, "U": 1.0,
              "sources": [{"source": "readings", "u": 6.16e-15, "unit": "um",
                           "sensitivity": 1.0, "contribution": 6.16e-15}]}
    assert '<span class="nw">6.16e-15</span>' in page.budgets_html([budget])


def test_an_option_of_a_command_line_is_kept_on_one_line():
    out = page.aligned("<table><tr><th>method</th><td>volerr iso10360 --artefact-cte-ppm-per-K"
                       " 11.5</td></tr></table>")
    assert '<span class="nw">--artefact-cte-ppm-per-K</span> 11.5' in out


def test_a_stamped_identification_keeps_the_command_line_as_typed():
    """stamp_html aligns the identification block (options kept on one line by a <span>)
    before it writes units in words: the method line must still read as typed."""
    from volerr.certificate import Identification

    ident = Identification(report_id="VE-0123456789ab", method={
        "command": "volerr check", "version": "0.1.0", "options": {"tolerance": "EX0C=30 um"}})
    text = page.stamp_html(page.document("t", "<h1>t</h1><p>moved 3 um</p>"), ident)
    seen = _visible(text)
    assert "EX0C=30 um" in seen and "moved 3 \u00b5m" in seen
