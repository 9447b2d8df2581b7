"""``volerr demo``: the README's first command runs the whole pipeline and its figures hold."""

import json
import subprocess
import sys


def test_demo_runs_every_section_and_reports_honest_figures(tmp_path):
    out = tmp_path / "demo"
    proc = subprocess.run([sys.executable, "-m", "volerr", "demo", "--out", str(out)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert len(summary) == 9
    for section in summary:
        for f in section["files"]:
            assert (out / f).exists(), f
    loop = json.loads((out / "loop.json").read_text())
    assert loop["effects"] and loop["rms_after_um"] < 0.5 * loop["rms_before_um"]
    cal = json.loads((out / "probe_cal.json").read_text())
    assert 0.99 < cal["r_eff_mm"] < 1.01
    html = (out / "index.html").read_text()
    assert html.count("<section") == 9 and "loop.html" in html
    assert html.count("<figcaption>") == html.count("<img ") > 10
    assert "map_MB1_random.png" in html  # the random component is shown


def test_demo_refuses_to_write_over_a_file(tmp_path):
    target = tmp_path / "file"
    target.write_text("keep")
    proc = subprocess.run([sys.executable, "-m", "volerr", "demo", "--out", str(target),
                           "--only", "cmm_a"], capture_output=True, text=True)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert target.read_text() == "keep"
