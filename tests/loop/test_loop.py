"""The closing loop: each undeclared effect kind is found, attributed and removed; clean data
give nothing; identifiability; augmented layouts; report files.  Simulated campaigns use the
exact chain (volerr.loop.simulate), the loop the first-order generated model: an honest round
trip.  Layouts, magnitudes and seeds vary from case to case."""

import json

import numpy as np
import pytest

import volerr
from volerr.loop.run import run_loop
from volerr.loop.simulate import demo_probes, simulate

CASES = [
    # (layout, effect, seed, rounds, check)
    ("MB1", {"kind": "thermal", "axis": "X", "ppm_per_K": 11.5}, 1, 1,
     lambda e: e["info"]["axis"] == "X" and abs(e["parameters"]["KT_X"] - 11.5) < 0.5),
    ("MH2", {"kind": "thermal", "axis": "Y", "ppm_per_K": 6.0}, 2, 1,
     lambda e: e["info"]["axis"] == "Y" and abs(e["parameters"]["KT_Y"] - 6.0) < 0.5),
    ("FB1", {"kind": "drift", "direction": "z", "um_per_h": 1.5}, 3, 1,
     lambda e: e["name"] == "drift_z" and abs(e["parameters"]["DR_Z"] - 1.5) < 0.2),
    ("MH2", {"kind": "reversal", "axis": "X", "um": 3.0}, 4, 1,
     lambda e: e["name"] == "reversal_X" and abs(e["parameters"]["RV_X"] - 3.0) < 0.3),
    ("FB1", {"kind": "coupling", "component": "EZX", "axis": "Y", "um": 5.0}, 5, 1,
     lambda e: e["name"] in ("coupling_EZX_Y", "coupling_EZY_X")
     and abs(abs(e["parameters"][f"CP_{e['info']['component']}_{e['info']['depends_on']}_11"]) - 5.0) < 0.5),
    ("MB1", {"kind": "periodic", "component": "EYY", "period_mm": 30.0, "um": 1.5}, 6, 1,
     lambda e: e["name"] == "periodic_EYY" and abs(e["info"]["period"] - 30.0) < 0.6
     and abs(np.hypot(*e["parameters"].values()) - 1.5) < 0.2),
    ("MB1", {"kind": "higher_order", "component": "EZX", "um": 3.0, "degree": 10}, 7, 1,
     lambda e: e["name"] == "higher_order_EZX"),
    ("FB1", {"kind": "probe_direction", "um": 2.0}, 8, 1,
     lambda e: abs(e["parameters"]["PR_R"] - 2.0) < 0.2),
    ("MH2", {"kind": "setup", "um": 8.0, "urad": 15.0}, 9, 2,
     lambda e: e["name"] == "setup_setup"),
]


@pytest.mark.parametrize("layout,effect,seed,rounds,check", CASES,
                         ids=[f"{c[1]['kind']}-{c[0]}" for c in CASES])
def test_effect_found_attributed_removed(layout, effect, seed, rounds, check):
    model = volerr.load(layout)
    camp = simulate(layout, n_points=400, seed=seed, probes=demo_probes(model), rounds=rounds,
                    effects=[effect], noise_um=0.3, magnitude_um=4.0 + seed % 3)
    rep = run_loop(layout, camp, seed=seed, progress=False)
    kinds = [e["kind"] for e in rep["effects"]]
    assert kinds and kinds[0] == effect["kind"], kinds
    assert all(k == effect["kind"] for k in kinds), kinds   # nothing spurious besides it
    assert check(rep["effects"][0]), rep["effects"][0]
    # held-out error clearly reduced, down to about the noise (3-D: sqrt(3) * 0.3 um)
    assert rep["rms_after_um"] < 0.7 * rep["rms_before_um"]
    assert rep["rms_after_um"] < 0.75
    assert set(rep["augmented_parameters"]) == set(rep["effects"][0]["parameters"])


@pytest.mark.parametrize("layout,seed,magnitude,noise", [("MB1", 11, 5.0, 0.3),
                                                          ("MH2", 12, 15.0, 0.1),
                                                          ("FB1", 13, 3.0, 0.8)])
