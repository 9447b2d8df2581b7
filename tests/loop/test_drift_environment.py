"""The loop on drift runs of several rooms (issue 44 item 2): the files name each run's
``environment``; the folds then hold out whole environments, and a run of a room behaviour
never seen in training is predicted within 1.5 x its floor.

The machine is the second simulated machine's physics (tests/helpers/spindle_machine_sim.py,
written by a tester from the physics: spindle heat ``(S/12000)^1.3``, ``10 um lag(q, 20 min)
- 6 um lag(q, 3 h)``, ``+1.5 um/K`` of the room's change), here logged every 60 s in three
room behaviours (the environments), built here:

* ``constant``: the room held by its air conditioning, 0.15 K of slow swing (two runs);
* ``daily``: the room following the day, 1.2 K sine (two runs);
* ``door``: a hall door opened in the 4th hour, the room 0.8 K cooler within half an hour
  (two runs);
* ``hvac-off``: the air conditioning off, the room rising 1.4 K through the run (one run,
  programme run4): held out whole (``--holdout-files``).

The floor: the TRUE model structure (its time constants, exponent and the room) refitted by
least squares on the training runs (a zero per run) and predicting the held-out run from its
first reading (the helper's :func:`true_model_prediction`).  Criteria: the loop's held-out
RMS within ``FLOOR_FACTOR`` x the floor; the folds are the three training environments
(the JSON's ``fold_rule``, ``n_folds``); the room enters the loop's model (a term in ``T_room``);
and a file whose ``environment`` changes within a run is refused in one line.  One loop run
(module fixture), a few seconds.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import spindle_machine_sim as M
from volerr.errors import InputError
from volerr.loop.drift.run import loop_drift

# the module fixture's loop runs once, on one xdist worker (not once per worker)
pytestmark = pytest.mark.xdist_group("drift_environment")

FLOOR_FACTOR = 1.5
SAMPLE_S = 60.0
SEED = 2044
#: (file, programme, environment, start hour of the room's day, room(t) kind)
RUNS = (("c1", "run1", "constant", 6.0), ("c2", "run3", "constant", 22.0),
        ("d1", "run2", "daily", 8.0), ("d2", "run1", "daily", 18.0),
        ("s1", "run3", "door", 10.0), ("s2", "run2", "door", 16.0),
        ("h1", "run4", "hvac-off", 9.0))
HELD_OUT = "h1"
ROOM_K = {"constant": 0.15, "daily": 1.2, "door": 0.8, "hvac-off": 1.4}


def _room(env: str, t: np.ndarray, hour: float) -> np.ndarray:
    """The room temperature (degC) of an environment over the run's time ``t`` (s)."""
    phase = 2 * np.pi * (t + hour * 3600.0) / M.DAY_S
    if env == "hvac-off":      # rising through the run, levelling off
        return 19.8 + ROOM_K[env] * (1 - np.exp(-t / (6 * 3600.0)))
    if env == "door":          # a hall door opened at the run's 4th hour: a step, 30 min lag
        return M.ROOM_MEAN - ROOM_K[env] * (t > 4 * 3600.0) * (
            1 - np.exp(-np.clip(t - 4 * 3600.0, 0, None) / 1800.0))
    return M.ROOM_MEAN + ROOM_K[env] * np.sin(phase)


def _run(programme: str, env: str, hour: float, rng) -> dict:
    steps, _ = M.PROGRAMMES[programme]
    h = SAMPLE_S
    t = np.arange(0.0, M.RUN_H * 3600.0 + h / 2, h)
    S = M.speed(t, steps)
    q = (S / M.S_REF) ** M.HEAT_P
    room = _room(env, t, hour)
    drift = (M.A_FAST * M.lag_hold(q, M.TAU_FAST, h) + M.A_SLOW * M.lag_hold(q, M.TAU_SLOW, h)
             + M.B_ROOM * (room - room[0]))
    true = {"T_room": room,
            "T_bearing": room + M.K_BEARING * M.lag_hold(q, M.TAU_BEARING, h),
            "T_casting": M.lag_linear(room, M.CASTING_ROOM_TAU_S, h)
            + M.K_CASTING * M.lag_hold(q, M.TAU_CASTING, h),
            "T_cabinet": M.CABINET_MEAN + 0.3 * np.sin(2 * np.pi * t / 20000.0
                                                       + rng.uniform(0, 6.3))}
    noise = rng.normal(0.0, M.D_NOISE_UM, len(t))
    out = {"t_s": t, "S_rpm": S, "d_x_um": rng.uniform(-5, 5) + drift + noise, "noise": noise}
    for k, v in true.items():
        out[k] = v + rng.normal(0.0, M.T_NOISE_K, len(t))
    return out


