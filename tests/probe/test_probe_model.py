"""Combined volumetric error with the probe error (Pahk eq. 14-17) against independent
computations: a numpy construction of the probe frame, and a simulated trigger probe
measuring surface points with pretravel."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import volerr
from volerr.probe import calibration as probe
from volerr.probe import plans as pp

R_S, R_BALL = 25.006, 1.006
C0 = np.array([10.0, 20.0, 30.0])


def frame(a_deg, b_deg):
    """Probe frame columns from eq. (11) by numpy cross products (0 < A < 180)."""
    a, b = math.radians(a_deg), math.radians(b_deg)
    ez = np.array([-math.sin(a) * math.cos(b), -math.sin(a) * math.sin(b), math.cos(a)])
    ey = np.cross(ez, [0, 0, 1.0])
    ey /= np.linalg.norm(ey)
    return np.column_stack([np.cross(ey, ez), ey, ez])


def independent_angles(dirs, a_deg, b_deg):
    m = dirs @ frame(a_deg, b_deg)  # rows: (e'_x.M, e'_y.M, e'_z.M) = M' (eq. 14)
    m = m / np.linalg.norm(m, axis=1)[:, None]
    phi = np.degrees(np.arccos(np.clip(m[:, 2], -1, 1)))           # eq. (15)
    theta = np.degrees(np.arctan2(m[:, 1], m[:, 0])) % 360.0         # eq. (16), quadrant
    return phi, theta


@pytest.fixture(scope="module")
def calibration():
    pts = pp.simulate_probing(pp.pahk_plan(), C0, R_S, R_BALL, noise_mm=0.2e-3, tilt_deg=40.0,
                              roll_deg=25.0, rng=4)
    return probe.calibrate(pts, R_S, tilt_deg=40.0, roll_deg=25.0)


def directions_in_cap(rng, n, a_deg, b_deg, phi_max=85.0):
    """Machine-frame directions whose probe-frame phi is below phi_max."""
    v = rng.normal(size=(6 * n, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    v = v[v[:, 2] > math.cos(math.radians(phi_max))][:n]
    return v @ frame(a_deg, b_deg).T


@pytest.mark.parametrize("layout", ["MB1", "MH2", "FB1", "CY"])
def test_combined_model_eq17(calibration, layout):
    """Model.volumetric_error(direction=M, probe_error=map) = geometric error + Probe(M) M
    (actual minus nominal; M the outward normal)."""
    model = volerr.load(layout)
    rng = np.random.default_rng(hash(layout) % 2**32)
    n = 50
    lo_hi = [model.travel[a] for a in model.axes]
    pos = np.column_stack([rng.uniform(lo, hi, n) for lo, hi in lo_hi])
    errs = {p: rng.normal(0, 5e-3 if p.startswith("E") and p[1] in "XYZ" else 10e-6, n)
            for p in model.parameters}
    off = (12.0, -7.0, -150.0)
    for a, b in [(40.0, 25.0), (75.0, -100.0), (10.0, 170.0)]:
        pmap = calibration.map.oriented(a, b)
        d = directions_in_cap(rng, n, a, b)
        geo = model.volumetric_error(pos, errs, probe=off)
        combined = model.volumetric_error(pos, errs, probe=off, direction=d, probe_error=pmap)
        phi, theta = independent_angles(d, a, b)
        expect = geo + calibration.map.at(phi, theta)[:, None] * d
        np.testing.assert_allclose(combined, expect, atol=1e-12)
        # a non-unit direction is normalised by the model
        again = model.volumetric_error(pos, errs, probe=off, direction=3.5 * d, probe_error=pmap)
        np.testing.assert_allclose(again, combined, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.floats(0.5, 179.5), st.floats(-180, 180))
def test_map_in_any_orientation(a, b):
    """The map belongs to the probe: directions in the probe frame, whatever the head angles."""
    pts = pp.simulate_probing(pp.pahk_plan(), C0, R_S, R_BALL, noise_mm=0.0)
    cal = probe.calibrate(pts, R_S)
    rng = np.random.default_rng(0)
    d = directions_in_cap(rng, 20, a, b)
    phi, theta = independent_angles(d, a, b)
    np.testing.assert_allclose(cal.map.oriented(a, b)(d), cal.map.at(phi, theta), atol=1e-12)


def test_vertical_probe_is_machine_frame():
    pts = pp.simulate_probing(pp.pahk_plan(), C0, R_S, R_BALL, noise_mm=0.0)
    cal = probe.calibrate(pts, R_S)  # A = B = 0
    v = np.random.default_rng(1).normal(size=(30, 3))
    v[:, 2] = np.abs(v[:, 2]) + 0.1
    v /= np.linalg.norm(v, axis=1)[:, None]
    phi = np.degrees(np.arccos(v[:, 2]))
    theta = np.degrees(np.arctan2(v[:, 1], v[:, 0])) % 360
    np.testing.assert_allclose(cal.map(v), cal.map.at(phi, theta), atol=1e-12)


def test_measurement_with_pretravel(calibration):
    """Physics: a trigger probe (head at A = 40, B = 25) with pretravel delta(M) measures
    surface points; after the stylus qualification on the sphere (centre and R_eff), the
    error along the surface normal M is -Probe(M), which the combined model reproduces."""
    a, b = 40.0, 25.0
    rng = np.random.default_rng(9)
    model = volerr.load("MB1")
    n = 80
    pos = np.column_stack([rng.uniform(0, 500, n), rng.uniform(0, 400, n),
                           rng.uniform(-300, 0, n)])
    errs = {"EXX": rng.normal(0, 3e-3, n), "EC0Y": 20e-6, "EBY": rng.normal(0, 5e-6, n)}
    geo = model.volumetric_error(pos, errs)
    m = directions_in_cap(rng, n, a, b)                  # outward normals at the contacts
    phi, theta = independent_angles(m, a, b)
    delta = pp.pahk_like_pretravel(np.radians(phi), np.radians(theta))
    surface = rng.uniform(-100, 100, (n, 3))
    # recorded ball centre: contact + (r - pretravel) M; the machine reads its nominal
    # position, actual minus the geometric error (geo = actual - nominal); the qualification
    # subtracts the sphere-centre bias and the effective radius
    centre_bias = calibration.center - C0
    recorded = surface - geo + (R_BALL - delta)[:, None] * m
    measured = recorded - centre_bias - calibration.r_eff * m
    err = measured - surface                             # reported minus true = -(combined)
    combined = model.volumetric_error(pos, errs, direction=m,
                                      probe_error=calibration.map.oriented(a, b))
    normal = np.sum((err + combined) * m, axis=1)
    assert np.sqrt(np.mean(normal ** 2)) < 0.25e-3      # within the calibration noise
    assert np.max(np.abs(normal)) < 0.8e-3
    # without the probe term the normal error would be off by the lobing (several um)
    plain = np.sum((err + geo) * m, axis=1)
    assert np.sqrt(np.mean(plain ** 2)) > 2e-3


def test_per_point_head_angles(calibration):
    """A head that changes tilt/roll from point to point: same as one orientation at a time."""
    rng = np.random.default_rng(3)
    a = rng.uniform(5, 90, 25)
    b = rng.uniform(-180, 180, 25)
    v = rng.normal(size=(25, 3))
    v[:, 2] = np.abs(v[:, 2]) + 0.2                      # probe-frame directions, phi < 90
    v /= np.linalg.norm(v, axis=1)[:, None]
    d = np.stack([frame(ai, bi) @ vi for ai, bi, vi in zip(a, b, v)])
    many = calibration.map.oriented(a, b)(d)
    one = [calibration.map.oriented(ai, bi)(di[None, :])[0] for ai, bi, di in zip(a, b, d)]
    np.testing.assert_allclose(many, one, atol=1e-15)
    model = volerr.load("MB1")
    pos = np.zeros((25, 3))
    out = model.volumetric_error(pos, {}, direction=d, probe_error=calibration.map.oriented(a, b))
    np.testing.assert_allclose(out, many[:, None] * d, atol=1e-15)
    with pytest.raises(volerr.InputError, match="one value per direction"):
        calibration.map.oriented(a[:3], b[:3])(d)