def test_clean_data_nothing_found(layout, seed, magnitude, noise):
    model = volerr.load(layout)
    camp = simulate(layout, n_points=500, seed=seed, probes=demo_probes(model),
                    magnitude_um=magnitude, noise_um=noise)
    rep = run_loop(layout, camp, seed=seed, progress=False)
    assert rep["effects"] == []
    assert rep["rms_after_um"] == rep["rms_before_um"]
    assert rep["rms_before_um"] < 2.2 * np.sqrt(3) * noise
    assert rep["unidentifiable"] == []
    assert abs(rep["noise_estimate_um"] - noise) < 0.2 * noise


@pytest.mark.parametrize("layout,seed", [("MB1", 14), ("MH1", 15)])
def test_clean_non_polynomial_errors_nothing_found(layout, seed):
    """Error functions that are sums of sinusoids (1/4 to 1 cycle over the travel), not
    polynomials: the degree rises by cross-validation and no effect is invented."""
    model = volerr.load(layout)
    camp = simulate(layout, n_points=600, seed=seed, probes=demo_probes(model), shape="smooth")
    rep = run_loop(layout, camp, seed=seed, progress=False)
    assert rep["effects"] == [], [e["name"] for e in rep["effects"]]
    assert rep["degree"] >= 6
    assert rep["rms_before_um"] < 2.5 * np.sqrt(3) * 0.3


def test_identifiability_single_probe_offset():
    """One probe offset straight down: yaw of X and Z have no lever arm at all, roll/pitch of
    Z only the constant one of the probe: they cannot be separated from the straightness of Z."""
    camp = simulate("MB1", n_points=400, seed=21, probes=[(0.0, 0.0, -120.0)])
    rep = run_loop("MB1", camp, progress=False, degree=4)
    first = {u["parameters"][0]: u for u in rep["unidentifiable"]}
    assert {"EAZ", "EBZ", "ECZ", "ECX"} <= set(first)
    assert "EYZ" in first["EAZ"]["parameters"] and "EXZ" in first["EBZ"]["parameters"]
    assert first["ECZ"].get("no_sensitivity")
    assert "probe" in first["EAZ"]["reason"]
    assert rep["effects"] == []
    # translational errors of X and Y, and the squareness, stay determined
    assert not {"EXX", "EYY", "EZZ", "EXX", "EC0Y"} & set(first)
    # several offsets make everything separable
    camp = simulate("MB1", n_points=400, seed=21, probes=demo_probes(volerr.load("MB1")))
    assert run_loop("MB1", camp, progress=False, degree=4)["unidentifiable"] == []


def test_augmented_layout_is_a_real_layout(tmp_path):
    """The written layout derives like any other; its new parameter acts as the effect says:
    KT_X = k is the same as a scale error EXX = k X (T - 20) of the declared model."""
    camp = simulate("MB1", n_points=400, seed=31, probes=demo_probes(volerr.load("MB1")),
                    effects=[{"kind": "thermal", "axis": "X", "ppm_per_K": 9.0}])
    rep = run_loop("MB1", camp, progress=False, out_dir=tmp_path, degree=4)
    path = tmp_path / "MB1_aug.toml"
    assert rep["augmented_layout"] == str(path) and (tmp_path / "mb1_aug.py").is_file()
    aug, base = volerr.load(str(path)), volerr.load("MB1")
    assert aug.parameters[:len(base.parameters)] == base.parameters
    assert aug.parameters[len(base.parameters):] == ("KT_X", "KT0_X")
    assert aug.covariates == ("T_C",)
    rng = np.random.default_rng(0)
    pos = {a: rng.uniform(*base.travel[a], 20) for a in base.axes}
    T = rng.uniform(15, 25, 20)
    probe = rng.uniform(-100, 100, (20, 3))
    k = 1.2e-5
    got = aug.volumetric_error(pos, {"KT_X": k}, probe, covariates={"T_C": T})
    want = base.volumetric_error(pos, {"EXX": k * pos["X"] * (T - 20.0)}, probe)
    np.testing.assert_allclose(got, want, atol=1e-15)
    # KT0_X: the scale's fixed point X0 = -KT0_X / KT_X (expansion k (X - X0) (T - 20))
    got = aug.volumetric_error(pos, {"KT_X": k, "KT0_X": -k * 300.0}, probe,
                               covariates={"T_C": T})
    want = base.volumetric_error(pos, {"EXX": k * (pos["X"] - 300.0) * (T - 20.0)}, probe)
    np.testing.assert_allclose(got, want, atol=1e-15)
    # and the generated module file is what `volerr derive` makes of that layout
    from volerr.derive.generate import generate_module
    from volerr.machine.layout import read_layout

    assert (tmp_path / "mb1_aug.py").read_text() == generate_module(read_layout(str(path)))


