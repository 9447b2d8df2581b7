"""The loop's blockwise least squares (volerr.estimate.blocks) against dense computations written
here: the normal equations, held-out residuals and screening scores must not depend on the
block size beyond round-off.  Blocks of 7 points force many partial blocks."""

import numpy as np
import pytest

import volerr
from volerr.estimate import blocks
from volerr.estimate.design import data_ranges, declared_design, gauge_mask
from volerr.loop.run import columns_to_data
from volerr.loop.simulate import demo_probes, simulate


@pytest.fixture(scope="module")
def problem():
    model = volerr.load("MB1")
    camp = simulate("MB1", n_points=90, seed=3, probes=demo_probes(model),
                    effects=[{"kind": "thermal", "axis": "X", "ppm_per_K": 8.0}])
    data = columns_to_data(camp.columns(), model)
    ranges = data_ranges(model, data)
    keep, _ = gauge_mask(model, data, 2, ranges)
    A = declared_design(model, data, 2, ranges).A[:, :, keep]          # (N, 3, p) dense
    rng = np.random.default_rng(0)
    extra = rng.normal(size=(data.n, 3, 2))                              # two effect columns
    design = blocks.Design(model, data, 2, ranges, keep, [extra])
    dense = np.concatenate([A, extra], axis=2).reshape(-1, design.p)      # point-major rows
    y = data.deviation.ravel()
    return design, dense, y, rng


@pytest.fixture(autouse=True)
def small_blocks(monkeypatch):
    monkeypatch.setattr(blocks, "BLOCK", 7)


def _w(sw):
    return np.repeat(sw, 3)