def _write(path, run: dict, env: str) -> None:
    M.write_run(path, run, env, ["t_s", "S_rpm", "d_x_um", "T_room", "T_bearing", "T_casting",
                                 "T_cabinet"])


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    folder = tmp_path_factory.mktemp("rooms")
    rng = np.random.default_rng(SEED)
    runs = {}
    for name, programme, env, hour in RUNS:
        runs[name] = _run(programme, env, hour, rng)
        _write(folder / f"{name}.csv", runs[name], env)
    paths = [folder / f"{name}.csv" for name, *_ in RUNS]
    rep = loop_drift("DMU50", paths, files=[folder / f"{HELD_OUT}.csv"])
    return runs, rep


def test_the_folds_hold_out_whole_environments(campaign):
    _, rep = campaign
    assert rep["fold_rule"] == "environments"
    assert rep["n_folds"] == 3            # constant, daily, door train; hvac-off held out
    assert rep["runs"][-1].startswith(HELD_OUT) and rep["n_test"] == len(
        campaign[0][HELD_OUT]["t_s"])
    assert rep["environments"] == {f"{name}.csv": env for name, _, env, _ in RUNS}
    assert rep["fold_environments"] == ["constant", "daily", "door"]
    assert "over 3 environments (constant, daily, door)" in rep.summary()


def test_a_room_never_seen_is_predicted_within_its_floor(campaign):
    runs, rep = campaign
    train = [runs[name] for name, *_ in RUNS if name != HELD_OUT]
    held = runs[HELD_OUT]
    floor = M.errors(held, M.true_model_prediction(train, held))
    noise = float(np.sqrt(np.mean(held["noise"] ** 2)))
    assert floor["rms"] <= 1.45 * noise, (floor, noise)     # the floor is the noise
    s = rep.series
    after = rep.pred["x"]["after"][s.test]
    np.testing.assert_array_equal(s.t_s[s.test], held["t_s"])
    e = held["d_x_um"] - after
    rms = float(np.sqrt(np.mean(e ** 2)))
    chosen = [t["basis"] for eff in rep.effects for t in eff["terms"]]
    assert rms <= FLOOR_FACTOR * floor["rms"], (rms, floor, chosen)
    # the room's effect is not left out: without it the held-out run drifts 2 um
    assert any("T_room" in eff["covariates"] for eff in rep.effects), chosen


def test_an_environment_that_changes_within_a_run_is_refused(tmp_path):
    rng = np.random.default_rng(1)
    run = _run("run3", "daily", 0.0, rng)
    _write(tmp_path / "bad.csv", run, "daily")
    lines = (tmp_path / "bad.csv").read_text().splitlines()
    lines[200] = lines[200].replace(",daily", ",constant")
    (tmp_path / "bad.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError) as err:
        loop_drift("DMU50", [tmp_path / "bad.csv"])
    msg = str(err.value)
    assert "bad.csv" in msg and "environment" in msg and "\n" not in msg


def test_one_file_of_labelled_runs_is_the_same_campaign(campaign, tmp_path):
    """The same runs in ONE file with ``run`` and ``environment`` columns (the held-out run
    last: without --holdout-* the last run is held out) give the same folds and the same
    held-out predictions as one file per run."""
    runs, rep = campaign
    cols = ["t_s", "S_rpm", "d_x_um", "T_room", "T_bearing", "T_casting", "T_cabinet"]
    lines = ["# channel d_x: X", ",".join(["run"] + cols + ["environment"])]
    for name, _, env, _ in RUNS:
        r = runs[name]
        lines += [f"{name}," + ",".join(f"{r[c][i]:.6f}" for c in cols) + f",{env}"
                  for i in range(len(r["t_s"]))]
    (tmp_path / "all.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    one = loop_drift("DMU50", [tmp_path / "all.csv"])
    assert one["fold_rule"] == "environments" and one["n_folds"] == 3
    assert one["fold_environments"] == ["constant", "daily", "door"]
    assert one["environments"]["all.csv[h1]"] == "hvac-off"
    a = one.pred["x"]["after"][one.series.test]
    b = rep.pred["x"]["after"][rep.series.test]
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-6)
