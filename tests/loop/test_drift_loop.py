"""The loop on drift runs, piece by piece: the split rule, the cross-validation from
cross-products against plain refits, a planted heat response found, nothing found in noise,
a held-out run predicted from its own zero, refusals (one line, exit 2, nothing written)."""

from __future__ import annotations

import numpy as np
import pytest

from volerr.errors import InputError
from helpers import drift_sim as D
from volerr.loop.drift import basis as B
from volerr.loop.drift import fit as core
from volerr.loop.drift.engine import Engine
from volerr.loop.drift.split import parse_window, stretch_split


def _first_order(u, tau, dt):
    """Independent first-order lag, tau y' + y = u, sampled every ``dt`` (exact for ``u``
    linear between samples: :func:`helpers.drift_sim.lag`)."""
    return D.lag(u, tau, dt)


def _series(n=3000, dt=30.0, plant=True, seed=1, runs=1):
    rng = np.random.default_rng(seed)
    t_all, run, S_all, T1, T2, y_all = [], [], [], [], [], []
    for r in range(runs):
        t = np.arange(n) * dt
        cycle = (t // 7200).astype(int)
        S = np.where(cycle % 2 == 1, np.array([1500.0, 4000.0, 2500.0])[(cycle // 2 + r) % 3],
                     0.0)        # several speeds: the exponent is determined
        q = (S / 4000.0) ** 1.5
        room = 20 + 0.5 * np.sin(2 * np.pi * t / 20000.0 + r)
        t_all.append(t), run.append(np.full(n, r)), S_all.append(S)
        T1.append(room + rng.normal(0, 0.01, n))
        T2.append(room + 0.3 * np.sin(2 * np.pi * t / 5000.0) + rng.normal(0, 0.01, n))
        y = 0.3 * r + rng.normal(0, 0.1, n)
        if plant:
            y = y + 12.0 * _first_order(q, 1800.0, dt)
        y_all.append(y)
    c = np.concatenate
    return B.DriftSeries(c(t_all), c(run), [(f"r{r}.csv", "") for r in range(runs)],
                         {"S_rpm": c(S_all), "T_a": c(T1), "T_b": c(T2)}, {"x": c(y_all)},
                         {"x": "X"}, {"x": None})


def test_window_units_and_open_ends():
    assert parse_window("100035s:") == (100035.0, np.inf)
    assert parse_window(":2h") == (-np.inf, 7200.0)
    assert parse_window("30min:1.5h") == (1800.0, 5400.0)
    for bad in ("100035", "5s:2s", ":", "ab:cd", "3 km:"):
        with pytest.raises(InputError):
            parse_window(bad)


def test_cross_validation_from_cross_products_equals_refits():
    rng = np.random.default_rng(3)
    n, n_runs = 240, 2
    run = np.repeat([0, 1], n // 2)
    R = (run[:, None] == np.arange(n_runs)).astype(float)
    X = rng.normal(size=(n, 4))
    Z = np.column_stack([R, X])
    y = X @ [1.0, -2.0, 0.5, 0.0] + run + rng.normal(0, 0.1, n)
    fold = np.tile(np.repeat(np.arange(4), 30), 2)
    eng = Engine(Z, y, fold, False, run, n_runs)
    W = np.eye(6)[:, :3]                       # zeros + column 0
    cands = np.array([[3, -1], [4, 5]])        # column 1; column 2 - column 3
    got, base = eng.cv_many(W, cands)
    for i, cols in enumerate([Z[:, [0, 1, 2, 3]], np.column_stack([Z[:, :3], Z[:, 4] - Z[:, 5]])]):
        sse = 0.0
        for k in range(4):
            tr, te = fold != k, fold == k
            b = np.linalg.lstsq(cols[tr], y[tr], rcond=None)[0]
            sse += float(np.sum((y[te] - cols[te] @ b) ** 2))
        assert got[i] == pytest.approx(sse, rel=1e-8)
    # whole-run folds: the held-out run is predicted from its first reading (its zero; the
    # basis columns of the loop are zero there, so the prediction is y_first + X b)
    fold_r = run.copy()
    eng = Engine(Z, y, fold_r, True, run, n_runs)
    sse = 0.0
    for k in range(2):
        tr, te = fold_r != k, fold_r == k
        cols = Z[:, [0, 1, 2]]
        b = np.linalg.lstsq(cols[tr], y[tr], rcond=None)[0]
        i0 = np.flatnonzero(te)[0]
        sse += float(np.sum((y[te] - y[i0] - X[te, 0] * b[2]) ** 2))
    assert eng.cv_sse(W) == pytest.approx(sse, rel=1e-8)


def test_planted_heat_response_found_with_its_time_constant():
    s = _series()
    s.test = s.t_s >= 0.75 * s.t_s[-1]
    res = core.run_drift(s)["channels"]["x"]
    heat = [t for t in res["terms"] if t["source"] == "heat"]
    assert heat and heat[0]["p"] == 1.5
    assert abs(heat[0]["tau_s"] / 1800.0 - 1) < 0.15
    assert all(t["source"] == "heat" for t in res["terms"])
    f = res["fit"]
    after = core.predict(s, f["design"], np.concatenate([f["zeros"], f["coef"]]), res["y"])
    assert np.mean(np.abs((res["y"] - after)[s.test])) < 0.1


def test_noise_alone_no_term():
    s = _series(plant=False, seed=4)
    s.test = s.t_s >= 0.75 * s.t_s[-1]
    assert core.run_drift(s)["channels"]["x"]["terms"] == []


def test_a_held_out_run_is_predicted_from_its_own_zero():
    s = _series(runs=3, n=1500)
    s.test = s.run == 2
    res = core.run_drift(s)
    assert res["fold_rule"] == "stretches"      # two training runs: stretches of each
    r = res["channels"]["x"]
    f = r["fit"]
    after = core.predict(s, f["design"], np.concatenate([f["zeros"], f["coef"]]), r["y"])
    first = np.flatnonzero(s.run == 2)[0]
    assert after[first] == r["y"][first]
    y2 = r["y"].copy()
    y2[s.run == 2] += 5.0                       # another zero of the held-out run
    after2 = core.predict(s, f["design"], np.concatenate([f["zeros"], f["coef"]]), y2)
    np.testing.assert_allclose(after2[s.run == 2] - after[s.run == 2], 5.0)


def test_stretch_split_holds_out_whole_stretches():
    t = np.arange(1000.0)
    test = stretch_split(t, None, 0.25)
    assert test.sum() == 250
    edges = np.flatnonzero(np.diff(test.astype(int)))
    assert len(edges) <= 10                     # 5 blocks of 50: never single readings
    assert not test[:50].any()


def _write(path, s, run):
    m = s.run == run
    names = ["t_s", "S_rpm", "T_a", "T_b", "d_x_um"]
    cols = [s.t_s[m], s.inputs["S_rpm"][m], s.inputs["T_a"][m], s.inputs["T_b"][m],
            s.channels["x"][m]]
    lines = ["# channel d_x: X", ",".join(names)]
    lines += [",".join(f"{c[i]:.6f}" for c in cols) for i in range(int(m.sum()))]
    path.write_text("\n".join(lines) + "\n")


def test_cli_refusals_one_line_nothing_written(tmp_path):
    import subprocess
    import sys

    s = _series(runs=2, n=400)
    _write(tmp_path / "a.csv", s, 0)
    _write(tmp_path / "b.csv", s, 1)
    cases = [["--holdout-time", "10 parsecs:"], ["--holdout-files", "zz.csv"],
             ["--holdout-time", "0s:1e9s"], ["--out-dir", "o"]]
    for extra in cases:
        r = subprocess.run([sys.executable, "-m", "volerr", "loop", "DMU50", "drift:a.csv",
                            "drift:b.csv", "--json", "j.json", *extra], cwd=tmp_path,
                           capture_output=True, text=True)
        assert r.returncode == 2, (extra, r.stderr)
        assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr
        assert not (tmp_path / "j.json").exists()
    r = subprocess.run([sys.executable, "-m", "volerr", "loop", "DMU50", "drift:a.csv",
                        "drift:b.csv", "--json", "j.json", "--predictions-out", "p.csv",
                        "--html", "p.html"], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "the last run (b.csv) held out" in r.stdout
    head = (tmp_path / "p.csv").read_text().splitlines()[0]
    assert head == "file,run,t_s,channel,measured_um,before_um,after_um,split,half_width_um"
    assert "<img" in (tmp_path / "p.html").read_text()


def test_3d_loop_split_by_time_window_or_stretches():
    from types import SimpleNamespace

    from volerr.loop.run import _split

    n = 400
    dat = SimpleNamespace(n=n, covariates={"t_min": np.arange(n) * 0.5}, file=np.zeros(n, int))
    spl = _split(dat, 0, 0.25, None, "100min:")         # t_min: 0 .. 199.5 min
    np.testing.assert_array_equal(spl.test, np.arange(200, n))
    spl = _split(dat, 0, 0.25, None)                     # default: stretches, not random
    assert len(spl.test) == 100 and len(np.flatnonzero(np.diff(spl.test) > 1)) <= 4
    with pytest.raises(InputError):
        _split(SimpleNamespace(n=n, covariates={}, file=None), 0, 0.25, None, "1s:")
