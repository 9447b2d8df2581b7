"""``volerr iso230-3`` (issue 35 item 5): the ISO 230-3 evaluation of a drift run against a
planted one -- drifts, tilts of two sensor pairs (one with a reversed direction), the stages of
a spindle programme -- and the command's JSON, plot, HTML and refusals."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from volerr.cli import main
from volerr.instruments import drift
from volerr.positioning import iso230_3

H = 3600.0
Z1, Z2 = 20.0, 120.0


def _planted(n=481, seed=3):
    """8 h at 60 s: spindle stopped 1 h, 3000 rpm 4 h, stopped 3 h.  The tool side moves along
    X by u(t) and Z by w(t), tilts about +Y by beta(t) and about +X by alpha(t) (urad)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 60.0
    s = np.where((t >= 1 * H) & (t < 5 * H), 3000.0, 0.0)
    on = np.clip(t - H, 0, 4 * H)
    heat = 1 - np.exp(-on / 3000.0)
    cool = np.where(t >= 5 * H, np.exp(-(t - 5 * H) / 4000.0), 1.0)
    u, w = 6.0 * heat * cool, -14.0 * heat * cool
    beta, alpha = 40.0 * heat * cool, -25.0 * heat * cool           # urad
    x1, x2 = u + beta * Z1 * 1e-3, u + beta * Z2 * 1e-3              # s_X(z) = u + beta z
    y_lo, y_hi = -alpha * Z1 * 1e-3, -alpha * Z2 * 1e-3              # s_Y(z) = -alpha z
    cols = {"t_s": t, "S_rpm": s, "d_x1_um": x1 + 0.3, "d_x2_um": x2 - 0.2,
            "d_y1_um": -y_lo, "d_y2_um": -y_hi,                      # read along -Y
            "d_z_um": w, "T_spindle": 22 + 8 * heat * cool + rng.normal(0, 0.01, n),
            "T_room": 20 + 0.5 * np.sin(t / 20000)}
    return cols, dict(u=u, w=w, beta=beta, alpha=alpha, s=s)


HEAD = (f"# channel d_x1: X at z={Z1:g}", f"# channel d_x2: X at z={Z2:g}",
        f"# channel d_y1: -Y at z={Z1:g}", f"# channel d_y2: -Y at z={Z2:g}",
        "# channel d_z: Z")


def _write(path: Path, cols: dict, head=HEAD) -> Path:
    names = list(cols)
    rows = np.column_stack([cols[k] for k in names])
    text = "\n".join(list(head) + [",".join(names)] + [",".join(repr(float(v)) for v in r)
                                                       for r in rows])
    path.write_text(text + "\n", encoding="utf-8")
    return path


def test_drift_tilts_and_stages(tmp_path):
    cols, truth = _planted()
    f = _write(tmp_path / "spindle.csv", cols)
    ev = iso230_3.evaluate(drift.read_runs(f)[0])
    doc = ev.to_dict()
    t = cols["t_s"]
    for k in ("x1", "x2", "y1", "y2", "z"):
        d = cols[f"d_{k}_um"] - cols[f"d_{k}_um"][0]
        c = doc["channels"][k]
        assert c["max_um"] == pytest.approx(d.max()) and c["min_um"] == pytest.approx(d.min())
        assert c["range_um"] == pytest.approx(np.ptp(d))
        assert c["t_max_s"] == t[np.argmax(d)]
    assert doc["channels"]["z"]["min_um"] == pytest.approx(truth["w"].min())
    # the tilts: X pair about +Y, the (-Y) pair about +X, as planted
    assert set(doc["tilts"]) == {"x1-x2", "y1-y2"}
    tx, ty = doc["tilts"]["x1-x2"], doc["tilts"]["y1-y2"]
    assert tx["about"] == "Y" and ty["about"] == "X" and tx["lever_mm"] == Z2 - Z1
    assert tx["max_urad"] == pytest.approx(truth["beta"].max(), abs=1e-6)
    assert ty["min_urad"] == pytest.approx(truth["alpha"].min(), abs=1e-6)
    series = {tl.name: tl.series for tl in ev.tilts}
    np.testing.assert_allclose(series["x1-x2"], truth["beta"] - truth["beta"][0], atol=1e-9)
    # stages from S_rpm: stopped, running, stopped
    st = doc["stages"]
    assert [s["value"] for s in st] == [0.0, 3000.0, 0.0]
    assert [s["t_start_s"] for s in st] == [0.0, H, 5 * H]
    run = st[1]["channels"]["z"]
    i0, i1 = int(H / 60), int(5 * H / 60) - 1
    assert run["change_um"] == pytest.approx(truth["w"][i1] - truth["w"][i0])
    assert "rotating spindle (clause 6)" in doc["test"]
    assert doc["temperatures"]["T_spindle"]["range_K"] == pytest.approx(
        np.ptp(cols["T_spindle"]))


