"""Irrelevant sensors on a single run: the differences screen of the drift loop (issue 44,
the independent tester's speed-only finding; ``_screen`` of ``screen_v1.patch`` /
``screen_v2.patch``).  NOT adopted (RESULTS.md): kept here, outside the test suite, as the
tests that would gate a screen; with a patch applied, run
``python -m pytest -p no:xdist -q benchmarks/research/spurious_sensor/gate_tests.py``.  On the
unchanged code the first and third fail (1.80x the floor; no ``_difference_rows``); the
second fails with a screen that keeps every sensor out (planted: the critical value x 100).

A level regression on a wandering series within one run is the spurious regression of
Granger & Newbold (1974, J. Econometrics 2, 111-120): the tester's speed-only machine
(`benchmarks/acceptance/issue44_independent/a44_scen1.py`, the drift from the spindle speed
only, two irrelevant sensors: a room swing plus a random walk), seed 3, 15 s, the last 20 %
held out: before the screen the regularised fit was pulled to 1.80x its floor and ``T_x1``
named as an effect.  Run as a user would (``python -m volerr loop``).  Units um, s, degC.
"""
import json
import os
import sys

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "acceptance", "issue44_independent"))

import a44_scen1 as scen1  # noqa: E402
import a44_sim as sim  # noqa: E402

from volerr.loop.drift import fit as core  # noqa: E402
from volerr.loop.drift.series import DriftSeries  # noqa: E402


@pytest.fixture
def out_dir(tmp_path, monkeypatch):
    monkeypatch.setattr(sim, "OUT", str(tmp_path))
    return tmp_path


def _named_sensors(r):
    return {c for e in r["effects"] for c in (e["covariates"] or []) if c.startswith("T_")}


def test_irrelevant_sensors_neither_named_nor_pulling_the_fit(out_dir, monkeypatch):
    monkeypatch.setattr(scen1, "VARIANT", "speedonly")
    (r,) = scen1.evaluate(3, 15.0, windows=(("forecast", (0.8, 1.0)),))
    assert r["rc"] == 0, r["stderr"]
    assert r["rms"] <= 1.5 * r["floor_rms"], (r["rms"], r["floor_rms"])
    assert not _named_sensors(r), r["effects"]
    with open(out_dir / (r["tag"] + ".json")) as f:
        data = json.load(f)
    assert set(data["sensor_screen"]["z1"]["screened_out"]) == {"T_x1", "T_x2"}


def test_heat_proxy_sensors_pass_the_screen(out_dir, monkeypatch):
    # the easy variant: eight sensors that follow the heat (T_h*), four irrelevant (T_x*)
    monkeypatch.setattr(scen1, "VARIANT", "easy")
    (r,) = scen1.evaluate(1, 60.0, windows=(("forecast", (0.8, 1.0)),))
    assert r["rc"] == 0, r["stderr"]
    with open(out_dir / (r["tag"] + ".json")) as f:
        data = json.load(f)
    out = set(data.get("sensor_screen", {}).get("z1", {}).get("screened_out", []))
    assert not any(k.startswith("T_h") for k in out), out


def test_differences_are_non_overlapping_and_stay_within_a_stretch():
    dt, h = 15.0, 600.0
    t = np.arange(0.0, 6 * 3600.0, dt)
    s = DriftSeries(t_s=t, run=np.zeros(len(t), int), runs=[("r.csv", "")],
                    inputs={"S_rpm": np.zeros(len(t))}, channels={"x": np.zeros(len(t))},
                    directions={"x": "?"}, heights={"x": None})
    s.test = (t >= 2 * 3600.0) & (t < 3 * 3600.0)
    a, b = core._difference_rows(s, h)
    assert np.all(s.train[a]) and np.all(s.train[b])
    assert np.allclose(t[b] - t[a], h)                    # one horizon each
    assert np.all(a[1:] >= b[:-1])                        # none overlaps the one before
    assert not np.any((t[a] < 2 * 3600.0) & (t[b] >= 3 * 3600.0))   # none spans the gap
    assert len(a) == (2 * 3600 - 15) // 600 + (3 * 3600 - 15) // 600
