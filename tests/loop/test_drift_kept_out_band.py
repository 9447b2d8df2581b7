"""The prediction interval holds what a kept-out input may do (issue 44 items 3 and 4,
:func:`volerr.loop.drift.interval.widen_for_kept_out`).

A small machine of this file's own: six 6 h runs train in a room held within 0.1 K, two are
held out in a room swinging about 2 K; the drift is a heat lag plus the room's own effect
through two hours, ``d = 8 lag(q, 1500 s) - 3 um/K (lag(T_room, 2 h) - start) + noise``.
``T_room`` changes more than ``KEEP_OUT_RATIO`` times as much held out as in training: it is
kept out of the model, and the room's own effect is what the model never fitted.  Measured
(seed 3): the band held 33.7 % of the held-out readings (room widening included; its
difference is 0 here), widened by ``b`` = -2.06 +- 0.46 um/K (true -3 through 30 min): 97.5 %
with ``(abs(b) + 2 u) abs(change)`` added as the rule was first written, 85.9 % with the
rule adopted (``abs(b change)`` added, ``2 u change`` in quadrature with the band:
docs/drift_loop.md, "What a kept-out input may do").  Asked: at least 80 % and at least
40 points above the band without the widening.

The first version of this machine (the room through 2 h, the held room 0.05 K over 1 h,
written before the rule's figures) did not pass: 33.7 % -> 45.0 % (room) -> 65.5 %, ``b`` =
-0.25 +- 0.17 um/K: the training room's changes are too fast for a 2 h lag to follow, so
the training residuals hold almost nothing of the room's gain (docs/drift_loop.md, "What a
kept-out input may do").  The machine kept (30 min, 0.15 K over 6 h) tests the mechanism
where the training readings can determine the gain; it is not evidence that the rule covers
in general.

Checked to fail without the change: with ``widen_for_kept_out`` a no-op (the code before)
the coverage test fails (the band holds the figure of ``coverage_test_unwidened``, below
0.5) and the key is missing; with the coefficient fitted on all readings instead of each
fold's the jackknife comparison fails; with the widening applied where nothing is kept out
the no-kept-out test fails (checked for all three).  Three loop runs, about 2 s of CPU.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from helpers import spindle_machine_sim as M
from volerr.loop.drift import basis
from volerr.loop.drift import interval as band
from volerr.loop.drift import run as run_mod
from volerr.loop.drift.run import loop_drift

SEED = 3
DT = 120.0
HOURS = 6.0
ROOM_TAU_S = 1800.0      # the room reaches the structure through this lag
TRAIN_AMP_K, TRAIN_PERIOD_S = 0.15, 6 * 3600.0   # the held room's small slow wander
COLS = ("t_s", "S_rpm", "d_x_um", "T_room", "T_spindle")
STEPS = {"a": ((0, 0), (0.25, 9000), (2.5, 0), (4, 12000)),
         "b": ((0, 0), (0.5, 12000), (3, 4000)),
         "c": ((0, 0), (0.25, 6000), (1.5, 12000), (4.5, 0))}
TRAIN = (("c1", "a"), ("c2", "b"), ("c3", "c"), ("c4", "b"), ("c5", "a"), ("c6", "c"))
HELD = (("v1", "b"), ("v2", "a"))


def _run(steps, varying: bool, rng) -> dict:
    """One run: the spindle programme ``steps``, the room held (0.05 K) or swinging."""
    t = np.arange(0.0, HOURS * 3600.0 + DT / 2, DT)
    S = M.speed(t, steps)
    q = (S / 12000.0) ** 1.3
    ph = rng.uniform(0, 2 * np.pi)
    amp = rng.uniform(1.0, 1.5) if varying else TRAIN_AMP_K
    period = 8 * 3600.0 if varying else TRAIN_PERIOD_S
    room = 20.0 + amp * (np.sin(2 * np.pi * t / period + ph) - np.sin(ph))
    struct = M.lag_linear(room, ROOM_TAU_S, DT)
    d = 8.0 * M.lag_hold(q, 1500.0, DT) - 3.0 * (struct - struct[0])
    return {"t_s": t, "S_rpm": S, "d_x_um": rng.uniform(-5, 5) + d + rng.normal(0, 0.2, len(t)),
            "T_room": room + rng.normal(0, 0.01, len(t)),
            "T_spindle": room + 5.0 * M.lag_hold(q, 600.0, DT) + rng.normal(0, 0.01, len(t))}


def _loop(folder, held_varying: bool):
    rng = np.random.default_rng(SEED)
    for name, p in TRAIN:
        M.write_run(folder / f"{name}.csv", _run(STEPS[p], False, rng), "constant", COLS, "?")
    env = "varying" if held_varying else "constant"
    for name, p in HELD:
        M.write_run(folder / f"{name}.csv", _run(STEPS[p], held_varying, rng), env, COLS, "?")
    paths = [folder / f"{n}.csv" for n, _ in TRAIN + HELD]
    return loop_drift("DMU50", paths, files=[folder / f"{n}.csv" for n, _ in HELD])


@pytest.fixture(scope="module")
def kept(tmp_path_factory):
    return _loop(tmp_path_factory.mktemp("kept_band"), True)


def test_the_band_holds_the_kept_out_room(kept):
    assert [e["input"] for e in kept["kept_out"]] == ["T_room"]
    iv = kept["channels"]["x"]["interval"]
    w = iv["kept_out_widening"]
    assert w["coverage_test_unwidened"] < 0.5, w          # the band before did not hold it
    assert iv["coverage_test"] >= max(0.8, w["coverage_test_unwidened"] + 0.4), iv
    assert [k["input"] for k in w["inputs"]] == ["T_room"]
    s = kept.series
    x = s.inputs["T_room"] - s.zero(s.inputs["T_room"])
    assert w["inputs"][0]["held_out_change_max"] == pytest.approx(
        float(np.max(np.abs(x[s.test]))), rel=1e-12)
    assert any("kept out, by their coefficients" in line for line in kept.summary_lines())


def test_the_coefficient_and_u_match_lstsq_per_fold(kept):
    s, w = kept.series, kept["channels"]["x"]["interval"]["kept_out_widening"]
    assert kept["fold_rule"] == "runs"
    y = s.channels["x"]
    r = y - kept.pred["x"]["after"]
    x = s.inputs["T_room"] - s.zero(s.inputs["T_room"])
    train_runs = sorted(set(s.run[s.train].tolist()))

    def coef(runs):
        m = s.train & np.isin(s.run, runs)
        A = np.column_stack([(s.run[m] == k).astype(float) for k in runs] + [x[m]])
        return np.linalg.lstsq(A, r[m], rcond=None)[0][-1]

    b = coef(train_runs)
    bk = np.array([coef([k for k in train_runs if k != j]) for j in train_runs])
    K = len(train_runs)
    u = np.sqrt((K - 1) / K * np.sum((bk - bk.mean()) ** 2))
    got = w["inputs"][0]
    assert got["coef_um_per_unit"] == pytest.approx(b, rel=1e-6, abs=1e-9)
    assert got["u"] == pytest.approx(u, rel=1e-6)
    # the band: the bias abs(b x) added, 2 u x in quadrature with the band before it
    p, te = kept.pred["x"], s.test
    h0 = band.interval(p["cv_resid"], y, p["after"], basis.folds(s)[0], te,
                       p["leverage"])["per_reading"][te]
    if p.get("alternative") is not None:        # the room's other reading (widen_for_room)
        h0 = h0 + np.abs(p["after"] - p["alternative"])[te]
    want = abs(b) * np.abs(x[te]) + np.sqrt(h0 ** 2 + (2 * u * x[te]) ** 2)
    np.testing.assert_allclose(p["half_width"][te], want, rtol=1e-6)
    d = want - h0
    assert w["difference_um"] == pytest.approx([np.median(d), np.max(d)], rel=1e-6)


def test_nothing_kept_out_nothing_changes(tmp_path, monkeypatch):
    def never(*a, **k):
        raise AssertionError("widened where nothing is kept out")

    (tmp_path / "a").mkdir()
    rep = _loop(tmp_path / "a", False)
    assert rep["kept_out"] == []
    assert "kept_out_widening" not in rep["channels"]["x"]["interval"]
    monkeypatch.setattr(run_mod.band, "widen_for_kept_out", never)
    monkeypatch.setattr(run_mod, "_kept_out_terms", never)
    (tmp_path / "b").mkdir()
    again = _loop(tmp_path / "b", False)
    a, b = rep.data, again.data
    assert json.dumps(a, sort_keys=True, default=str).replace(str(tmp_path / "a"), "") == \
        json.dumps(b, sort_keys=True, default=str).replace(str(tmp_path / "b"), "")
