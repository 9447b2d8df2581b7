"""The drift loop says when its held-out readings lie outside the training range of an input
(a speed never run, a temperature never reached): there a prediction is an extrapolation.
Checked on a simulated run whose held-out stretch runs the spindle faster than any training
stretch, against the ranges computed here from the file itself."""

from __future__ import annotations

import json

import numpy as np

from volerr.cli import main


def _write(path, fast_test: bool):
    t = np.arange(0.0, 12 * 3600.0, 30.0)
    speed = np.where(t < 6 * 3600, 2000.0, 0.0)
    speed[(t >= 9 * 3600) & (t < 11 * 3600)] = 4000.0 if fast_test else 2000.0
    rng = np.random.default_rng(5)
    temp = 22.0 + np.cumsum(speed) * 1e-6 + rng.normal(0, 0.01, len(t))
    d = 2.0 * (temp - temp[0]) + rng.normal(0, 0.05, len(t))
    rows = ["t_s,S_rpm,T_spindle,d_z_um"] + [f"{a:.1f},{b:.1f},{c:.5f},{e:.5f}"
                                             for a, b, c, e in zip(t, speed, temp, d)]
    path.write_text("\n".join(rows) + "\n")
    return t, speed, temp


def test_held_out_speed_above_training_is_flagged(tmp_path, capsys):
    f = tmp_path / "run.csv"
    t, speed, temp = _write(f, fast_test=True)
    out = tmp_path / "r.json"
    assert main(["loop", "DMU50", f"drift:{f}", "--holdout-time", "9h:", "--json", str(out)]) == 0
    doc = json.loads(out.read_text())
    flagged = {e["input"]: e for e in doc["extrapolation"]}
    assert "S_rpm" in flagged
    test = t >= 9 * 3600
    assert flagged["S_rpm"]["test_max"] == speed[test].max()
    assert flagged["S_rpm"]["train_max"] == speed[~test].max()
    assert "extrapolates" in capsys.readouterr().out


def test_held_out_within_training_is_not_flagged(tmp_path, capsys):
    f = tmp_path / "run.csv"
    _write(f, fast_test=False)
    out = tmp_path / "r.json"
    assert main(["loop", "DMU50", f"drift:{f}", "--holdout-time", "9h:11h", "--json",
                 str(out)]) == 0
    doc = json.loads(out.read_text())
    assert "S_rpm" not in {e["input"] for e in doc["extrapolation"]}


def test_a_term_dropped_as_not_significant_is_listed(tmp_path):
    """A term the selection took and the significance test dropped is named under
    ``not_significant`` (before: the list was reset at every refit and always empty).  The
    run: a drift that follows one sensor, a second sensor that wanders on its own (given to
    the test as a term; its coefficient is within 2 u of zero, checked here)."""
    from volerr.loop.drift import basis
    from volerr.loop.drift import fit as core

    rng = np.random.default_rng(11)
    t = np.arange(0.0, 16 * 3600.0, 30.0)
    S = np.where((t % (4 * 3600)) < 2 * 3600, 3000.0, 0.0)
    a = 22 + np.convolve(S / 3000.0, np.ones(60) / 60, mode="full")[:len(t)] * 3
    ins = {"S_rpm": S, "T_a": a + rng.normal(0, 0.02, len(t)),
           "T_b": 22 + np.cumsum(rng.normal(0, 0.002, len(t)))}
    y = 2.0 * (a - a[0]) + rng.normal(0, 0.05, len(t))
    s = basis.DriftSeries(t, np.zeros(len(t), int), [("f.csv", "")], ins, {"c": y})
    s.test = t >= 12 * 3600
    sig = core._significant
    specs = [{"source": "T_a", "p": None, "tau_s": 0.0, "minus": None},
             {"source": "T_b", "p": None, "tau_s": 0.0, "minus": None}]
    fold, rule = basis.folds(s)
    R = np.ones((len(t), 1))
    ch = core.Channel(s, y, R, fold, rule)
    kept, fit = sig(ch, specs)
    full = core._jackknife(ch, specs)
    assert abs(full["coef"][1]) < 1.5 * full["coef_std"][1]      # clearly not significant
    assert abs(full["coef"][0]) > 10 * full["coef_std"][0]
    assert [k["source"] for k in kept] == ["T_a"]
    assert [d["source"] for d in fit["dropped"]] == ["T_b"]
