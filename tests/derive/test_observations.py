"""The instruments' generated observation equations against independent computations: exact
ballbar lengths and sphere offsets by finite differences, and the layouts' workpiece rotation
against the exact numpy chain of tests/helpers/reference_chain.py."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from helpers import reference_chain as ref
from volerr.generated import instruments
from volerr.machine.layout import read_layout

coords = st.floats(-500, 500)


@settings(max_examples=40, deadline=None)
@given(t=st.tuples(coords, coords, coords), p=st.tuples(coords, coords, coords),
       e=st.tuples(*[st.floats(-1e-3, 1e-3)] * 3), s=st.tuples(*[st.floats(-1e-3, 1e-3)] * 4))
def test_ballbar_first_order_matches_exact_length(t, p, e, s):
    t, p, e, s = map(np.array, (t, p, e, s))
    length = float(np.linalg.norm(t - p))
    if length < 50:
        return
    m = instruments.ballbar(*t, *p, length)[0]          # (8,)
    exact = np.linalg.norm(t + e - p - s[:3]) - length + s[3]
    first = m[0] + m[1:4] @ e + m[4:8] @ s
    # second-order remainder: |e - dp|^2 / (2 L) at most
    assert abs(exact - first) <= np.sum((e - s[:3]) ** 2) / length + 1e-15
    assert abs(m[0]) < 1e-9


def test_sphere_reading_is_tool_minus_centre():
    rng = np.random.default_rng(3)
    t, c, e, dc = rng.normal(0, 100, (4, 3))
    m = instruments.sphere(*t, *c)                       # (3, 7)
    np.testing.assert_allclose(m[:, 0] + m[:, 1:4] @ e + m[:, 4:7] @ dc, t + e - c - dc,
                               atol=1e-12)


@pytest.mark.parametrize("name", ["DMU50", "TT_AC", "TH_BC", "HH_BC", "MB1"])
def test_work_rotation_against_exact_chain(name):
    """A vector fixed in the workpiece frame, seen in the base frame: the exact chain moves a
    workpiece point by the table's rotation, which the generated rotation must reproduce."""
    import volerr

    model = volerr.load(name)
    lay = read_layout(name)
    rng = np.random.default_rng(5)
    for _ in range(4):
        q = {a: rng.uniform(*lay.axes[a].travel) for a in lay.axis_names}
        qr = {a: np.deg2rad(v) if lay.axes[a].kind == "rotary" else v for a, v in q.items()}
        m_work = np.eye(4)
        for entry in reversed(lay.workpiece_chain):
            m_work = m_work @ ref.stage(lay, entry, qr, {}, table=True)
        base2work = m_work[:3, :3]
        R = model.module.work_rotation(**qr)
        np.testing.assert_allclose(np.asarray(R, float).reshape(3, 3), base2work.T, atol=1e-12)


# ---- issue 20: artifact, distances, interferometer -----------------------------------------
small = st.floats(-1e-3, 1e-3)


@settings(max_examples=30, deadline=None)
@given(t=st.tuples(coords, coords, coords), e=st.tuples(small, small, small),
       rv=st.tuples(*[st.floats(-np.pi, np.pi)] * 3), p=st.tuples(coords, coords, coords),
       s=st.tuples(*[small] * 9))
def test_artifact_first_order_matches_exact(t, e, rv, p, s):
    """Reading = R^T (t + e - a), a = o + R (d + Rot(r) (p + c)) exactly, R any rotation:
    the generated columns reproduce it to second order in (e, d, r, c)."""
    from scipy.spatial.transform import Rotation

    t, e, p, s = map(np.array, (t, e, p, s))
    R = Rotation.from_rotvec(rv).as_matrix()
    o = t - R @ p + np.array([0.3, -0.2, 0.1])           # nominal reading about (0.3, -0.2, 0.1)
    m = instruments.artifact(*t, *o, *R.ravel(), *p)     # (3, 13)
    d, r, c = s[:3], s[3:6], s[6:9]
    a = o + R @ (d + Rotation.from_rotvec(r).apply(p + c))
    exact = R.T @ (t + e - a)
    first = m[:, 0] + m[:, 1:4] @ e + m[:, 4:13] @ s
    lever = np.linalg.norm(p) + 1.0
    assert np.max(np.abs(exact - first)) <= (np.sum(r ** 2) * lever + np.sum(r ** 2) ** 0.5
                                             * np.sum(c ** 2) ** 0.5 + 1e-9)
    np.testing.assert_allclose(m[:, 0], R.T @ (t - o) - p, atol=1e-9)


@settings(max_examples=30, deadline=None)
@given(t=st.tuples(coords, coords, coords), sp=st.tuples(coords, coords, coords),
       e=st.tuples(small, small, small), s=st.tuples(*[small] * 4))
def test_distances_first_order_matches_exact(t, sp, e, s):
    t, sp, e, s = map(np.array, (t, sp, e, s))
    length = float(np.linalg.norm(t - sp))
    if length < 50:
        return
    m = instruments.distances(*t, *sp)[0]                # (8,)
    exact = np.linalg.norm(t + e - sp - s[:3]) + s[3]
    first = m[0] + m[1:4] @ e + m[4:8] @ s
    assert abs(exact - first) <= np.sum((e - s[:3]) ** 2) / length + 1e-12
    assert abs(m[0] - length) < 1e-9


def test_interferometer_readings_are_the_stated_projections():
    """Positioning (1 + k) b.(t + e - r) + z, straightness s.(t + e - r) + z + m b.(t + e - r),
    angular b.((t2 + e2) - (t + e)) / L + z: linear parts exactly, products k e and m e
    second order."""
    rng = np.random.default_rng(4)
    t, r, e, t2, e2 = rng.normal(0, 100, (5, 3))
    e, e2 = 1e-3 * e / 100, 1e-3 * e2 / 100
    b = rng.normal(size=3)
    b /= np.linalg.norm(b)
    s = np.cross(b, rng.normal(size=3))
    s /= np.linalg.norm(s)
    k, z, mm = 2e-6, 3e-4, 5e-6
    m = instruments.interferometer_positioning(*t, *b, *r)[0]        # (6,) z, k
    exact = (1 + k) * b @ (t + e - r) + z
    assert abs(m[0] + m[1:4] @ e + m[4:6] @ (z, k) - exact) <= abs(k * b @ e) + 1e-12
    m = instruments.interferometer_straightness(*t, *s, *b, *r)[0]   # (6,) z, m
    exact = s @ (t + e - r) + z + mm * b @ (t + e - r)
    assert abs(m[0] + m[1:4] @ e + m[4:6] @ (z, mm) - exact) <= abs(mm * b @ e) + 1e-12
    L = 30.0
    m = instruments.interferometer_angular(*t, *t2, *b, L)[0]        # (8,) e1, e2, z
    exact = b @ ((t2 + e2) - (t + e)) / L + z
    assert abs(m[0] + m[1:4] @ e + m[4:7] @ e2 + m[7] * z - exact) < 1e-12
