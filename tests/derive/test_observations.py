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
