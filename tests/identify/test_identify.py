"""Three-point identification: exact rigid-body simulation -> identify -> known error motions."""

import math

import numpy as np
import pytest
from helpers import in_process
from helpers.tracker_sim import simulate, smooth_errors, to_csv

from volerr.errors import InputError  # noqa: E402
from volerr.identify.solve import identify, tracker_covariance  # noqa: E402
from volerr.machine.layout import parse_layout, read_layout  # noqa: E402
from volerr.identify.tracker_io import Round, read_thesis_export, read_tracker_csv  # noqa: E402

REF = np.array([[60.0, 10.0, -150.0], [-40.0, 50.0, -100.0], [10.0, -60.0, -200.0]])
LABELS = ("P", "Q", "K")
ROTARY_LAYOUT = """
name = "RT"
kind = "machine_tool"
[axes.X]
kind = "linear"
direction = [1, 0, 0]
travel = [0, 500]
[axes.C]
kind = "rotary"
direction = [0, 0, 1]
travel = [0, 360]
[axes.B]
kind = "rotary"
direction = [0, 0.7071067811865476, 0.7071067811865476]
travel = [-90, 90]
[chain]
tool = ["X"]
workpiece = ["B", "C"]
"""


def second_order_bound(errors, points, origin=(0, 0, 0)):
    """|exact - first order| <= |e|^2 |r| (rotation) plus rounding."""
    e = np.max(np.linalg.norm(errors[:, 3:], axis=1))
    r = np.max(np.linalg.norm(np.asarray(points) - origin, axis=1))
    return e ** 2 * r + 1e-9


def _check(res, e, tol_mm, tol_rad):
    d = np.abs(res.values - e)
    assert d[:, :3].max() <= tol_mm, d[:, :3].max()
    assert d[:, 3:].max() <= tol_rad, d[:, 3:].max()


@pytest.mark.parametrize("axis,direction", [("X", (1, 0, 0)), ("Y", (0, 1, 0)),
                                            ("Z", (0, 0, 1))])
def test_linear_noise_free_recovered(axis, direction):
    pos = np.linspace(0, 400, 9)
    e = smooth_errors(pos, seed=hash(axis) % 100)
    pts = simulate("linear", REF, pos, e, direction=direction)
    for method in ("lsq", "closed"):
        res = identify([Round("r", pos, LABELS, pts)], "MB1", axis, method=method)
        b = second_order_bound(e, REF)
        # the closed form uses 6 of 9 equations: second-order terms enter with its gain
        k = 1.0 if method == "lsq" else 50.0
        _check(res, e, k * b, k * b / 50.0)
        assert np.all(res.values[0] == 0)


@pytest.mark.parametrize("sense", [1, -1])
def test_rotary_noise_free_recovered_with_origin(sense):
    lay = parse_layout(ROTARY_LAYOUT)
    pos = np.arange(0.0, 361.0, 20.0)
    e = smooth_errors(pos, seed=7)
    origin = np.array([250.0, -120.0, 30.0])
    pts = simulate("rotary", REF + origin, pos, e, direction=(0, 0, 1), origin=origin,
                   sense=sense)
    res = identify([Round("r", pos, LABELS, pts)], lay, "C", origin=origin)
    assert res.rounds[0].sense == sense
    b = second_order_bound(e, REF)
    _check(res, e, b, b / 50.0)
    # wrong origin: refused or visibly wrong, never silently "right"
    res2 = identify([Round("r", pos, LABELS, pts)], lay, "C", origin=origin + [0.2, 0, 0])
    assert np.abs(res2.values - e).max() > 1e-3


def test_inclined_rotary_axis():
    lay = parse_layout(ROTARY_LAYOUT)
    pos = np.arange(-90.0, 91.0, 10.0)
    e = smooth_errors(pos, seed=11)
    d = lay.axes["B"].direction
    pts = simulate("rotary", REF, pos, e, direction=d, sense=1)
    res = identify([Round("r", pos, LABELS, pts)], lay, "B")
    b = second_order_bound(e, REF)
    _check(res, e, b, b / 50.0)


