"""Probe frame (Pahk eq. 11-12), direction conversion (eq. 14-16): derivation and generated code
against an independent numpy construction of eq. 11's cross products."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from volerr.probe import calibration as probe
from volerr.generated import probe as gen

angles = st.floats(min_value=-720.0, max_value=720.0, allow_nan=False)
tilts = st.floats(min_value=0.01, max_value=179.99, allow_nan=False)


def construct_basis(a_deg: float, b_deg: float) -> np.ndarray:
    """Eq. (11) built literally with numpy cross products: columns e'_x, e'_y, e'_z."""
    a, b = math.radians(a_deg), math.radians(b_deg)
    ez = np.array([-math.sin(a) * math.cos(b), -math.sin(a) * math.sin(b), math.cos(a)])
    ey = np.cross(ez, [0.0, 0.0, 1.0])
    ey /= np.linalg.norm(ey)
    ex = np.cross(ey, ez)
    ex /= np.linalg.norm(ex)
    return np.column_stack([ex, ey, ez])


@settings(max_examples=200, deadline=None)
@given(tilts, angles)
def test_generated_probe2machine_is_eq11_construction(a, b):
    r = probe.probe2machine(a, b)
    np.testing.assert_allclose(r, construct_basis(a, b), atol=1e-12)
    np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-12)
    assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(probe.machine2probe(a, b), r.T, atol=1e-15)


@settings(max_examples=100, deadline=None)
@given(tilts, angles)
def test_printed_closed_forms_of_eq11(a, b):
    """The closed forms printed in eq. (11) are the cross-product construction."""
    ar, br = math.radians(a), math.radians(b)
    printed = np.column_stack([
        [math.cos(ar) * math.cos(br), math.cos(ar) * math.sin(br), math.sin(ar)],
        [-math.sin(br), math.cos(br), 0.0],
        [-math.sin(ar) * math.cos(br), -math.sin(ar) * math.sin(br), math.cos(ar)]])
    np.testing.assert_allclose(printed, construct_basis(a, b), atol=1e-12)


@settings(max_examples=100, deadline=None)
@given(angles, angles, st.lists(st.floats(-1, 1, allow_nan=False), min_size=3, max_size=3))
def test_tp_is_orthonormal_for_any_angles(a, b, m):
    tp = probe.machine2probe(a, b)
    np.testing.assert_allclose(tp @ tp.T, np.eye(3), atol=1e-12)
    v = np.asarray(m)
    # eq. (14) with the printed matrix (= probe2machine): M' = Tp^-1 M
    printed = probe.probe2machine(a, b)
    np.testing.assert_allclose(np.linalg.solve(printed, v), tp @ v, atol=1e-12)
    mp = gen.direction_to_probe(*probe._head_angles_rad(a, b), *v)
    np.testing.assert_allclose(np.array(mp), tp @ v, atol=1e-12)


@pytest.mark.parametrize("b", [0.0, 30.0, -135.0])
def test_vertical_probe(b):
    """A = 0: eq. (11) is undefined (the cross product vanishes); as the issue states, the
    probe frame is then the machine frame, whatever the roll.  Just off vertical the eq. (11)
    construction is the machine frame turned by the roll (its limit A -> 0+)."""
    ez = np.array([0.0, 0.0, 1.0])
    assert np.linalg.norm(np.cross(ez, [0, 0, 1])) == 0.0
    rz = np.array([[math.cos(math.radians(b)), -math.sin(math.radians(b)), 0],
                   [math.sin(math.radians(b)), math.cos(math.radians(b)), 0], [0, 0, 1]])
    np.testing.assert_array_equal(probe.probe2machine(0.0, b), np.eye(3))
    np.testing.assert_array_equal(probe.machine2probe(0.0, b), np.eye(3))
    np.testing.assert_allclose(construct_basis(1e-7, b), rz, atol=1e-8)
    np.testing.assert_allclose(probe.probe2machine(1e-7, b), rz, atol=1e-8)
    phi, theta = probe.angles_of([[0, 0, 1], [1, 0, 0], [0, -1, 0], [-1, 0, -1]], 0.0, b)
    np.testing.assert_allclose(phi, [0, 90, 90, 135], atol=1e-12)
    np.testing.assert_allclose(theta[1:], [0, 270, 180], atol=1e-12)


def test_sympy_derivation():
    from volerr.derive import probe as d

    a, b = d.A, d.B
    assert sp.simplify(d.probe2machine() - d.printed_tp()) == sp.zeros(3, 3)
    assert sp.simplify(d.machine2probe() * d.probe2machine() - sp.eye(3)) == sp.zeros(3, 3)
    for derived, printed in zip(d.basis(), d.printed_basis()):
        assert sp.simplify(derived - printed) == sp.zeros(3, 1)
    assert d.construction_limit_at_vertical() == sp.Matrix(
        [[sp.cos(b), -sp.sin(b), 0], [sp.sin(b), sp.cos(b), 0], [0, 0, 1]])
    # eq. (12) as stated ([x'] = Tp [x]) is NOT the printed matrix unless B and A vanish
    assert sp.simplify(d.machine2probe() - d.printed_tp()) != sp.zeros(3, 3)
    assert a.is_real


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-10, 10, allow_nan=False), min_size=3, max_size=3))
def test_direction_angles_eq15_16(m):
    v = np.asarray(m)
    n = np.linalg.norm(v)
    if n < 1e-6:
        return
    phi, theta = gen.direction_angles(*v)
    assert phi == pytest.approx(math.acos(np.clip(v[2] / n, -1, 1)), abs=1e-6)  # eq. (15)
    if math.hypot(v[0], v[1]) > 1e-6 * n:
        # eq. (16) with the quadrant: tan(theta) = My'/Mx' and the signs of cos/sin match
        assert 0.0 <= theta <= 2 * math.pi
        t_deg = probe.angles_of(v)[1][0]
        assert 0.0 <= t_deg < 360.0
        assert math.cos(theta) * math.hypot(v[0], v[1]) == pytest.approx(v[0], abs=1e-9)
        assert math.sin(theta) * math.hypot(v[0], v[1]) == pytest.approx(v[1], abs=1e-9)
    back = np.array(gen.unit_direction(phi, theta))
    np.testing.assert_allclose(back * n, v, atol=1e-9)


@settings(max_examples=100, deadline=None)
@given(tilts, angles, st.floats(0, 180), st.floats(0, 360, exclude_max=True))
def test_direction_round_trip(a, b, phi, theta):
    """Probe-frame angles -> machine direction (columns of eq. 11) -> angles (eq. 14-16)."""
    p, t = math.radians(phi), math.radians(theta)
    local = np.array([math.sin(p) * math.cos(t), math.sin(p) * math.sin(t), math.cos(p)])
    d = probe.directions_of([phi], [theta], a, b)
    np.testing.assert_allclose(d[0], construct_basis(a, b) @ local, atol=1e-12)
    p2, t2 = probe.angles_of(d, a, b)
    assert p2[0] == pytest.approx(phi, abs=1e-6)
    if 1e-3 < phi < 180 - 1e-3:
        assert (t2[0] - theta + 180) % 360 - 180 == pytest.approx(0, abs=1e-5)


def test_generated_module_is_current():
    from volerr.derive.probe import generate_module

    path = gen.__file__
    with open(path, encoding="utf-8") as fh:
        assert fh.read() == generate_module(), "generated/probe.py is stale: volerr derive --all"
