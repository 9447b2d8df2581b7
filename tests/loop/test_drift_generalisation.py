"""Does the loop's drift model of the FL_THERMAL spindle test generalise to OTHER held-out
windows than the published one?  (An independent acceptance test: the loop judged against
the shop's usual model, computed here, and not against its own report only.)

Data: runtime/data/fl_thermal_spindle.csv (the real 46.3 h spindle test, 11 115 readings every
15 s, t = 0 .. 166 710 s, 16 temperatures, 5 channels of unknown direction; README in
/work/shared/data/thermal/).  Each window below is held out of the WHOLE file with
``volerr loop DMU50 drift:FILE --holdout-time A:B`` (training: every reading outside the
window, before and after it), run once per window (tests/helpers/fl_runs.py, shared with
test_drift_sampling.py; one xdist group for every window so the tests share the runs):

=========  ==================  =====================================================
window     A:B (s)             what the training part has not seen
=========  ==================  =====================================================
0-20 %     0 : 33345           the run's start: the 1250 rpm run and its cool-down
                               (training after it only: every lag starts at rest)
20-40 %    33345 : 66690       the 2500 rpm cool-down and the 3750 rpm run (most of it)
40-60 %    66690 : 100035      the 3750 rpm cool-down and the 5000 rpm run (the fastest;
                               only its last 20 min, 100035 .. 101268 s, are in training)
60-80 %    100035 : 133380     the published test window (5000 rpm cool-down, 3500 rpm)
80-100 %   133380 :            the variable-speed block 500/1500/2500/4500 rpm
=========  ==================  =====================================================

Criteria a metrologist would accept (per channel, on the held-out readings):

* the loop's MAE (recomputed here from ``--predictions-out`` against the data file's own
  values) is not worse than the STATIC multiple linear regression on all sixteen
  temperatures (their change since the run's start plus a constant), fitted here with
  ``numpy.linalg.lstsq`` on the same training readings:
  ``mae_loop <= STATIC_FACTOR * mae_static + STATIC_SLACK_UM`` -- a model with lags, heat
  input and cross-validated choices that predicts a new stretch of the run worse than a plain
  regression on the same temperatures has learnt the training part, not the machine;
* on the 60-80 % window (the publication's), trained here on everything else, every channel
  stays below the best published MAE (seq2seq with attention).

Issue 44: the model each channel reports (the lag model, or the better baseline where the
lag model's blocked-CV error is not significantly below both baselines') is not worse than
the better of the static regression and a constant (the training readings' mean), both
computed here: ``mae_loop <= STATIC_FACTOR * min(static, constant) + STATIC_SLACK_UM``; the
JSON's baselines are those computed here, and its prediction interval's held-out coverage is
the share of held-out readings of the predictions file within its half-width.

The loop's own ``mae_static_um`` must also agree with the regression computed here (it is
the same model by INTERFACE.md's description), so that its console's comparison can be
trusted.
"""

from __future__ import annotations

import csv
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from helpers import fl_runs

CHANNELS = ("ch1", "ch2", "ch3", "ch4", "ch5")
PUBLISHED_MAE_UM = {"ch1": 3.561, "ch2": 3.755, "ch3": 3.704, "ch4": 3.461, "ch5": 4.284}
STATIC_FACTOR = 1.05
STATIC_SLACK_UM = 0.2
#: the loop's own static figure vs the regression computed here (same model, other solver)
STATIC_AGREE_REL = 0.01

#: window name -> (A, B) seconds (B None: open end), as ``--holdout-time`` reads it
WINDOWS = {"0-20": (0.0, 33345.0), "20-40": (33345.0, 66690.0), "40-60": (66690.0, 100035.0),
           "60-80": (100035.0, 133380.0), "80-100": (133380.0, None)}

#: measured on a shared 2-core machine (load ~4), one loop run each: 20-40 % 27 s,
#: 40-60 % 14 s, 60-80 % 15 s, 80-100 % 32 s (the training part on both sides of the
#: window: a longer span, a longer grid of time constants)
SLOW_WINDOWS = ("20-40", "80-100")


def _data() -> Path:
    return Path(str(resources.files("volerr") / "data" / "fl_thermal_spindle.csv"))


def _read_table(path: Path) -> dict:
    """The drift file's columns {name: (N,) float} (header lines ``#`` skipped)."""
    with open(path, newline="") as fh:
        rows = [r for r in csv.reader(ln for ln in fh if not ln.startswith("#"))]
    head, body = rows[0], np.array(rows[1:], float)
    return {h: body[:, j] for j, h in enumerate(head)}


@pytest.fixture(scope="module")
def table():
    return _read_table(_data())


def _window_arg(a, b) -> str:
    return f"{a:g}s:" + ("" if b is None else f"{b:g}s")


