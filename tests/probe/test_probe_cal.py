"""Master-sphere calibration (Pahk eq. 13) on simulated kinematic-probe lobing.

The reference is an independent linear computation: to first order the least-squares sphere
absorbs the part of the pretravel pattern spanned by (1, Mx, My, Mz) over the probed points
(mean radius and centre shift), so the recoverable Probe is the residual of that linear fit
of the true pretravel, and centre / R_eff follow from its coefficients."""

from __future__ import annotations

import math

import numpy as np
import pytest

from volerr import InputError
from volerr.probe import calibration as probe
from volerr.probe import plans as pp

R_S = 25.006
R_BALL = 1.006
C0 = np.array([412.5, -73.25, 118.0])


def expected(plan, pretravel, tilt=0.0, roll=0.0, eval_dirs=None):
    """Independent first-order prediction: (centre, R_eff, Probe at the points (mm), and the
    recoverable map at ``eval_dirs`` (machine frame))."""
    u = plan.directions(tilt, roll)
    pt = pretravel(np.radians(plan.phi_deg), np.radians(plan.theta_deg))
    x = np.column_stack([np.ones(len(u)), u])
    coef, *_ = np.linalg.lstsq(x, pt, rcond=None)
    out = [C0 - coef[1:], R_BALL - coef[0], pt - x @ coef]
    if eval_dirs is not None:
        ph, th = probe.angles_of(eval_dirs, tilt, roll)
        pe = pretravel(np.radians(ph), np.radians(th))
        out.append(pe - np.column_stack([np.ones(len(eval_dirs)), eval_dirs]) @ coef)
    return out


