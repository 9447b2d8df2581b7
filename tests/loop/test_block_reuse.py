"""The loop's faster paths give what the plain ones give (issue 42 item 7): candidate groups
scored in stacks (``BlockBase.score_many``), design blocks kept between the passes over the
same points (``Kept``: ``BlockBase``, ``cv_sq``, the robust weights), the robust weights'
down-weighted points taken from the kept blocks, and the p-value of a fit through
``scipy.special``.  Each against a computation written here or the plain path (blocks
generated per pass, groups one at a time).  Blocks of 7 points force many partial blocks."""

import numpy as np
import pytest

import volerr
from volerr.estimate import blocks
from volerr.estimate.design import data_ranges, declared_design, gauge_mask
from volerr.loop.run import columns_to_data, robust_weights
from volerr.loop.simulate import demo_probes, simulate


@pytest.fixture(scope="module")
def problem():
    model = volerr.load("MB1")
    camp = simulate("MB1", n_points=80, seed=11, probes=demo_probes(model),
                    effects=[{"kind": "thermal", "axis": "Y", "ppm_per_K": 5.0}])
    data = columns_to_data(camp.columns(), model)
    ranges = data_ranges(model, data)
    keep, _ = gauge_mask(model, data, 2, ranges)
    A = declared_design(model, data, 2, ranges).A[:, :, keep]          # (N, 3, p) dense
    design = blocks.Design(model, data, 2, ranges, keep)
    return design, A.reshape(-1, design.p), data.deviation.ravel()


@pytest.fixture(autouse=True)
def small_blocks(monkeypatch):
    monkeypatch.setattr(blocks, "BLOCK", 7)


def _rss(A, y):
    return float(np.sum((y - A @ np.linalg.lstsq(A, y, rcond=None)[0]) ** 2))


def _groups(n: int):
    """Five candidate groups of 1-4 columns (15 in all), fixed seed."""
    rng = np.random.default_rng(4)
    return [rng.normal(size=(n, 3, m)) for m in (1, 3, 4, 2, 5)]


def test_stacked_scores_are_the_rss_drops_of_refits(problem, monkeypatch):
    """Each group's score equals the RSS drop of refitting with its columns (dense lstsq);
    stacks of at most 4 columns (several stacks, the 5-column group alone in one) score as
    the groups one at a time do, to round-off."""
    design, dense, y = problem
    n = len(y) // 3
    rng = np.random.default_rng(5)
    pts = np.sort(rng.choice(n, 70, replace=False))
    sw = rng.uniform(0.3, 1.0, len(pts))
    rows = (3 * pts[:, None] + np.arange(3)).ravel()
    wr = np.repeat(sw, 3)
    Aw, yw = dense[rows] * wr[:, None], y[rows] * wr
    rss0 = _rss(Aw, yw)
    groups = _groups(n)
    fns = [lambda idx, g=g: g[idx] for g in groups]
    monkeypatch.setattr(blocks, "STACK_COLUMNS", 4)
    base = blocks.BlockBase(design, pts, sw, y)
    stacked = base.score_many(fns)
    monkeypatch.setattr(blocks, "STACK_COLUMNS", 1)     # every group alone
    alone = base.score_many(fns)
    for g, (gain, rank), (gain1, rank1) in zip(groups, stacked, alone):
        m = g.shape[-1]
        Bw = g[pts].reshape(-1, m) * wr[:, None]
        want = rss0 - _rss(np.concatenate([Aw, Bw], axis=1), yw)
        assert rank == rank1 == m
        assert np.isclose(gain, want, rtol=1e-6)
        assert gain == pytest.approx(gain1, rel=1e-12)