def test_stage_rule():
    # a measured speed wandering by < 2 % stays one stage; a step is a new one
    v = np.r_[np.zeros(5), 3000 + np.array([0, 20, -30, 50, 10]), np.full(3, 1500.0)]
    st = iso230_3.stages_of(v)
    assert [(s.start, s.stop, s.value) for s in st] == [(0, 5, 0.0), (5, 10, 3000.0),
                                                      (10, 13, 1500.0)]


def test_etve_without_directions(tmp_path):
    cols, _ = _planted()
    cols = {k: v for k, v in cols.items() if k != "S_rpm"}
    f = _write(tmp_path / "etve.csv", cols, head=())
    ev = iso230_3.evaluate(drift.read_runs(f)[0])
    doc = ev.to_dict()
    assert "ETVE (clause 5)" in doc["test"] and doc["tilts"] == {} and len(doc["stages"]) == 1
    assert any("no channel has a direction" in n for n in doc["notes"])


def test_command_outputs(tmp_path, capsys):
    cols, truth = _planted()
    f = _write(tmp_path / "spindle.csv", cols)
    j, h, p = tmp_path / "r.json", tmp_path / "r.html", tmp_path / "r.png"
    assert main(["iso230-3", str(f), "--json", str(j), "--html", str(h), "--plot", str(p),
                 "--machine", "test lathe"]) == 0
    doc = json.loads(j.read_text())
    assert set(doc) >= {"channels", "tilts", "stages"}
    assert set(doc["channels"]["x1"]) >= {"range_um", "max_um", "min_um"}
    page = h.read_text()
    assert "ISO 230-3" in page and "test lathe" in page and "data:image/png" in page
    assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    out = capsys.readouterr().out
    assert "x1-x2" in out and "clause 6" in out


def test_command_refuses_bad_file(tmp_path, capsys):
    cols, _ = _planted()
    cols["d_z_um"] = np.full_like(cols["d_z_um"], 1.5)
    f = _write(tmp_path / "bad.csv", cols)
    j, h = tmp_path / "r.json", tmp_path / "r.html"
    assert main(["iso230-3", str(f), "--json", str(j), "--html", str(h)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "d_z_um is constant" in err
    assert not j.exists() and not h.exists()
    assert main(["iso230-3", str(_write(tmp_path / "ok.csv", _planted()[0])),
                 "--stage-column", "feed"]) == 2
    assert "no such logged column" in capsys.readouterr().err


def test_real_spindle_programme_stages():
    """The FL_THERMAL file's stages are its README's spindle programme (start h -> rpm)."""
    fl = Path("/work/shared/data/thermal/fl_thermal_spindle.csv")
    if not fl.is_file():
        pytest.skip(f"{fl} not present")
    doc = iso230_3.evaluate(drift.read_runs(fl)[0]).to_dict()
    readme = [(0, 0), (0.13, 1250), (4.13, 0), (8.13, 2500), (12.13, 0), (16.13, 3750),
              (20.13, 0), (24.13, 5000), (28.13, 0), (32.13, 3500), (36.13, 0), (40.13, 500),
              (42.13, 1500), (44.13, 2500), (45.13, 4500), (46.13, 0)]
    got = [(s["t_start_s"] / H, s["value"]) for s in doc["stages"]]
    assert [v for _, v in got] == [float(v) for _, v in readme]
    assert np.allclose([t for t, _ in got], [t for t, _ in readme], atol=0.01)
    assert doc["tilts"] == {} and len(doc["channels"]) == 5


def test_example_files_evaluate_and_convert(tmp_path):
    """The example drift files (volerr examples): the spindle test evaluates with the tilts it
    plants (1.5 urad/K about +Y, 0.5 about +X, the headstock up to ~12 K), the logger's file
    converts."""
    from volerr.example_files import write_drift_examples

    write_drift_examples(tmp_path)
    doc = iso230_3.evaluate(drift.read_runs(tmp_path / "drift_spindle.csv")[0]).to_dict()
    assert 14 < doc["tilts"]["x1-x2"]["max_urad"] < 24
    assert 4 < doc["tilts"]["y1-y2"]["max_urad"] < 10
    assert doc["channels"]["z"]["min_um"] < -12
    assert [s["value"] for s in doc["stages"]] == [0, 3000, 0, 6000, 0]
    out = tmp_path / "drift.csv"
    assert main(["drift", "convert", str(tmp_path / "drift_logger_raw.csv"), "--out",
                 str(out), "--channel", "ch1=X at z=20", "--channel", "ch2=Z"]) == 0
    r = drift.read_runs(out)[0]
    assert r.t_s[1] == 30.0 and r.directions == {"ch1": "X", "ch2": "Z"}
