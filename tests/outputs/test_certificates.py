"""Issue 45: the reports a calibration lab signs.  Every report is identified (a TOML file
beside the data or options; validated; carried into the JSON, the HTML, the PDF and the
history), the PDF certificate reads back as text (identification, conditions, results with U
and k, decision rule, "page x of y" and the report id on every page, A4), and each
uncertainty budget combines to the stated u."""

from __future__ import annotations

import datetime
import json
import math

import pytest

from volerr.cli import main

# the module fixtures once, on one xdist worker (not once per worker)
pytestmark = pytest.mark.xdist_group("outputs_certificates")

pypdf = pytest.importorskip("pypdf")

A4_PT = (595.28, 841.89)
IDENT = """\
operator = "A. Person"
customer = "ACME Precision Ltd"
authorised_by = "B. Person"
date = 2026-11-30
[machine]
id = "VMC-7"
make = "Maker"
model = "V-800"
serial = "SN-4711"
location = "hall 3"
[[instrument]]
id = "LI-1"
description = "laser interferometer"
serial = "LS-99"
certificate = "CAL-2025-17"
due = 2026-06-30
uncertainty = "0.5 ppm (k = 2)"
[environment]
"air temperature" = "20.3 degC, u = 0.1 K"
[conditions]
feed = "1000 mm/min"
dwell = "2 s"
"""


def _run_csv(path, slope_um_per_mm=0.01, step=150, cycles=(1, 2, 3, 4, 5)):
    """An ISO 230-2 run: deviation = slope * target + 1 um (forward) / -1 um (backward) +
    0.1 um * cycle."""
    lines = ["target_mm,cycle,direction,deviation_um"]
    for t in range(0, 901, step):
        for c in cycles:
            for word, off in (("+1", 1.0), ("-1", -1.0)):
                lines.append(f"{t},{c},{word},{slope_um_per_mm * t + off + 0.1 * c}")
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def iso(tmp_path_factory):
    """One iso230-2 run with the identification file beside the data (read automatically),
    a tolerance (a verdict), a thermal correction and EVE (every source of the budget)."""
    d = tmp_path_factory.mktemp("cert")
    run = _run_csv(d / "run.csv")
    (d / "volerr-identification.toml").write_text(IDENT)
    out = {k: d / f"r.{k}" for k in ("json", "html", "pdf")}
    argv = ["iso230-2", str(run), "--axis", "X", "--tolerance", "A=20,E=15",
            "--cte-ppm-per-K", "11.5", "--material-temp-C", "21", "--eve-um", "1",
            "--json", str(out["json"]), "--html", str(out["html"]), "--pdf", str(out["pdf"])]
    assert main(argv) == 0
    reader = pypdf.PdfReader(str(out["pdf"]))
    pages = [p.extract_text() for p in reader.pages]
    return {"dir": d, "run": run, "argv": argv, "out": out, "reader": reader, "pages": pages,
            "doc": json.loads(out["json"].read_text())}


def test_identification_file_beside_the_data_is_in_json_html_and_pdf(iso):
    ident = iso["doc"]["identification"]
    assert ident["operator"] == "A. Person" and ident["customer"] == "ACME Precision Ltd"
    assert ident["date"] == "2026-11-30"                      # of the measurement
    assert ident["report_date"] == datetime.datetime.now(datetime.timezone.utc).date().isoformat()
    assert ident["machine_details"]["serial"] == "SN-4711"
    assert ident["instruments"][0]["certificate"] == "CAL-2025-17"
    assert ident["method"]["command"] == "volerr iso230-2"
    assert ident["method"]["options"]["tolerance"] == "A=20,E=15"
    assert ident["report_id"].startswith("VE-") and len(ident["report_id"]) == 15
    html = iso["out"]["html"].read_text(encoding="utf-8")
    text = "\n".join(iso["pages"])
    for where in (html, text):
        for field in ("A. Person", "ACME Precision Ltd", "VMC-7", "Maker", "V-800", "SN-4711",
                      "hall 3", "LI-1", "LS-99", "CAL-2025-17", "0.5 ppm (k = 2)",
                      "2026-11-30", ident["report_date"], "B. Person", "20.3 degC, u = 0.1 K",
                      ident["report_id"], "volerr iso230-2"):
            assert field in where, field
    # the due date lies before the date of the measurement: a warning, not a refusal
    assert "warning: instrument LI-1: calibration due 2026-06-30" in html
    assert "calibration due 2026-06-30" in text