def test_dense_stacked_scores_are_the_rss_drops_of_refits(problem, monkeypatch):
    """The dense screening base (``select.Base``, a few thousand training points) scores
    candidate groups in stacks of ``STACK_COLUMNS`` columns (one product with the design per
    stack): each group's score is the RSS drop of refitting with its columns (dense lstsq
    written here), stacks of at most 4 columns give what each group alone gives (to
    round-off: only the order of summation differs), one column (no 1 x 1 eigh) included, and
    a group inside the design's span (a design column, scaled) adds nothing (rank 0)."""
    from volerr.loop import select

    _, dense, y = problem
    rng = np.random.default_rng(6)
    wr = np.repeat(rng.uniform(0.3, 1.0, len(y) // 3), 3)
    Aw, yw = dense * wr[:, None], y * wr
    rss0 = _rss(Aw, yw)
    groups = [g.reshape(-1, g.shape[-1]) * wr[:, None] for g in _groups(len(y) // 3)]
    inside = Aw[:, 2:3] * 3.0
    monkeypatch.setattr(select, "STACK_COLUMNS", 4)
    base = select.Base(Aw, yw)
    assert base.rss == pytest.approx(rss0, rel=1e-9)
    stacked = base.score_many(groups + [inside])
    monkeypatch.setattr(select, "STACK_COLUMNS", 1)     # every group alone
    alone = base.score_many(groups + [inside])
    assert len({g.shape[1] for g in groups}) == 5 and stacked[-1] == alone[-1] == (0.0, 0)
    for B, (gain, rank), (gain1, rank1) in zip(groups, stacked, alone):
        want = rss0 - _rss(np.concatenate([Aw, B], axis=1), yw)
        assert rank == rank1 == B.shape[1]
        assert np.isclose(gain, want, rtol=1e-6)
        assert gain == pytest.approx(gain1, rel=1e-12)
        assert base.score(B) == (gain1, rank1)


def test_kept_blocks_give_the_generated_ones(problem, monkeypatch):
    """BlockBase, cv_sq (leave-one-out and k-fold) with the blocks kept between passes equal
    the same with every pass generating them (KEEP_BYTES 0), to round-off."""
    design, dense, y = problem
    n = len(y) // 3
    rng = np.random.default_rng(6)
    pts = np.arange(n)
    sw = rng.uniform(0.5, 1.0, n)
    folds = rng.permutation(n) % 4
    groups = [lambda idx, g=g: g[idx] for g in _groups(n)]

    def run():
        base = blocks.BlockBase(design, pts, sw, y)
        return (base.rss, base.score_many(groups), blocks.cv_sq(design, y, None, pts, sw),
                blocks.cv_sq(design, y, folds, pts, sw), base._kept is not None)

    kept = run()
    monkeypatch.setattr(blocks, "KEEP_BYTES", 0)
    plain = run()
    assert kept[-1] and not plain[-1]
    assert kept[0] == pytest.approx(plain[0], rel=1e-12)
    for (g, r), (g1, r1) in zip(kept[1], plain[1]):
        assert r == r1 and g == pytest.approx(g1, rel=1e-12)
    for a, b in zip(kept[2:4], plain[2:4]):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=0)


def test_robust_weights_from_kept_blocks(problem, monkeypatch):
    """Gross outliers planted on 6 points: the robust weights with the down-weighted points'
    columns taken from the kept blocks equal those with every block generated again, and
    both flag the planted points (weight 0) and leave the bulk at full weight."""
    design, dense, y = problem
    n = len(y) // 3
    bad = np.array([3, 17, 18, 40, 41, 77])
    y = y.copy()
    y[3 * bad] += 0.05                                  # 50 um on X of each
    pts = np.arange(n)
    kept = robust_weights(design, y, pts, n)
    monkeypatch.setattr(blocks, "KEEP_BYTES", 0)
    plain = robust_weights(design, y, pts, n)
    np.testing.assert_allclose(kept.weights, plain.weights, rtol=1e-12, atol=1e-15)
    assert kept.sigma == pytest.approx(plain.sigma, rel=1e-12)
    assert np.array_equal(kept.outliers, plain.outliers)
    assert set(bad) <= set(kept.outliers.tolist())
    assert np.all(kept.weights[bad] == 0.0)
    assert np.median(kept.weights) > 0.5 * np.median(design.data.point_weights())


@pytest.mark.parametrize("chi2,dof", [(0.0, 1), (0.5, 1), (3.2, 2), (120.0, 100),
                                      (4.1e5, 3.0e5), (1e300, 7)])
def test_p_value_is_the_chi2_survival_function(chi2, dof):
    from scipy.stats import chi2 as dist

    from volerr.fit_quality import FitQuality

    got = FitQuality(chi2, dof, "u").p_value
    assert got == float(dist.sf(chi2, dof))
