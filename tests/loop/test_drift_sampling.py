"""Does the drift loop name the same diagnosis of the FL_THERMAL spindle test when the same
readings are logged every 60 s instead of every 15 s?  (Issue 44, done-when 2: "decimated
to 60 s, every FL window names the same sources and time constants (within their
uncertainty) as at 15 s, or lists the CV-equivalent alternatives; no reported term's k = 2
interval includes zero".)

Data: runtime/data/fl_thermal_spindle.csv (15 s) and every 4th reading of it (60 s, written
by tests/helpers/fl_runs.py); the six windows of tests/loop/test_drift_generalisation.py:
five 20 % windows held out of the whole file (training on both sides) and the publication
split (the file before 133 380 s, 100 035 s on held out).  ``volerr loop`` runs once per
window and sampling (tests/helpers/fl_runs.py, in-process, shared with
test_drift_generalisation.py and test_drift_fl_thermal.py; one xdist group per window,
``fl_window_W``; the 60 s runs are 4x smaller).

A reported term is a *group*: its source through its time constant (tau +- 2 u, where u is
its blocked-jackknife standard uncertainty; u not determined: any tau), the span of its own
source's time constants the cross-validation cannot tell apart (``tau_equivalent_s``), and
its CV-equivalent alternatives, each a source at a lag of the grid (standing for the lags
within half a grid step of it).  A lag shorter than 4 reading intervals of the coarser
sampling (240 s) is not resolved at 60 s: there it stands for the plain source as well.
Two terms agree when their groups share a source whose time-constant ranges overlap.  A
channel-window agrees when both samplings report the same family and every reported term
of each agrees with a term of the other.  Where they do not (measured when this test was
written: 13 of 30; 14 with the regularised family), the channel-window is listed in
``DIFFERENT`` (strict: a fix makes the test fail until the list is updated).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from helpers.fl_runs import WINDOWS, loop_run
from volerr.loop.drift.basis import N_TAU

pytestmark = [pytest.mark.slow]

CHANNELS = ("ch1", "ch2", "ch3", "ch4", "ch5")
STEPS = (1, 4)                # every reading (15 s), every 4th (60 s)
SHORTEST_60S = 4 * 60.0       # the shortest lag searched at 60 s (4 reading intervals)

#: measured when this test was written (both samplings): the channel-windows whose
#: diagnoses differ.  Two differ in family (0-20 % ch5: lag at 15 s, static at 60 s; 60-80 %
#: ch5 the reverse); the others by a term one sampling finds and the other does not (a
#: plain T_1 or T_4, a long lag of T_6, T_7, T_9, T_13 or T_15) or, on 40-60 % ch4 and the
#: publication's ch3, by several terms.  With the regularised family (issue 44) one more:
#: 20-40 % ch3, the lag model at 15 s, the regularised fit at 60 s.
DIFFERENT = {("0-20", "ch1"), ("0-20", "ch3"), ("0-20", "ch4"), ("0-20", "ch5"),
             ("20-40", "ch3"), ("20-40", "ch4"), ("40-60", "ch1"), ("40-60", "ch2"),
             ("40-60", "ch3"), ("40-60", "ch4"), ("60-80", "ch5"), ("80-100", "ch2"), ("pub", "ch1"),
             ("pub", "ch3")}


@pytest.fixture(scope="module")
def runs():
    """(step, window) -> the loop's JSON (``volerr loop --json``, the same as
    ``loop_drift(...).data``), run once per process for every test file that asks for it
    (tests/helpers/fl_runs.py; the tests of window W in xdist group ``fl_window_W``)."""

    def get(step: int, name: str) -> dict:
        run = loop_run(step, name)
        assert run.returncode == 0, run.stderr
        return run.doc

    return get


def _window(name):
    """A window as a parameter, in the xdist group of its runs (tests/helpers/fl_runs.py)."""
    return pytest.param(name, id=name, marks=pytest.mark.xdist_group(f"fl_window_{name}"))


def _half_step(step: int, name: str) -> float:
    """Half the ln step of the grid of time constants an alternative's lag lies on: the
    grid runs from 4 reading intervals (at least 60 s) to half the training span, ``N_TAU``
    values, geometric (``volerr formats loop-lags``); computed here from the file's times."""
    win, cut = WINDOWS[name]
    t = np.arange(0.0, 166710.0 + 1.0, 15.0 * step)
    if cut is not None:
        t = t[t < cut]
    a, b = (float(x[:-1]) if x else np.inf for x in win.split(":"))
    train = t[(t < a) | (t >= b)]
    lo, hi = max(60.0, 4 * 15.0 * step), max(np.ptp(train) / 2, 4 * max(60.0, 60.0 * step))
    return 0.5 * math.log(hi / lo) / (N_TAU - 1)


