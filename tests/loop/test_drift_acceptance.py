"""Acceptance of the loop on drift runs (issue 35 "Done when": an independent simulator, a
tester who did not write the loop), against the command line and the JSON contract of
INTERFACE.md ("Thermal drift tests (ISO 230-3) and the loop on measured heat") only:

    volerr loop DMU50 drift:run1.csv drift:run2.csv --holdout-files run3.csv --json F
                [--predictions-out P.csv]

Campaigns (tests/helpers/drift_sim.py): three 8 h spindle runs of different duty cycles and
speeds (run 3 held out), one displacement channel along X, four proxy sensors of one heat source
(a fast one at the bearings, the coolant return, a slow one in the casting, the room) and the
spindle speed; the readings are a lag of ONE sensor's true temperature plus 0.15 um noise:

* ``fast``: 2.5 um/K x lag(T_fast, 1800 s); ``slow``: 3 um/K x lag(T_slow, 900 s) -- the loop
  names that sensor, its time constant within 25 %, one effect, and predicts the held-out run
  (from its inputs and its first reading) with a mean absolute error at most 1.15 x the true
  model's (tests/loop/test_drift_sim.py shows every other sensor predicts >= 3 x worse);
* ``fast?``: the same with the channel's direction not known (``# channel d_x: ?``, as in the
  FL_THERMAL file): modelled on its own, the same findings;
* ``none``: the readings are noise about the sensor's zero -- no effect;
* one 16 h run held out by time from 10 h on (``--holdout-time 36000s:``): the same findings,
  the window predicted with the lag continued through the run (the floor: the true model's
  MAE there, with its true zero).

Until ``volerr loop`` takes drift runs (the branch ``loop-drift``) these tests SKIP, naming the
message the command gave (an unknown ``--holdout-files`` option, or drift files refused as
points at one position); any other failure fails.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from helpers.in_process import volerr as volerr_cmd
from helpers import drift_sim as D

# the module fixture's loop runs once, on one xdist worker (a case's two tests share it)
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("drift_acceptance")]

FLOOR_FACTOR = 1.15
TAU_TOLERANCE = 0.25
#: what ``volerr loop`` answers before it takes drift runs (the skip's reason)
NOT_YET = ("unrecognized option --holdout", "unrecognized arguments",
           "stand at one position", "invalid choice: 'drift'")


RUNS = ("drift:run1.csv", "drift:run2.csv", "--holdout-files", "run3.csv")


#: the skip's reason once one run found that the loop does not take drift runs yet
_SKIP: list = []


def _loop(folder: Path, files=RUNS) -> tuple:
    """Run the command of the module docstring in ``folder``: (process, JSON or None)."""
    if _SKIP:
        pytest.skip(_SKIP[0])
    r = volerr_cmd(*["loop", "DMU50", *files, "--json", "loop.json",     # in-process
                     "--predictions-out", "pred.csv"], cwd=folder)
    if r.returncode != 0 and any(m in r.stderr for m in NOT_YET):
        _SKIP.append("volerr loop does not take drift runs yet: "
                     + (r.stderr.strip().splitlines() or [""])[-1])
        pytest.skip(_SKIP[0])
    assert r.returncode == 0, r.stderr
    return r, json.loads((folder / "loop.json").read_text())


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """Each campaign simulated and run through the loop once (the module's tests share it)."""
    cache: dict = {}

    def get(case: str):
        if case not in cache:
            folder = tmp_path_factory.mktemp(f"drift_{case}")
            runs = D.campaign(D.CASES[case.rstrip("?")], folder,     # "fast?": a '?' channel
                              direction="?" if case.endswith("?") else "X")
            cache[case] = (folder, runs, _loop(folder)[1])
        return cache[case]

    return get


def _listed(effect: dict, singular: str, plural: str) -> list:
    """An effect's ``channel(s)`` / ``covariate(s)`` as a list (the contract names them
    "its channel(s), covariate(s)")."""
    v = effect.get(plural, effect.get(singular))
    return [] if v is None else ([v] if isinstance(v, str) else list(v))


@pytest.mark.parametrize("case", ["fast", "slow", "fast?"])
def test_names_the_planted_sensor_and_lag(results, case):
    planted = D.CASES[case.rstrip("?")]
    _, _, doc = results(case)
    effects = doc["effects"]
    assert len(effects) == 1, [e.get("name") for e in effects]
    eff = effects[0]
    assert _listed(eff, "covariate", "covariates") == [planted.sensor], eff
    chans = _listed(eff, "channel", "channels")
    assert chans == [] or "x" in chans or "d_x" in chans or "d_x_um" in chans, chans
    lag = eff["lag_s"]
    assert abs(lag["value"] / planted.tau_s - 1) <= TAU_TOLERANCE, lag
    assert np.isfinite(lag["std"]) and lag["std"] > 0


@pytest.mark.parametrize("case", ["fast", "slow", "fast?"])
def test_predicts_the_held_out_run_to_the_noise_floor(results, case):
    planted = D.CASES[case.rstrip("?")]
    folder, runs, doc = results(case)
    ch = doc["channels"]
    label = next(k for k in ch if k in ("x", "d_x", "d_x_um"))
    held = runs[2]
    assert ch[label]["n_test"] == len(held["t_s"])
    floor = D.true_mae(held, planted)
    assert ch[label]["mae_after_um"] <= FLOOR_FACTOR * floor, (ch[label], floor)
    assert ch[label]["mae_before_um"] > 5 * floor         # the declared model sees no drift
    # the predictions file holds the same figures, reading by reading
    with open(folder / "pred.csv", newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if r["split"] == "test"]
    assert len(rows) == len(held["t_s"])
    measured = np.array([float(r["measured_um"]) for r in rows])
    after = np.array([float(r["after_um"]) for r in rows])
    np.testing.assert_allclose(np.sort(measured), np.sort(held["d_x_um"]), atol=1e-5)
    assert np.mean(np.abs(measured - after)) == pytest.approx(ch[label]["mae_after_um"],
                                                              rel=1e-6, abs=1e-9)


def test_no_planted_effect_no_effect(results):
    _, runs, doc = results("none")
    assert doc["effects"] == [], [e.get("name") for e in doc["effects"]]
    ch = doc["channels"]
    label = next(k for k in ch if k in ("x", "d_x", "d_x_um"))
    assert ch[label]["mae_after_um"] <= FLOOR_FACTOR * D.true_mae(runs[2], None)


def test_holdout_time_window_of_one_run(tmp_path):
    """One 16 h run, the readings from 10 h on held out by time (``--holdout-time 36000s:``):
    the same sensor and lag, one effect, and the window predicted (the lag continued through
    the run) to within 1.15 x the true model's MAE."""
    planted = D.CASES["fast"]
    run = D.long_run(planted, tmp_path)
    start = D.LONG_RUN[3]
    _, doc = _loop(tmp_path, ("drift:long.csv", "--holdout-time", f"{start:g}s:"))
    assert len(doc["effects"]) == 1
    eff = doc["effects"][0]
    assert _listed(eff, "covariate", "covariates") == [planted.sensor], eff
    assert abs(eff["lag_s"]["value"] / planted.tau_s - 1) <= TAU_TOLERANCE, eff["lag_s"]
    ch = doc["channels"]
    label = next(k for k in ch if k in ("x", "d_x", "d_x_um"))
    held = int(np.sum(run["t_s"] >= start))
    assert ch[label]["n_test"] == held
    assert ch[label]["mae_after_um"] <= FLOOR_FACTOR * D.true_window_mae(run, planted, start)
    with open(tmp_path / "pred.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    test_t = sorted(float(r["t_s"]) for r in rows if r["split"] == "test")
    assert test_t == sorted(run["t_s"][run["t_s"] >= start].tolist())
