"""Task-specific Monte Carlo against independent computations (GUM linear, LS Jacobian,
constrained machines re-tested by hand, chunk/worker invariance, bad input)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import volerr
from volerr.cli import main
from volerr.tables import ErrorFunctions, ErrorTable
from volerr.uncertainty import ensemble, iso10360, montecarlo as mc, tasks

MB1 = volerr.load("MB1")


def _task(points, directions=None):
    p = np.asarray(points, float)
    return tasks.Task({"X": p[:, 0], "Y": p[:, 1], "Z": p[:, 2]}, np.zeros_like(p),
                      None if directions is None else np.asarray(directions, float))


def _exx_funcs(std_um):
    nodes = np.linspace(0, 900, 10)
    t = ErrorTable("X", nodes, {"EXX": 1e-6 * nodes}, std={"EXX": np.full(10, std_um * 1e-3)})
    return ErrorFunctions({"X": t}, {}, MB1)


@pytest.mark.parametrize("mode", ["repeatability", "systematic"])
def test_linear_distance_equals_gum(mode):
    """Distance along X, only EXX uncertain (Gaussian): the adaptive Monte Carlo result agrees
    with the GUM linear propagation of Model.random_error within JCGM 101's numerical
    tolerance (7.9.2), and passes the validation of JCGM 101 8 (interval endpoints)."""
    funcs = _exx_funcs(0.8)
    pts = np.array([[100.0, 200.0, 100.0], [700.0, 200.0, 100.0]])  # both on table nodes
    task = _task(pts)
    ens = ensemble.Ensemble.build(funcs, mode=mode)
    prob = mc.prepare(MB1, "MB1", task, "distance", ens, seed=3)
    values, _, rec = mc.run_adaptive(prob, n_dig=2)
    assert rec.converged
    # GUM: d = x2 - x1 - (e2x - e1x) (reading = actual - e); independent nodes -> quadrature
    r = MB1.random_error(pts, funcs.sigmas(pts))
    u_gum = math.hypot(r[0, 0], r[1, 0])
    q = mc.summarize(prob, values)["distance"]
    delta = mc.numerical_tolerance(q["standard_uncertainty_um"] * 1e-3, 2)
    assert abs(q["standard_uncertainty_um"] * 1e-3 - u_gum) <= delta
    y = 600.0 - (funcs(pts)["EXX"][1] - funcs(pts)["EXX"][0])
    assert abs(q["bias_um"] * 1e-3 - (y - 600.0)) < 1e-12
    U95 = 1.959964 * u_gum
    assert abs(y - U95 - q["coverage_interval_mm"][0]) <= delta
    assert abs(y + U95 - q["coverage_interval_mm"][1]) <= delta


def test_systematic_between_nodes_is_correlated():
    """Two points between the same two nodes share the perturbation of those nodes: the GUM
    result with the linear-interpolation weights (computed here) is reproduced."""
    funcs = _exx_funcs(1.0)
    pts = np.array([[110.0, 0, 0], [130.0, 0, 0]])  # between nodes 100 and 200
    prob = mc.prepare(MB1, "MB1", _task(pts), "distance", ensemble.Ensemble.build(funcs), seed=1)
    v, _ = mc.run(prob, 40000)
    w1 = np.array([0.9, 0.1])   # weights of nodes 100, 200 at x = 110
    w2 = np.array([0.7, 0.3])   # ... at x = 130
    u = 1e-3 * np.linalg.norm(w2 - w1)
    s = v[:, 0].std(ddof=1)
    assert abs(s - u) < 4 * u / math.sqrt(2 * 40000)
    # point-wise independence would give sqrt(0.82 + 0.58) um instead: clearly different
    assert s < 0.5 * 1e-3 * math.sqrt(0.82 + 0.58)


def test_sphere_diameter_probe_noise_against_ls_jacobian():
    """Pure probe noise along the probing directions: u(diameter) and u(centre) from the
    linearised least-squares propagation cov = sigma^2 (J^T J)^-1 of the geometric sphere fit."""
    rng = np.random.default_rng(5)
    n = rng.normal(size=(17, 3))
    n[:, 2] = np.abs(n[:, 2])  # a hemisphere, as probed on a CMM
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    c, R, sigma = np.array([400.0, 300.0, 150.0]), 12.5, 0.7e-3
    pts = c + R * n
    J = np.column_stack([-n, -np.ones(17)])  # d(|p - c| - r)/d(c, r)
    cov = sigma ** 2 * np.linalg.inv(J.T @ J)
    u_d, u_c = 2 * math.sqrt(cov[3, 3]), np.sqrt(np.diag(cov)[:3])
    ens = ensemble.Ensemble.build(noise_um=0.7)
    prob = mc.prepare(MB1, "MB1", _task(pts, n), "sphere", ens, seed=11)
    N = 40000
    v, _ = mc.run(prob, N)
    s = v.std(axis=0, ddof=1)
    tol = 4 / math.sqrt(2 * N)
    assert abs(s[0] / u_d - 1) < tol
    assert np.all(np.abs(s[1:] / u_c - 1) < tol)
    assert abs(v[:, 0].mean() - 2 * R) < 4 * u_d / math.sqrt(N) + 1e-9


def test_temperature_distance():
    """Part 1 K +- 0.3 K above 20 C, CTE 11.5e-6 +- 1e-6 /K, compensated: u(L) of a 500 mm
    distance from the product's first-order propagation."""
    pts = np.array([[100.0, 100, 100], [600.0, 100, 100]])
    T = ensemble.Temperature(part_cte=11.5e-6, u_part_cte=1e-6, part_dt=1.0, u_part_dt=0.3,
                             compensated=True)
    prob = mc.prepare(MB1, "MB1", _task(pts), "distance",
                      ensemble.Ensemble.build(temperature=T), seed=2)
    v, _ = mc.run(prob, 40000)
    u = 500 * math.sqrt((1.0 * 1e-6) ** 2 + (11.5e-6 * 0.3) ** 2 + (1e-6 * 0.3) ** 2)
    assert abs(v[:, 0].std(ddof=1) / u - 1) < 0.03
    assert abs(mc.summarize(prob, v)["distance"]["bias_um"]) < 1e-9


