"""Directed drift channels as rows of the layout's model, fitted jointly
(:mod:`volerr.loop.drift.rows`), and the Python API on drift runs.

The simulator here is its own: a machine whose tool point moves along X by 0.8 um/K of a lag
(tau 1500 s) of sensor ``T_a`` and along Z by -1.1 um/K of the same, while the spindle tilts
about +Y by 2.5 urad/K of sensor ``T_b`` (no lag); two X sensors at z = 20 and 100 mm and one
Z sensor, 0.05 um noise; three runs of 8 h (the third held out: the loop's default).  The lag
is integrated on a 1 s grid (implicit Euler), not by the loop's lag."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from helpers.in_process import volerr as volerr_cmd
from helpers import drift_sim as D
from volerr.loop.drift import rows as R

# the module fixtures once, on one xdist worker (not once per worker)
pytestmark = pytest.mark.xdist_group("drift_rows")

DT = 30.0
HOURS = 8.0
NOISE = 0.05
X_UM_PER_K, Z_UM_PER_K, TAU_S = 0.8, -1.1, 1500.0
TILT_URAD_PER_K = 2.5
HEIGHTS = {"x1": 20.0, "x2": 100.0}


def _lag(u, tau, t):
    """First-order lag of ``u`` at times ``t``, at rest at the start (the tests' independent
    lag, :func:`helpers.drift_sim.lag_irregular`)."""
    return D.lag_irregular(u, tau, t)


def _run(r: int, rng) -> dict:
    """One run: two heat sources with their own duty (so T_a and T_b do not move together)."""
    t = np.arange(0.0, HOURS * 3600 + DT / 2, DT)
    on_a = ((t // (5400 + 1200 * r)) % 2 == 1).astype(float)
    on_b = ((t // (2400 + 600 * r)) % 2 == 0).astype(float) * (t > 1800)
    room = 20.0 + 0.3 * np.sin(2 * np.pi * t / 30000.0 + r)
    Ta = room + 6.0 * _lag(on_a, 2400.0, t)
    Tb = room + 4.0 * _lag(on_b, 700.0, t)
    offset = X_UM_PER_K * (_lag(Ta, TAU_S, t) - Ta[0])
    tilt = TILT_URAD_PER_K * (Tb - Tb[0])                       # urad about +Y
    z_growth = Z_UM_PER_K * (_lag(Ta, TAU_S, t) - Ta[0])
    true = {k: offset + tilt * h * 1e-3 for k, h in HEIGHTS.items()}
    true["z"] = z_growth
    meas = {k: v + 3.0 * r + rng.normal(0, NOISE, len(t)) for k, v in true.items()}
    return {"t_s": t, "T_a": Ta + rng.normal(0, 0.005, len(t)),
            "T_b": Tb + rng.normal(0, 0.005, len(t)), "T_room": room + rng.normal(0, 0.005, len(t)),
            "true": true, "meas": meas}


def _write(path, run, heads, chans=("x1", "x2", "z")):
    names = ["t_s", "T_a", "T_b", "T_room"] + [f"d_{k}_um" for k in chans]
    cols = [run["t_s"], run["T_a"], run["T_b"], run["T_room"]] + [run["meas"][k] for k in chans]
    lines = [f"# channel d_{k}: {v}" for k, v in heads.items()] + [",".join(names)]
    lines += [",".join(f"{c[i]:.6f}" for c in cols) for i in range(len(run["t_s"]))]
    path.write_text("\n".join(lines) + "\n")


HEADS = {"x1": "X at z=20", "x2": "X at z=100", "z": "Z"}


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    folder = tmp_path_factory.mktemp("rows")
    rng = np.random.default_rng(11)
    runs = [_run(r, rng) for r in range(3)]
    for r, run in enumerate(runs):
        _write(folder / f"r{r}.csv", run, HEADS)
    specs = [f"drift:r{r}.csv" for r in range(3)]
    p = volerr_cmd(*["loop", "DMU50", *specs, "--json", "j.json", "--predictions-out",
                     "p.csv"], cwd=folder)         # in-process, one BLAS thread as the API here
    assert p.returncode == 0, p.stderr
    return folder, runs, json.loads((folder / "j.json").read_text()), p.stdout


def test_rows_of_two_heights_offset_and_tilt():
    rows = R.rows_of({"x1": "X", "x2": "-X", "y": "Y", "w": "?"},
                     {"x1": 20.0, "x2": 100.0, "y": None, "w": None})
    assert [q.kind for q in rows.quantities] == ["offset", "tilt", "offset"]
    assert rows.channels == ["x1", "x2", "y"]
    # x1 = EX + 0.02 EB; x2 (read along -X) = -(EX + 0.1 EB); y = EY
    np.testing.assert_allclose(rows.A, [[1, 0.02, 0], [-1, -0.1, 0], [0, 0, 1]])
    Q = np.array([[3.0, 50.0, -2.0]])
    Y = Q @ rows.A.T
    got, resid = rows.solve(Y)
    np.testing.assert_allclose(got, Q)
    np.testing.assert_allclose(resid, 0, atol=1e-12)


def test_names_offset_and_tilt_with_their_sensors(campaign):
    _, _, doc, out = campaign
    q = doc["quantities"]
    assert set(q) == {"EXZ", "EBZ", "EZZ"}        # DMU50: Z carries the spindle
    assert q["EBZ"]["kind"] == "tilt" and q["EBZ"]["about"] == "Y" and q["EBZ"]["unit"] == "urad"
    assert q["EBZ"]["channels"] == ["x1", "x2"] and "EBZ" in q["EBZ"]["layout_parameters"]
    by = {}
    for e in doc["effects"]:
        by.setdefault(e["quantity"], []).append(e)
    assert set(by) == {"EXZ", "EBZ", "EZZ"}, [e["name"] for e in doc["effects"]]
    for sym, sensor, size, lag in (("EXZ", "T_a", X_UM_PER_K, TAU_S),
                                   ("EBZ", "T_b", TILT_URAD_PER_K, None),
                                   ("EZZ", "T_a", Z_UM_PER_K, TAU_S)):
        (e,) = by[sym]
        assert e["covariates"] == [sensor], e
        assert e["channels"] == q[sym]["channels"]
        # one lag may come as two near ones (two time constants where one is not enough):
        # their sum is the planted size, each lag near the planted one
        assert abs(sum(t["value"] for t in e["terms"]) / size - 1) < 0.05, e["terms"]
        for t in e["terms"]:
            assert t["unit"] == f"{q[sym]['unit']}/K"
            if lag is None:
                assert t["lag_s"] is None or t["lag_s"]["value"] < 120, t
            else:
                assert abs(t["lag_s"]["value"] / lag - 1) < 0.25, t
    assert "EBZ (channels x1, x2) varies with T_b" in out


def test_channels_predicted_to_the_noise_floor(campaign):
    folder, runs, doc, _ = campaign
    held = runs[2]
    for k in ("x1", "x2", "z"):
        c = doc["channels"][k]
        y, true = held["meas"][k], held["true"][k]
        floor = float(np.mean(np.abs(y - (y[0] + true - true[0]))))   # the true model's MAE
        assert c["n_test"] == len(held["t_s"])
        assert c["mae_after_um"] <= 1.15 * floor, (k, c, floor)
        assert c["mae_before_um"] > 5 * floor
        assert c["row_residual_rms_um"] < 1e-9             # two channels, two quantities: exact
    # every X channel's prediction is its row: x2 - x1 = 0.08 mm x the predicted tilt
    with open(folder / "p.csv", newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if r["split"] == "test"]
    a = {r["t_s"]: float(r["after_um"]) for r in rows if r["channel"] == "x1"}
    b = {r["t_s"]: float(r["after_um"]) for r in rows if r["channel"] == "x2"}
    diff = np.array([b[t] - a[t] for t in a])
    true = held["true"]["x2"] - held["true"]["x1"]
    assert np.mean(np.abs(diff - (true - true[0]))) < 3 * NOISE


def test_disagreeing_channels_fitted_with_their_residual(tmp_path):
    """Two X channels at one height that disagree (one reads the offset, the other along -X
    reads it too, but with the tilt's sensor in it): one quantity, least squares, the
    residual reported; the run goes through."""
    rng = np.random.default_rng(5)
    runs = [_run(r, rng) for r in range(2)]
    heads = {"x1": "X at z=50", "x2": "-X at z=50", "z": "Z"}
    for r, run in enumerate(runs):
        _write(tmp_path / f"r{r}.csv", run, heads)
    p = volerr_cmd(*["loop", "TC_XZ", "drift:r0.csv", "drift:r1.csv", "--json", "j.json"],
               cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    doc = json.loads((tmp_path / "j.json").read_text())
    assert set(doc["quantities"]) == {"EXX", "EZX"}      # TC_XZ: X carries the turret
    assert doc["quantities"]["EXX"]["rows"] == {"x1": 1.0, "x2": -1.0}
    for k in ("x1", "x2"):
        assert doc["channels"][k]["row_residual_rms_um"] > 10 * NOISE


def test_bad_headers_refused(tmp_path):
    run = _run(0, np.random.default_rng(1))
    for heads in ({"x1": "W at z=20"}, {"x1": "X at z=abc"}, {"q9": "X"}):
        _write(tmp_path / "bad.csv", run, heads)
        p = volerr_cmd("loop", "DMU50", "drift:bad.csv", "--json", "j.json", cwd=tmp_path)
        assert p.returncode == 2, (heads, p.stderr)
        assert len(p.stderr.strip().splitlines()) == 1 and "Traceback" not in p.stderr
        assert not (tmp_path / "j.json").exists()


def test_api_equals_cli(campaign):
    import volerr

    folder, _, doc, out = campaign
    specs = [str(folder / f"r{r}.csv") for r in range(3)]      # detected as drift
    res = volerr.loop("DMU50", specs)
    got = json.loads(json.dumps(res.to_dict()))
    assert got["channels"] == doc["channels"] and got["effects"] == doc["effects"]
    assert {k: v for k, v in got.items() if k != "runs"} == \
        {k: v for k, v in doc.items() if k != "runs"}
    assert res.summary() == out.rstrip("\n")
    assert res["channels"] == res.data["channels"] and res.effects == res.data["effects"]
    res.write_predictions(folder / "api_p.csv")
    assert (folder / "api_p.csv").read_text() == (folder / "p.csv").read_text()
    res.write_json(folder / "api.json")
    res.write_html(folder / "api.html")
    assert "<img" in (folder / "api.html").read_text()


def test_drift_result_contract(campaign):
    """The drift loop's result keeps the result contract (issue 42): a short repr (before: a
    23,401-character dump of its data), a table of every reported coefficient and time
    constant with its standard uncertainty, one figure per channel, the page from the
    loop's template and style."""
    import matplotlib.figure

    import volerr

    folder, _, doc, out = campaign
    res = volerr.loop("DMU50", [f"drift:{folder / f'r{r}.csv'}" for r in range(3)])
    assert "\n" not in repr(res) and len(repr(res)) < 160
    assert repr(res).startswith("<volerr DriftReport: ") and out.split("\n")[0][:60] in repr(res)
    rows = {r.name: r for r in res._rows()}
    terms = [(f"{e['name']}_{j}", t) for e in doc["effects"] for j, t in enumerate(e["terms"])]
    assert terms, "the campaign's loop found no effect: the table test would test nothing"
    for name, t in terms:
        assert (rows[name].value, rows[name].std, rows[name].unit) == (t["value"], t["std"],
                                                                       t["unit"])
        if t["lag_s"]:
            assert (rows[f"{name}:tau"].value, rows[f"{name}:tau"].unit) == \
                (t["lag_s"]["value"], "s")
    for label, c in doc["channels"].items():
        assert rows[f"{label}:mae_after"].value == c["mae_after_um"]
    figs = res.figures()
    assert sorted(figs) == sorted(f"channel {k}" for k in doc["channels"])
    assert all(isinstance(f, matplotlib.figure.Figure) for f in figs.values())
    res.write_html(folder / "contract.html")
    page = (folder / "contract.html").read_text()
    assert "border-collapse" in page and page.count("<img") == len(doc["channels"])
    assert res.to_dict() == json.loads((folder / "j.json").read_text()) | {"runs": res["runs"]}


def test_cli_refuses_outputs_the_kind_does_not_have(campaign, tmp_path):
    """One line, exit 2, nothing written: ``--errors-out`` on drift runs, ``--predictions-out``
    on measured deviations (the refusals stated once, by ``volerr.loop`` and its results)."""
    folder = campaign[0]
    p = volerr_cmd("loop", "DMU50", "drift:r0.csv", "drift:r1.csv", "drift:r2.csv",
                   "--json", tmp_path / "a.json", "--errors-out", tmp_path / "err", cwd=folder)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1, p.stderr
    assert "--errors-out" in p.stderr and "drift" in p.stderr
    assert not (tmp_path / "a.json").exists() and not (tmp_path / "err").exists()
    p = volerr_cmd("loop", "DMU50", "drift:r0.csv", "--out-dir", tmp_path / "aug", cwd=folder)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1, p.stderr
    assert "--out-dir" in p.stderr and not (tmp_path / "aug").exists()
