"""Issue 9: the loop traces ANY missing effect to the parameter and covariate behind it.

Data from the independent simulator (tests/helpers/indep_sim.py: its own exact chain, wavy
non-polynomial component errors, its own squareness convention: the Y axis tilts) with effects
that are none of the eight former family names: an angular error growing with a vertical
temperature gradient, a squareness changing with temperature, a saturating warm-up drift, a
step in a scale.  Each must be named by its parameter AND covariate, ranked first among the
residual sources, and leave a held-out RMS within 15 % of the floor a perfect model reaches on
the same points (the RMS of the simulated noise at the held-out points, computed here)."""

import numpy as np
import pytest

from volerr.loop.run import run_loop, split_points

from helpers import indep_sim as sim

N = 800


def _run(tmp_path, effects, seed, layout="MB1", noise_um=0.3):
    truth = {}
    cols = sim.campaign(layout, N, seed, effects, noise_um=noise_um, channels=True, truth=truth)
    path = sim.write_csv(str(tmp_path / "data.csv"), cols)
    rep = run_loop(layout, path, seed=0, progress=False)
    test = split_points(N, 0, 0.25, None).test          # the split run_loop uses (seed 0)
    floor = 1e3 * np.sqrt(np.mean(np.sum(truth["noise"][test] ** 2, axis=1)))
    return rep, floor


CASES = [  # effect, (parameter, covariate) expected, check of the value
    ({"kind": "gradient", "component": "EBX", "urad_per_K": 12.0}, ("EBX", "T_top - T_bottom"),
     lambda e: abs(list(e["parameters"].values())[0] - 12.0) < 1.0),
    # (a roll EAY would be the same columns as EAX on this chain: X moves along x)
    ({"kind": "gradient", "component": "ECY", "urad_per_K": -9.0}, ("ECY", "T_top - T_bottom"),
     lambda e: abs(list(e["parameters"].values())[0] + 9.0) < 1.0),
    # the simulator tilts Y; volerr's EC0Y tilts X: the same squareness up to a rigid rotation
    ({"kind": "squareness_T", "index": 0, "urad_per_K": -8.0}, ("EC0Y", "T_C"),
     lambda e: abs(abs(list(e["parameters"].values())[0]) - 8.0) < 0.5),
    ({"kind": "warmup", "dir": "x", "um": 4.0, "tau_h": 1.5}, ("setup.dx", "t_s"),
     lambda e: e["basis"] == "saturating" and abs(e["parameters"]["WU_X"] - 4.0) < 0.6
     and abs(e["info"]["tau_h"] - 1.5) < 0.5),
    ({"kind": "warmup", "dir": "z", "um": 3.0, "tau_h": 0.8}, ("setup.dz", "t_s"),
     lambda e: e["basis"] == "saturating" and abs(e["parameters"]["WU_Z"] - 3.0) < 0.6),
    ({"kind": "scale_step", "axis": "X", "um": 2.0}, ("EXX", "X"),
     lambda e: e["basis"] == "step" and abs(abs(e["parameters"]["ST_EXX"]) - 2.0) < 0.3
     and abs(e["info"]["location_mm"] - (450 + 0.23 * 450)) < 15),
]


# The first case's run (the gradient of EBX, seed 5) is also the run whose report
# test_residual_sources_json_contract reads: computed once, in one xdist group.
GRADIENT_GROUP = "loop_trace_gradient"


@pytest.fixture(scope="module")
def gradient_run(tmp_path_factory):
    """(report, floor) of CASES[0] (seed 5), shared by its case and the JSON contract."""
    return _run(tmp_path_factory.mktemp("trace_gradient"), [CASES[0][0]], 5)


@pytest.mark.slow
@pytest.mark.parametrize("i", [pytest.param(i, marks=pytest.mark.xdist_group(GRADIENT_GROUP))
                               if i == 0 else i for i in range(len(CASES))],
                         ids=[f"{c[0]['kind']}-{c[1][0]}" for c in CASES])
