"""Drift files of many runs as a user has them (issue 44): a day whose file lacks a sensor, a
sensor that froze or stepped, runs that start at different room temperatures.

* an input missing from one file is left out of every run and named (JSON
  ``inputs_left_out``, one console line); a channel missing is still refused (the measurand);
* a frozen stretch and an offset step are found against the sensor's own scatter
  (:func:`volerr.instruments._fields.sensor_faults`), the sensor left out and named; a frozen
  channel refuses its file; clean series (seeded noise, a door opening that relaxes, a step
  every sensor shares, FL_THERMAL, the tests' simulators) raise none;
* the extrapolation warning judges each temperature's change since its run's first reading;
* the JSON has no empty ``static_regression`` (the baselines carry the static regression).

Expected values are the planted ones (times, sizes, names), never the code's own output."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from volerr.cli import main
from volerr.instruments import _fields as F

FL = Path("/work/shared/data/thermal/fl_thermal_spindle.csv")
DT = 30.0


def _run(seed: int, hours: float = 6.0, room0: float = 21.0, warm: float = 2.0) -> dict:
    """A spindle run at ``DT`` s: speed on for the first half, two sensors (a lag of the heat,
    the room), a channel following the first; 0.03 K and 0.05 um of noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, hours * 3600.0, DT)
    S = np.where(t < hours * 1800.0, 3000.0, 0.0)
    heat = np.zeros(len(t))
    for i in range(1, len(t)):
        heat[i] = heat[i - 1] + (S[i] / 3000.0 - heat[i - 1]) * DT / 3600.0
    a = room0 + warm * heat
    room = room0 + 0.3 * np.sin(2 * np.pi * t / 86400.0)
    d = 4.0 * (a - a[0]) + rng.normal(0, 0.05, len(t))
    return {"t_s": t, "S_rpm": S, "T_a": a + rng.normal(0, 0.03, len(t)),
            "T_room": room + rng.normal(0, 0.03, len(t)), "d_z_um": d}


def _write(path: Path, run: dict, drop=()) -> Path:
    cols = [c for c in run if c not in drop]
    rows = [",".join(cols)] + [",".join(f"{run[c][i]:.5f}" for c in cols)
                               for i in range(len(run["t_s"]))]
    path.write_text("\n".join(rows) + "\n")
    return path


def _loop(tmp_path, files, held, capsys):
    out = tmp_path / "r.json"
    code = main(["loop", "DMU50", *[f"drift:{f}" for f in files], "--holdout-files", str(held),
                 "--json", str(out)])
    text = capsys.readouterr()
    return code, (json.loads(out.read_text()) if code == 0 else None), text


# ---- the check itself ----------------------------------------------------------------------
def test_planted_frozen_and_step_are_found_where_planted():
    r = _run(1)
    t = r["t_s"]
    frozen = r["T_a"].copy()
    frozen[300:] = frozen[300]                      # the logger holds its last value
    step = r["T_room"].copy()
    step[450:] += 0.8                               # a re-plugged thermocouple
    found = F.sensor_faults(t, {"T_a": frozen, "T_room": step},
                            {"S_rpm": r["S_rpm"], "T_a": frozen, "T_room": step})
    got = {e["input"]: e for e in found}
    assert got["T_a"]["fault"] == "frozen"
    assert got["T_a"]["from_s"] == t[300] and got["T_a"]["to_s"] == t[-1]
    assert got["T_a"]["readings"] == len(t) - 300
    assert got["T_room"]["fault"] == "step" and got["T_room"]["at_s"] == t[450]
    assert abs(got["T_room"]["step"] - 0.8) < 0.2          # 0.8 K plus two readings' noise
    # the noise scale is the planted 0.03 K reading noise's change: sqrt(2) 0.03
    assert 0.7 * np.sqrt(2) * 0.03 < got["T_room"]["noise"] < 1.3 * np.sqrt(2) * 0.03


@pytest.mark.parametrize("seed", [1, 2, 3, 4, 5])
def test_clean_series_raise_no_fault(seed):
    r = _run(seed)
    cols = {k: r[k] for k in ("T_a", "T_room")}
    assert F.sensor_faults(r["t_s"], cols, {k: r[k] for k in ("S_rpm", "T_a", "T_room")}) == []
    # a coarse logger (0.1 K resolution) repeating values is no frozen sensor
    coarse = {k: np.round(v, 1) for k, v in cols.items()}
    assert F.sensor_faults(r["t_s"], coarse, {**coarse, "S_rpm": r["S_rpm"]}) == []


def test_a_door_that_relaxes_and_a_shared_jump_are_no_fault():
    r = _run(7)
    t, n = r["t_s"], len(r["t_s"])
    door = r["T_room"].copy()
    k = np.arange(n) - 400
    door[k >= 0] -= 2.5 * np.exp(-k[k >= 0] * DT / 900.0)       # air replaced, warms again
    assert F.sensor_faults(t, {"T_room": door}, {"T_room": door, "T_a": r["T_a"]}) == []
    both = {k2: r[k2].copy() for k2 in ("T_a", "T_room")}
    for v in both.values():
        v[450:] += 0.8                                           # every sensor at once
    assert F.sensor_faults(t, both, both) == []


