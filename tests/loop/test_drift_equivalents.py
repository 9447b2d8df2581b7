"""The CV-equivalent alternatives of a drift term (issue 44, :mod:`volerr.loop.drift.select`):
a candidate the blocked cross-validation cannot tell from the chosen term in its place (the
chosen term's block mean squares not significantly below the candidate's, the paired t of
:func:`volerr.selection.rules.significantly_below` over the sub-blocks of every fold, the
rule :mod:`volerr.loop.drift.family` judges the families by) is named beside it.

Checked here on small simulated series (a few seconds):

* the block mean squares the engine computes from cross-products are those of refitting the
  model on the other folds and predicting every block (:func:`volerr.loop.drift.family.
  cv_residuals`, :func:`~volerr.loop.drift.family.block_mse`): for the model alone and with
  a candidate added, for folds of stretches and of whole runs;
* two sensors reading the same temperature (0.005 K noise each) are named as alternatives
  of each other; a sensor that carries nothing of the drift is not; every alternative, by
  refitting here, has a CV RMS within 1 % of the chosen term's or a paired t below the
  one-sided 95 % Student quantile (scipy's), the t the JSON reports; the chosen term's span
  of equivalent time constants holds its own.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from helpers.drift_sim import lag
from volerr.loop.drift import basis, family
from volerr.loop.drift import fit as core
from volerr.loop.drift.engine import Engine
from volerr.loop.drift.series import DriftSeries

DT = 60.0


def _series(n_runs: int = 1, seed: int = 11) -> DriftSeries:
    """A channel following a 40 min lag of a bearing temperature read by two sensors
    ``T_a`` and ``T_b`` (each with 0.005 K noise of its own; the channel 0.3 um); ``T_c`` a
    wandering sensor that carries nothing of the drift.  No speed is logged (no heat
    input): the first term is chosen beside the run zeros alone, where its alternatives are
    scored."""
    rng = np.random.default_rng(seed)
    hours = 20.0 / n_runs
    t1 = np.arange(0.0, hours * 3600.0, DT)
    t = np.concatenate([t1] * n_runs)
    run = np.repeat(np.arange(n_runs), len(t1))
    on = ((t1 // 5400.0) % 2 == 1).astype(float) * (1 + (t1 // 10800.0) % 3)
    T = np.concatenate([20.0 + 6.0 * lag(on / 3, 1500.0, DT)] * n_runs)
    Ta = T + rng.normal(0, 0.005, len(t))       # two sensors reading the same temperature
    Tb = T + rng.normal(0, 0.005, len(t))
    Tc = 20.0 + np.cumsum(rng.normal(0, 0.02, len(t)))
    y = np.zeros(len(t))
    for r in range(n_runs):
        m = run == r
        y[m] = 2.5 * lag(T[m] - T[m][0], 2400.0, DT)
    y = y + rng.normal(0, 0.3, len(t))
    s = DriftSeries(t_s=t, run=run, runs=[("sim.csv", str(r)) for r in range(n_runs)],
                    inputs={"T_a": Ta, "T_b": Tb, "T_c": Tc}, channels={"x": y},
                    directions={"x": "?"}, heights={"x": None})
    s.test = np.zeros(len(t), bool)
    for r in range(n_runs):
        m = run == r
        s.test[m] = t[m] >= 0.8 * t[m].max()
    return s


@pytest.mark.parametrize("n_runs,rule", [(1, "stretches"), (4, "runs")])
def test_block_mean_squares_are_those_of_refitting(n_runs, rule):
    s = _series(n_runs)
    cols, X = basis.library(s)
    fold, got_rule = basis.folds(s)
    assert got_rule == rule
    R = s.indicators()
    Z = np.column_stack([R, X])
    ch = core.Channel(s, s.channels["x"], R, fold, rule)
    eng = Engine(Z, ch.y, fold, basis.whole_runs(rule), s.run, n_runs)
    j1, j2 = n_runs + 5, n_runs + 20          # two basis columns (a sensor's lags)
    W = np.eye(Z.shape[1])[:, list(range(n_runs)) + [j1]]
    blocks, base = eng.cv_blocks(W, np.array([[j2, -1], [j2, j1]]), family.SUB_BLOCKS)
    D0 = Z[:, list(range(n_runs)) + [j1]]
    want0 = family.block_mse(fold, family.cv_residuals(ch, D0))
    np.testing.assert_allclose(base, want0, rtol=1e-7)
    want1 = family.block_mse(fold, family.cv_residuals(ch, np.column_stack([D0, Z[:, j2]])))
    np.testing.assert_allclose(blocks[0], want1, rtol=1e-7)
    diff = np.column_stack([D0, Z[:, j2] - Z[:, j1]])
    np.testing.assert_allclose(blocks[1], family.block_mse(fold, family.cv_residuals(ch, diff)),
                               rtol=1e-7)


def test_a_twin_sensor_is_named_and_a_stranger_is_not():
    s = _series()
    out = core.run_drift(s)["channels"]["x"]
    terms = out["terms"]
    assert terms, "the lag of T_a (or its twin) must be found"
    first = terms[0]
    assert first["source"] in ("T_a", "T_b")
    twin = "T_b" if first["source"] == "T_a" else "T_a"
    named = {a["covariate"] for a in first["alternatives"]}
    assert twin in named, first["alternatives"]
    assert "T_c" not in named
    lo, hi = first["tau_equivalent_s"]
    assert lo <= first["tau_s"] * 1.5 and hi >= first["tau_s"] / 1.5


def test_every_alternative_is_one_the_cv_cannot_tell_apart_by_refitting():
    """The chosen first term against each named alternative, both alone beside the run's
    zero: by refitting here, the alternative's CV RMS is within 1 % of the chosen one's or
    the paired t over the blocks of (alternative's - chosen's) CV mean square is below
    Student's one-sided 95 % quantile (scipy's); the reported paired t is that t."""
    s = _series()
    fold, rule = basis.folds(s)
    R = s.indicators()
    ch = core.Channel(s, s.channels["x"], R, fold, rule)
    out = core.run_drift(s)["channels"]["x"]
    sel = out["terms"][0]

    def resid(source, tau):
        col = basis.series(s, source, tau or 0.0)
        return family.cv_residuals(ch, np.column_stack([R, col]))

    # the first term as chosen on the grid: its alternatives were scored against it there
    grid = basis.tau_grid(s)
    tau0 = float(grid[np.argmin(np.abs(np.log(grid / sel["tau_s"])))]) if sel["tau_s"] else 0
    r0 = resid(sel["source"], tau0)
    rms0 = np.sqrt(np.nanmean(r0 ** 2))
    assert sel["cv_rms_um"] == pytest.approx(rms0, rel=1e-6)
    assert sel["alternatives"]
    for a in sel["alternatives"]:
        r = resid(a["covariate"], a["lag_s"])
        d = family.block_mse(fold, r) - family.block_mse(fold, r0)
        t = d.mean() / (d.std(ddof=1) / np.sqrt(len(d)))
        same = np.sqrt(np.nanmean(r ** 2)) <= rms0 * 1.01
        assert same or t < stats.t.ppf(0.95, len(d) - 1), (a, t)
        assert t == pytest.approx(a["paired_t"], abs=2e-3)