def test_effect_outside_the_eight_traced(tmp_path, request, i):
    effect, pc, check = CASES[i]
    seed = 5 + i            # machine and plan differ from case to case
    rep, floor = request.getfixturevalue("gradient_run") if i == 0 else \
        _run(tmp_path, [effect], seed)
    named = [(e["parameter"], e["covariate"]) for e in rep["effects"]]
    assert named and named[0] == pc, named
    # no pile-up: one effect, or a second one marked as the same cause
    assert len(named) == 1 or all(e["evidence"].get("same_cause_as")
                                  for e in rep["effects"]), named
    assert check(rep["effects"][0]), rep["effects"][0]
    top = rep["residual_sources"][0]
    assert (top["parameter"], top["covariate"]) == pc and top["accepted"]
    assert rep["rms_after_um"] <= 1.15 * floor, (rep["rms_after_um"], floor)
    # what is left: nothing of that size
    assert rep["residual_sources_after"][0]["explained_um"] < max(0.2 * top["explained_um"], 0.1)


@pytest.mark.slow
@pytest.mark.parametrize("layout,seed", [("MB1", 31), ("FB1", 32), ("MH2", 33), ("MB1", 34)])
def test_clean_machines_at_most_one_spurious(tmp_path, layout, seed):
    """Clean wavy machines with every covariate column (T_C, T_top, T_bottom, t_s, dir_*,
    round, nx ny nz): over these runs nothing (at most one spurious effect in total is
    allowed by the issue; each run must stay at the floor)."""
    rep, floor = _run(tmp_path, [], seed, layout)
    assert len(rep["effects"]) <= 1, [e["name"] for e in rep["effects"]]
    assert rep["rms_after_um"] <= 1.15 * floor
    assert rep["residual_note"] is None or len(rep["effects"]) == 0


@pytest.mark.slow
@pytest.mark.xdist_group(GRADIENT_GROUP)
def test_residual_sources_json_contract(gradient_run):
    """Keys of the contract; sources ranked by BIC; every effect names P, C and the basis (on
    the report of the EBX gradient case: an effect found, sources before and after)."""
    rep, _ = gradient_run
    assert rep["effects"] and len(rep["residual_sources"]) >= 2, rep["residual_sources"]
    for key in ("layout", "n_points", "rms_before_um", "rms_after_um", "max_before_um",
                "max_after_um", "effects", "unidentifiable", "residual_sources",
                "residual_sources_after"):
        assert key in rep.data
    for src in rep["residual_sources"] + rep["residual_sources_after"]:
        assert {"parameter", "covariate", "basis", "explained_um", "accepted"} <= set(src)
    d = [s["delta_bic"] for s in rep["residual_sources"]]
    assert d == sorted(d)
    for e in rep["effects"]:
        assert {"kind", "name", "parameters", "evidence", "parameter", "covariate",
                "basis"} <= set(e)


@pytest.mark.slow
def test_outliers_do_not_inflate_the_noise(tmp_path):
    """Five gross outliers (20-50 um) and three of 2-4 um on 0.3 um noise: the robust noise
    estimate stays at the noise, all eight are flagged, held-out figures on the inliers."""
    cols = sim.campaign("MB1", 600, 51, [], noise_um=0.3)
    rng = np.random.default_rng(0)
    bad = rng.choice(600, 8, replace=False)
    sizes = [20, 30, 40, 50, 25, 3.5, 4.0, 3.8]
    for i, s in zip(bad, sizes):
        v = rng.normal(size=3)
        v *= s / np.linalg.norm(v)
        for k, c in enumerate(("dx_um", "dy_um", "dz_um")):
            cols[c][i] += v[k]
    path = sim.write_csv(str(tmp_path / "o.csv"), cols)
    rep = run_loop("MB1", path, seed=0, progress=False)
    assert abs(rep["noise_estimate_um"] - 0.3) < 0.06, rep["noise_estimate_um"]
    assert set(rep["outliers"]["data_rows"]) >= {int(i) + 1 for i in bad}
    assert rep["effects"] == []
    assert rep["inliers"]["rms_after_um"] < 0.7


@pytest.mark.slow
def test_bad_covariate_columns_left_out_with_a_warning(tmp_path):
    """A constant column, a text column and one with NaN: named once each, left out; the
    rest runs as without them."""
    cols = sim.campaign("MB1", 300, 61, [{"kind": "reversal", "axis": "X", "um": 4.0}])
    path = sim.write_csv(str(tmp_path / "a.csv"), cols)
    ref = run_loop("MB1", path, seed=0, progress=False, degree=4)   # degree: not under test
    cols["T_const"] = np.full(300, 20.0)
    cols["T_nan"] = cols["T_C"].copy()
    cols["T_nan"][17] = np.nan
    path = sim.write_csv(str(tmp_path / "b.csv"), cols, extra_text=("label", lambda i: f"p{i}"))
    rep = run_loop("MB1", path, seed=0, progress=False, degree=4)
    text = " | ".join(rep["warnings"])
    for c in ("T_const", "T_nan", "label"):
        assert sum(c in w for w in rep["warnings"]) == 1, text
    assert [e["name"] for e in rep["effects"]] == [e["name"] for e in ref["effects"]]
    assert rep["rms_after_um"] == ref["rms_after_um"]


