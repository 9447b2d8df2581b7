"""The drift-run simulator of the loop's acceptance tests (tests/helpers/drift_sim.py) checked on
its own: its lag is the exact first-order response, its runs read as drift files, and its
campaigns make the planted sensor and time constant the only explanation of the readings (every
other single sensor, and the heat input S^p, at its best lag predicts the held-out run at least
3 times worse than the truth), so a loop can name them."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import drift_sim as D
from helpers.drift_sim import CASES, SPECS, campaign


def test_lag_is_the_exact_first_order_response():
    t = np.arange(0, 3600.0, 5.0)
    y = D.lag(np.r_[0.0, np.ones(len(t) - 1)], 600.0, 5.0)     # a step just after the start
    # linear from 0 to 1 over the first 5 s, then constant: the exact solution
    tau, h = 600.0, 5.0
    ramp_end = 1 - tau / h * (1 - np.exp(-h / tau))
    want = 1 - (1 - ramp_end) * np.exp(-(t - h) / tau)
    np.testing.assert_allclose(y[1:], want[1:], atol=1e-12)
    ramp = 0.01 * t                    # at rest, then u - s tau (1 - exp(-t / tau)) exactly
    np.testing.assert_allclose(D.lag(ramp, 300.0, 5.0),
                               ramp - 0.01 * 300.0 * (1 - np.exp(-t / 300.0)), atol=1e-12)
    np.testing.assert_allclose(D.lag_irregular(ramp, 300.0, t), D.lag(ramp, 300.0, 5.0),
                               atol=1e-12)


def test_runs_read_as_drift_files(tmp_path):
    from volerr.instruments import drift

    runs = campaign(CASES["fast"], tmp_path)
    r = drift.read_runs(tmp_path / "run1.csv")[0]
    assert r.directions == {"x": "X"} and set(r.inputs) == {"S_rpm", *D.SENSORS}
    np.testing.assert_allclose(r.channels["x"], runs[0]["d_x_um"], atol=1e-6)


@pytest.mark.parametrize("case", ["fast", "slow"])
def test_planted_sensor_is_the_only_explanation(case, tmp_path):
    planted = CASES[case]
    runs = campaign(planted, tmp_path)
    floor = D.true_mae(runs[2], planted)
    assert floor < 1.0 * D.D_NOISE_UM                # the floor is the noise
    truth = D.fit_single(runs[:2], runs[2], planted.sensor, planted.tau_s)
    assert truth <= 1.05 * floor
    taus = np.geomspace(60.0, 30000.0, 24)
    others = [(c, None) for c in D.SENSORS if c != planted.sensor] + [
        ("S_rpm", p) for p in (1.0, 1.5, 2.0)]
    for col, power in others:
        best = min(D.fit_single(runs[:2], runs[2], col, tau, power) for tau in taus)
        assert best >= 3.0 * floor, (col, power, best / floor)
    assert len(SPECS) == 3