# ---------------------------------------------------------------------------------------------
def _distance_u(spec_text, a, b, seed=4, n=3000):
    spec = ensemble.parse_spec(spec_text)
    prob = mc.prepare(MB1, "MB1", _task(np.array([a, b])), "distance",
                      ensemble.Ensemble.build(spec=spec, seed=seed), seed=seed)
    v, info = mc.run(prob, n)
    return v[:, 0].std(ddof=1), spec


def test_constrained_machines_pass_the_test_by_independent_check():
    """Every kept machine, re-tested here with Model.volumetric_error: |E| <= MPE."""
    spec = ensemble.parse_spec("E0=1.5+L/400")
    src = ensemble.SpecMachines(spec, 0.0, seed=9)
    test = iso10360.length_test(MB1)
    # the task = the test's gauge-face points, so the drawn errors are the machines there
    pts = test.targets.reshape(-1, 3)
    src.prepare(MB1, _task(pts), None)
    d = src.draw(np.random.default_rng(1), 100, MB1)
    assert d.info["kept"] == 100 and d.info["candidates"] > 100  # some were rejected
    lengths = test.lengths
    for s in range(100):
        errs = {k: np.broadcast_to(v[s], (pts.shape[0],)) for k, v in d.errors.items()}
        e = MB1.volumetric_error(pts, errs).reshape(test.targets.shape)
        u = test.targets[:, :, 1] - test.targets[:, :, 0]
        u /= np.linalg.norm(u, axis=-1, keepdims=True)
        E = -np.sum((e[:, :, 1] - e[:, :, 0]) * u, axis=-1)  # reading = actual - e
        assert np.all(np.abs(E) * 1e3 <= spec.A_um + lengths / spec.K + 1e-9)