@pytest.fixture(scope="module")
def loop_runs():
    """window -> (JSON, predictions rows): ``volerr loop DMU50 drift:FILE --holdout-time A:B
    --json --predictions-out`` on the shipped file, run once per process for every test
    file that asks for it (tests/helpers/fl_runs.py: in-process, one BLAS thread; the same
    bytes as a ``python -m volerr`` process writes)."""

    def get(name: str):
        assert fl_runs.WINDOWS[name] == (_window_arg(*WINDOWS[name]), None)   # same run
        run = fl_runs.loop_run(1, name)
        assert run.returncode == 0, run.stderr
        assert run.input == _data()
        return run.doc, run.rows

    return get


def _mask(t, name):
    a, b = WINDOWS[name]
    return (t >= a) & (t < (np.inf if b is None else b))


def static_regression_mae(table: dict, channel: str, name: str) -> float:
    """MAE on the window of the static multiple linear regression on all temperatures'
    change since the run's start plus a constant, least squares on the readings outside it."""
    t = table["t_s"]
    test = _mask(t, name)
    temps = sorted((k for k in table if k.startswith("T_")), key=lambda k: int(k[2:]))
    assert len(temps) == 16
    X = np.column_stack([np.ones(len(t))] + [table[k] - table[k][0] for k in temps])
    y = table[f"d_{channel}_um"]
    coef, *_ = np.linalg.lstsq(X[~test], y[~test], rcond=None)
    return float(np.mean(np.abs(y[test] - X[test] @ coef)))


def loop_mae(table: dict, rows: list, channel: str, name: str) -> float:
    """The loop's held-out MAE from its predictions file, against the data file's values."""
    test = [r for r in rows if r["channel"] == channel and r["split"] == "test"]
    t = np.array([float(r["t_s"]) for r in test])
    expected_t = table["t_s"][_mask(table["t_s"], name)]
    np.testing.assert_array_equal(np.sort(t), expected_t)       # exactly the window held out
    measured = np.interp(t, table["t_s"], table[f"d_{channel}_um"])
    after = np.array([float(r["after_um"]) for r in test])
    return float(np.mean(np.abs(measured - after)))


def _param(name):
    """A window as a parameter: its tests in one xdist group (they share its loop run); the
    windows whose run takes longest (measured, see SLOW_WINDOWS) marked slow as well."""
    marks = [pytest.mark.xdist_group(fl_runs.GROUP)]
    if name in SLOW_WINDOWS:
        marks.append(pytest.mark.slow)
    return pytest.param(name, id=name, marks=marks)


#: channel-windows where the loop is known to lose to the static regression (issue 35 left
#: open on them; measured on the lead's branch: ch5 40-60 % 4.44 vs 2.91 um, ch5 60-80 %
#: 7.58 vs 2.32 um: a heat input at p = 0.5 with two lags, its sensor terms dropped as not
#: significant one by one; ch2 80-100 % 3.41 vs 3.04 um).  Issue 44 (the baselines as
#: candidates of the same blocked CV) reports the static regression on ch5 60-80 % (2.32 um);
#: on the two left the blocked CV itself prefers the lag model significantly (its pooled CV
#: mean square far below both baselines'), so no choice among the three families fixes them
#: (measured: ch5 40-60 % 4.45 vs 2.91 um, ch2 80-100 % 3.41 vs a constant's 2.32 um).
#: Strict: a fix makes the test fail until this list is updated.
#: Issue 44 item 1 (a fourth candidate, the regularised fit over the lag bank): 80-100 % ch2
#: 1.81 um (the regularised fit); 40-60 % ch5 stays (the lag model is significantly below the
#: regularised fit there too: 4.44 um).
KNOWN_GAPS = {("40-60", "ch5"): True}


def _pair(name, channel):
    p = _param(name)
    marks = list(p.marks)
    if (name, channel) in KNOWN_GAPS:
        marks.append(pytest.mark.xfail(reason="issue 35: known gap, see KNOWN_GAPS",
                                       strict=KNOWN_GAPS[(name, channel)]))
    return pytest.param(name, channel, id=f"{channel}-{name}", marks=marks)


@pytest.mark.parametrize("name,channel", [_pair(n, c) for n in WINDOWS for c in CHANNELS])
def test_no_worse_than_static_regression_on_all_temperatures(loop_runs, table, name, channel):
    doc, rows = loop_runs(name)
    mine = loop_mae(table, rows, channel, name)
    static = static_regression_mae(table, channel, name)
    assert doc["channels"][channel]["mae_after_um"] == pytest.approx(mine, rel=1e-6)
    chosen = [t["basis"] for e in doc["effects"] if e["channels"] == [channel]
              for t in e["terms"]]
    assert mine <= STATIC_FACTOR * static + STATIC_SLACK_UM, (
        f"window {name} %, {channel}: loop MAE {mine:.3f} um > {STATIC_FACTOR} x static "
        f"regression {static:.3f} um + {STATIC_SLACK_UM} um; the loop chose {chosen}")


@pytest.mark.parametrize("name", [_param(n) for n in WINDOWS])
def test_the_reported_static_regression_is_the_one_computed_here(loop_runs, table, name):
    doc, _ = loop_runs(name)
    for ch in CHANNELS:
        static = static_regression_mae(table, ch, name)
        assert doc["channels"][ch]["mae_static_um"] == pytest.approx(
            static, rel=STATIC_AGREE_REL), (name, ch)


