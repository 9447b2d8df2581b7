"""Alternatives the cross-validation cannot tell apart, beyond a term's rivals in its place
(issue 44, done-when 2): a term the CV cannot tell from its *absence*
(:func:`volerr.loop.drift.family.without_each`, ``"cv_decided"``) and the model families it
cannot tell from the reported one (:func:`volerr.loop.drift.family.equivalent_families`,
``"families_equivalent"``).  Both by the rule the families are chosen by: the paired t over
the blocks of every blocked-CV fold, one-sided 95 % Student quantile.

Checked on a small simulated series (the one of ``test_drift_family.py``'s kind, built here):
a lag of the heat input the channel follows is decided, a column of white noise (drawn here,
independent of the channel) is not; the paired t is recomputed here from CV residuals refitted
per fold with ``numpy.linalg.lstsq`` and blocks cut with ``numpy.array_split`` and the t by
``scipy.stats.ttest_rel`` (independent of the engine); the families' equivalence on mean
squares constructed here.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from helpers.drift_sim import lag
from volerr.loop.drift import basis, family
from volerr.loop.drift import fit as core
from volerr.loop.drift.series import DriftSeries

DT = 60.0
TAU = 3000.0
SUB = 8                      # blocks per fold (family.SUB_BLOCKS, stated by the docs)


def _channel():
    rng = np.random.default_rng(44)
    t = np.arange(0.0, 24 * 3600.0, DT)
    S = 2000.0 * ((t // 7200.0) % 2 == 1) * (1 + (t // 14400.0) % 3)
    heat = lag(S / S.max(), TAU, DT)
    y = 12.0 * heat + rng.normal(0, 0.3, len(t))
    s = DriftSeries(t_s=t, run=np.zeros(len(t), int), runs=[("sim.csv", "")],
                    inputs={"S_rpm": S, "T_a": 20 + 5 * lag(S / S.max(), 600.0, DT)},
                    channels={"x": y}, directions={"x": "?"}, heights={"x": None})
    s.test = t >= 0.8 * t[-1]
    fold, rule = basis.folds(s)
    ch = core.Channel(s, y, s.indicators(), fold, rule)
    noise = rng.normal(0, 1.0, len(t))
    return ch, np.column_stack([ch.R, heat, noise])


def _block_mse_here(ch, D):
    """Per fold refitted on the other training folds (lstsq), 8 blocks of every fold."""
    out = []
    for k in range(int(ch.fold.max()) + 1):
        m, o = ch.fold == k, (ch.fold >= 0) & (ch.fold != k)
        b = np.linalg.lstsq(D[o], ch.y[o], rcond=None)[0]
        r = ch.y - D @ b
        out += [float(np.mean(r[p] ** 2)) for p in np.array_split(np.flatnonzero(m), SUB)]
    return np.array(out)


def test_a_real_term_is_decided_a_noise_column_is_not():
    ch, D = _channel()
    got = family.without_each(ch, D)
    assert [g["cv_decided"] for g in got] == [True, False]
    full = _block_mse_here(ch, D)
    for j, g in zip((ch.n_runs, ch.n_runs + 1), got):
        without = _block_mse_here(ch, np.delete(D, j, axis=1))
        t = stats.ttest_rel(without, full).statistic
        assert g["cv_without"]["paired_t"] == pytest.approx(t, abs=2e-3)
        # far from the critical value (1.645-1.68 for 47 df): the verdict is no borderline
        assert (t > 2 * stats.t.ppf(0.95, len(full) - 1)) if g["cv_decided"] else (t < 1.6)


def test_families_the_cv_cannot_tell_apart():
    rng = np.random.default_rng(7)
    static = rng.uniform(1.0, 2.0, 48)
    mse = {"static": static,
           "constant": static * np.tile([0.9, 1.1], 24),       # no consistent difference
           "lag": static * 1.5,                                 # consistently worse
           "regularised": static * 0.6}                         # consistently better
    rms = {k: float(np.sqrt(v.mean())) for k, v in mse.items()}
    t_const = stats.ttest_rel(mse["constant"], static).statistic
    assert abs(t_const) < 1.0                               # the construction holds
    got = family.equivalent_families(mse, rms, "static", has_terms=True)
    assert [g["family"] for g in got] == ["constant"]
    assert got[0]["paired_t"] == pytest.approx(t_const, abs=2e-3)
    # the lag model equal to the static regression but without terms: it is the constant
    # a lag model no better than the static regression is listed, lowest CV RMS first;
    # without terms it is the constant and is not
    mse["lag"] = static * np.tile([1.12, 0.9], 24)
    rms["lag"] = float(np.sqrt(mse["lag"].mean()))
    got = family.equivalent_families(mse, rms, "static", True)
    want = sorted(["constant", "lag"], key=lambda f: rms[f])
    assert [g["family"] for g in got] == want
    assert [g["family"] for g in family.equivalent_families(mse, rms, "static", False)] == \
        ["constant"]