def test_blockwise_normal_equations_equal_dense(problem):
    design, dense, y, rng = problem
    pts = np.sort(rng.choice(len(y) // 3, 60, replace=False))
    sw = rng.uniform(0.2, 1.0, len(pts))
    G, b, colsq = blocks.normal(design, pts, sw, y)
    rows = (3 * pts[:, None] + np.arange(3)).ravel()
    Aw = dense[rows] * _w(sw)[:, None]
    G0, b0 = Aw.T @ Aw, Aw.T @ (y[rows] * _w(sw))
    tol = 1e-12 * np.abs(G0).max()
    assert np.abs(G - G0).max() < tol
    assert np.abs(b - b0).max() < 1e-12 * np.abs(Aw).max() * np.abs(y).max() * len(rows)
    assert np.allclose(colsq, np.diag(G0), rtol=1e-12)
    # rows in point-major order are the dense rows; predictions too
    assert np.array_equal(design.rows(pts[:9]), dense[rows[:27]])
    c = rng.normal(size=design.p)
    assert np.allclose(blocks.predict(design, pts, c), dense[rows] @ c, rtol=0, atol=1e-12 *
                       np.abs(dense).max() * np.abs(c).sum())


def _lsq(A, y):
    return np.linalg.lstsq(A, y, rcond=None)[0]


def test_leave_one_point_out_equals_refits(problem):
    design, dense, y, rng = problem
    n = len(y) // 3
    pts = np.arange(n)
    sw = rng.uniform(0.5, 1.0, n)
    Aw, yw = dense * _w(sw)[:, None], y * _w(sw)
    assert np.linalg.matrix_rank(Aw) == design.p
    want = np.empty(n)
    for i in range(n):
        m = np.ones(3 * n, bool)
        m[3 * i:3 * i + 3] = False
        c = _lsq(Aw[m], yw[m])
        want[i] = np.sum((yw[~m] - Aw[~m] @ c) ** 2)
    got = blocks.cv_sq(design, y, None, pts, sw)
    assert np.allclose(got, want, rtol=1e-6, atol=1e-9 * want.max())


def test_kfold_equals_refits(problem):
    design, dense, y, rng = problem
    n = len(y) // 3
    pts = np.arange(n)
    sw = rng.uniform(0.5, 1.0, n)
    folds = rng.permutation(n) % 4
    Aw, yw = dense * _w(sw)[:, None], y * _w(sw)
    want = np.empty(n)
    for f in range(4):
        m = np.repeat(folds == f, 3)
        c = _lsq(Aw[~m], yw[~m])
        want[folds == f] = np.sum(((yw[m] - Aw[m] @ c).reshape(-1, 3)) ** 2, axis=1)
    got = blocks.cv_sq(design, y, folds, pts, sw)
    assert np.allclose(got, want, rtol=1e-6, atol=1e-9 * want.max())


def test_screening_score_is_the_rss_reduction_of_a_refit(problem):
    """BlockBase.score from the blockwise cross-products A_c^T r, A_c^T A_c, A_c^T A equals the
    RSS drop of refitting with the candidate's columns added (lstsq on the dense rows)."""
    design, dense, y, rng = problem
    n = len(y) // 3
    pts = np.sort(rng.choice(n, 70, replace=False))
    sw = rng.uniform(0.3, 1.0, len(pts))
    rows = (3 * pts[:, None] + np.arange(3)).ravel()
    Aw, yw = dense[rows] * _w(sw)[:, None], y[rows] * _w(sw)
    cand = rng.normal(size=(n, 3, 2)) * 1e-3 + dense.reshape(n, 3, -1)[:, :, :1] * 0.5
    Bw = cand[pts].reshape(-1, 2) * _w(sw)[:, None]
    rss0 = np.sum((yw - Aw @ _lsq(Aw, yw)) ** 2)
    AB = np.concatenate([Aw, Bw], axis=1)
    rss1 = np.sum((yw - AB @ _lsq(AB, yw)) ** 2)
    base = blocks.BlockBase(design, pts, sw, y)
    assert np.isclose(base.rss, rss0, rtol=1e-9)
    gain, rank = base.score(lambda idx: cand[idx])
    assert rank == 2
    assert np.isclose(gain, rss0 - rss1, rtol=1e-6)
    # a candidate inside the span of the design adds nothing
    inside = dense.reshape(n, 3, -1)[:, :, 3:4] * 2.0
    assert base.score(lambda idx: inside[idx])[1] == 0


@pytest.mark.parametrize("layout", ["MB1", "TT_AC"])     # TT_AC: numeric layout parameters
def test_reduced_fitting_module_equals_the_full_module(layout):
    """The loop derives only the fitting functions of its augmented layout during the run
    (derivation.fit_source); they must equal those of the full generated module."""
    from volerr.loop.run import augmented_layout_text
    from volerr.machine import derivation
    from volerr.machine.layout import parse_layout

    model = volerr.load(layout)

    class S:                                       # an accepted effect: thermal growth of X
        cand = type("C", (), {"name": "thermal_X", "kind": "thermal", "info": {},
                              "terms": [("KT_X", "EXX", "X*(T_C - 20)"),
                                        ("KT0_X", "EXX", "(T_C - 20)")]})()

    lay = parse_layout(augmented_layout_text(model, [S]), f"{layout}_aug.toml")
    full = derivation.module_from_source(derivation.generate_source(lay), lay.name)
    red = derivation.module_from_source(derivation.fit_source(lay), lay.name)
    for k in ("AXES", "ROTARY_AXES", "PARAMETERS", "PARAMETER_AXIS", "COVARIATES"):
        assert getattr(red, k) == getattr(full, k)
    rng = np.random.default_rng(5)
    pos = {a: rng.uniform(0, 500, 50) for a in full.AXES}
    probe = {k: rng.uniform(-80, 80, 50) for k in ("Xp", "Yp", "Zp")}
    cov = {"T_C": rng.uniform(18, 24, 50)}
    assert np.array_equal(red.sensitivity(**pos, **cov, **probe),
                          full.sensitivity(**pos, **cov, **probe))
    assert np.array_equal(red.setup_sensitivity(**pos, **probe),
                          full.setup_sensitivity(**pos, **probe))
    assert "exact_error" not in red.__dict__