def test_fl_thermal_and_the_simulators_raise_no_fault(tmp_path):
    from helpers import drift_sim, spindle_machine_sim as M
    from volerr.instruments import drift

    files = [FL] if FL.exists() else []
    for name, planted in drift_sim.CASES.items():
        (tmp_path / name).mkdir()
        drift_sim.campaign(planted, tmp_path / name)
        files += sorted((tmp_path / name).glob("run*.csv"))
    files.append(tmp_path / "long.csv")
    drift_sim.long_run(drift_sim.CASES["fast"], tmp_path)
    files += M.write_campaign(tmp_path, M.campaign())
    runs = [r for f in files for r in drift.read_runs(f)]
    assert len(runs) >= 10
    assert [e for r in runs for e in drift.faults(r)] == []


# ---- the loop on campaigns -------------------------------------------------------------------
def test_an_input_missing_from_one_file_is_left_out_and_named(tmp_path, capsys):
    files = [_write(tmp_path / f"day{i}.csv", _run(10 + i), drop=("T_room",) if i == 2 else ())
             for i in range(3)]
    code, doc, text = _loop(tmp_path, files[:2], files[2], capsys)
    assert code == 0, text.err
    assert doc["inputs_left_out"] == [{"input": "T_room", "reason": "missing",
                                       "files": ["day2.csv"], "faults": []}]
    line = [x for x in text.out.splitlines() if "left out" in x]
    assert len(line) == 1 and "T_room" in line[0] and "day2.csv" in line[0]
    assert all("T_room" not in e["covariates"] for e in doc["effects"])


def test_the_page_names_the_input_left_out(tmp_path):
    import volerr

    files = [_write(tmp_path / f"day{i}.csv", _run(70 + i), drop=("T_room",) if i == 0 else ())
             for i in range(3)]
    r = volerr.loop("DMU50", [f"drift:{f}" for f in files])
    page = tmp_path / "p.html"
    r.write_html(page)
    text = page.read_text()
    assert "left out of the model" in text and "missing from day0.csv" in text
    assert r.summary().splitlines()[0].strip().startswith("note: left out")


def test_a_channel_missing_from_one_file_is_refused(tmp_path, capsys):
    files = [_write(tmp_path / f"day{i}.csv", _run(20 + i)) for i in range(2)]
    r = _run(22)
    r["d_x_um"] = r["d_z_um"]
    held = _write(tmp_path / "day2.csv", r, drop=("d_z_um",))
    code, _, text = _loop(tmp_path, files, held, capsys)
    assert code == 2
    err = text.err.strip().splitlines()
    assert len(err) == 1 and "day2.csv" in err[0] and "channels" in err[0]
    assert not (tmp_path / "r.json").exists()


def test_a_faulty_sensor_is_left_out_and_named(tmp_path, capsys):
    runs = [_run(30 + i) for i in range(3)]
    runs[1]["T_room"][300:] += 0.8
    files = [_write(tmp_path / f"day{i}.csv", r) for i, r in enumerate(runs)]
    code, doc, text = _loop(tmp_path, files[:2], files[2], capsys)
    assert code == 0, text.err
    (e,) = doc["inputs_left_out"]
    assert e["input"] == "T_room" and e["reason"] == "faulty" and e["files"] == []
    (f,) = e["faults"]
    assert f["fault"] == "step" and f["file"] == "day1.csv" and f["at_s"] == runs[1]["t_s"][300]
    assert any("T_room steps by" in x and "day1.csv" in x for x in text.out.splitlines())


def test_a_frozen_channel_refuses_its_file(tmp_path, capsys):
    runs = [_run(40 + i) for i in range(3)]
    runs[0]["d_z_um"][200:] = runs[0]["d_z_um"][200]
    files = [_write(tmp_path / f"day{i}.csv", r) for i, r in enumerate(runs)]
    code, _, text = _loop(tmp_path, files[:2], files[2], capsys)
    assert code == 2
    err = text.err.strip().splitlines()
    assert len(err) == 1 and "day0.csv" in err[0] and "d_z_um frozen" in err[0]


# ---- extrapolation on what the model uses; no empty static_regression -------------------------
def test_runs_at_other_room_temperatures_are_no_extrapolation(tmp_path, capsys):
    """Three days alike but for the room they start in (21, 22, 24 degC; the held-out day the
    first day's noise, 3 K warmer): the held-out day's absolute temperatures lie beyond
    training, its changes since its first reading do not."""
    files = [_write(tmp_path / f"day{i}.csv", _run(seed, room0=r0))
             for i, (seed, r0) in enumerate(((50, 21.0), (51, 22.0), (50, 24.0)))]
    code, doc, text = _loop(tmp_path, files[:2], files[2], capsys)
    assert code == 0, text.err
    assert doc["extrapolation"] == []
    assert "static_regression" not in doc
    for c in doc["channels"].values():
        assert set(c["baselines"]) == {"static", "constant"}


def test_a_warming_beyond_training_is_named_as_a_change(tmp_path, capsys):
    """The held-out day warms T_a by 4 K where training days warmed 2 K: named, with the
    changes' ranges computed here from the files."""
    runs = [_run(60 + i, warm=w) for i, w in enumerate((2.0, 2.0, 4.0))]
    files = [_write(tmp_path / f"day{i}.csv", r) for i, r in enumerate(runs)]
    code, doc, text = _loop(tmp_path, files[:2], files[2], capsys)
    assert code == 0, text.err
    got = {e["input"]: e for e in doc["extrapolation"]}
    assert "T_a" in got and got["T_a"]["basis"] == "change"
    written = [np.round(r["T_a"], 5) for r in runs]           # as read back from the files
    change = [w - w[0] for w in written]
    assert got["T_a"]["test_max"] == pytest.approx(change[2].max(), abs=1e-9)
    assert got["T_a"]["train_max"] == pytest.approx(max(change[0].max(), change[1].max()),
                                                    abs=1e-9)
    assert "T_a change" in text.out