def test_noise_several_rounds_within_propagated_uncertainty():
    pos = np.linspace(0, 500, 11)
    e = smooth_errors(pos, seed=3)
    rng = np.random.default_rng(5)
    sigma = 0.002
    R = 6
    rounds = [Round(f"r{i}", pos, LABELS, simulate("linear", REF, pos, e, noise_mm=sigma,
                                                   rng=rng)) for i in range(R)]
    res = identify(rounds, "MB1", "X")
    assert res.std is not None and res.std.shape == (11, 6)
    u_mean = res.u_tracker / math.sqrt(R)
    z = np.abs(res.values - e)[1:] / u_mean[1:]
    assert z.max() < 5.0
    # residual-based noise estimate: Delta = p - p_ref has variance 2 sigma^2 per coordinate
    est = np.mean([r.sigma_mm for r in res.rounds])
    assert 0.7 * sigma * math.sqrt(2) < est < 1.3 * sigma * math.sqrt(2)
    # Type A std agrees with the propagated uncertainty of one round (on average)
    ratio = np.mean(res.std[1:]) / np.mean(res.u_tracker[1:])
    assert 0.6 < ratio < 1.5


def test_tracker_model_uncertainty_matches_scatter():
    """Noise drawn from the AT960 covariance: the propagated u equals the observed scatter."""
    pos = np.linspace(0, 300, 4)
    e = smooth_errors(pos, seed=9)
    tracker = np.array([-2500.0, 1500.0, 400.0])
    rng = np.random.default_rng(21)
    est = []
    res = None
    for _ in range(150):
        pts = simulate("linear", REF, pos, e)
        cov = tracker_covariance(pts, tracker)
        noise = np.einsum("knab,knb->kna", np.linalg.cholesky(cov),
                          rng.normal(size=pts.shape))
        res = identify([Round("r", pos, LABELS, pts + noise)], "MB1", "X", tracker=tracker,
                       cross_check=False)
        est.append(res.values)
    est = np.array(est)
    scatter = est.std(axis=0, ddof=1)[1:]
    ratio = scatter / res.u_tracker[1:]
    assert np.all((ratio > 0.75) & (ratio < 1.3)), ratio
    # weighting by the tracker model beats equal weights on anisotropic noise
    assert res.weighted


def test_closed_form_equals_lsq_on_exact_first_order_data():
    """Data that satisfy the linear model exactly: every method gives the same answer."""
    rng = np.random.default_rng(2)
    for _ in range(5):
        ref = rng.uniform(-200, 200, size=(3, 3))
        pos = np.linspace(0, 100, 5)
        theta = rng.normal(size=(5, 6)) * [0.01, 0.01, 0.01, 1e-4, 1e-4, 1e-4]
        theta[0] = 0
        # independent first-order model: t + e x r
        pts = ref[None] + pos[:, None, None] * np.array([1.0, 0, 0]) + theta[:, None, :3] + \
            np.cross(theta[:, None, 3:], ref[None])
        r1 = identify([Round("r", pos, LABELS, pts)], "MB1", "X", method="lsq")
        r2 = identify([Round("r", pos, LABELS, pts)], "MB1", "X", method="closed")
        scale = np.array([1, 1, 1, 100, 100, 100])
        assert np.abs((r1.values - theta) * scale).max() < 1e-9
        assert np.abs((r2.values - r1.values) * scale).max() < 1e-8
        assert r1.report()["closed_form"]["consistency_max"] < 1e-9


def test_more_than_three_points_better_than_three():
    pos = np.linspace(0, 500, 6)
    e = smooth_errors(pos, seed=4)
    ref5 = np.vstack([REF, [[-80.0, -40.0, -120.0], [90.0, 70.0, -180.0]]])
    errs3, errs5 = [], []
    rng = np.random.default_rng(8)
    for _ in range(40):
        pts = simulate("linear", ref5, pos, e, noise_mm=0.002, rng=rng)
        r5 = identify([Round("r", pos, tuple("PQKAB"), pts)], "MB1", "X", cross_check=False)
        r3 = identify([Round("r", pos, LABELS, pts[:, :3])], "MB1", "X", cross_check=False)
        errs3.append(r3.values - e)
        errs5.append(r5.values - e)
    assert np.std(errs5, axis=0)[1:, 3:].mean() < np.std(errs3, axis=0)[1:, 3:].mean()


