"""Issue 45 item 3, done-when: every reported uncertainty has a budget whose combined u
equals the stated u to 1e-6 relative.

Walks every result kind of :mod:`test_result_contract` (its ``CASES``, built by the API on
the shipped examples, tests/api/conftest.py's ``ex``; the results themselves, made once
per process: ``api_result``): for each row of ``table()`` with a standard
uncertainty u > 0 (a u of 0 is a datum, fixed by definition: no budget), the budget of that
row (:func:`volerr.report.budget.of_row` over :func:`volerr.report.content.budgets_of` of the
JSON document) exists, and

* its combined u, recomputed here as the root sum of squares of |c_i| u(x_i) of its sources
  (not the budget's own ``u`` field), equals the row's u to 1e-6 relative;
* its ``u`` field and ``U = k u`` agree with that;
* every contribution is |c_i| u(x_i) of its source.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from api.test_result_contract import CASES, api_result
from volerr.report.budget import of_row
from volerr.report.content import budgets_of

pytestmark = pytest.mark.xdist_group("api_examples")


#: a budget in another unit than its row (the Monte Carlo's in um, its row in mm): factor
#: to the row's unit
TO_ROW_UNIT = {("um", "mm"): 1e-3}


def _combined(b: dict) -> float:
    total = 0.0
    for s in b["sources"]:
        c = abs(float(s["sensitivity"])) * float(s["u"])
        assert math.isclose(c, s["contribution"], rel_tol=1e-12, abs_tol=1e-300), s
        total += c * c
    return math.sqrt(total)


@pytest.mark.parametrize("kind", list(CASES))
def test_every_reported_uncertainty_has_its_budget(kind, ex):
    r = api_result(kind, ex)          # the result the result contract checks (one per process)
    budgets = budgets_of(r.to_dict())
    missing, wrong = [], []
    for row in r._rows():
        if row.std is None or not row.std > 0:
            continue
        b = of_row(budgets, row.name)
        if b is None:
            missing.append(row.name)
            continue
        u = _combined(b) * TO_ROW_UNIT.get((b["unit"], row.unit), 1.0)
        if not math.isclose(u, row.std, rel_tol=1e-6):
            wrong.append((row.name, row.std, u))
        assert math.isclose(b["u"], _combined(b), rel_tol=1e-9) and \
            math.isclose(b["U"], b["k"] * b["u"], rel_tol=1e-9), b
    assert not missing, f"{kind}: no budget for {len(missing)} rows: {missing[:5]}"
    assert not wrong, f"{kind}: combined u != stated u: {wrong[:5]}"


def _series(y, s, step_days=7.0):
    from volerr.history import analysis as an

    t = 20000.0 + step_days * np.arange(len(y))
    return an.Series("P", "um", [an.date_of(x) for x in t], t, np.asarray(y, float),
                     np.asarray(s, float))


def test_history_steps_and_trends_have_their_budgets():
    """The example history has one entry per parameter (no step, no trend): a planted step
    and a drifting series here.  The slope of a line through equally uncertain entries
    (chi2/dof <= 1: not widened) has u = u_entry / sqrt(sum (t - mean t)^2) (textbook WLS),
    the budget's combined u; a step's budget combines to the std the rule states."""
    from volerr.history import analysis as an

    rng = np.random.default_rng(7)
    y = np.r_[np.zeros(8), np.full(8, 20.0)] + rng.normal(0, 0.3, 16)
    steps = [c for c in an.changes(_series(y, np.full(16, 0.5))) if c["kind"] == an.STEP]
    assert steps
    for c in steps:
        assert math.isclose(_combined(c["budget"]), c["std"], rel_tol=1e-6)
    t = 7.0 * np.arange(10)
    s = _series(0.01 * t + rng.normal(0, 0.05, 10), np.full(10, 0.5))   # scatter < u
    tr = an.trend(s)
    assert not tr.scaled
    expected = 0.5 / math.sqrt(np.sum((t - t.mean()) ** 2))
    assert math.isclose(_combined(tr.budget), expected, rel_tol=1e-9)
    assert math.isclose(_combined(tr.budget), math.sqrt(tr.cov[1, 1]), rel_tol=1e-6)


def test_ballbar_g_f_h_budgets_on_an_oval_trace():
    """An oval path dr = A cos(2 theta), every reading u = 0.5 um: the largest radius at
    theta = 0, the smallest at 90 deg, so their radial directions differ by sqrt(2); the
    least-squares centre's u per coordinate is u sqrt(2 / n).  Expected (GUM, by hand):
    u(G) = sqrt(2 u^2 + 2 (u sqrt(2 / n))^2), u(F_max) = u(F_min) = u; H of a clockwise
    trace read at the same angles: the interpolation is exact there, u(H) = sqrt(2) u."""
    from volerr.ballbar import iso230_4 as iso

    n, u, A = 72, 0.5, 4e-3
    th = np.linspace(0, 2 * np.pi, n, endpoint=False)
    dr = A * np.cos(2 * th)

    def trace(direction, extra):
        return iso.Trace("t.csv", "p", direction, "XY", 150.0, th, dr + extra,
                         np.arange(n), np.zeros(3), np.full(n, u * 1e-3))

    trs = [trace(1, 0.0), trace(-1, 1e-3 * (th > np.pi))]
    res = iso.evaluate_all(trs)
    b = iso.budgets(trs, res)
    assert math.isclose(_combined(b["G t.csv p ccw"]),
                        math.sqrt(2 * u ** 2 + 2 * (u * math.sqrt(2 / n)) ** 2), rel_tol=1e-9)
    assert math.isclose(_combined(b["F_max t.csv p ccw"]), u, rel_tol=1e-12)
    assert math.isclose(_combined(b["H t.csv p"]), math.sqrt(2) * u, rel_tol=1e-9)
    assert res[0]["u_H_um"] == res[1]["u_H_um"] == b["H t.csv p"]["u"]


def test_iso230_3_budget_of_a_drift_range_from_planted_noise():
    """A channel with a slow linear drift plus white noise sigma, recorded to 0.001 um:
    the budget's noise source is within 10 % of sigma (second differences remove the
    drift; 4000 readings: the estimate's relative u is about 1 %), its resolution 0.001 um,
    and u(range) = sqrt(2 (sigma_hat^2 + r^2 / 12))."""
    from types import SimpleNamespace

    from volerr.positioning import iso230_3

    rng = np.random.default_rng(11)
    t = 30.0 * np.arange(4000)
    sigma = 0.2
    x = np.round(1e-4 * t + rng.normal(0, sigma, t.size), 3)
    run = SimpleNamespace(name="r", t_s=t, channels={"a": x}, directions={"a": "X"},
                          heights={"a": None}, inputs={})
    ev = iso230_3.evaluate(run)
    noise, res = ev.reading_u()["a"]
    assert abs(noise / sigma - 1) < 0.1 and res == pytest.approx(1e-3)
    b = ev.budgets()["a:range"]
    assert math.isclose(_combined(b), math.sqrt(2 * (noise ** 2 + res ** 2 / 12)),
                        rel_tol=1e-12)


def test_monte_carlo_budget_of_two_independent_groups(ex, monkeypatch):
    """The machine (spec) and the probing noise are independent groups: their one-at-a-time
    Monte Carlo variances add up to the joint run's (the budget's common sensitivity within
    5 % of 1); the noise group alone on the distance of two probed points is the noise of a
    difference of two points along the line, sqrt(2) sigma (within 10 %: 2000 samples);
    the combined u is the stated one; the MC standard error of u, u / sqrt(2 (M - 1)), is
    stated in a note."""
    import volerr

    monkeypatch.chdir(ex)
    sigma = 0.3
    r = volerr.uncertainty("MH2", "task_distance.csv", "distance", spec="E0=2+L/300",
                           noise_um=sigma, samples=2000, contributions=2000)
    d = r.to_dict()
    b = d["budgets"]["distance"]
    u = d["quantities"]["distance"]["standard_uncertainty_um"]
    assert math.isclose(_combined(b), u, rel_tol=1e-9)
    assert len(b["sources"]) == 2 and abs(b["sources"][0]["sensitivity"] - 1) < 0.05
    noise = next(s for s in b["sources"] if s["source"].startswith("probing noise"))
    assert abs(noise["u"] / (math.sqrt(2) * sigma) - 1) < 0.1
    assert f"{u / math.sqrt(2 * 1999):.3g} \u00b5m (2000 samples)" in b["notes"][0]


def test_squareness_rows_have_budgets_from_their_two_legs(tmp_path):
    """``volerr squareness`` (not among the contract's kinds): straightness tables with noise
    on a straight line; each squareness's u is the root sum of squares of its two legs'
    slope standard errors, sigma / sqrt(sum (s - mean s)^2) each (textbook), in urad."""
    from volerr.cmm.api import squareness
    from volerr.tables.table import ErrorTable, write_error_dir

    rng = np.random.default_rng(5)
    s = np.linspace(0, 400, 9)
    sig = 1e-3                                               # mm
    tables = {ax: ErrorTable(ax, s, {f"E{c}{ax}": 2e-5 * s + rng.normal(0, sig, s.size)
                                     for c in "XYZ" if c != ax}) for ax in "XYZ"}
    write_error_dir(tmp_path / "d", tables, {})
    r = squareness("MB1", tmp_path / "d")
    budgets = budgets_of(r.to_dict())
    rows = [row for row in r._rows() if row.std]
    assert rows
    sxx = float(np.sum((s - s.mean()) ** 2))
    for row in rows:
        b = of_row(budgets, row.name)
        assert math.isclose(_combined(b), row.std, rel_tol=1e-9)
        assert len(b["sources"]) == 2
        for src in b["sources"]:          # each leg's slope u from its own residuals
            assert 0.3 < src["u"] / (sig / math.sqrt(sxx) * 1e6) < 2.0
