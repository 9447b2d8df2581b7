"""``volerr demo``: the README's first command runs the whole pipeline and its figures hold."""

import json
import subprocess
import sys


def test_demo_runs_every_section_and_reports_honest_figures(tmp_path):
    out = tmp_path / "demo"
    proc = subprocess.run([sys.executable, "-m", "volerr", "demo", "--out", str(out)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    from volerr.cli.demo import SECTIONS

    summary = json.loads((out / "summary.json").read_text())
    assert len(summary) == len(SECTIONS)
    for section in summary:
        for f in section["files"]:
            assert (out / f).exists(), f
    loop = json.loads((out / "loop.json").read_text())
    assert loop["effects"] and loop["rms_after_um"] < 0.5 * loop["rms_before_um"]
    cal = json.loads((out / "probe_cal.json").read_text())
    assert 0.99 < cal["r_eff_mm"] < 1.01
    html = (out / "index.html").read_text()
    assert html.count("<section") == len(SECTIONS) and "loop.html" in html
    # the instrument sections recover the planted truth within 3 standard uncertainties
    from volerr.calibrate.examples import BALLBAR_TRUTH, SPHERE_TRUTH

    diag = {d["parameter"]: d for d in json.loads((out / "ballbar.json").read_text())["diagnosis"]}
    for name in ("EC0Y", "EB0Z", "EA0Z"):
        assert abs(diag[name]["value"] - BALLBAR_TRUTH[name]) < 3 * diag[name]["std"], diag[name]
    rot = json.loads((out / "calibrate_rotary.json").read_text())
    assert len(rot["parameters"]) >= 4
    for name, v in rot["parameters"].items():
        assert abs(v["value"] - SPHERE_TRUTH[name]) < 3 * v["std"], (name, v)
    # issue 20: ball plate and multilateration beside their planted truth
    from volerr.calibrate.examples import PLATE_TRUTH, TRACER_STATIONS, TRACER_TRUTH

    for name, truth in (("ballplate", PLATE_TRUTH), ("multilateration", TRACER_TRUTH)):
        rep = json.loads((out / f"calibrate_{name}.json").read_text())
        assert set(rep["parameters"]) == set(truth), (name, rep["unidentifiable"])
        for p, v in rep["parameters"].items():
            assert abs(v["value"] - truth[p]) < 3 * v["std"], (name, p, v)
        assert rep["consistency"]["inconsistent"] == []
    for k, s in TRACER_STATIONS.items():
        e = rep["stations"][f"multilateration_DMU50.csv#{k}"]
        for got, want, u in zip(e["position_mm"], s, e["position_std_um"]):
            assert abs(got - want) * 1e3 < 3 * u, (k, e)
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