def test_report_files(tmp_path):
    camp = simulate("MB1", n_points=300, seed=41, probes=demo_probes(volerr.load("MB1")),
                    effects=[{"kind": "reversal", "axis": "Y", "um": 5.0}])
    rep = run_loop("MB1", camp, progress=False, degree=4)
    rep.write_json(tmp_path / "r.json")
    rep.write_html(tmp_path / "r.html")
    d = json.loads((tmp_path / "r.json").read_text())
    for key in ("layout", "n_points", "rms_before_um", "rms_after_um", "max_before_um",
                "max_after_um", "effects", "unidentifiable"):
        assert key in d
    assert d["layout"] == "MB1" and d["n_points"] == 300
    e = d["effects"][0]
    assert {"kind", "name", "parameters", "evidence"} <= set(e)
    assert e["kind"] == "reversal" and e["evidence"]["delta_bic"] < -10
    # RMS = root mean square of the 3-D residual length: not below the max / sqrt(n_test)
    assert d["max_after_um"] >= d["rms_after_um"]
    html = (tmp_path / "r.html").read_text()
    assert html.count("data:image/png;base64,") >= 3 and "reversal_Y" in html


def test_demo_campaign_runs():
    from volerr.loop.run import demo_campaign

    name, path = demo_campaign(seed=0, n_points=400)
    rep = run_loop(name, path, progress=False)
    assert rep["effects"] and rep["effects"][0]["name"] == "thermal_X"
    assert rep["rms_after_um"] < 0.3 * rep["rms_before_um"]


def test_leave_one_point_out_equals_refits():
    """The hat-matrix shortcut against brute-force refits without each point."""
    from volerr.estimate.design import Problem, rows_of

    rng = np.random.default_rng(3)
    A = rng.normal(size=(3 * 30, 8))
    y = rng.normal(size=90)
    prob = Problem(A, y)
    pts = np.arange(30)
    brute = np.concatenate([y[rows_of([i])] - prob.predict(prob.fit(np.delete(pts, i)), [i])
                            for i in pts])
    np.testing.assert_allclose(prob.loo_residuals(pts), brute, atol=1e-10)


def test_five_axis_clean_and_rotary_columns():
    """A table-table five-axis machine (rotary columns in deg, tool lengths as offsets): the
    declared model with rotary location errors explains clean data; nothing is found."""
    model = volerr.load("TT_AC")
    camp = simulate("TT_AC", n_points=500, seed=51, probes=demo_probes(model))
    rep = run_loop("TT_AC", camp, seed=1, progress=False)
    assert rep["effects"] == []
    assert rep["rms_before_um"] < 2.2 * np.sqrt(3) * 0.3
    assert {"A", "C"} <= set(rep["residual_analysis"])


def test_two_effects_at_once():
    camp = simulate("MB1", n_points=600, seed=61, probes=demo_probes(volerr.load("MB1")),
                    effects=[{"kind": "thermal", "axis": "Y", "ppm_per_K": 8.0},
                             {"kind": "periodic", "component": "EXX", "period_mm": 22.0,
                              "um": 1.2}])
    rep = run_loop("MB1", camp, progress=False)
    names = sorted(e["name"] for e in rep["effects"])
    assert names == ["periodic_EXX", "thermal_Y"]
    per = next(e for e in rep["effects"] if e["kind"] == "periodic")
    assert abs(per["info"]["period"] - 22.0) < 0.3 and abs(per["info"]["amplitude_um"] - 1.2) < 0.15