def test_pdf_holds_conditions_results_with_U_and_k_and_the_decision_rule(iso):
    text = "\n".join(iso["pages"])
    doc = iso["doc"]
    assert "Test conditions" in text and "ISO 230-2" in text
    assert "7 targets, 0 to 900 mm" in text and "5 per direction" in text
    assert "1000 mm/min" in text and "2 s" in text          # stated in [conditions]
    assert "overrun not stated" in text                       # never hidden
    assert "u (k = 1)" in text and "U = k u" in text and "k = 2" in text
    for q in ("A", "E", "R"):
        U = doc["uncertainty_um"][q]
        assert f"X:{q} {doc[f'{q}_um']:.4g} {U / 2:.3g} 2 {U:.3g} \u00b5m" in text
    assert "Decision rule: ISO 14253-1" in text
    assert "A PASS" in text and "E PASS" in text


def test_every_pdf_page_is_a4_numbered_and_carries_the_report_id(iso):
    rid = iso["doc"]["identification"]["report_id"]
    n = len(iso["pages"])
    assert n >= 2
    for i, (page, text) in enumerate(zip(iso["reader"].pages, iso["pages"]), start=1):
        assert (float(page.mediabox.width), float(page.mediabox.height)) == \
            pytest.approx(A4_PT, abs=0.5)
        assert f"page {i} of {n}" in text
        assert text.count(rid) >= 2                           # header and footer


def test_each_budget_combines_to_the_stated_uncertainty(iso):
    doc = iso["doc"]
    L = 900.0
    assert set(doc["budgets"]) == {"A", "E", "M", "R", "B"}
    for q, b in doc["budgets"].items():
        for s in b["sources"]:
            assert s["contribution"] == pytest.approx(abs(s["sensitivity"]) * s["u"], rel=1e-12)
        u = math.sqrt(sum(s["contribution"] ** 2 for s in b["sources"]))
        stated_u = doc["uncertainty_um"][q] / 2          # the certificate's U, k = 2
        assert u == pytest.approx(stated_u, rel=1e-6) and b["k"] == 2
        assert b["U"] == pytest.approx(doc["uncertainty_um"][q], rel=1e-6)
    by = {s["source"].split(" (")[0]: s for s in doc["budgets"]["A"]["sources"]}
    # independently: 0.5 ppm rectangular over 900 mm; 0.2 K of a 11.5 ppm/K scale over 900 mm;
    # 1 ppm/K at 1 K from 20 degC over 900 mm; EVE 1 um rectangular over its range
    assert by["instrument"]["contribution"] == pytest.approx(0.5e-6 * L * 1e3 / math.sqrt(3))
    assert by["material temperature reading"]["contribution"] == pytest.approx(
        L * 1e3 * 11.5e-6 * 0.2)
    assert by["expansion coefficient"]["contribution"] == pytest.approx(L * 1e3 * 1e-6 * 1.0)
    assert by["environmental variation"]["contribution"] == pytest.approx(1 / (2 * math.sqrt(3)))
    # R and B are differences at one target: instrument and temperature cancel
    assert {s["source"].split(" (")[0] for s in doc["budgets"]["R"]["sources"]} == \
        {"environmental variation", "repeatability"}
    text = "\n".join(iso["pages"])
    assert "Uncertainty budget: X A" in text and "combined standard uncertainty u" in text