@pytest.mark.parametrize("bad", ["collinear", "coincident", "near_collinear"])
def test_degenerate_geometry_refused_with_condition_number(bad):
    pos = np.linspace(0, 100, 3)
    if bad == "collinear":
        ref = np.array([[0, 0, 0], [50, 50, 50], [100, 100, 100.0]])
    elif bad == "coincident":
        ref = np.array([[10, 10, 10], [10, 10, 10], [10, 10, 10.0]])
    else:
        ref = np.array([[0, 0, 0], [50, 50, 50], [100, 100, 100.001]])
    pts = simulate("linear", ref, pos, np.zeros((3, 6)))
    with pytest.raises(InputError, match="condition number"):
        identify([Round("r", pos, LABELS, pts)], "MB1", "X")


def test_closed_form_singular_selection_but_lsq_fine():
    """Points at equal z: Zhang & Hu's N = 0 for every selection, least squares still works."""
    ref = np.array([[60.0, 10.0, -150.0], [-40.0, 50.0, -150.0], [10.0, -60.0, -150.0]])
    pos = np.linspace(0, 100, 3)
    e = smooth_errors(pos, seed=2)
    pts = simulate("linear", ref, pos, e)
    res = identify([Round("r", pos, LABELS, pts)], "MB1", "X", cross_check=False)
    _check(res, e, second_order_bound(e, ref), 1e-8)
    with pytest.raises(InputError, match="singular"):
        identify([Round("r", pos, LABELS, pts)], "MB1", "X", method="closed")


def test_outlier_flagged():
    pos = np.linspace(0, 500, 11)
    e = smooth_errors(pos, seed=5)
    rng = np.random.default_rng(1)
    pts = simulate("linear", REF, pos, e, noise_mm=0.001, rng=rng)
    pts[6, 1, 1] += 0.05
    res = identify([Round("r", pos, LABELS, pts)], "MB1", "X")
    flagged = {(o[1], o[2]) for o in res.outliers()}
    assert (pos[6], "Q") in flagged or any(p == pos[6] for p, _ in flagged)
    assert all(p == pos[6] for p, _ in flagged)


def test_csv_and_thesis_formats_agree(tmp_path):
    pos = np.linspace(0, 500, 11)
    e = smooth_errors(pos, seed=6)
    rng = np.random.default_rng(4)
    rounds = [simulate("linear", REF, pos, e, noise_mm=0.001, rng=rng) for _ in range(2)]
    (tmp_path / "a.csv").write_text(to_csv(rounds, pos, LABELS))
    files = []
    for i, pts in enumerate(rounds):
        # thesis export: block K, then P, then Q; label per row
        order = [2, 0, 1]
        lines = [f"{LABELS[j]}{k + 1},{pts[k, j, 0]:.9f},{pts[k, j, 1]:.9f},{pts[k, j, 2]:.9f}"
                 for j in order for k in range(len(pos))]
        f = tmp_path / f"Round {i + 1}.csv"
        f.write_text("\n".join(lines) + "\n")
        files.append(f)
    r_csv = read_tracker_csv(tmp_path / "a.csv")
    r_th = [read_thesis_export(f, pos, ["K", "P", "Q"]) for f in files]
    a = identify(r_csv, "MB1", "X")
    b = identify(r_th, "MB1", "X")
    assert np.allclose(a.values, b.values, atol=1e-12)
    assert np.allclose(a.std, b.std, atol=1e-12)


def test_rounds_table_written_with_std(tmp_path):
    from volerr.tables.table import read_error_table

    pos = np.linspace(0, 500, 6)
    e = smooth_errors(pos, seed=8)
    rng = np.random.default_rng(0)
    rounds = [simulate("linear", REF, pos, e, noise_mm=1e-5, rng=rng) for _ in range(3)]
    f = tmp_path / "in.csv"
    f.write_text(to_csv(rounds, pos, LABELS))
    out = tmp_path / "X.csv"
    cp = in_process.volerr("identify", "MB1", "--axis", "X", f, "--out", out,
                           "--tracker=-2000,1000,500")      # as python -m volerr, in-process
    assert cp.returncode == 0, cp.stderr
    t = read_error_table(out)
    assert t.axis == "X" and set(t.std) == set(t.values) and set(t.u95) == set(t.values)
    assert np.allclose(t.values["EXX"], e[:, 0], atol=3e-4)
    # AT960 at ~2.2 m: the angle encoders dominate, u95(EXX) is tens of um
    assert 0.005 < t.u95["EXX"][-1] < 0.1
    assert f.read_text() == to_csv(rounds, pos, LABELS)


