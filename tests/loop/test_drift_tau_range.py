"""The profile range of a fitted time constant (``lag_s.range_k2``,
:mod:`volerr.loop.drift.tau_range`; issue 44 done-when 2): on a simulated run where the
blocked jackknife's tau +- 2 u misses a planted time constant, the profile range holds it;
and the range is an addition only (every other number of the JSON as without it).

The run (written here, fixed seed): one run of 24 h at 15 s, the spindle stepping between
speeds at random (0.5-3 h a step), the displacement d = 6 lag(q, 1020 s) + 14 lag(q,
9720 s) + 0.05 um noise with q = (S / 6000 rpm)^1.5 (the speed-only variant of the issue's
independent tester, benchmarks/acceptance/issue44_independent/a44_scen1.py), two room
sensors that do not explain it; the last 20 % of the time held out.  Measured on it (seed 1):
the first heat term's tau 2998 s, jackknife u 153 s (tau +- 2 u: 2693-3303 s), profile
range 971-15159 s, which holds both planted time constants.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from volerr.loop.drift import tau_range
from volerr.loop.drift.run import loop_drift
from volerr.machine.lags import lag

PLANTED = (1020.0, 9720.0)      # s


def _run_file(path, seed=1, hours=24.0, dt=15.0) -> float:
    """Write the run of the module docstring; its last time (s)."""
    rng = np.random.default_rng(seed)
    n = int(hours * 3600 / dt) + 1
    t = dt * np.arange(n)
    S = np.zeros(n)
    k, last = 120, 0
    while k < n:
        m = int(rng.uniform(0.5, 3.0) * 3600 / dt)
        last = rng.choice([v for v in (1500, 3000, 4500, 6000) if v != last])
        S[k:k + m] = last
        k += m
    q = (S / 6000.0) ** 1.5
    room = 0.6 * np.sin(2 * np.pi * t / 86400 + 1.0)
    d = 6 * lag(q, 1020.0, t) + 14 * lag(q, 9720.0, t) + 0.05 * rng.standard_normal(n)
    T1 = 21 + 0.5 * room + np.cumsum(rng.standard_normal(n)) * 0.004
    T2 = 21 - 0.8 * room + 0.02 * rng.standard_normal(n)
    np.savetxt(path, np.column_stack([t, S, T1, T2, d]), delimiter=",",
               header="t_s,S_rpm,T_x1,T_x2,d_x_um", comments="", fmt="%.6f")
    return float(t[-1])


def _loop(tmp_path):
    path = tmp_path / "run.csv"
    span = _run_file(path)
    return loop_drift("DMU50", [path], window=f"{0.8 * span:g}s:")


def _heat_lags(rep) -> list:
    return [t["lag_s"] for e in rep["effects"] for t in e["terms"]
            if t["lag_s"] and e["covariate"] == "S_rpm"]


def test_planted_tau_inside_the_range_where_the_jackknife_misses_it(tmp_path):
    lags = _heat_lags(_loop(tmp_path))
    assert lags, "the loop names no lag of the heat input"
    first = lags[0]
    lo, hi = first["range_k2"]
    assert lo is not None and hi is not None
    for tau in PLANTED:
        assert lo <= tau <= hi
        assert abs(tau - first["value"]) > 2 * first["std"]   # outside tau +- 2 u


def test_range_is_an_addition_only(tmp_path, monkeypatch):
    with_range = _loop(tmp_path).data
    monkeypatch.setattr(tau_range, "ranges", lambda ch, specs, fit: None)
    without = _loop(tmp_path).data
    seen = []

    def strip(o):
        if isinstance(o, dict):
            if "range_k2" in o:
                seen.append(o.pop("range_k2"))
            for v in o.values():
                strip(v)
        elif isinstance(o, list):
            for v in o:
                strip(v)
    strip(with_range)
    assert seen                              # the feature was on in the first run
    assert json.dumps(with_range, sort_keys=True, default=str) == \
        json.dumps(without, sort_keys=True, default=str)


@pytest.mark.parametrize("step,uneven", [(1, False), (3, False), (3, True)])
def test_lag_of_several_taus_is_the_lag_of_each_tau(step, uneven):
    """:func:`volerr.machine.lags.lag` at several time constants at once (the profile's
    trial columns) equals it one tau at a time (two runs, a held-out stretch in the first;
    evenly sampled: the batched path, not: one tau at a time)."""
    rng = np.random.default_rng(3)
    t = np.r_[10.0 * np.arange(900), 10.0 * np.arange(600)]
    if uneven:
        t[900:] = np.cumsum(rng.uniform(5.0, 15.0, 600))
    run = np.r_[np.zeros(900, int), np.ones(600, int)]
    u = np.cumsum(rng.standard_normal(len(t)))
    idx = np.flatnonzero(~((t > 3000) & (t < 5000) & (run == 0)))
    rows = np.concatenate([idx[run[idx] == r][::step] for r in (0, 1)])
    taus = np.geomspace(40.0, 40000.0, 17)
    got = lag(u, taus, t, run, rows=rows, step=step)
    assert got.shape == (len(rows), len(taus))
    for j, tau in enumerate(taus):
        want = lag(u, tau, t, run)[rows]
        np.testing.assert_allclose(got[:, j], want, rtol=0, atol=1e-9 * np.abs(want).max())


@pytest.mark.parametrize("rng,value,words", [
    ([900.0, 1100.0], 1000.0, ", range 900 .. 1100 s"),
    ([900.0, 1100.0], 11501.0, "(not this fit's tau"),
    ([None, 1100.0], 1000.0, ", range below 1100 s"),
    ([900.0, None], 800.0, "(not this fit's tau"),
    ([None, None], 5.0, ", range not determined by these runs")])
def test_the_console_says_when_the_range_does_not_hold_the_reported_tau(rng, value, words):
    """The range lies where the least RSS is with the other time constants free, the
    reported tau is the cross-validation's choice: where the range does not hold it the line
    says so instead of printing a range beside a value outside it without a word."""
    from volerr.loop.drift.report import _range_text

    text = _range_text({"value": value, "std": None, "range_k2": rng})
    assert words in text, text
    assert ("not this fit's tau" in text) == (words == "(not this fit's tau"), text