def _group(t: dict, covariate: str, h: float) -> dict:
    """source -> (lo, hi) s of the time constants the term's group holds (0: plain)."""
    g: dict = {}

    def add(src, lo, hi):
        a, b = g.get(src, (math.inf, -math.inf))
        g[src] = (min(a, lo), max(b, hi))

    lag = t["lag_s"]
    if not lag:
        add(covariate, 0.0, 0.0)
    elif lag["std"] is None:
        add(covariate, 0.0, math.inf)
    else:
        add(covariate, max(lag["value"] - 2 * lag["std"], 0.0), lag["value"] + 2 * lag["std"])
    if t.get("tau_equivalent_s"):
        add(covariate, *t["tau_equivalent_s"])
    for a in t["alternatives"]:
        x = a["lag_s"] or 0.0
        add(a["covariate"], x * math.exp(-h), x * math.exp(h))
    return {k: ((0.0, max(hi, SHORTEST_60S)) if lo < SHORTEST_60S else (lo, hi))
            for k, (lo, hi) in g.items()}


def _terms(doc, ch, h) -> list:
    return [(t["basis"], _group(t, e["covariate"], h)) for e in doc["effects"]
            if e["channels"] == [ch] for t in e["terms"]]


def _agrees(g: dict, others: list) -> bool:
    return any(src in o and lo <= o[src][1] and o[src][0] <= hi
               for _, o in others for src, (lo, hi) in g.items())


def _pair(name, ch):
    marks = [pytest.mark.xdist_group(f"fl_window_{name}")]
    if (name, ch) in DIFFERENT:
        marks.append(pytest.mark.xfail(reason="issue 44: the samplings' diagnoses differ "
                                              "(measured, see DIFFERENT)", strict=True))
    return pytest.param(name, ch, id=f"{ch}-{name}", marks=marks)


@pytest.mark.parametrize("name,ch", [_pair(n, c) for n in WINDOWS for c in CHANNELS])
def test_60_s_names_the_diagnosis_of_15_s_or_its_equivalents(runs, name, ch):
    a, b = runs(1, name), runs(4, name)
    fa, fb = a["channels"][ch]["family"], b["channels"][ch]["family"]
    assert fa == fb, f"{name} {ch}: family {fa} at 15 s, {fb} at 60 s"
    ta, tb = _terms(a, ch, _half_step(1, name)), _terms(b, ch, _half_step(4, name))
    lost = [x for x, g in ta if not _agrees(g, tb)] + [x for x, g in tb if not _agrees(g, ta)]
    assert not lost, f"{name} {ch}: terms without a counterpart in the other sampling: {lost}"


@pytest.mark.parametrize("name", [_window(n) for n in WINDOWS])
@pytest.mark.parametrize("step", STEPS)
def test_no_reported_term_includes_zero_at_k_2(runs, step, name):
    doc = runs(step, name)
    for e in doc["effects"]:
        for t in e["terms"]:
            assert abs(t["value"]) >= 2 * t["std"], (name, step, t["basis"], t["value"], t["std"])


@pytest.mark.parametrize("name", [_window(n) for n in WINDOWS])
def test_every_term_names_its_group(runs, name):
    """Every reported term's alternatives carry their CV RMS and paired t, lowest CV RMS
    first; a lag's span of equivalent time constants holds the lag itself."""
    for step in STEPS:
        for e in runs(step, name)["effects"]:
            for t in e["terms"]:
                rms = [x["cv_rms_um"] for x in t["alternatives"]]
                assert rms == sorted(rms)
                assert all(np.isfinite(x["paired_t"]) for x in t["alternatives"])
                if t["lag_s"]:
                    lo, hi = t["tau_equivalent_s"]
                    assert lo <= t["lag_s"]["value"] <= hi, (name, step, t["basis"])
                else:
                    assert t["tau_equivalent_s"] is None