def random_dirs_in_cap(rng, n, tilt=0.0, roll=0.0, phi_max=88.0):
    v = rng.normal(size=(4 * n, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    v = v[v[:, 2] > math.cos(math.radians(phi_max))][:n]
    return v @ probe.probe2machine(tilt, roll).T  # probe-frame cap -> machine frame


def test_pahk_plan():
    plan = pp.pahk_plan()
    assert len(plan) == 101
    assert plan.phi_deg[0] == 0.0
    phis, counts = np.unique(plan.phi_deg[1:], return_counts=True)
    np.testing.assert_allclose(phis, [18, 36, 54, 72, 90])
    assert set(counts) == {20}
    np.testing.assert_allclose(np.unique(plan.theta_deg[1:]), np.arange(0, 360, 18))
    custom = pp.circles_plan([30, 60, 85], 12, pole=False)
    assert len(custom) == 36


def test_sphere_fit_exact_and_independent():
    rng = np.random.default_rng(3)
    d = rng.normal(size=(40, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    d[:, 2] = np.abs(d[:, 2])  # a hemisphere
    pts = C0 + 12.3 * d
    fit = probe.fit_sphere(pts)
    np.testing.assert_allclose(fit.center, C0, atol=1e-10)
    assert fit.radius == pytest.approx(12.3, abs=1e-10)
    # noisy: same optimum as an independent solver from a poor start
    from scipy.optimize import least_squares

    noisy = pts + 0.002 * rng.normal(size=pts.shape)
    fit = probe.fit_sphere(noisy)
    ref = least_squares(lambda q: np.linalg.norm(noisy - q[:3], axis=1) - q[3],
                        np.r_[C0 + 1.0, 10.0], xtol=1e-15, ftol=1e-15, gtol=1e-15)
    np.testing.assert_allclose(fit.center, ref.x[:3], atol=1e-9)
    assert fit.radius == pytest.approx(ref.x[3], abs=1e-9)
    assert fit.radius == pytest.approx(np.linalg.norm(noisy - fit.center, axis=1).mean())


@pytest.mark.parametrize("seed,scale,noise_um", [(0, 1.0, 0.0), (1, 1.0, 0.3), (2, 0.4, 0.2),
                                                 (3, 2.5, 0.5), (4, 1.0, 1.0)])
def test_pahk_simulation_recovered(seed, scale, noise_um):
    rng = np.random.default_rng(100 + seed)
    plan = pp.pahk_plan()

    def pretravel(phi, theta):
        return pp.pahk_like_pretravel(phi, theta, scale=scale, orientation_deg=37.0 * seed)

    pts = pp.simulate_probing(plan, C0, R_S, R_BALL, pretravel, noise_um * 1e-3, rng=rng)
    dirs = random_dirs_in_cap(rng, 300)
    c_exp, reff_exp, probe_exp, map_exp = expected(plan, pretravel, eval_dirs=dirs)
    cal = probe.calibrate(pts, R_S)
    noise = noise_um * 1e-3
    n = len(plan)
    # centre and R_eff: within the noise of a 101-point fit (plus 10 nm of second order)
    tol_c = 4 * noise * math.sqrt(8.0 / n) + 1e-5
    np.testing.assert_allclose(cal.center, c_exp, atol=tol_c)
    assert cal.r_eff == pytest.approx(reff_exp, abs=tol_c)
    # Probe at every point: within the (radial) noise
    diff = cal.probe - probe_exp
    assert np.sqrt(np.mean(diff ** 2)) <= 1.3 * noise + 1e-5
    assert np.max(np.abs(diff)) <= 5 * noise + 1e-5
    # the smooth map anywhere in the probed cap: within the noise (smoothing averages it)
    est = cal.map(dirs)
    assert np.sqrt(np.mean((est - map_exp) ** 2)) <= 0.9 * noise + 1e-4
    assert np.max(np.abs(est - map_exp)) <= 4 * noise + 4e-4
    # nothing flagged on clean Gaussian noise
    assert not cal.outlier.any()
    # reported statistics are those of the per-point values
    s = cal.summary()["probe_error_um"]
    assert s["max"] == pytest.approx(cal.probe.max() * 1e3)
    assert s["rms"] == pytest.approx(math.sqrt(np.mean(cal.probe ** 2)) * 1e3)


@pytest.mark.parametrize("tilt,roll", [(0.0, 0.0), (30.0, 45.0), (90.0, -120.0)])
def test_tilted_probe_directions_and_map(tilt, roll):
    """The map lives in the probe frame: a tilted head gives the same Probe(phi, theta)."""
    rng = np.random.default_rng(7)
    plan = pp.pahk_plan()
    pts = pp.simulate_probing(plan, C0, R_S, R_BALL, pp.pahk_like_pretravel, 0.2e-3,
                              tilt, roll, rng=rng)
    cal = probe.calibrate(pts, R_S, tilt_deg=tilt, roll_deg=roll)
    np.testing.assert_allclose(cal.phi_deg, plan.phi_deg, atol=0.05)  # centre shift 8 um
    dtheta = (cal.theta_deg - plan.theta_deg + 180) % 360 - 180
    assert np.all(np.abs(dtheta[1:]) < 0.05)
    dirs = random_dirs_in_cap(rng, 200, tilt, roll)
    *_, map_exp = expected(plan, pp.pahk_like_pretravel, tilt, roll, dirs)
    assert np.sqrt(np.mean((cal.map(dirs) - map_exp) ** 2)) < 0.2e-3
    # the same calibration read with the nominal directions given as columns
    cal2 = probe.calibrate(pts, R_S, plan.phi_deg, plan.theta_deg, tilt, roll)
    assert cal2.direction_source == "columns"
    np.testing.assert_allclose(cal2.probe, cal.probe, atol=1e-12)
    assert np.median(cal2.direction_mismatch_deg) < 0.05 and not cal2.notes


def test_pahk_like_figures():
    """Pahk's example: 25.006 mm sphere, 1 mm ball, 101 points -> R_eff 0.997 mm,
    Probe max 6.6 / min -9.0 / rms 4.0 um.  The simulated kinematic probe lands close."""
    pts = pp.simulate_probing(pp.pahk_plan(), C0, R_S, R_BALL, noise_mm=0.3e-3, rng=11)
    cal = probe.calibrate(pts, R_S)
    s = cal.summary()
    assert s["r_eff_mm"] == pytest.approx(0.997, abs=0.0005)
    assert s["probe_error_um"]["max"] == pytest.approx(6.6, abs=1.0)
    assert s["probe_error_um"]["min"] == pytest.approx(-9.0, abs=1.0)
    assert s["probe_error_um"]["rms"] == pytest.approx(4.0, abs=0.5)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_outlier_flagged_not_dropped(seed):
    rng = np.random.default_rng(seed)
    plan = pp.pahk_plan()
    pts = pp.simulate_probing(plan, C0, R_S, R_BALL, noise_mm=0.3e-3, rng=rng)
    k = int(rng.integers(1, len(plan)))
    u = (pts[k] - C0) / np.linalg.norm(pts[k] - C0)
    bad = pts.copy()
    bad[k] -= 0.008 * u  # a dust particle: 8 um short
    cal = probe.calibrate(bad, R_S)
    assert np.flatnonzero(cal.outlier).tolist() == [k]
    assert cal.used.all() and len(cal.probe) == len(plan)
    ref = probe.calibrate(pts, R_S)
    assert cal.probe[k] - ref.probe[k] > 0.007
    refit = probe.calibrate(bad, R_S, exclude_outliers=True)
    assert refit.outlier[k] and not refit.used[k]
    others = np.arange(len(plan)) != k
    assert (np.abs(refit.probe - ref.probe)[others].max()
            < np.abs(cal.probe - ref.probe)[others].max())


def test_map_outside_probed_range():
    pts = pp.simulate_probing(pp.pahk_plan(), C0, R_S, R_BALL, noise_mm=0.1e-3, rng=1)
    cal = probe.calibrate(pts, R_S)
    below = np.array([[0.0, 0.6, -0.8]])  # phi = 143 deg: never probed
    with pytest.raises(InputError, match="outside the calibrated range"):
        cal.map(below)
    clamped = cal.map.with_outside("clamp")(below)
    edge = cal.map.at(cal.map.phi_range_deg[1], probe.angles_of(below)[1])
    np.testing.assert_allclose(clamped, edge)


def test_map_csv_round_trip(tmp_path):
    pts = pp.simulate_probing(pp.pahk_plan(), C0, R_S, R_BALL, noise_mm=0.2e-3, rng=5)
    cal = probe.calibrate(pts, R_S)
    path = tmp_path / "map.csv"
    path.write_text(probe.map_csv_text(cal))
    m = probe.read_probe_map(path)
    dirs = random_dirs_in_cap(np.random.default_rng(0), 100)
    assert m.degree == cal.map.degree
    np.testing.assert_allclose(m(dirs), cal.map(dirs), atol=2e-6)
    import json

    exact = probe.probe_map_from_json(json.loads(json.dumps(cal.summary())))
    np.testing.assert_allclose(exact(dirs), cal.map(dirs), atol=1e-12)
    with pytest.raises(InputError, match="not a probe-cal report"):
        probe.probe_map_from_json({"r_eff_mm": 1.0})


def test_spherical_harmonics_orthonormal():
    """The real harmonics are orthonormal on the sphere (Gauss-Legendre x uniform quadrature)."""
    x, w = np.polynomial.legendre.leggauss(24)
    theta = np.linspace(0, 2 * math.pi, 48, endpoint=False)
    pp_, tt = np.meshgrid(np.arccos(x), theta, indexing="ij")
    ww = np.outer(w, np.full(48, 2 * math.pi / 48)).ravel()
    y = probe.sh_design(6, pp_.ravel(), tt.ravel())
    np.testing.assert_allclose(y.T @ (ww[:, None] * y), np.eye(49), atol=1e-10)


@pytest.mark.parametrize("make,match", [
    (lambda p: p[:5], "at least 6"),
    (lambda p: np.column_stack([p[:, 0], p[:, 1], np.full(len(p), 3.0)]), "one plane"),
    (lambda p: p[41:61], "one plane"),  # a single latitude circle (with lobing)
    (lambda p: p[[0] + list(range(1, 101, 10))], "one plane"),  # theta 0 / 180 only
    (lambda p: np.where(np.arange(len(p))[:, None] == 3, np.nan, p), "NaN"),
])
def test_degenerate_inputs(make, match):
    pts = pp.simulate_probing(pp.pahk_plan(), C0, R_S, R_BALL, noise_mm=0.0)
    with pytest.raises(InputError, match=match):
        probe.calibrate(make(pts), R_S)


def test_tiny_cap_refused():
    pts = pp.simulate_probing(pp.circles_plan([1.0, 2.0], 12), C0, R_S, R_BALL,
                              noise_mm=0.3e-3, rng=2)
    with pytest.raises(InputError, match="cover too little|one plane"):
        probe.calibrate(pts, R_S)


def test_sphere_radius_that_does_not_fit():
    pts = pp.simulate_probing(pp.pahk_plan(), C0, R_S, R_BALL, noise_mm=0.0)
    with pytest.raises(InputError, match="not a diameter"):
        probe.calibrate(pts, 2 * R_S)
    with pytest.raises(InputError, match="not a plausible stylus"):
        probe.calibrate(pts, 0.5)
    with pytest.raises(InputError, match="positive"):
        probe.calibrate(pts, -1.0)
    fit_radius = probe.fit_sphere(pts).radius
    with pytest.raises(InputError, match="not a plausible stylus"):
        probe.calibrate(pts, fit_radius - 0.001)  # a 1 um ball


def test_type_a_uncertainty_matches_scatter():
    """u(centre), u(R_eff) from the map residuals against the scatter of repeated runs."""
    plan = pp.pahk_plan()
    runs = [probe.calibrate(pp.simulate_probing(plan, C0, R_S, R_BALL, noise_mm=0.5e-3,
                                                rng=1000 + k), R_S) for k in range(60)]
    sd_c = np.std([r.center for r in runs], axis=0, ddof=1)
    sd_r = np.std([r.r_eff for r in runs], ddof=1)
    u_c = np.mean([r.u_center for r in runs], axis=0)
    u_r = np.mean([r.u_r_eff for r in runs])
    assert np.all((0.7 < u_c / sd_c) & (u_c / sd_c < 1.6)), (u_c, sd_c)
    assert 0.7 < u_r / sd_r < 1.6
    assert 0.4e-3 < np.mean([r.noise for r in runs]) < 0.65e-3   # radial noise 0.5 um


def test_map_hole_in_azimuth():
    """Half of the azimuths never probed: directions there are refused, or clamped to the
    nearest probed direction."""
    plan = pp.pahk_plan()
    keep = (plan.theta_deg < 180) | (plan.phi_deg == 0)
    half = pp.Plan(plan.phi_deg[keep], plan.theta_deg[keep])
    pts = pp.simulate_probing(half, C0, R_S, R_BALL, noise_mm=0.1e-3, rng=3)
    cal = probe.calibrate(pts, R_S)
    assert cal.map.coverage_deg == pytest.approx(27.0, abs=0.5)   # 1.5 x 18 deg spacing
    inside = probe.directions_of([60.0], [90.0])
    cal.map(inside)                                             # fine
    hole = probe.directions_of([60.0], [270.0])
    with pytest.raises(InputError, match="nearest probed direction"):
        cal.map(hole)
    clamped = cal.map.with_outside("clamp")(hole)
    u = half.directions()
    k = int(np.argmax(u @ hole[0]))
    np.testing.assert_allclose(clamped, cal.map.at(cal.phi_deg[k], cal.theta_deg[k]))


def test_plot_with_uncalibrated_hole(tmp_path):
    from volerr.probe.plots import plot_probe_map_2d

    plan = pp.pahk_plan()
    keep = (plan.theta_deg < 180) | (plan.phi_deg == 0)
    pts = pp.simulate_probing(pp.Plan(plan.phi_deg[keep], plan.theta_deg[keep]), C0, R_S,
                              R_BALL, noise_mm=0.1e-3, rng=3)
    cal = probe.calibrate(pts, R_S)
    grid = cal.map.covered(*np.meshgrid([30.0, 60.0], [90.0, 270.0]))
    assert grid[0].all() and not grid[1].any()
    out = plot_probe_map_2d(cal, tmp_path / "half.png")
    assert out.read_bytes()[:4] == b"\x89PNG"