def test_report_id_is_stable_for_the_same_inputs_and_changes_with_them(iso, tmp_path):
    argv = iso["argv"][:iso["argv"].index("--json")] + ["--json", str(tmp_path / "json")]
    assert main(argv) == 0
    again = json.loads((tmp_path / "json").read_text())["identification"]["report_id"]
    assert again == iso["doc"]["identification"]["report_id"]
    other = [a if a != "A=20,E=15" else "A=21" for a in argv]
    assert main(other) == 0
    assert json.loads((tmp_path / "json").read_text())["identification"]["report_id"] != again


def test_options_replace_the_file_and_an_explicit_file_is_read(tmp_path):
    (tmp_path / "data").mkdir()
    run = _run_csv(tmp_path / "data" / "run.csv")
    ident = tmp_path / "lab.toml"                  # not beside the data: named by the option
    ident.write_text(IDENT)
    out = tmp_path / "r.json"
    base = ["iso230-2", str(run), "--identification", str(ident), "--json", str(out)]
    assert main(base + ["--operator", "C. Other", "--date", "2026-10-01", "--customer",
                        "Other Ltd"]) == 0
    d = json.loads(out.read_text())["identification"]
    assert (d["operator"], d["date"], d["customer"]) == ("C. Other", "2026-10-01", "Other Ltd")
    assert d["machine_details"]["id"] == "VMC-7"
    assert d["warnings"] == ["instrument LI-1: calibration due 2026-06-30, before the date of "
                             "the measurement 2026-10-01"]
    assert main(base + ["--date", "2026-06-01"]) == 0      # within the calibration's validity
    assert "warnings" not in json.loads(out.read_text())["identification"]


@pytest.mark.parametrize("bad, words", [
    ("date = 2026-13-01\n", ("volerr-identification.toml", "date")),
    ('date = "30.11.2026"\n', ("date", "YYYY-MM-DD")),
    ("operater = \"x\"\n", ("unknown key operater", "misspelt")),
    ("date = 2999-01-01\n", ("date", "future")),
])
def test_a_bad_identification_file_is_refused_in_one_line_and_nothing_written(
        tmp_path, capsys, bad, words):
    run = _run_csv(tmp_path / "run.csv")
    (tmp_path / "volerr-identification.toml").write_text(bad)
    out = tmp_path / "r.pdf"
    assert main(["iso230-2", str(run), "--pdf", str(out), "--json", str(tmp_path / "r.json")]) \
        == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert all(w in err for w in words), err
    assert not out.exists() and not (tmp_path / "r.json").exists()


def test_a_date_of_measurement_in_the_future_is_refused(tmp_path, capsys):
    run = _run_csv(tmp_path / "run.csv")
    future = (datetime.date.today() + datetime.timedelta(days=3)).isoformat()
    assert main(["iso230-2", str(run), "--date", future, "--json", str(tmp_path / "r.json")]) \
        == 2
    err = capsys.readouterr().err
    assert "--date" in err and "future" in err and not (tmp_path / "r.json").exists()


def test_history_add_keeps_the_date_of_the_measurement(tmp_path, capsys):
    from importlib import resources

    trace = resources.files("volerr") / "data" / "ballbar_example_XY.csv"
    cal = tmp_path / "cal.json"
    assert main(["calibrate", "MB1", str(trace), "--json", str(cal), "--date", "2026-11-02",
                 "--machine", "VMC-7"]) == 0
    assert json.loads(cal.read_text())["identification"]["date"] == "2026-11-02"
    capsys.readouterr()
    assert main(["history", "add", "--db", str(tmp_path / "h.sqlite"), "--machine", "VMC-7",
                 str(cal)]) == 0
    assert "on 2026-11-02" in capsys.readouterr().out


def test_every_reporting_command_takes_the_identification_and_pdf():
    from volerr.cli import build_parser

    parser = build_parser()
    commands = [["calibrate"], ["ballbar", "evaluate"], ["check"], ["history", "show"],
                ["loop"], ["uncertainty"], ["probe-cal"], ["identify"], ["plan"], ["iso230-2"],
                ["iso230-3"], ["iso10360"], ["map"], ["compensate"]]
    for words in commands:
        p = parser
        for w in words:
            p = next(a for a in p._actions if a.__class__.__name__ == "_SubParsersAction") \
                .choices[w]
        flags = p._option_string_actions
        for flag in ("--identification", "--pdf", "--operator", "--date", "--customer"):
            assert flag in flags, (words, flag)