def test_constrained_uncertainty_shrinks_and_small_part_far_below_mpe():
    a, b = [250.0, 150.0, 100.0], [650.0, 400.0, 300.0]
    L = float(np.linalg.norm(np.subtract(b, a)))
    u_loose, loose = _distance_u("E0=3+L/250", a, b)
    u_tight, tight = _distance_u("E0=1.5+L/500", a, b)
    assert u_tight < 0.7 * u_loose
    assert 2 * u_loose * 1e3 < loose.mpe_um(L)
    # a 20 mm length in the middle of the volume
    c = np.array([450.0, 287.5, 200.0])
    u_small, _ = _distance_u("E0=3+L/250", c - [10, 0, 0], c + [10, 0, 0])
    assert 2 * u_small * 1e3 < 0.2 * loose.mpe_um(20.0)


# ---------------------------------------------------------------------------------------------
def _circle_problem(seed=7):
    th = np.linspace(0, 2 * np.pi, 9, endpoint=False)
    n = np.column_stack([np.cos(th), np.sin(th), np.zeros(9)])
    pts = np.array([420.0, 260.0, 180.0]) + 15 * n
    funcs = _exx_funcs(0.5)
    ens = ensemble.Ensemble.build(funcs, noise_um=0.4)
    return mc.prepare(MB1, "MB1", _task(pts, n), "circle", ens, seed=seed)


def test_same_seed_any_chunking_identical():
    prob = _circle_problem()
    v1, _ = mc.run(prob, 1900, mc.Runner(chunks=1))
    v7, _ = mc.run(prob, 1900, mc.Runner(chunks=7))
    assert np.array_equal(v1, v7)
    other, _ = mc.run(_circle_problem(seed=8), 1900)
    assert not np.array_equal(v1, other)


@pytest.mark.slow
def test_same_seed_dask_local_cluster_identical():
    pytest.importorskip("dask.distributed", reason="dask is an optional extra (volerr[dask])")
    prob = _circle_problem()
    v1, _ = mc.run(prob, 1900, mc.Runner(chunks=1))
    with mc.Runner("dask", chunks=5, workers=2) as runner:
        vd, _ = mc.run(prob, 1900, runner)
    assert np.array_equal(v1, vd)


# ---------------------------------------------------------------------------------------------
def _write(path, text):
    path.write_text(text)
    return str(path)


def _cli_error(capsys, argv):
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    return err


def test_bad_input_one_line(tmp_path, capsys):
    good = _write(tmp_path / "t.csv", "X,Y,Z\n100,100,100\n300,100,100\n")
    out = str(tmp_path / "o.json")
    base = ["uncertainty", "MB1", "--json", out, "--noise-um", "1", "--samples", "500",
            "--contributions", "0", "--quiet"]
    assert "unknown evaluation" in _cli_error(capsys, base + ["--task", good, "--evaluate",
                                                               "cone"])
    assert "needs at least 4 points" in _cli_error(capsys, base + ["--task", good,
                                                                    "--evaluate", "sphere"])
    nan = _write(tmp_path / "n.csv", "X,Y,Z\n100,100,100\nnan,100,100\n")
    assert "NaN" in _cli_error(capsys, base + ["--task", nan, "--evaluate", "distance"])
    err = _cli_error(capsys, ["uncertainty", "MB1", "--task", good, "--evaluate", "distance",
                              "--spec", "E0=0.2+L/1e9", "--noise-um", "5", "--samples", "300",
                              "--json", out, "--quiet"])
    assert "no sampled machine satisfies" in err
    assert "--spec" in _cli_error(capsys, base + ["--task", good, "--evaluate", "distance",
                                                   "--spec", "E0=5"])
    assert not (tmp_path / "o.json").exists()
    # and a good run writes the contract's keys
    assert main(base + ["--task", good, "--evaluate", "distance"]) == 0
    doc = json.loads((tmp_path / "o.json").read_text())
    q = doc["quantities"]["distance"]
    assert set(q) >= {"estimate_mm", "bias_um", "standard_uncertainty_um",
                      "expanded_uncertainty_um", "coverage_interval_mm"}
    assert doc["samples"] == 500
    # perfect machine, isotropic noise 1 um per coordinate: u(distance along X) = sqrt(2) um
    assert abs(q["standard_uncertainty_um"] / math.sqrt(2) - 1) < 0.15
