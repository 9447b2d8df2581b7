"""The loop on real measured drift data (issue 35 "Done when"): the FL_THERMAL spindle test
(runtime/data/fl_thermal_spindle.csv, MIT licence in runtime/data/LICENSE-FL_THERMAL), the
readings up to 80 % of the run (t < 133380 s), the publication's test window 60-80 % held out
(``--holdout-time 100035s:``).  The held-out MAE of every channel must be below the best
published model's (seq2seq with attention, the data's README): ch1 3.561, ch2 3.755,
ch3 3.704, ch4 3.461, ch5 4.284 um, with at most 6 effects per channel, each naming its
sensors and time constants with uncertainties.  The MAE is recomputed here from the
predictions file and the data file itself (not taken from the report)."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("drift_fl_thermal")]  # fixture once

PUBLISHED_MAE_UM = {"ch1": 3.561, "ch2": 3.755, "ch3": 3.704, "ch4": 3.461, "ch5": 4.284}
END_S = 133380.0


def _data() -> Path:
    return Path(str(resources.files("volerr") / "data" / "fl_thermal_spindle.csv"))


def test_the_licence_travels_with_the_data():
    lic = _data().parent / "LICENSE-FL_THERMAL"
    assert lic.is_file() and "MIT" in lic.read_text()


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fl")
    lines = _data().read_text().splitlines()
    head = [ln for ln in lines if ln.startswith("#")]
    body = [ln for ln in lines if not ln.startswith("#")]
    keep = [body[0]] + [ln for ln in body[1:] if float(ln.split(",")[0]) < END_S]
    (folder / "fl80.csv").write_text("\n".join(head + keep) + "\n")
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    r = subprocess.run([sys.executable, "-m", "volerr", "loop", "DMU50", "drift:fl80.csv",
                        "--holdout-time", "100035s:", "--json", "fl.json",
                        "--predictions-out", "p.csv"],
                       capture_output=True, text=True, cwd=folder, env=env)
    assert r.returncode == 0, r.stderr
    return folder, r, json.loads((folder / "fl.json").read_text())


def test_beats_the_published_models_on_the_held_out_window(run):
    folder, _, doc = run
    with open(folder / "p.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    data = np.genfromtxt(folder / "fl80.csv", delimiter=",", names=True, comments=None,
                         skip_header=8)
    for ch, published in PUBLISHED_MAE_UM.items():
        test = [r for r in rows if r["channel"] == ch and r["split"] == "test"]
        t = np.array([float(r["t_s"]) for r in test])
        assert t.min() >= 100035.0 and t.max() < END_S
        assert len(test) == int(np.sum(data["t_s"] >= 100035.0))
        measured = np.interp(t, data["t_s"], data[f"d_{ch}_um"])    # the file's own values
        after = np.array([float(r["after_um"]) for r in test])
        mae = float(np.mean(np.abs(measured - after)))
        assert mae < published, (ch, mae, published)
        assert doc["channels"][ch]["mae_after_um"] == pytest.approx(mae, rel=1e-6)
        # and the shop's static regression on all temperatures does worse
        assert doc["channels"][ch]["mae_static_um"] > mae


def test_effects_name_sensors_and_time_constants_with_uncertainties(run):
    _, out, doc = run
    for ch in PUBLISHED_MAE_UM:
        mine = [e for e in doc["effects"] if e["channels"] == [ch]]
        assert 1 <= len(mine) <= 6 and sum(len(e["terms"]) for e in mine) <= 6
        for e in mine:
            assert e["covariates"] and all(c.startswith(("T_", "S_rpm")) for c in e["covariates"])
            for t in e["terms"]:
                assert t["std"] > 0 and abs(t["value"]) >= 2 * t["std"]   # significant, k = 2
    lags = [t["lag_s"] for e in doc["effects"] for t in e["terms"] if t["lag_s"]]
    assert lags and sum(lag["std"] is not None for lag in lags) >= len(lags) // 2
    assert "(k = 2)" in out.stdout