def test_write_pdf_of_an_api_result_has_vector_figures_and_page_numbers(tmp_path):
    import volerr
    from importlib import resources

    trace = resources.files("volerr") / "data" / "ballbar_example_XY.csv"
    ev = volerr.ballbar_evaluate([str(trace)])
    path = ev.write_pdf(tmp_path / "bb.pdf")
    reader = pypdf.PdfReader(str(path))
    n = len(reader.pages)
    text = [p.extract_text() for p in reader.pages]
    assert all(f"page {i} of {n}" in t for i, t in enumerate(text, start=1))
    assert "ISO 230-4" in "\n".join(text) and "150 mm" in "\n".join(text)
    # the polar plot is drawn as paths, not embedded as a raster image
    assert not any(page.images for page in reader.pages)
    assert "EC0Y" in text[0] and "\u00b5rad" in text[0]
    # the budgets of the rows: ISO 230-4 G, F, H and the diagnosis (the estimator's)
    budgets = ev.to_dict()["budgets"]
    std = {r.name: r.std for r in ev._rows()}
    assert "EC0Y" in budgets
    for name, b in budgets.items():
        assert b["u"] == pytest.approx(std[name], rel=1e-6)
        assert f"Uncertainty budget: {name}" in "\n".join(text)


def test_calibrate_budget_splits_the_stated_u_by_file_and_model_residual(tmp_path):
    """Two ballbar files of the same geometry and weights: each file's readings contribute
    the same share; the single file's u is twice the share of each of two (the a-priori
    covariance halves with twice the data, then splits in two); the model residual adds
    (s0^2 - 1) times the a-priori variance; combined u = the stated u (1e-6)."""
    import numpy as np
    from importlib import resources

    import volerr

    trace = resources.files("volerr") / "data" / "ballbar_example_XY.csv"
    lines = trace.read_text().splitlines()
    rng = np.random.default_rng(7)
    noisy = [lines[0]]
    for line in lines[1:]:
        c = line.split(",")
        c[10] = f"{float(c[10]) + rng.normal(0.0, 1.5):.5f}"    # dr_um: 1.5 um more scatter
        noisy.append(",".join(c))
    (tmp_path / "noisy.csv").write_text("\n".join(noisy) + "\n")
    one = volerr.calibrate("MB1", [str(trace)]).to_dict()
    two = volerr.calibrate("MB1", [str(trace), str(tmp_path / "noisy.csv")]).to_dict()
    s0_sq = two["variance_factor"]
    assert s0_sq > 1.5 and set(two["budgets"]) == set(two["parameters"])
    for name, b in two["budgets"].items():
        f1, f2, model = (s["contribution"] for s in b["sources"])
        assert f1 == pytest.approx(f2, rel=1e-9)
        assert f1 == pytest.approx(one["budgets"][name]["u"] / 2, rel=1e-6)
        assert model ** 2 == pytest.approx((s0_sq - 1) * (f1 ** 2 + f2 ** 2), rel=1e-3)
        assert b["u"] == pytest.approx(two["parameters"][name]["std"], rel=1e-6)
        assert b["U"] == pytest.approx(2 * two["parameters"][name]["std"], rel=1e-6)


def test_html_page_carries_conditions_budgets_and_the_print_stylesheet(iso):
    html = iso["out"]["html"].read_text(encoding="utf-8")
    assert html.index("<h2>Identification</h2>") < html.index("<h2>Test conditions</h2>")
    assert html.count("class='ident'") >= 2 and "Uncertainty budget: X A" in html
    for rule in ("size: A4", "counter(page)", "counter(pages)", "word-break: keep-all",
                 "hyphens: none", iso["doc"]["identification"]["report_id"]):
        assert rule in html, rule
    body = html.split("<body", 1)[1]
    import re

    visible = re.sub(r"<style>.*?</style>|<[^>]*>", " ", body, flags=re.S)
    assert not re.search(r"\d um\b", visible)          # µm on the page, never "um"


