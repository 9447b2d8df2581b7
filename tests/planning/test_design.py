"""The design algorithm of ``volerr plan`` (volerr.plan._design) on small synthetic problems:
the Woodbury gains against the criterion recomputed directly, greedy + Fedorov exchange
against the exhaustive optimum, the allocation within its bounds."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from volerr.plan import _design as D


def _pool(n=12, q=5, rank=2, seed=0):
    rng = np.random.default_rng(seed)
    U = rng.normal(size=(n, q, rank)) * rng.uniform(0.2, 2.0, size=(n, 1, 1))
    info = np.einsum("cir,cjr->cij", U, U)
    return D.Candidates(info, D.factors(info), np.zeros(n, int), np.full(n, 2),
                        np.full(n, 40), np.full(n, 10), np.ones(n), np.zeros(n))


def _W(q, seed=1):
    J = np.random.default_rng(seed).normal(size=(20, q))
    return J.T @ J / 20


@pytest.mark.parametrize("kind", ["I", "D"])
def test_gains_equal_the_criterion_recomputed(kind):
    cand = _pool()
    W = _W(5)
    M = np.eye(5) * 0.3 + cand.info[:3].sum(axis=0)
    g = D.gains(np.linalg.inv(M), W, cand.factor, kind)
    direct = [D.criterion(M, W, kind) - D.criterion(M + cand.info[c], W, kind)
              for c in range(len(cand.info))]
    assert np.allclose(g, direct, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("seed", range(8))
def test_greedy_and_exchange_reach_the_exhaustive_optimum(seed):
    cand = _pool(seed=seed)
    W, P0 = _W(5, seed + 10), np.zeros((5, 5))
    k = 3
    best = min(D.criterion(cand.info[list(s)].sum(axis=0), W, "I")
               for s in itertools.combinations(range(len(cand.info)), k))
    mean = np.mean([D.criterion(cand.info[list(s)].sum(axis=0), W, "I")
                    for s in itertools.combinations(range(len(cand.info)), k)])
    chosen = D.best_exchange(cand, W, P0, "I", D.greedy(cand, W, P0, "I", k, {0: k}))
    got = D.criterion(cand.info[chosen].sum(axis=0), W, "I")
    assert got <= 1.02 * best < mean
    assert len(set(chosen)) == k


def test_allocation_keeps_bounds_and_total():
    cand = _pool()
    cand.min_readings[:] = 5
    cand.max_readings[:] = 30
    W = _W(5)
    m = D.allocate(cand, W, np.zeros((5, 5)), "I", [0, 3, 5, 7], 90)
    assert m.sum() == 90 and np.all(m >= 5) and np.all(m <= 30)
    # the multiplicative algorithm's weights beat equal readings
    equal = D.plan_value(cand, W, np.zeros((5, 5)), "I", [0, 3, 5, 7], [22, 22, 23, 23])
    assert D.plan_value(cand, W, np.zeros((5, 5)), "I", [0, 3, 5, 7], m) <= equal * 1.0001
