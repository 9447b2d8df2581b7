"""``volerr calibrate`` on tracking-interferometer distances (issue 20: self-calibrating
multilateration): 4 stations on the table of the DMU50, 200 targets (tool point at random
poses of the five axes, reflector 100 mm out), each measured from every station, noise 0.3 um
+ 0.3 um/m, readings relative to each station's first one (``dd_mm``); simulated with the
independent exact chain (tests/helpers/metrology_sim.py).

Checked: the identifiability report agrees with the rank analysis of the finite-difference
design of the exact simulator (stations' positions and dead paths as unknowns); every
identifiable planted parameter is within 3 standard uncertainties; every station's identified
position contains the planted one within 3 standard uncertainties; the held-out residual is at
the floor of the true model on the same split; nothing is flagged inconsistent."""

import numpy as np
import pytest

from helpers import instrument_sim as S
from helpers import metrology_sim as M
from instruments._common import FLOOR_FACTOR, K_SIGMA, run_json, series_terms

LOCATION = ["EX0B", "EY0B", "EA0B", "EB0B", "EX0C", "EY0C", "EA0C", "EB0C"]
VALUES = {"EXX@slope": 0.012, "EYY@slope": -0.010, "EZZ@slope": 0.015, "EC0Y": 20.0,
          "EB0Z": -15.0, "EA0Z": 12.0, "EX0B": 12.0, "EY0B": -8.0, "EA0B": 35.0,
          "EB0B": -20.0, "EX0C": 15.0, "EY0C": -10.0, "EA0C": 25.0, "EB0C": -30.0}
STATIONS = {"S1": (-180.0, -170.0, 10.0), "S2": (190.0, -160.0, 40.0),
            "S3": (170.0, 185.0, 5.0), "S4": (-160.0, 175.0, 60.0)}
DEAD = {"S1": 0.012, "S2": -0.020, "S3": 0.030, "S4": 0.0}


def _targets(m, n, rng):
    """n poses with the reflector (100 mm out along the tool) inside a box on the table."""
    probe = np.array([0.0, 0.0, 100.0])
    pos = {a: [] for a in m.axes}
    while len(pos["X"]) < n:
        k = 4 * n
        t = rng.uniform([-150, -150, 20], [150, 150, 250], (k, 3))
        rot = {"B": rng.choice([0.0, 20.0, 45.0, 70.0, 90.0], k),
               "C": rng.uniform(0.0, 360.0, k)}
        q = m.inverse(t, rot, probe, check_travel=False)
        ok = np.ones(k, bool)
        for a in m.axes:
            lo, hi = m.travel[a]
            ok &= (q[a] >= lo) & (q[a] <= hi)
        for a in m.axes:
            pos[a] += list(q[a][ok])
    return {a: np.asarray(v[:n]) for a, v in pos.items()}, probe


def test_multilateration_dmu50(tmp_path):
    m = S.Machine("DMU50")
    rng = np.random.default_rng(31)
    pos, probe = _targets(m, 200, rng)
    blk = M.distances_block("lt.csv", pos, probe, STATIONS, DEAD)
    blocks = [blk]
    terms = series_terms(blocks, ["EXX", "EYY", "EZZ"], 1)
    terms += [S.constant(c) for c in ["EC0Y", "EB0Z", "EA0Z", *LOCATION]]
    y, raw = M.simulate(m, blk, terms, VALUES, {}, rng)
    M.write_csv(tmp_path / "lt.csv", M.distance_columns(m, blk, raw, relative=True))
    r, doc = run_json(["calibrate", "DMU50", tmp_path / "lt.csv", "--parameters",
                       "EXX,EYY,EZZ,EC0Y,EB0Z,EA0Z," + ",".join(LOCATION), "--degree", "1",
                       "--seed", "2"], tmp_path / "cal.json")
    assert r.returncode == 0, r.stderr[-3000:]
    d = M.design(m, blocks, terms)
    ok, rel = S.identifiability(d)
    # the design: clear-cut, and the plan determines the scales, squareness and C's location
    assert all(v > 1e-3 or v < 1e-8 for v in rel.values()), rel
    for p in ("EXX@slope", "EYY@slope", "EZZ@slope", "EC0Y", "EB0Z", "EA0Z", "EX0C", "EY0C"):
        assert ok[p], (p, rel[p])
    theta, cov, _ = S.wls(d, y)
    for j, p in enumerate(d.params):
        if ok[p]:     # the data set is no statistical outlier
            assert abs(theta[j] - VALUES[p]) <= K_SIGMA * np.sqrt(cov[j, j]), p
    # identifiability and values
    bad = []
    for p, ident in ok.items():
        assert doc["identifiability"][p]["identifiable"] == ident, (p, doc["identifiability"][p])
        if ident:
            e = doc["parameters"][p]
            if abs(e["value"] - VALUES[p]) > K_SIGMA * e["std"]:
                bad.append((p, e["value"], VALUES[p], e["std"]))
    assert not bad, f"outside 3 std (name, value, planted, std): {bad}"
    # stations recovered
    for label, s in STATIONS.items():
        e = doc["stations"][f"lt.csv#{label}"]
        d_um = 1e3 * (np.asarray(e["position_mm"]) - np.asarray(s))
        assert np.all(np.abs(d_um) <= K_SIGMA * np.asarray(e["position_std_um"])), (
            label, d_um, e["position_std_um"])
        assert max(e["position_std_um"]) < 5.0, e
    # held-out floor, consistency
    (inst,) = doc["instruments"]
    test = np.isin(d.rows[:, 1], inst["test_rows"])
    _, _, res = S.wls(d, y, ~test)
    floor = float(np.sqrt(np.mean(res[test] ** 2)))
    assert floor / FLOOR_FACTOR <= inst["heldout_rms"] <= FLOOR_FACTOR * floor, (
        inst["heldout_rms"], floor)
    assert doc["consistency"]["inconsistent"] == []