@pytest.mark.parametrize("layout", ["MB1", "FB1", "TT_AC"])
def test_candidate_bases_agree_with_the_derivation(layout):
    """Every candidate's basis text evaluates the same in the runtime (numpy, no eval) and in
    the derivation (sympy, lambdified): the search and the augmented model use one formula."""
    import sympy as sp

    from volerr.loop import candidates
    from volerr.machine.expressions import evaluate, variables
    from volerr.derive.effects import basis_expr
    from volerr.estimate.design import data_ranges, rotary_rad
    from volerr.loop.run import columns_to_data

    model = volerr.load(layout)
    camp = simulate(layout, n_points=60, seed=1, rounds=2)
    data = columns_to_data(camp.columns(), model)
    values = {**rotary_rad(model, data.positions), **data.covariates}
    cands = candidates.build(model, data, data_ranges(model, data), 4)
    terms = [t for c in cands for t in c.terms]
    terms += [t for c in cands if c.search is not None for t in c.search.make(c.search.grid[1])[0]]
    terms += candidates.periodic_terms("EXX", "X", 37.5)
    assert set(candidates.FAMILIES) - {c.kind for c in cands} <= {"covariate"}
    for text in sorted({t[2] for t in terms}):          # each basis text once
        if "lag(" in text:      # a symbol in the derivation: test_lags.py checks the module
            continue
        names = variables(text)
        f = sp.lambdify([sp.Symbol(v, real=True) for v in names], basis_expr(text), "numpy")
        want = np.broadcast_to(f(*(values[v] for v in names)), (data.n,))
        np.testing.assert_allclose(evaluate(text, values), want, rtol=1e-9, atol=1e-9)


def _rigid_residual(model, pos, probe, d):
    """d (N, 3) minus its best first-order rigid motion t + w x p (the instrument's placement)."""
    nom = model.nominal_position(pos, probe)
    n = len(nom)
    A = np.zeros((3 * n, 6))
    for i in range(3):
        A[i::3, i] = 1.0
    for k in range(3):
        A[:, 3 + k] = np.cross(np.eye(3)[k], nom).ravel()
    c, *_ = np.linalg.lstsq(A, d.ravel(), rcond=None)
    return (d.ravel() - A @ c).reshape(-1, 3)


@pytest.mark.parametrize("layout,seed,effect", [
    ("MH2", 71, {"kind": "thermal", "axis": "Z", "ppm_per_K": 9.0}),
    ("FB1", 72, {"kind": "periodic", "component": "EXX", "period_mm": 35.0, "um": 1.0})])
def test_exported_error_map_is_the_machine(tmp_path, layout, seed, effect):
    """The fitted error functions, written as error tables and read back through
    volerr.tables.table, predict the simulated machine's true (exact-chain) error at new points to
    a small fraction of its size, up to the instrument's rigid placement."""
    from volerr.tables.functions import ErrorFunctions
    from volerr.tables.table import read_error_dir

    model = volerr.load(layout)
    camp = simulate(layout, n_points=700, seed=seed, probes=demo_probes(model),
                    effects=[effect])
    rep = run_loop(layout, camp, progress=False)
    rep.write_error_tables(tmp_path / "errors")
    tables, (consts, _, _) = read_error_dir(tmp_path / "errors", model.axes)
    funcs = ErrorFunctions(tables, consts, model, method="cubic")
    rng = np.random.default_rng(seed)
    pos = {a: rng.uniform(camp.positions[a].min(), camp.positions[a].max(), 400)
           for a in model.axes}
    probe = np.array(demo_probes(model))[rng.integers(0, 5, 400)]
    truth = {p: (f(pos[model.parameter_axis[p]]) if callable(f) else f)
             for p, f in camp.truth["functions"].items()}
    true = model.exact_error(pos, truth, probe)
    err = _rigid_residual(model, pos, probe, model.volumetric_error(pos, funcs(pos), probe) - true)
    size = np.sqrt(np.mean(np.sum(_rigid_residual(model, pos, probe, true) ** 2, axis=1)))
    rms_err = np.sqrt(np.mean(np.sum(err ** 2, axis=1)))
    assert rms_err < 0.05 * size and rms_err < 0.2e-3, (rms_err, size)


def test_blunders_are_flagged_not_explained():
    camp = simulate("MH1", n_points=400, seed=81, probes=demo_probes(volerr.load("MH1")))
    camp.deviation[[7, 150, 333]] += np.array([0.012, -0.008, 0.0])   # 12-14 um blunders
    rep = run_loop("MH1", camp, progress=False)
    assert rep["outliers"]["data_rows"] == [8, 151, 334]
    assert rep["effects"] == []
