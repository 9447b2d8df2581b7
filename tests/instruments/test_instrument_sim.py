"""Self-tests of the independent instrument simulator (tests/helpers/instrument_sim.py): its
chain against the scipy reference chain, zero errors -> zero readings, closed forms of the
set-up unknowns, a squareness and a rotary location error by hand, the frame and tool-length
conventions, and the ISO 230-4 helpers on circles with known answers."""

import numpy as np
import pytest

from helpers import instrument_sim as S
from helpers.reference_chain import tool_point as reference_tool_point

LAYOUTS = ["MB1", "CY", "FB1", "DMU50", "TT_AC", "HH_BC", "TH_BC"]


@pytest.mark.parametrize("name", LAYOUTS)
def test_chain_equals_reference_chain(name):
    """Vectorised chain == tests/helpers/reference_chain.py (exact, per point) with random
    large errors, positions and tool offsets; the inverse puts the tool point on target."""
    m = S.Machine(name)
    rng = np.random.default_rng(3)
    n = 6
    pos = {a: rng.uniform(*m.travel[a], n) for a in m.axes}
    params = m.layout.parameter_names
    err = {p: rng.normal(0, 1e-3 if p[1] in "XYZ" else 1e-4, n) for p in params}
    probe = rng.normal(0, 50, (n, 3))
    mine = m.tool_point(pos, err, probe)
    ref = np.array([reference_tool_point(
        m.layout, {a: np.deg2rad(pos[a][i]) if a in m.rotary else pos[a][i] for a in m.axes},
        {p: err[p][i] for p in params}, probe[i]) for i in range(n)])
    assert np.abs(mine - ref).max() < 1e-11
    t = rng.uniform(-60, 60, (n, 3))
    inv = m.inverse(t, {a: pos[a] for a in m.rotary}, probe, check_travel=False)
    assert np.abs(m.tool_point(inv, None, probe) - t).max() < 1e-12


def _mb1_circle(n=48, **kw):
    m = S.Machine("MB1")
    return m, S.ballbar_circle(m, "c.csv", "XY", (450.0, 290.0, 200.0), 100.0, n, **kw)


@pytest.mark.parametrize("name", ["MB1", "TT_AC", "DMU50", "HH_BC", "TH_BC"])
def test_zero_errors_give_zero_readings(name):
    m = S.Machine(name)
    if m.rotary:
        piv = {"TT_AC": (100, 0, 30), "DMU50": (80, 0, 40), "TH_BC": (80, 0, 120),
               "HH_BC": (900, 700, 300)}[name]
        bb = S.ballbar_sweep(m, "b.csv", "C", 0, 300, 11, piv, (0, 80, 0))
        tilt = [a for a in m.rotary if a != "C"][0]
        grid = [{tilt: t, "C": c} for t in (0, 20) for c in (0, 90, 200)]
        sp = S.sphere_block(m, "s.csv", {"P1": piv}, grid, frame="machine")
        assert np.abs(S.readings(m, sp, [], {})).max() < 1e-9
    else:
        bb = S.ballbar_circle(m, "b.csv", "YZ", (450, 290, 200), 120.0, 36)
    assert np.abs(S.readings(m, bb, [], {})).max() < 1e-9


def test_ballbar_setup_closed_forms():
    """A pure pivot offset dp gives dr = -u . dp (to second order |dp|^2 / 2L); a length
    offset dL gives dr = +dL exactly; the design's set-up columns are -u and 1."""
    m, b = _mb1_circle()
    dp = np.array([12.0, -7.0, 5.0])          # um
    key = f"{b.name}#P1:"
    dr = S.readings(m, b, [], {}, {key + "pivot_dx": dp[0], key + "pivot_dy": dp[1],
                                   key + "pivot_dz": dp[2]})
    t = m.tool_point(b.pos, None, b.probe)
    u = (t - b.pivot) / np.linalg.norm(t - b.pivot, axis=1)[:, None]
    second = (np.linalg.norm(dp) * 1e-3) ** 2 / (2 * 100.0) * 1e3     # um
    assert np.abs(dr - (-(u @ dp))).max() <= 1.01 * second
    assert np.abs(S.readings(m, b, [], {}, {key + "length": 3.5}) - 3.5).max() < 1e-9
    d = S.design(m, [b], [S.constant("EC0Y")])
    cols = [d.columns.index(key + k) for k in ("pivot_dx", "pivot_dy", "pivot_dz", "length")]
    assert np.abs(d.J[:, cols[:3]] + u).max() < 1e-8
    assert np.abs(d.J[:, cols[3]] - 1.0).max() < 1e-8


def test_squareness_by_hand():
    """MB1 carries EC0Y on X: the X line of motion turns by -EC0Y about z, so the tool point
    moves by (0, -a X, 0) and a ballbar in XY reads dr = -a X sin(theta) (first order)."""
    m, b = _mb1_circle()
    a = 30.0                                   # urad
    # the odd part in a: first order exactly up to third-order terms (the even part is the
    # second-order |e_perp|^2 / 2L, ~1e-3 um here)
    dr = (S.readings(m, b, [S.constant("EC0Y")], {"EC0Y": a})
          - S.readings(m, b, [S.constant("EC0Y")], {"EC0Y": -a})) / 2
    th = np.deg2rad(0.0) + 2 * np.pi * np.arange(b.n) / b.n
    hand = -a * 1e-6 * b.pos["X"] * np.sin(th) * 1e3          # um
    assert np.abs(dr - hand).max() < 1e-4
    # in-plane, once the pivot-offset part (X of the pivot) is removed: -(a R / 2) sin 2 theta
    assert np.abs(dr + a * 1e-6 * 450.0 * np.sin(th) * 1e3
                  + a * 1e-6 * 100.0 / 2 * np.sin(2 * th) * 1e3).max() < 1e-4


