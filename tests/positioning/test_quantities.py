"""ISO 230-2 quantities against hand-computed runs (2 targets x 3 cycles) and properties."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from volerr.positioning import PositioningRun, evaluate

SQ3 = math.sqrt(3.0)


def make_run(fwd, bwd, targets=(0.0, 100.0)):
    """fwd, bwd: per target a list of cycle deviations in um -> run (mm)."""
    dev = np.array([[f, b] for f, b in zip(fwd, bwd)], dtype=float) * 1e-3
    return PositioningRun("X", targets, tuple(str(j + 1) for j in range(dev.shape[2])), dev)


# target 0 mm: forward 1 2 3, backward 0 0 3; target 100 mm: forward 4 6 8, backward 9 9 9 (um)
HAND = make_run([[1, 2, 3], [4, 6, 8]], [[0, 0, 3], [9, 9, 9]])


def test_per_target_quantities_by_hand():
    ev = evaluate(HAND)
    um = ev.per_target_um()
    # means: (1+2+3)/3 = 2, (0+0+3)/3 = 1, (4+6+8)/3 = 6, 9
    assert um["mean_fwd_um"] == pytest.approx([2.0, 6.0])
    assert um["mean_bwd_um"] == pytest.approx([1.0, 9.0])
    assert um["mean_um"] == pytest.approx([1.5, 7.5])
    assert um["reversal_um"] == pytest.approx([1.0, -3.0])
    # S (n - 1 = 2): sqrt((1 + 0 + 1)/2) = 1, sqrt((1 + 1 + 4)/2) = sqrt(3), sqrt((4+0+4)/2) = 2, 0
    assert um["s_fwd_um"] == pytest.approx([1.0, 2.0])
    assert um["s_bwd_um"] == pytest.approx([SQ3, 0.0], abs=1e-12)
    assert um["R_i_fwd_um"] == pytest.approx([4.0, 8.0])
    assert um["R_i_bwd_um"] == pytest.approx([4 * SQ3, 0.0], abs=1e-12)
    # R_i = max(2S_up + 2S_dn + |B_i|, R_up, R_dn): max(2 + 2 sqrt3 + 1, 4, 4 sqrt3) = 4 sqrt3;
    # max(4 + 0 + 3, 8, 0) = 8
    assert um["R_i_um"] == pytest.approx([4 * SQ3, 8.0])
    assert um["targets_mm"] == [0.0, 100.0]


def test_axis_figures_by_hand():
    f = evaluate(HAND).figures_um()
    expected = {
        "B_um": 3.0, "B_avg_um": (1.0 - 3.0) / 2,
        "R_fwd_um": 8.0, "R_bwd_um": 4 * SQ3, "R_um": 8.0,
        "E_fwd_um": 6.0 - 2.0, "E_bwd_um": 9.0 - 1.0,
        "E_um": max(2, 6, 1, 9) - min(2, 6, 1, 9),
        "M_um": 7.5 - 1.5,
        # A_up = max(2 + 2, 6 + 4) - min(2 - 2, 6 - 4)
        "A_fwd_um": 10.0 - 0.0,
        # A_dn = max(1 + 2 sqrt3, 9 + 0) - min(1 - 2 sqrt3, 9 - 0)
        "A_bwd_um": 9.0 - (1 - 2 * SQ3),
        "A_um": max(4, 10, 1 + 2 * SQ3, 9) - min(0, 2, 1 - 2 * SQ3, 9),
    }
    assert set(f) == set(expected)
    for k, v in expected.items():
        assert f[k] == pytest.approx(v, abs=1e-12), k


def test_E_is_bidirectional_not_max_of_unidirectional():
    # forward means 0, 10; backward means 5, 15 (reversal -5 everywhere): E_up = E_dn = 10 but
    # the two directions together span 0 .. 15
    run = make_run([[-1, 0, 1], [9, 10, 11]], [[5, 5, 5], [14, 15, 16]])
    f = evaluate(run).figures_um()
    assert f["E_fwd_um"] == pytest.approx(10.0)
    assert f["E_bwd_um"] == pytest.approx(10.0)
    assert f["E_um"] == pytest.approx(15.0)
    assert f["E_um"] > max(f["E_fwd_um"], f["E_bwd_um"]) + 4.9
    assert f["M_um"] == pytest.approx(12.5 - 2.5)


def test_sign_of_reversal_is_forward_minus_backward():
    run = make_run([[3, 3, 3], [3, 3, 3]], [[1, 1, 1], [1, 1, 1]])
    f = evaluate(run).figures_um()
    assert f["B_avg_um"] == pytest.approx(2.0)
    assert f["B_um"] == pytest.approx(2.0)
    # zero scatter: R_i = |B_i| (2S + 2S + |B|), A = E = range of both directions = 2
    assert f["R_um"] == pytest.approx(2.0)
    assert f["A_um"] == pytest.approx(2.0)


runs = st.tuples(st.integers(2, 6), st.integers(2, 6)).flatmap(
    lambda mn: arrays(np.float64, (mn[0], 2, mn[1]),
                      elements=st.floats(-50, 50, allow_nan=False, allow_subnormal=False)))
SCALAR = ("A_um", "A_fwd_um", "A_bwd_um", "B_um", "B_avg_um", "R_um", "R_fwd_um", "R_bwd_um",
          "E_um", "E_fwd_um", "E_bwd_um", "M_um")


def _run(dev_um):
    m, _, n = dev_um.shape
    return PositioningRun("X", np.arange(m) * 50.0, tuple(map(str, range(n))), dev_um * 1e-3)


@settings(max_examples=60, deadline=None)
@given(runs, st.floats(-100, 100, allow_nan=False))
def test_shift_changes_only_the_means(dev, c):
    a, b = evaluate(_run(dev)), evaluate(_run(dev + c))
    fa, fb = a.figures_um(), b.figures_um()
    for k in SCALAR:
        assert fb[k] == pytest.approx(fa[k], abs=1e-9), k
    pa, pb = a.per_target_um(), b.per_target_um()
    for k in ("mean_fwd_um", "mean_bwd_um", "mean_um"):
        assert np.allclose(np.array(pb[k]) - np.array(pa[k]), c, atol=1e-9)
    for k in ("reversal_um", "s_fwd_um", "s_bwd_um", "R_i_fwd_um", "R_i_bwd_um", "R_i_um"):
        assert np.allclose(pb[k], pa[k], atol=1e-9), k


@settings(max_examples=60, deadline=None)
@given(runs)
def test_swapping_directions(dev):
    a, b = evaluate(_run(dev)), evaluate(_run(dev[:, ::-1, :].copy()))
    fa, fb = a.figures_um(), b.figures_um()
    assert fb["B_avg_um"] == pytest.approx(-fa["B_avg_um"], abs=1e-9)
    for k in ("A_um", "B_um", "R_um", "E_um", "M_um"):        # bidirectional: unchanged
        assert fb[k] == pytest.approx(fa[k], abs=1e-9), k
    for k in ("A", "R", "E"):                                # unidirectional: exchanged
        assert fb[f"{k}_fwd_um"] == pytest.approx(fa[f"{k}_bwd_um"], abs=1e-9)
        assert fb[f"{k}_bwd_um"] == pytest.approx(fa[f"{k}_fwd_um"], abs=1e-9)


@settings(max_examples=60, deadline=None)
@given(runs)
def test_orderings_implied_by_the_definitions(dev):
    f = evaluate(_run(dev)).figures_um()
    tol = 1e-9
    assert f["E_um"] >= max(f["E_fwd_um"], f["E_bwd_um"]) - tol
    assert f["M_um"] <= f["E_um"] + tol          # the bidirectional mean lies between directions
    assert f["A_um"] >= max(f["A_fwd_um"], f["A_bwd_um"], f["E_um"]) - tol
    assert f["R_um"] >= max(f["R_fwd_um"], f["R_bwd_um"], f["B_um"]) - tol
    assert abs(f["B_avg_um"]) <= f["B_um"] + tol
    # an independent computation of E and A from the raw readings
    xm, s = dev.mean(axis=2), dev.std(axis=2, ddof=1)
    assert f["E_um"] == pytest.approx(xm.max() - xm.min(), abs=1e-9)
    assert f["A_um"] == pytest.approx((xm + 2 * s).max() - (xm - 2 * s).min(), abs=1e-9)