@pytest.mark.parametrize("channel", CHANNELS)
@pytest.mark.xdist_group(fl_runs.GROUP)
def test_published_window_trained_on_the_rest_beats_the_published_best(loop_runs, table,
                                                                      channel):
    _, rows = loop_runs("60-80")
    mae = loop_mae(table, rows, channel, "60-80")
    assert mae < PUBLISHED_MAE_UM[channel], (channel, mae, PUBLISHED_MAE_UM[channel])


def constant_mae(table: dict, channel: str, name: str) -> float:
    """MAE on the window of a constant: the mean of the readings outside it."""
    test = _mask(table["t_s"], name)
    y = table[f"d_{channel}_um"]
    return float(np.mean(np.abs(y[test] - y[~test].mean())))


@pytest.mark.parametrize("name,channel", [_pair(n, c) for n in WINDOWS for c in CHANNELS])
def test_never_worse_than_the_better_baseline(loop_runs, table, name, channel):
    doc, rows = loop_runs(name)
    c = doc["channels"][channel]
    static = static_regression_mae(table, channel, name)
    const = constant_mae(table, channel, name)
    assert c["baselines"]["static"]["mae_um"] == pytest.approx(static, rel=STATIC_AGREE_REL)
    assert c["baselines"]["constant"]["mae_um"] == pytest.approx(const, rel=1e-6)
    mine = loop_mae(table, rows, channel, name)
    assert c["family"] in ("lag", "regularised", "static", "constant")
    if c["family"] in ("static", "constant"):  # the baseline IS the model, and no effect of it
        assert mine == pytest.approx(c["baselines"][c["family"]]["mae_um"], rel=1e-6)
        assert not [e for e in doc["effects"] if e["channels"] == [channel]]
        assert "no lag model beats" in c["verdict"]
    if c["family"] == "regularised":     # its figures are the channel's; effects only if named
        assert mine == pytest.approx(c["regularised"]["mae_um"], rel=1e-6)
        named = [e for e in doc["effects"] if e["channels"] == [channel]]
        assert bool(named) == c["lag_terms_named"]
    best = min(static, const)
    assert mine <= STATIC_FACTOR * best + STATIC_SLACK_UM, (
        f"window {name} %, {channel} ({c['family']}): MAE {mine:.3f} um > {STATIC_FACTOR} x "
        f"min(static {static:.3f}, constant {const:.3f}) + {STATIC_SLACK_UM} um")


@pytest.mark.parametrize("name", [_param(n) for n in WINDOWS])
def test_interval_coverage_is_that_of_the_predictions(loop_runs, table, name):
    """The reported held-out coverage of the 95 % interval is the share of the window's
    readings (the data file's values) within the half-width of the predictions file's."""
    doc, rows = loop_runs(name)
    for ch in CHANNELS:
        iv = doc["channels"][ch]["interval"]
        assert iv["level"] == 0.95 and iv["half_width_um"] > 0
        test = [r for r in rows if r["channel"] == ch and r["split"] == "test"]
        t = np.array([float(r["t_s"]) for r in test])
        e = np.interp(t, table["t_s"], table[f"d_{ch}_um"]) - np.array(
            [float(r["after_um"]) for r in test])
        hw = np.array([float(r["half_width_um"]) for r in test])
        assert np.all(hw > 0) and iv["half_width_um"] == pytest.approx(np.median(hw), rel=1e-5)
        assert iv["coverage_test"] == pytest.approx(float(np.mean(np.abs(e) <= hw)),
                                                    abs=1e-9), (name, ch)


#: issue 44 item 4: the share of ALL held-out readings of the channel-windows (pooled) inside
#: their 95 % interval; per window 90-98 % is out of reach for any honest rule (one held-out
#: stretch is one draw of its level, docs/drift_loop.md), the pooled share is the target.
#: Measured: 95.3 % over these 25 channel-windows (95.9 % with the publication split's 5).
POOLED_COVERAGE = (0.90, 0.98)


@pytest.mark.xdist_group(fl_runs.GROUP)
def test_pooled_interval_coverage_of_all_windows(loop_runs, table):
    """Pooled over every held-out reading of the five windows' 25 channel-windows, the share
    inside the predictions file's per-reading half-width (the data file's values) is within
    ``POOLED_COVERAGE``.  No loop run of its own: it reads the windows the tests above ran in
    this process (every FL window's tests are in one xdist group, tests/helpers/fl_runs.py)."""
    inside = total = 0
    for name in WINDOWS:
        _, rows = loop_runs(name)
        for ch in CHANNELS:
            test = [r for r in rows if r["channel"] == ch and r["split"] == "test"]
            t = np.array([float(r["t_s"]) for r in test])
            e = np.interp(t, table["t_s"], table[f"d_{ch}_um"]) - np.array(
                [float(r["after_um"]) for r in test])
            inside += int(np.sum(np.abs(e) <= np.array([float(r["half_width_um"])
                                                        for r in test])))
            total += len(test)
    lo, hi = POOLED_COVERAGE
    assert lo <= inside / total <= hi, (inside, total)