def test_scale_and_series_terms():
    """EXX@slope s (um/mm): e_x = s (X - mid); P2 over the range has zero mean at the ends'
    midpoint and value 1 at the ends."""
    t = S.series("EXX", 1, 200.0, 600.0)
    b = type("B", (), {"pos": {"X": np.array([200.0, 400.0, 600.0])}, "n": 3})
    assert np.allclose(t.basis(b), 1e-3 * np.array([-200.0, 0.0, 200.0]))
    t2 = S.series("EYX", 2, 200.0, 600.0)
    assert np.allclose(t2.basis(b), 1e-3 * np.array([1.0, -0.5, 1.0]))
    assert S.series("EAX", 0, 0, 1).param == "EAX@offset"


def test_rotary_location_error_by_hand():
    """TT_AC, C table (axis z through the workpiece origin) offset by EX0C = e along x: the
    sphere turns about the actual axis while the tool goes to the nominal centre, so the
    reading is the offset vector turned with the table: |d| = e at every C, and d(C) - d(0)
    has length 2 e |sin(C / 2)|."""
    m = S.Machine("TT_AC")
    grid = [{"C": c} for c in (0.0, 90.0, 180.0, 270.0)]
    b = S.sphere_block(m, "s.csv", {"P1": (100.0, 0.0, 30.0)}, grid)
    d = S.readings(m, b, [S.constant("EX0C")], {"EX0C": 10.0})
    q = np.deg2rad([0.0, 90.0, 180.0, 270.0])
    assert np.allclose(np.linalg.norm(d - d[0], axis=1), 2 * 10.0 * np.abs(np.sin(q / 2)),
                       atol=1e-6)
    assert np.allclose(np.linalg.norm(d, axis=1), 10.0, atol=1e-6)
    assert np.allclose(d[:, 2], 0.0, atol=1e-9)


def test_machine_frame_and_tool_length():
    """frame=machine: the workpiece-frame vector turned by the table's orientation (TT_AC:
    the table turns by -A about x); tool_dz moves the tool point along the tool's own z
    (HH_BC: the tool turns by +B about y)."""
    m = S.Machine("TT_AC")
    A = 30.0
    grid = [{"A": A, "C": 0.0}]
    w = S.sphere_block(m, "w.csv", {"P1": (50.0, 20.0, 40.0)}, grid, frame="work")
    k = S.sphere_block(m, "k.csv", {"P1": (50.0, 20.0, 40.0)}, grid, frame="machine")
    dw = S.readings(m, w, [], {}, {"w.csv#P1:centre_dz": 10.0})
    dk = S.readings(m, k, [], {}, {"k.csv#P1:centre_dz": 10.0})
    assert np.allclose(dw, [[0, 0, -10.0]], atol=1e-9)
    a = np.deg2rad(A)
    assert np.allclose(dk, [[0.0, -10.0 * np.sin(a), -10.0 * np.cos(a)]], atol=1e-9)
    h = S.Machine("HH_BC")
    for B in (0.0, 30.0):
        s = S.sphere_block(h, "t.csv", {"P1": (900.0, 700.0, 300.0)}, [{"B": B, "C": 0.0}])
        d = S.readings(h, s, [], {}, {"t.csv:tool_dz": 5.0})
        b = np.deg2rad(B)
        assert np.allclose(d, [[5 * np.sin(b), 0.0, 5 * np.cos(b)]], atol=1e-9)


def test_ls_circle_and_hysteresis():
    """Least-squares circle of an exact circle; G of an ellipse (a, b) about its centre is
    a - b; H of two traces differing by a constant is that constant."""
    th = np.linspace(0, 2 * np.pi, 100, endpoint=False)
    c0 = np.array([0.013, -0.021])
    pts = c0 + 100.0 * np.column_stack([np.cos(th), np.sin(th)])
    c, rho = S.ls_circle(pts)
    assert np.abs(c - c0).max() < 1e-12 and abs(rho - 100.0) < 1e-12
    dr = 3.0 * np.cos(2 * th)                         # um: an ellipse of semi-axes L +- 3 um
    g = S.evaluate_trace(th, dr, 100.0)
    assert abs(g["G_um"] - 6.0) < 1e-6 and abs(g["F_max_um"] - 3.0) < 1e-12
    assert np.abs(g["centre_offset_um"]).max() < 1e-9
    thw = th[::-1] + 0.01
    assert abs(S.hysteresis(th, 1.0 + 0 * th, thw, 0 * thw) - 1.0) < 1e-12
    # linear periodic interpolation across the 2 pi seam
    h = S.hysteresis(np.array([0.0]), np.array([0.0]), np.array([-0.1, 0.1]),
                     np.array([1.0, 3.0]))
    assert abs(h - 2.0) < 1e-12


def test_identifiability_of_a_known_design():
    """One XY circle of MB1 with its own pivot and length: it sees EC0Y (sin 2 theta) but
    neither EZZ (out of plane) nor the scale common to X and Y (= a length offset)."""
    m, b = _mb1_circle(n=72)
    lo, hi = b.pos["X"].min(), b.pos["X"].max()
    loy, hiy = b.pos["Y"].min(), b.pos["Y"].max()
    terms = [S.constant("EC0Y"), S.series("EXX", 1, lo, hi), S.series("EYY", 1, loy, hiy),
             S.constant("EB0Z")]
    ok, rel = S.identifiability(S.design(m, [b], terms))
    assert ok == {"EC0Y": True, "EXX@slope": False, "EYY@slope": False, "EB0Z": False}, rel
