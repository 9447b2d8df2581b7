"""The selection core (:mod:`volerr.selection`): its rules stated once, the stepwise passes,
the ln-tau profile and the linear algebra, each against an independent computation (numpy's
own least squares and pseudo-inverse, a parabola whose vertex is known in closed form, toy
scorers whose answer is counted by hand)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from volerr.selection import linalg, profile, rules, stepwise

RUNTIME = Path(__file__).resolve().parents[2] / "runtime"


# ---- the rules, once ---------------------------------------------------------------------
RULE_NAMES = ("BIC_GAIN", "BIC_TIE", "CV_T", "CV_GAIN", "CV_SAME", "ALT_REL", "SIG_K",
              "LAG_EARN", "TIE_BIC_REL", "TIE_BIC_ABS", "TIE_SCORE_REL")


def test_every_rule_is_defined_in_one_place():
    """A selection constant is assigned a number only in ``selection/rules.py`` (before:
    ``SIG_K`` in loop/drift.py and loop/api.py, ``ALT_REL`` = ``lags.CV_SAME``, the check
    importing the loop's internals)."""
    pat = re.compile(r"^(%s)\s*=\s*[-+0-9.]" % "|".join(RULE_NAMES), re.M)
    where = {}
    for f in RUNTIME.rglob("*.py"):
        for m in pat.finditer(f.read_text(encoding="utf-8")):
            where.setdefault(m.group(1), []).append(f.relative_to(RUNTIME).as_posix())
    assert where, "no rule found at all: the pattern is wrong"
    assert all(files == ["selection/rules.py"] for files in where.values()), where


def test_the_three_selections_read_the_same_rules():
    from volerr.check import _select as check_select
    from volerr.loop import api, fitting, lags, select
    from volerr.loop.drift import fit as drift_fit
    from volerr.loop.drift import select as drift_select

    assert select.BIC_GAIN is rules.BIC_GAIN and check_select.BIC_GAIN is rules.BIC_GAIN
    assert fitting.CV_T is rules.CV_T and check_select.CV_T is rules.CV_T
    assert lags.CV_SAME is rules.CV_SAME and check_select.CV_SAME is rules.CV_SAME
    assert drift_select.CV_GAIN is rules.CV_GAIN and drift_fit.SIG_K is api.SIG_K
    # the two tie tolerances keep their values (outputs unchanged), under their names
    assert (fitting.TIE_REL, fitting.TIE_ABS) == (1e-7, 1e-9)
    assert drift_select.TIE_REL == check_select.TIE == 1e-9


def test_delta_bic_and_ties():
    n, r0, r1, m = 500, 2.0, 1.5, 2
    assert rules.delta_bic(n, r1, r0, m) == pytest.approx(n * math.log(0.75) + 2 * math.log(n))
    assert rules.bic_accepts(-rules.BIC_GAIN) and not rules.bic_accepts(-rules.BIC_GAIN + 1e-9)
    assert rules.tied(-100.0, -100.0 - 0.5e-5) and not rules.tied(-100.0, -100.0 - 2e-5)
    assert rules.cv_gain(0.99, 1.0) and not rules.cv_gain(0.995, 1.0)
    assert rules.significant(2.0, 1.0) and not rules.significant(1.99, 1.0)
    d = np.array([1.0, 2.0, 3.0, 4.0])
    assert rules.paired_t(d) == pytest.approx(2.5 / (np.std(d, ddof=1) / 2.0))


# ---- linear algebra ------------------------------------------------------------------------
def _rank_deficient(rng, n=40, p=6):
    A = rng.normal(size=(n, p))
    A[:, 4] = A[:, 0] + 2 * A[:, 1]           # a dependent column
    return A


def test_pinv_sym_is_the_pseudo_inverse():
    rng = np.random.default_rng(3)
    A = _rank_deficient(rng)
    G = A.T @ A
    assert np.allclose(linalg.pinv_sym(G), np.linalg.pinv(G, rcond=1e-10), atol=1e-10)


def test_normal_equation_solves_give_the_minimum_norm_least_squares_solution():
    rng = np.random.default_rng(4)
    A = _rank_deficient(rng)
    y = rng.normal(size=len(A))
    ref = np.linalg.lstsq(A, y, rcond=None)[0]
    assert np.allclose(linalg.solve_normal(A.T @ A, A.T @ y, 1e-12), ref, atol=1e-9)
    # column-scaled: the same fit (scaling changes which minimum-norm point, not the fit)
    A2 = np.column_stack([A[:, [0, 1, 2, 3, 5]] * [1e-3, 1.0, 1e3, 1.0, 1.0],
                          np.zeros(len(A))])       # a column all zero: coefficient 0
    b = linalg.solve_scaled(A2.T @ A2, A2.T @ y)
    ref2 = np.linalg.lstsq(A2[:, :5], y, rcond=None)[0]
    assert b[5] == 0.0 and np.allclose(b[:5], ref2, rtol=1e-8)


# ---- the ln-tau profile ----------------------------------------------------------------------
def test_profile_argmin_finds_a_parabola_vertex_and_recentres():
    x_true, q_true = 0.9, 3.0

    def rss_at(xs):
        return q_true * (xs - x_true) ** 2 + 5.0, list(range(len(xs)))

    steps = np.linspace(-0.3, 0.3, 13)
    x, q, rss_min, k = profile.profile_argmin(rss_at, 0.0, steps)   # the least is off range
    assert x == pytest.approx(x_true, abs=1e-9) and q == pytest.approx(q_true)
    assert rss_min == pytest.approx(5.0, abs=1e-12)
    assert profile.profile_argmin(lambda xs: (-(xs ** 2), [0] * len(xs)), 0.0, steps) is None


def test_profile_vertex_inside_and_at_the_edge():
    half = 0.2

    def bowl(centre):
        return lambda x0, xs: list(2.0 * (x0 + xs - centre) ** 2 + 1.0)

    x, edge = profile.profile_vertex(bowl(0.05), half, 7, 3)
    assert x == pytest.approx(0.05, abs=1e-9) and not edge
    x, edge = profile.profile_vertex(bowl(0.5), half, 7, 3)       # 2.5 steps away: found
    assert x == pytest.approx(0.5, abs=1e-9) and not edge
    x, edge = profile.profile_vertex(bowl(5.0), half, 7, 3)       # beyond 3 re-centrings
    assert edge and x == pytest.approx(3 * half)


def test_tau_std_from_the_curvature():
    # RSS = q (x - x*)^2 + rss_min: u(x) = sqrt(2 s^2 / RSS''), s^2 = rss_min / dof
    tau, q, rss_min, dof = 1800.0, 50.0, 10.0, 100
    assert profile.tau_std(tau, q, rss_min, dof) == pytest.approx(
        tau * math.sqrt(2 * (rss_min / dof) / (2 * q)))


# ---- stepwise ----------------------------------------------------------------------------------
def test_forward_takes_the_best_while_the_rule_accepts():
    gains = {"a": 5.0, "b": 3.0, "c": 0.5}
    taken = []

    def propose(chosen):
        left = [k for k in gains if k not in chosen]
        return max(left, key=lambda k: gains[k]) if left else None

    got = stepwise.forward(propose, lambda k, chosen: gains[k] > 1.0, 10, take=taken.append)
    assert got == ["a", "b"] and taken == ["a", "b"]
    assert stepwise.forward(propose, lambda k, c: True, 1) == ["a"]


def test_backward_drops_the_cheapest_first_ties_to_the_first():
    worth = {"a": 4.0, "b": 0.1, "c": 0.1, "d": 2.0}

    def without(items, i):
        return worth[items[i]], None

    kept, last = stepwise.backward(list("abcd"), without, lambda res, items: res[0] < 1.0)
    assert kept == ["a", "d"] and [c for c, _ in last] == [4.0, 2.0]
    order = []
    stepwise.backward(list("abcd"), without,
                      lambda res, items: order.append(items[[worth[x] for x in items]
                                                             .index(res[0])]) or res[0] < 1.0)
    assert order[:2] == ["b", "c"]           # b and c tie: b (first) goes first
    assert stepwise.backward(["a"], without, lambda r, i: True, keep=1) == (["a"], None)


def test_merge_repeats_while_a_replacement_is_found():
    def pair_to_sum(items):
        return [items[0] + items[1]] + items[2:] if len(items) >= 2 and items[0] < 5 else None

    assert stepwise.merge([1, 2, 3, 4], pair_to_sum) == [6, 4]      # 1+2, then 3+3, 6 stops
    assert stepwise.merge([1, 1], pair_to_sum) == [2]                # one item left: stops
