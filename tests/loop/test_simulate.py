"""The virtual machine: exact chain, plans, CSV output, effects, bad input."""

import numpy as np
import pytest

import volerr
from volerr.errors import InputError
from volerr.loop.run import read_deviations
from volerr.loop.simulate import simulate

from helpers import in_process


def _rz(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def _ry(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def test_exact_chain_not_small_angle():
    """MB1 (Y, X, Z on the tool side) with a large yaw of X and a large pitch of Y: the
    simulated deviation equals the rigid-body product written out by hand, not the first-order
    model."""
    ecx, eby = 0.02, -0.015
    camp = simulate("MB1", n_points=50, seed=3, probes=[(30.0, -20.0, -120.0)],
                    errors={p: 0.0 for p in volerr.load("MB1").parameters} | {"ECX": ecx, "EBY": eby},
                    noise_um=0.0, setup_um=0.0, setup_urad=0.0)
    X, Y, Z = (camp.positions[a] for a in "XYZ")
    probe = np.array([30.0, -20.0, -120.0])
    # tool2work = Trans(Y) Ry(eby) Trans(X) Rz(ecx) Trans(Z) ; applied to the probe
    nominal = np.column_stack([X, Y, Z]) + probe
    actual = np.array([np.array([0, y, 0]) + _ry(eby) @ (np.array([x, 0, 0]) + _rz(ecx) @
                                                          (np.array([0, 0, z]) + probe))
                       for x, y, z in zip(X, Y, Z)])
    np.testing.assert_allclose(camp.deviation, actual - nominal, atol=1e-12)
    first = volerr.load("MB1").volumetric_error(camp.positions, {"ECX": ecx, "EBY": eby},
                                                 camp.probe)
    assert np.max(np.abs(first - camp.deviation)) > 1e-3   # second order is visible (mm)


def test_plan_probes_rounds_and_covariates():
    camp = simulate("FB1", n_points=120, seed=1, probes=[(0, 0, -50), (40, 0, -80)], rounds=3)
    assert camp.n_points == 120
    assert len(np.unique(camp.probe, axis=0)) == 2
    assert set(np.unique(camp.covariates["setup"])) == {1.0, 2.0, 3.0}
    # rounds repeat the same positions
    m1, m2 = camp.covariates["setup"] == 1, camp.covariates["setup"] == 2
    np.testing.assert_array_equal(camp.positions["X"][m1], camp.positions["X"][m2])
    n = np.column_stack([camp.covariates[c] for c in ("nx", "ny", "nz")])
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0)
    assert np.ptp(camp.covariates["T_C"]) > 1.0 and np.all(np.diff(np.sort(camp.covariates["t_s"])) >= 0)


def test_csv_round_trip(tmp_path):
    camp = simulate("MH2", n_points=60, seed=2)
    path = camp.write_csv(tmp_path / "d.csv")
    data = read_deviations(path, volerr.load("MH2"))
    np.testing.assert_allclose(data.deviation, camp.deviation, atol=2e-9)
    np.testing.assert_allclose(data.probe, camp.probe)
    for a in "XYZ":
        np.testing.assert_allclose(data.positions[a], camp.positions[a], atol=1e-6)
    assert {"T_C", "t_s", "dir_X", "nx", "setup"} <= set(data.covariates)


def test_noise_level_and_seed():
    a = simulate("MB1", n_points=300, seed=5, noise_um=1.0)
    b = simulate("MB1", n_points=300, seed=5, noise_um=1.0)
    np.testing.assert_array_equal(a.deviation, b.deviation)
    c = simulate("MB1", n_points=300, seed=5, noise_um=0.0)
    noise = (a.deviation - c.deviation) * 1e3
    assert 0.85 < noise.std() < 1.15


def test_thermal_effect_is_scale_growth():
    """Thermal growth of X: with everything else zero the x deviation is k * X * (T - 20)."""
    zero = {p: 0.0 for p in volerr.load("MB1").parameters}
    camp = simulate("MB1", n_points=40, seed=0, errors=zero, noise_um=0, setup_um=0,
                    setup_urad=0, effects=[{"kind": "thermal", "axis": "X", "ppm_per_K": 10}])
    expect = 10e-6 * camp.positions["X"] * (camp.covariates["T_C"] - 20.0)
    np.testing.assert_allclose(camp.deviation[:, 0], expect, atol=1e-12)
    np.testing.assert_allclose(camp.deviation[:, 1:], 0.0, atol=1e-12)


@pytest.mark.parametrize("effect", [{"kind": "warp"}, {"kind": "thermal", "ppm": 3},
                                    {"kind": "coupling", "component": "EQQ"}])
def test_bad_effects(effect):
    with pytest.raises(InputError):
        simulate("MB1", n_points=30, effects=[effect])


def _cli(*args):
    """``volerr ARGS`` in this process (``helpers.in_process``: ``main``'s exit code and
    lines; a warning a process would print is appended to stderr), without starting an
    interpreter; the entry point's own process is tests/cli/test_cli_core.py's."""
    return in_process.volerr(*args)


def test_cli_simulate(tmp_path):
    out = tmp_path / "s.csv"
    r = _cli("simulate", "MB1", "--out", str(out), "--points", "50", "--effect",
             "periodic:component=EXX,period_mm=30,um=2", "--probe", "0,0,-100")
    assert r.returncode == 0, r.stderr
    assert out.read_text().splitlines()[0].startswith("X,Y,Z,Xp,Yp,Zp,dx_um,dy_um,dz_um")


@pytest.mark.parametrize("args", [["--effect", "bogus"], ["--probe", "1,2"],
                                  ["--points", "3"], ["--effect", "thermal:axis"]])
def test_cli_simulate_bad_input(tmp_path, args):
    out = tmp_path / "s.csv"
    r = _cli("simulate", "MB1", "--out", str(out), *args)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr
    assert not out.exists()
