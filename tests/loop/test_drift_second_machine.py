"""The loop on drift runs of a SECOND machine (tests/helpers/spindle_machine_sim.py, written
from the physics by a tester who did not write the loop): spindle heat ``(S/S_ref)^1.3``, the
drift ``10 um lag(q, 20 min) - 6 um lag(q, 3 h) + 1.5 um/K x room change`` (and, scenario
``same``, ``+ 4 um lag(q, 3 h)``), proxies of the
heat (bearing, casting, coolant), the room, two unrelated sensors; four 12 h runs of different
duty cycles at 15 s, ``run4`` held out whole::

    volerr loop DMU50 drift:run1.csv ... drift:run4.csv --holdout-files run4.csv --json F
                --predictions-out P.csv

Criteria (the held-out run, its readings predicted from its inputs and its first reading):

* RMS after within ``FLOOR_FACTOR`` x the floor: the TRUE model structure refitted here by
  least squares on the training runs and predicting run4 the same way (the floor is also
  checked against the planted noise: it cannot beat it by much);
* no worse than the static regression on all temperatures computed here (MAE and RMS);
* ``none``: the same inputs, the readings pure noise about a constant: no effect chosen;
* sampling: the same campaign logged every 60 s (every 4th reading): held-out MAE within
  ``SAMPLING_REL`` of the 15 s result, and the same dominant covariate (the effect whose terms
  move the prediction most over the training runs, computed here from the reported terms).

One loop run per scenario (module fixture; one xdist group, the scenarios share it).
"""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from helpers.in_process import volerr as volerr_cmd
from helpers import spindle_machine_sim as M

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("drift_second_machine")]

FLOOR_FACTOR = 1.5
SAMPLING_REL = 0.25
STATIC_FACTOR = 1.0
SEED_PLANTED, SEED_NONE, SEED_SAME = 31, 57, 43
#: the slow term of the ``same`` scenario: the column growing with the nose (same sign)
A_SLOW_SAME = 4.0


def _loop(folder) -> dict:
    files = [f"drift:{n}.csv" for n in M.PROGRAMMES]
    r = volerr_cmd(*["loop", "DMU50", *files, "--holdout-files", f"{M.HELD_OUT}.csv",
                     "--json", "loop.json", "--predictions-out", "pred.csv"], cwd=folder)
    assert r.returncode == 0, r.stderr
    with open(folder / "pred.csv", newline="") as fh:
        rows = [row for row in csv.DictReader(fh) if row["split"] == "test"]
    return {"doc": json.loads((folder / "loop.json").read_text()), "test_rows": rows,
            "console": r.stdout}


@pytest.fixture(scope="module")
def scenario(tmp_path_factory):
    """name -> {"runs", "doc", "test_rows"}: ``planted`` (15 s, the two heat terms of
    opposite signs), ``same`` (both terms of the same sign), ``planted60`` (``planted``'s
    readings every 60 s), ``none`` -- simulated and looped once each."""
    cache: dict = {}

    def get(name: str):
        if name not in cache:
            if name == "none":
                runs = M.campaign(SEED_NONE, planted=False)
            elif name == "same":
                runs = M.campaign(SEED_SAME, a_slow=A_SLOW_SAME)
            else:
                runs = M.campaign(SEED_PLANTED)
                if name == "planted60":
                    runs = {k: M.subsample(v, 4) for k, v in runs.items()}
            folder = tmp_path_factory.mktemp(f"second_{name}")
            M.write_campaign(folder, runs)
            cache[name] = {"runs": runs, **_loop(folder)}
        return cache[name]

    return get


def _split(runs):
    return [r for k, r in runs.items() if k != M.HELD_OUT], runs[M.HELD_OUT]


def _held_out_errors(sc) -> dict:
    """MAE, RMS of the loop's predictions of run4, against the simulated readings."""
    held = sc["runs"][M.HELD_OUT]
    rows = sc["test_rows"]
    t = np.array([float(r["t_s"]) for r in rows])
    np.testing.assert_array_equal(np.sort(t), held["t_s"])
    after = np.array([float(r["after_um"]) for r in rows])[np.argsort(t, kind="stable")]
    e = held["d_x_um"] - after
    return {"mae": float(np.mean(np.abs(e))), "rms": float(np.sqrt(np.mean(e ** 2)))}


def _chosen(doc) -> list:
    return [t["basis"] for e in doc["effects"] for t in e["terms"]]


def test_the_floor_is_the_planted_noise():
    """The simulator's own check: the true model refitted predicts run4 to about its noise
    (the first reading's noise sets the zero: at most sqrt(2) x the planted noise), and the
    static regression cannot (else the scenario would not tell lags from no lags)."""
    train, held = _split(M.campaign(SEED_PLANTED))
    floor = M.errors(held, M.true_model_prediction(train, held))
    noise = float(np.sqrt(np.mean(held["noise"] ** 2)))
    assert 0.8 * noise <= floor["rms"] <= 1.45 * noise, (floor, noise)
    static = M.errors(held, M.static_prediction(train, held))
    assert static["rms"] > 2 * floor["rms"], (static, floor)


#: ``same`` (same-sign lags, planted exponent 1.3 between the grid's 1 and 1.5) was 1.64 x
#: the floor with the sparse lag model (issue 35); issue 44's regularised fit over the lag
#: bank is its model now (the lag model not significantly below it): 1.29 x (measured)
@pytest.mark.parametrize("name", ["planted", "same"])
def test_held_out_run_to_the_noise_floor(scenario, name):
    sc = scenario(name)
    train, held = _split(sc["runs"])
    got = _held_out_errors(sc)
    floor = M.errors(held, M.true_model_prediction(train, held))
    assert sc["doc"]["channels"]["x"]["rms_after_um"] == pytest.approx(got["rms"], rel=1e-5)
    assert got["rms"] <= FLOOR_FACTOR * floor["rms"], (got, floor, _chosen(sc["doc"]))


@pytest.mark.parametrize("name", ["planted", "same"])
def test_no_worse_than_the_static_regression(scenario, name):
    sc = scenario(name)
    train, held = _split(sc["runs"])
    got = _held_out_errors(sc)
    static = M.errors(held, M.static_prediction(train, held))
    assert got["mae"] <= STATIC_FACTOR * static["mae"], (got, static, _chosen(sc["doc"]))
    assert got["rms"] <= STATIC_FACTOR * static["rms"], (got, static, _chosen(sc["doc"]))
    assert sc["doc"]["channels"]["x"]["mae_static_um"] == pytest.approx(static["mae"],
                                                                        rel=0.01)


def test_no_planted_effect_no_effect(scenario):
    sc = scenario("none")
    assert sc["doc"]["effects"] == [], _chosen(sc["doc"])
    got = _held_out_errors(sc)
    # the declared model (the run's first reading) is the truth here: nothing to gain
    assert got["rms"] <= 1.05 * sc["doc"]["channels"]["x"]["rms_before_um"] + 1e-9


def test_sampling_60_s_gives_the_same_answer(scenario):
    fast, slow = scenario("planted"), scenario("planted60")
    e15, e60 = _held_out_errors(fast), _held_out_errors(slow)
    assert abs(e60["mae"] / e15["mae"] - 1) <= SAMPLING_REL, (e15, e60)
    train15, _ = _split(fast["runs"])
    train60, _ = _split(slow["runs"])
    d15 = M.dominant_covariate(train15, fast["doc"]["effects"])
    d60 = M.dominant_covariate(train60, slow["doc"]["effects"])
    assert d15 is not None and d15 == d60, (d15, d60, _chosen(fast["doc"]),
                                            _chosen(slow["doc"]))