def test_printed_html_is_a4_with_page_x_of_y(iso, tmp_path):
    import shutil
    import subprocess

    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.skip("no Chromium installed (apt-get install chromium)")
    out = tmp_path / "printed.pdf"
    subprocess.run([exe, "--headless", "--no-sandbox", "--disable-gpu",
                    "--no-pdf-header-footer", f"--print-to-pdf={out}",
                    iso["out"]["html"].as_uri()], check=True, capture_output=True, timeout=120)
    reader = pypdf.PdfReader(str(out))
    n = len(reader.pages)
    rid = iso["doc"]["identification"]["report_id"]
    for i, page in enumerate(reader.pages, start=1):
        assert (float(page.mediabox.width), float(page.mediabox.height)) == \
            pytest.approx(A4_PT, abs=1.0)
        text = page.extract_text()
        assert f"page {i} of {n}" in text and rid in text


def test_iso10360_test_uncertainty_budget_at_the_largest_U(tmp_path, inputs):
    """U(L) = 2 sqrt((U_cal/2)^2 + (L |T - 20| u(alpha))^2 + (L alpha u(T))^2), written out
    by hand for L = the longest length, T = 21.5 degC: its budget combines to the stated U."""
    out = tmp_path / "i.json"
    pdf = tmp_path / "i.pdf"
    assert main(["iso10360", "MB1", "--errors", str(inputs["errors"]), "--json", str(out),
                 "--temperature-C", "21.5", "--mpe", "E0=2+L/300", "--pdf", str(pdf)]) == 0
    d = json.loads(out.read_text())
    L = max(x for p in d["positions"] for x in p["lengths_mm"])
    by_hand = 2 * math.sqrt((0.5 * (0.1 + L / 2000)) ** 2 + (L * 1.5 * 1.0e-3) ** 2
                            + (L * 11.5 * 0.2e-3) ** 2)
    b = d["budgets"]["E0"]
    assert b["U"] == pytest.approx(by_hand, rel=1e-6)
    assert b["u"] == pytest.approx(d["uncertainty_um"]["E0"] / 2, rel=1e-6)
    text = "\n".join(p.extract_text() for p in pypdf.PdfReader(str(pdf)).pages)
    assert "Uncertainty budget: E0 at L" in text and "Decision rule: ISO 14253-1" in text
    assert "max |E0|" in text and "repetitions 3" in text


def test_ballbar_page_states_the_iso230_4_conditions(tmp_path):
    """The ISO 230-4 conditions on the ballbar page: radius, direction, plane, readings from
    the traces; feed and compensation from [conditions]; the bar's calibration from the
    instrument's certificate; the rest "not stated"."""
    from importlib import resources

    src = resources.files("volerr") / "data" / "ballbar_example_XY.csv"
    trace = tmp_path / "trace.csv"
    trace.write_bytes(src.read_bytes())
    (tmp_path / "volerr-identification.toml").write_text(
        IDENT.replace('"LI-1"', '"QC20-W"').replace("laser interferometer", "ballbar")
        .replace('dwell = "2 s"', 'compensation = "off"'))
    out = {k: tmp_path / f"bb.{k}" for k in ("json", "html")}
    assert main(["ballbar", "evaluate", str(trace), "--json", str(out["json"]), "--html",
                 str(out["html"])]) == 0
    assert json.loads(out["json"].read_text())["identification"]["instruments"][0]["id"] == \
        "QC20-W"
    html = out["html"].read_text(encoding="utf-8")
    for cell in ("ISO 230-4 (circular test, ballbar)", "<td class='l'>150 mm</td>",
                 "<td class='l'>ccw, cw</td>", "<td class='l'>1000 mm/min</td>",
                 "<td class='l'>off</td>", "QC20-W certificate CAL-2025-17",
                 "<th class='l'>overrun arcs</th><td class='l'>not stated</td>"):
        assert cell in html, cell