def _five_axis_campaign(n, seed, planted):
    """TT_AC measured with the independent exact chain (tests/helpers/reference_chain.py, scipy
    rotations): smooth component errors, constant squareness / location errors, the rotary
    location error ``planted`` = (name, um per K) growing with T_C, rigid instrument
    placement, 0.3 um noise.  Returns CSV columns and the noise (n, 3) mm."""
    import volerr
    from helpers.reference_chain import tool_point

    from helpers.indep_sim import rot

    model = volerr.load("TT_AC")
    lay = model.layout
    rng = np.random.default_rng(seed)
    pos = {a: rng.uniform(*model.travel[a], n) for a in model.axes}
    probes = np.array([(0, 0, 100.0), (0, 0, 200.0), (30, 0, 150.0), (0, 30, 150.0)])
    probe = probes[rng.integers(0, 4, n)]
    t_s = np.sort(rng.uniform(0, 6 * 3600, n))[rng.permutation(n)]
    T = 20.5 + 1.5 * np.sin(2 * np.pi * t_s / (4.5 * 3600)) + rng.normal(0, 0.03, n)
    coef = {}
    for p in model.parameters:
        a = model.parameter_axis.get(p)
        size = 3e-3 if p[1] in "XYZ" else 5e-6
        coef[p] = rng.normal(0, size, 4 if a else 1) / np.array([1, 1, 2, 3][:4 if a else 1])
    dev = np.zeros((n, 3))
    for i in range(n):
        q = {a: (np.deg2rad(pos[a][i]) if a in model.rotary_axes else pos[a][i])
             for a in model.axes}
        err = {}
        for p in model.parameters:
            a = model.parameter_axis.get(p)
            if a is None:
                err[p] = coef[p][0]
            else:
                lo, hi = model.travel[a]
                u = (2 * pos[a][i] - lo - hi) / (hi - lo)
                err[p] = coef[p] @ np.array([0.0, u, u * u - 1 / 3, u ** 3 - 0.6 * u])
        name, per_k = planted
        err[name] = err[name] + per_k * 1e-3 * (T[i] - 20.0)
        dev[i] = tool_point(lay, q, err, probe[i]) - tool_point(lay, q, {}, probe[i])
    nom = model.nominal_position(pos, probe)
    R = rot(*rng.normal(0, 10e-6, 3))          # the instrument's placement, exact
    meas = (nom + dev) @ R.T + rng.normal(0, 5e-3, 3)
    noise = rng.normal(0, 0.3e-3, (n, 3))
    d = meas - nom + noise
    cols = {**pos, "Xp": probe[:, 0], "Yp": probe[:, 1], "Zp": probe[:, 2],
            "dx_um": d[:, 0] * 1e3, "dy_um": d[:, 1] * 1e3, "dz_um": d[:, 2] * 1e3,
            "T_C": T, "t_s": t_s}
    return cols, noise


@pytest.mark.slow
@pytest.mark.parametrize("planted,seed", [(("EY0C", 1.5), 81)])
def test_five_axis_rotary_location_error_with_temperature(tmp_path, planted, seed):
    """A rotary location error of the C table that moves with temperature (outside the eight
    former families): named by parameter and covariate on a five-axis layout."""
    cols, noise = _five_axis_campaign(700, seed, planted)
    path = sim.write_csv(str(tmp_path / "f.csv"), cols)
    rep = run_loop("TT_AC", path, seed=0, progress=False)
    named = [(e["parameter"], e["covariate"]) for e in rep["effects"]]
    assert named and named[0] == (planted[0], "T_C"), named
    assert len(named) == 1 or all(e["evidence"].get("same_cause_as") for e in rep["effects"])
    assert abs(list(rep["effects"][0]["parameters"].values())[0] - planted[1]) < 0.2
    test = split_points(700, 0, 0.25, None).test
    floor = 1e3 * np.sqrt(np.mean(np.sum(noise[test] ** 2, axis=1)))
    assert rep["rms_after_um"] <= 1.15 * floor, (rep["rms_after_um"], floor)
    top = rep["residual_sources"][0]
    assert (top["parameter"], top["covariate"]) == (planted[0], "T_C")
