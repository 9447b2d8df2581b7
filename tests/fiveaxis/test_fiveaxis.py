"""Five-axis layouts: forward kinematics against closed forms and independent matrix products,
inverse kinematics round trips, error conventions of table rotary axes."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import volerr
from helpers.fiveaxis_chain import (D, err_htm, head_stage, loc_htm, rot, table_stage,  # noqa: F401
                                    tool2work, tool_side_linear, trans)

FAMILIES = ("DMU50", "TT_AC", "HH_BC", "TH_BC")


def random_pose(m, rng, n):
    cols = []
    for a in m.axes:
        lo, hi = m.travel[a]
        if a in m.rotary_axes:
            lo, hi = max(lo, -180), min(hi, 180)
        cols.append(rng.uniform(lo, hi, n))
    return np.column_stack(cols)


# ------------------------------------------------------------------ DMU 50 closed forms
def sorby_forward(X, Y, Z, Bdeg, Cdeg, d=D):
    """Thesis eq. 3.19-3.24 (Sorby), coded independently."""
    B, C = np.deg2rad(Bdeg), np.deg2rad(Cdeg)
    sB, cB, sC, cC = np.sin(B), np.cos(B), np.sin(C), np.cos(C)
    r2 = np.sqrt(2.0)
    i = 0.5 * (r2 * cC * sB - sC * cB + sC)
    j = 0.5 * (r2 * sC * sB + cC * cB - cC)
    k = 0.5 + 0.5 * cB
    x = r2 / 2 * (X * sC + (Y + Z - d) * cC) * sB + 0.5 * (-Y + Z - d - (Y + Z - d) * cB) * sC \
        + X * cC * cB
    y = r2 / 2 * ((Y + Z - d) * sC - X * cC) * sB + X * sC * cB + 0.5 * (
        (Y + Z - d) * cC * cB + (Y - Z + d) * cC)
    z = 0.5 * (-r2 * X * sB + (Y + Z - d) * cB - Y + Z + d)
    return np.column_stack([x, y, z, i, j, k])


def test_dmu50_is_listed_and_declares_d():
    assert "DMU50" in volerr.layouts()
    m = volerr.load("DMU50")
    assert m.axes == ("X", "Y", "Z", "B", "C")
    assert m.layout.parameters["d"] == pytest.approx(154.996)
    b = np.array(m.layout.axes["B"].direction)
    # inclined at 45 deg, not orthogonal (nor parallel) to any linear axis
    assert np.all(np.abs(b @ np.eye(3)) > 0.1) or np.count_nonzero(np.abs(b) > 1e-12) == 2
    assert np.degrees(np.arccos(abs(b[2]))) == pytest.approx(45.0)


def test_dmu50_forward_matches_sorby_closed_forms():
    m = volerr.load("DMU50")
    rng = np.random.default_rng(1)
    q = random_pose(m, rng, 500)
    got = m.forward(q)
    want = sorby_forward(*q.T)
    assert np.abs(got - want).max() < 1e-10


@pytest.mark.parametrize("name", FAMILIES)
def test_forward_matches_independent_matrix_product(name):
    m = volerr.load(name)
    rng = np.random.default_rng(2)
    q = random_pose(m, rng, 40)
    tool = np.array([3.0, -2.0, 40.0])
    f = m.forward(q, tool)
    for row, out in zip(q, f):
        t = tool2work(name, dict(zip(m.axes, row)), {})
        assert np.allclose(out[:3], (t @ np.r_[tool, 1.0])[:3], atol=1e-10)
        assert np.allclose(out[3:], t[:3, 2], atol=1e-12)


@pytest.mark.parametrize("name", FAMILIES)
def test_exact_error_matches_independent_matrix_product(name):
    """All error parameters at once, large enough that second-order terms show (1 mrad)."""
    m = volerr.load(name)
    rng = np.random.default_rng(3)
    q = random_pose(m, rng, 10)
    tool = np.array([1.0, 2.0, 60.0])
    for row in q:
        e = {p: rng.normal(0, 0.02 if p[1] in "XYZ" else 1e-3) for p in m.parameters}
        got = m.exact_error(row, e, probe=tool)[0]
        qd = dict(zip(m.axes, row))
        want = (tool2work(name, qd, e) @ np.r_[tool, 1]
                - tool2work(name, qd, {}) @ np.r_[tool, 1])[:3]
        assert np.allclose(got, want, atol=1e-11), (name, got, want)
        # the first-order model differs at second order: 10x smaller errors, ~100x smaller
        first = np.abs(m.volumetric_error(row, e, probe=tool)[0] - want).max()
        e10 = {p: v / 10 for p, v in e.items()}
        want10 = (tool2work(name, qd, e10) @ np.r_[tool, 1]
                  - tool2work(name, qd, {}) @ np.r_[tool, 1])[:3]
        first10 = np.abs(m.volumetric_error(row, e10, probe=tool)[0] - want10).max()
        assert first10 < first / 50


@pytest.mark.parametrize("name", FAMILIES)
def test_orientation_error_is_first_order_of_exact_tool_axis(name):
    m = volerr.load(name)
    rng = np.random.default_rng(4)
    row = random_pose(m, rng, 1)[0]
    e = {p: rng.normal(0, 1e-7 if p[1] in "ABC" else 1e-4) for p in m.parameters}
    qd = dict(zip(m.axes, row))
    want = tool2work(name, qd, e)[:3, 2] - tool2work(name, qd, {})[:3, 2]
    got = m.orientation_error(row, e)[0]
    assert np.allclose(got, want, atol=1e-12)


def test_table_location_error_turns_with_the_table():
    """An offset of the C axis line moves the tool relative to the workpiece by a vector that
    turns with C (a constant vector in the workpiece frame would only be a setup shift)."""
    m = volerr.load("DMU50")
    cs = np.arange(0, 360, 45.0)
    q = np.column_stack([np.full(8, 10.0), np.full(8, 20.0), np.full(8, 100.0), np.zeros(8), cs])
    e = m.volumetric_error(q, {"EX0C": 0.01})
    want = np.column_stack([0.01 * np.cos(np.deg2rad(cs)), 0.01 * np.sin(np.deg2rad(cs)),
                            np.zeros(8)])
    assert np.allclose(e, want, atol=1e-15)


# ------------------------------------------------------------------ inverse kinematics
def test_inverse_keeps_full_precision_next_to_the_singular_orientation():
    """1e-7 .. 1e-3 deg from the singular orientation (tool axis along C) the closed form alone
    loses half the digits (a square root of a difference of nearly equal numbers: 1.2e-8 rad
    at 1e-6 deg); forward(inverse(f)) must still be f to rounding."""
    m = volerr.load("DMU50")
    b = np.array([1e-7, 1e-6, 1e-5, 1e-4, 1e-3, -1e-6])
    q = np.column_stack([np.full(6, 10.0), np.full(6, -20.0), np.full(6, 150.0), b,
                         np.full(6, 33.0)])
    f = m.forward(q)
    qi = m.inverse(f, near=q)
    assert np.abs(m.forward(qi) - f).max() < 1e-12
    assert np.allclose(qi[:, 3], b, rtol=1e-6, atol=1e-12)


@pytest.mark.parametrize("name", FAMILIES)
@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_inverse_after_forward_is_identity(name, data):
    m = volerr.load(name)
    vals = []
    for a in m.axes:
        lo, hi = m.travel[a]
        if a in m.rotary_axes:
            lo, hi = max(lo, -179.0), min(hi, 179.0)
        vals.append(data.draw(st.floats(lo, hi, allow_nan=False), label=a))
    q = np.array([vals])
    tool = np.array([0.0, 0.0, data.draw(st.floats(-100, 100), label="tool_z")])
    f = m.forward(q, tool)
    # away from the singular orientation (tool axis along the first rotary axis) the rotary
    # positions are unique up to the branch; forward(inverse(f)) must always reproduce f
    qi = m.inverse(f, tool, near=q)
    assert np.allclose(m.forward(qi, tool), f, atol=1e-8)
    rot = dict(zip(m.rotary_axes, q[0, 3:, None]))
    sens = min(volerr.machine.kinematics._axis_sensitivity(m, rot, a)[0] for a in m.rotary_axes)
    if sens > 1e-3:
        assert np.allclose(qi, q, atol=1e-7)


def test_dmu50_inverse_matches_printed_inverse_branch():
    """Eq. 3.25 takes B in [0, 180 deg]: the generated inverse picks that branch inside the
    travel and agrees with eq. 3.25-3.26 coded here."""
    m = volerr.load("DMU50")
    rng = np.random.default_rng(5)
    q = random_pose(m, rng, 200)
    q[:, 3] = rng.uniform(1, 179, 200)
    f = m.forward(q)
    qi = m.inverse(f)
    i, j, k = f[:, 3], f[:, 4], f[:, 5]
    s = np.sqrt(2 * (k - k * k))
    b = np.degrees(np.arccos(2 * k - 1))
    c = np.degrees(np.arctan2((1 - k) * i + s * j, s * i + (k - 1) * j))
    assert np.allclose(qi[:, 3], b, atol=1e-8)
    assert np.allclose((qi[:, 4] - c + 180) % 360 - 180, 0, atol=1e-8)


def test_singular_orientation_keeps_the_previous_rotary_position():
    m = volerr.load("DMU50")
    q = np.array([[10.0, 20.0, 30.0, 0.0, 77.0]])
    f = m.forward(q)
    qi = m.inverse(f, near=q)
    assert np.allclose(qi, q, atol=1e-9)
    qi0 = m.inverse(f)  # no reference: C undetermined -> middle of the travel (0)
    assert qi0[0, 4] == pytest.approx(0.0)
    assert np.allclose(m.forward(qi0), f, atol=1e-9)


def test_inverse_refuses_bad_input():
    m = volerr.load("DMU50")
    with pytest.raises(volerr.errors.InputError):
        m.inverse([[0, 0, 0, 0, 0, 0]])
    with pytest.raises(volerr.errors.InputError):
        m.inverse([[0, 0, 0, np.nan, 0, 1]])
    with pytest.raises(volerr.errors.InputError):
        volerr.load("MB1").inverse([[0, 0, 0, 0, 0, 1]])