def test_layout_axis_direction_used():
    lay = read_layout("MB1")
    assert lay.axes["Y"].direction == (0.0, 1.0, 0.0)


def test_dmu50_inclined_b_axis_with_layout_origin():
    """DMU 50 B axis: inclined 45 deg, through (0, 0, d); table points turn about it."""
    lay = read_layout("DMU50")
    d = float(lay.parameters["d"])
    origin = np.array([0.0, 0.0, d])
    pos = np.arange(0.0, 181.0, 10.0)
    e = smooth_errors(pos, seed=13)
    table_pts = np.array([[150.0, 20.0, 30.0], [-90.0, 120.0, 60.0], [10.0, -140.0, 90.0]])
    pts = simulate("rotary", table_pts, pos, e, direction=lay.axes["B"].direction,
                   origin=origin, sense=-1)
    res = identify([Round("r", pos, LABELS, pts)], lay, "B", origin="layout")
    assert res.rounds[0].sense == -1
    b = second_order_bound(e, table_pts, origin)
    _check(res, e, b, b / 50.0)
    with pytest.raises(InputError, match="deviate"):  # origin off the axis: refused or wrong
        identify([Round("r", pos, LABELS, pts)], lay, "B")


from hypothesis import given, settings, strategies as st  # noqa: E402


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), scale=st.floats(10.0, 400.0))
def test_random_geometry_recovered(seed, scale):
    """Random well-conditioned point sets of any size and random errors: exact recovery up to
    the second-order term of the rigid-body motion."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 7))
    ref = rng.uniform(-1, 1, size=(n, 3)) * scale + rng.uniform(-300, 300, size=3)
    from volerr.identify.solve import geometry_condition
    if geometry_condition(ref) > 50:
        return
    pos = np.linspace(0, 300, 5)
    e = smooth_errors(pos, seed=seed)
    pts = simulate("linear", ref, pos, e, direction=(0, 1, 0))
    res = identify([Round("r", pos, tuple(f"p{i}" for i in range(n)), pts)], "MB1", "Y",
                   cross_check=n == 3)
    b = second_order_bound(e, ref) * 50  # gain of an off-centre frame origin
    assert np.abs(res.values - e)[:, :3].max() < b + 1e-7
    assert np.abs(res.values - e)[:, 3:].max() < b / max(scale, 1) + 1e-9


def test_round_measured_backwards_referred_to_the_first_rounds_reference():
    """A round measured in the other direction (first position 500) is referred to the first
    round's reference position (0), so the rounds average the same error motions."""
    lay = read_layout("MB1")
    pos = np.linspace(0, 500, 6)
    e = smooth_errors(pos, seed=11)
    fwd = simulate("linear", REF, pos, e)
    # the same machine measured backwards: simulated with reference at 0, rows in reverse order
    back = Round("2", pos[::-1].copy(), LABELS, fwd[::-1].copy())
    res = identify([Round("1", pos, LABELS, fwd), back], lay, "X")
    _check(res, e, second_order_bound(e, REF), 1e-8)
    assert np.allclose(res.std, 0, atol=1e-12)


def test_rotary_points_at_one_height_least_squares_default():
    """Three balls at one height on a rotary table: every Zhang & Hu selection is singular
    (they divide by height differences) but least squares is well determined; the default
    (lsq) identifies, only method="closed" is refused."""
    lay = parse_layout(ROTARY_LAYOUT)
    pos = np.arange(0.0, 360.0, 20.0)
    e = smooth_errors(pos, seed=5)
    flat = np.array([[150.0, 0.0, 50.0], [-75.0, 130.0, 50.0], [-75.0, -130.0, 50.0]])
    pts = simulate("rotary", flat, pos, e, direction=(0, 0, 1))
    res = identify([Round("r", pos, LABELS, pts)], lay, "C")
    b = second_order_bound(e, flat)
    _check(res, e, b, b / 50.0)
    with pytest.raises(InputError, match="singular"):
        identify([Round("r", pos, LABELS, pts)], lay, "C", method="closed")
