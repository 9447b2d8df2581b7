"""The baselines as candidates of the drift loop's selection (issue 44,
:mod:`volerr.loop.drift.family`), on small series built here (a few seconds in all):

* the rule of :func:`volerr.selection.rules.significantly_below`: its critical values are
  Student's (scipy's quantile, an independent source), a consistent gain passes, a gain of
  one lucky block among losses does not;
* the blocked-CV residuals the families are scored by are the SAME cross-validation the lag
  selection uses: their sum of squares is the engine's cross-validated SSE (computed by the
  engine from cross-products, here by refitting per fold);
* a channel that is a constant plus noise while a sensor wanders reports the constant, a
  channel that follows a lag of the heat input (its sensor a faster lag of it) reports the
  lag model, a channel following two temperatures statically reports the static regression
  (the lag model found is not significantly better); the interval's coverage and half-width
  are recomputed here.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from volerr.loop.drift import basis, family
from volerr.loop.drift import interval as band
from volerr.loop.drift import fit as core
from volerr.loop.drift.engine import Engine
from volerr.loop.drift.series import DriftSeries
from volerr.selection.rules import significantly_below, t95

DT = 60.0
HOURS = 24.0
TAU = 3000.0


def _first_order(u, tau, dt):
    """Implicit-Euler first-order lag of ``u`` (at rest at the start): the tests' own."""
    y = np.zeros_like(u)
    a = dt / (tau + dt)
    for i in range(1, len(u)):
        y[i] = y[i - 1] + a * (u[i] - y[i - 1])
    return y


def _series(channel: str, seed: int = 3) -> DriftSeries:
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, HOURS * 3600.0, DT)
    on = ((t // 7200.0) % 2 == 1).astype(float) * (1 + (t // 14400.0) % 3)   # 3 speeds
    S = 2000.0 * on
    heat = _first_order(S / S.max(), TAU, DT)
    room = 20.0 + 0.5 * np.sin(2 * np.pi * t / 40000.0)
    wander = 20.0 + np.cumsum(rng.normal(0, 0.02, len(t)))
    T_a = room + 5.0 * _first_order(S / S.max(), 600.0, DT) + rng.normal(0, 0.01, len(t))
    noise = rng.normal(0, 0.3, len(t))
    y = {"noise": 2.0 + noise,
         "lag": 12.0 * heat + noise,
         "static": 1.5 * (room - room[0]) + 0.8 * (wander - wander[0]) + noise}[channel]
    s = DriftSeries(t_s=t, run=np.zeros(len(t), int), runs=[("sim.csv", "")],
                    inputs={"S_rpm": S, "T_room": room + rng.normal(0, 0.01, len(t)),
                            "T_a": T_a, "T_w": wander}, channels={"x": y},
                    directions={"x": "?"}, heights={"x": None})
    s.test = t >= 0.8 * t[-1]
    return s


def test_critical_values_are_students():
    for df in (1, 2, 5, 10, 29, 30):
        assert t95(df) == pytest.approx(stats.t.ppf(0.95, df), abs=2e-3)
    assert t95(200) == pytest.approx(stats.norm.ppf(0.95), abs=1e-3)


def test_consistent_gain_passes_a_lucky_block_does_not():
    old = np.array([4.0, 5.0, 6.0, 5.0, 4.5, 5.5])
    assert significantly_below(old * 0.7, old)
    lucky = old.copy()
    lucky[0] = 0.1                       # one block far better ...
    worse = old * 1.05
    worse[0] = 0.1                       # ... the others all a little worse
    assert worse.mean() < old.mean() and not significantly_below(worse, old)
    assert not significantly_below(old, old)


def _channel(s):
    cols, X = basis.library(s)
    fold, rule = basis.folds(s)
    R = s.indicators()
    return core.Channel(s, s.channels["x"], R, fold, rule), np.column_stack([R, X])


def test_the_families_are_scored_by_the_same_blocked_cv():
    s = _series("lag")
    ch, Z = _channel(s)
    D = np.column_stack([ch.R, Z[:, ch.n_runs + 3], Z[:, ch.n_runs + 20]])
    r = family.cv_residuals(ch, D)
    eng = Engine(D, ch.y, ch.fold, ch.rule == "runs", s.run, ch.n_runs)
    sse = eng.cv_sse(np.eye(D.shape[1]))
    assert np.isnan(r[s.test]).all()
    assert float(np.sum(r[s.train] ** 2)) == pytest.approx(sse, rel=1e-8)


@pytest.mark.parametrize("name,want", [("noise", {"constant"}), ("lag", {"lag"}),
                                       ("static", {"static"})])
def test_the_channel_reports_the_family_its_cv_supports(name, want):
    s = _series(name)
    out = core.run_drift(s)["channels"]["x"]
    c = out["choice"]
    assert c["family"] in want, (c["family"], c["cv_rms_um"], c["t"])
    if c["family"] == "lag":      # the lag model beat both baselines: its CV RMS is lower
        assert c["cv_rms_um"]["lag"] < min(c["cv_rms_um"]["static"], c["cv_rms_um"]["constant"])
    pred = out["constant"] if c["family"] == "constant" else (
        out["static"] if c["family"] == "static" else None)
    if pred is not None:          # a baseline is the model: its prediction is the baseline's
        y = s.channels["x"]
        fold, _ = basis.folds(s)
        iv = band.interval(c["cv_resid"], y, pred, fold, s.test)    # no leverage: one width
        e = np.abs(y - pred)[s.test]
        assert iv["coverage_test"] == pytest.approx(np.mean(e <= iv["half_width_um"]))
        ln = np.log([np.quantile(np.abs(c["cv_resid"][fold == k]), 0.95)
                     for k in sorted(set(fold[fold >= 0]))])
        K = len(ln)         # one more fold's 95 % quantile: log-normal, Student bound
        q = np.exp(ln.mean() + stats.t.ppf(0.95, K - 1) * ln.std(ddof=1) * np.sqrt(1 + 1 / K))
        assert iv["half_width_um"] == pytest.approx(q, rel=1e-3)
