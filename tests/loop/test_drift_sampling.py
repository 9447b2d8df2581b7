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
test_drift_generalisation.py and test_drift_fl_thermal.py; one xdist group for every
window, ``fl_runs.GROUP``; the 60 s runs are 4x smaller).

A reported term is a *group*: its source through its time constant (tau +- 2 u, where u is
its blocked-jackknife standard uncertainty; u not determined: any tau), the span of its own
source's time constants the cross-validation cannot tell apart (``tau_equivalent_s``), and
its CV-equivalent alternatives, each a source at a lag of the grid (standing for the lags
within half a grid step of it).  A lag shorter than 4 reading intervals of the coarser
sampling (240 s) is not resolved at 60 s: there it stands for the plain source as well.
Two terms agree when their groups share a source whose time-constant ranges overlap.

The rule (issue 44: "... or lists the CV-equivalent alternatives", alternatives "the CV
cannot tell apart, named as such").  A channel-window agrees when

* both samplings report the same family, or each lists the other's family among the
  families its cross-validation cannot tell from its own (``families_equivalent``: neither
  significantly below the other by the paired t the families are chosen by); and
* every reported term of each sampling the cross-validation decides (``cv_decided``: the
  model with it significantly below the model without it) agrees with a reported term of
  the other, decided or not; a term not decided in its own sampling agrees as it is (the
  model without it is that sampling's CV-equivalent alternative, named as such).

Measured: by the first rule (the same family, every reported term with a reported
counterpart) 16 of 30; by this rule 19 of 30 (0-20 % ch1, 40-60 % ch2 and 80-100 % ch2 now
agree: each differed by one term the cross-validation cannot tell from its absence).
Where they do not agree, the channel-window is listed in ``DIFFERENT`` (strict: a fix
makes the test fail until the list is updated).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from helpers.fl_runs import GROUP, WINDOWS, loop_run
from volerr.loop.drift.basis import N_TAU, TAU_MIN_STEPS

pytestmark = [pytest.mark.slow]

CHANNELS = ("ch1", "ch2", "ch3", "ch4", "ch5")
STEPS = (1, 4)                # every reading (15 s), every 4th (60 s)
SHORTEST_60S = 4 * 60.0       # the shortest lag searched at 60 s (4 reading intervals)

#: measured (both samplings) with the rule of the module docstring: the channel-windows
#: whose diagnoses differ.  Six differ in family, the lag model at 15 s and the regularised
#: fit at 60 s, where the 15 s cross-validation finds the lag model significantly below
#: the regularised fit (so lists no family as equivalent) and the 60 s one does not (0-20 %
#: ch3, ch4, ch5; 20-40 % ch3; 40-60 % ch3, ch4: two of them list the lag model as
#: CV-equivalent at 60 s, which the rule asks of both samplings); the others by terms one
#: sampling reports as decided and the other does not report (20-40 % ch4 a 3.4 h lag of
#: T_9; 40-60 % ch1 and the publication's ch1 a plain T_1, T_6; 60-80 % ch5 and the
#: publication's ch3 several).  Before issue 44's undecided terms and equivalent families:
#: 14 (also 0-20 % ch1, 40-60 % ch2 and 80-100 % ch2, where one sampling's term is one the
#: cross-validation cannot tell from its absence).
DIFFERENT = {("0-20", "ch3"), ("0-20", "ch4"), ("0-20", "ch5"), ("20-40", "ch3"),
             ("20-40", "ch4"), ("40-60", "ch1"), ("40-60", "ch3"), ("40-60", "ch4"),
             ("60-80", "ch5"), ("pub", "ch1"), ("pub", "ch3")}


@pytest.fixture(scope="module")
def runs():
    """(step, window) -> the loop's JSON (``volerr loop --json``, the same as
    ``loop_drift(...).data``), run once per process for every test file that asks for it
    (tests/helpers/fl_runs.py; the tests of window W in xdist group ``fl_runs.GROUP``)."""

    def get(step: int, name: str) -> dict:
        run = loop_run(step, name)
        assert run.returncode == 0, run.stderr
        return run.doc

    return get


def _window(name):
    """A window as a parameter, in the xdist group of its runs (tests/helpers/fl_runs.py)."""
    return pytest.param(name, id=name, marks=pytest.mark.xdist_group(GROUP))


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
            if e["channels"] == [ch] for t in e["terms"] if t["cv_decided"] is not False]


def _not_decided(doc, ch, h) -> list:
    """The channel's reported terms the cross-validation could not tell from their absence
    (``cv_decided`` false: the model without the term is that sampling's CV-equivalent
    alternative)."""
    return [(t["basis"], _group(t, e["covariate"], h)) for e in doc["effects"]
            if e["channels"] == [ch] for t in e["terms"] if t["cv_decided"] is False]


def _families_agree(a: dict, b: dict) -> bool:
    """The same family, or each sampling lists the other's family among those its
    cross-validation cannot tell from its own (``families_equivalent``)."""
    fa, fb = a["family"], b["family"]
    return fa == fb or (fb in {f["family"] for f in a["families_equivalent"]}
                        and fa in {f["family"] for f in b["families_equivalent"]})


def _agrees(g: dict, others: list) -> bool:
    return any(src in o and lo <= o[src][1] and o[src][0] <= hi
               for _, o in others for src, (lo, hi) in g.items())


def _pair(name, ch):
    marks = [pytest.mark.xdist_group(GROUP)]
    if (name, ch) in DIFFERENT:
        marks.append(pytest.mark.xfail(reason="issue 44: the samplings' diagnoses differ "
                                              "(measured, see DIFFERENT)", strict=True))
    return pytest.param(name, ch, id=f"{ch}-{name}", marks=marks)


@pytest.mark.parametrize("name,ch", [_pair(n, c) for n in WINDOWS for c in CHANNELS])
def test_60_s_names_the_diagnosis_of_15_s_or_its_equivalents(runs, name, ch):
    a, b = runs(1, name), runs(4, name)
    ca, cb = a["channels"][ch], b["channels"][ch]
    assert _families_agree(ca, cb), f"{name} {ch}: family {ca['family']} at 15 s, " \
        f"{cb['family']} at 60 s, neither listed as the other's CV-equivalent"
    ha, hb = _half_step(1, name), _half_step(4, name)
    ta, tb = _terms(a, ch, ha), _terms(b, ch, hb)
    # a term of one sampling agrees with a term of the other, or with a term the other
    # could not tell from its absence; a term not decided in its own sampling agrees
    oa, ob = tb + _not_decided(b, ch, hb), ta + _not_decided(a, ch, ha)
    lost = [x for x, g in ta if not _agrees(g, oa)] + [x for x, g in tb if not _agrees(g, ob)]
    assert not lost, f"{name} {ch}: terms without a counterpart in the other sampling: {lost}"


@pytest.mark.parametrize("name", [_window(n) for n in WINDOWS])
def test_a_term_the_cv_cannot_tell_from_its_absence_is_named_so(runs, name):
    """Every reported term says whether the cross-validation tells the model from the model
    without it: decided where its paired t reaches the channel's critical value, not
    decided (and so named) below it; the model without it has a finite CV RMS."""
    for step in STEPS:
        doc = runs(step, name)
        for e in doc["effects"]:
            crit = doc["channels"][e["channel"]]["t_critical"]
            for t in e["terms"]:
                w = t["cv_without"]
                assert math.isfinite(w["cv_rms_um"]) and w["cv_rms_um"] > 0
                assert t["cv_decided"] is (w["paired_t"] >= crit), (name, step, t["basis"], w)


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


@pytest.mark.parametrize("name", [_window(n) for n in WINDOWS])
def test_every_named_lag_is_within_the_searched_grid(runs, name):
    """A named lag is no shorter than the grid's shortest, ``TAU_MIN_STEPS`` reading
    intervals and at least 60 s (docs/drift_loop.md, basis.py): a lag of fewer readings is
    not resolved by them.  Before the refinement was clipped to the grid, 0-20 % named
    ``lag(T_4, 35 s)`` at 15 s (ch1, ch2) and ``lag(T_8, 193-215 s)`` at 60 s (ch3, ch4)."""
    for step in STEPS:
        lo = max(60.0, TAU_MIN_STEPS * 15.0 * step)
        for e in runs(step, name)["effects"]:
            for t in e["terms"]:
                if t["lag_s"]:
                    assert t["lag_s"]["value"] >= lo - 0.05, (name, step, t["basis"])
