"""``volerr ballbar evaluate`` (ISO 230-4): circular deviation G, circular hysteresis H, radial
deviations F_max / F_min and the least-squares centre equal an independent computation from
the trace's own columns (contract definitions, 1e-9 um for G and H); the diagnosis recovers a
planted squareness within 3 standard uncertainties.

Traces from the independent simulator (tests/helpers/instrument_sim.py): MB1, an XY circle in
both directions with squareness, scale mismatch, a backlash of X and Y and noise (the CW trace
starts 1.3 deg off the CCW angles, so H needs the periodic interpolation), and a ZX circle
in one direction (no H)."""

import csv

import numpy as np
import pytest

from helpers import instrument_sim as S
from instruments._common import K_SIGMA, Campaign, run_json

# module-scoped simulated data: keep the module on one xdist worker
pytestmark = pytest.mark.xdist_group("test_ballbar_evaluate")

PIVOT = (450.0, 290.0, 200.0)


def _read(path):
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    return {k: np.array([r[k] for r in rows]) for k in rows[0]}


def _independent(path, plane):
    """Per direction: G, F, centre offset; H when both directions (contract definitions),
    computed from the file's columns only."""
    c = _read(path)
    f = lambda k: c[k].astype(float)  # noqa: E731
    t = np.column_stack([f("X") + f("Xp"), f("Y") + f("Yp"), f("Z") + f("Zp")])  # CMM chain
    piv = np.column_stack([f("pivot_x"), f("pivot_y"), f("pivot_z")])
    th = S.trace_angles(plane, t, piv)
    dr, L, dirs = f("dr_um"), f("length_mm"), f("direction").astype(int)
    out = {}
    for d in np.unique(dirs):
        m = dirs == d
        out[int(d)] = S.evaluate_trace(th[m], dr[m], L[m][0])
    h = None
    if set(out) == {1, -1}:
        h = S.hysteresis(th[dirs == 1], dr[dirs == 1], th[dirs == -1], dr[dirs == -1])
    return out, h


@pytest.fixture(scope="module")
def traces(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bb_eval")
    m = S.Machine("MB1")
    xy = S.concat([S.ballbar_circle(m, "xy.csv", "XY", PIVOT, 100.0, 120, 1, "P1", u_um=0.2),
                   S.ballbar_circle(m, "xy.csv", "XY", PIVOT, 100.0, 120, -1, "P1",
                                    start_deg=1.3, u_um=0.2)])
    zx = S.ballbar_circle(m, "zx.csv", "ZX", PIVOT, 150.0, 90, 1, "P1", u_um=0.2)
    lo, hi = 300.0, 600.0
    terms = [S.constant("EC0Y"), S.series("EXX", 1, lo, hi), S.series("EYY", 1, 140.0, 440.0),
             S.reversal("EXX", "X"), S.reversal("EYY", "Y")]
    values = {"EC0Y": 30.0, "EXX@slope": 0.015, "EYY@slope": -0.005, "EXX@reversal": 3.0,
              "EYY@reversal": -2.0}
    camp = Campaign(m, [xy, zx], terms, values, {"xy.csv#P1:pivot_dx": 20.0,
                                                 "xy.csv#P1:length": -4.0}, seed=5)
    paths = camp.write(folder)
    r, doc = run_json(["ballbar", "evaluate", *paths], folder / "ev.json")
    return dict(paths=paths, r=r, doc=doc, folder=folder)


def _dir(value) -> int:
    """A trace's direction as +1 (CCW) / -1 (CW): the JSON may give it as a number or as
    "ccw" / "cw"."""
    if isinstance(value, str):
        return {"ccw": 1, "cw": -1, "+1": 1, "1": 1, "-1": -1}[value.strip().lower()]
    return int(value)


def _entries(doc, name):
    return [t for t in doc["traces"] if t["file"] == name]


def test_g_h_f_equal_independent_computation(traces):
    r, doc = traces["r"], traces["doc"]
    assert r.returncode == 0, r.stderr[-3000:]
    for path, plane in zip(traces["paths"], ("XY", "ZX")):
        mine, h = _independent(path, plane)
        got = _entries(doc, path.split("/")[-1])
        assert sorted(_dir(t["direction"]) for t in got) == sorted(mine), got
        for t in got:
            ref = mine[_dir(t["direction"])]
            assert t["plane"] == plane and abs(t["radius_mm"] - (100.0 if plane == "XY"
                                                                 else 150.0)) < 1e-12, t
            assert abs(t["G_um"] - ref["G_um"]) <= 1e-9, (path, t["G_um"], ref["G_um"])
            assert abs(t["F_max_um"] - ref["F_max_um"]) <= 1e-9, (t, ref)
            assert abs(t["F_min_um"] - ref["F_min_um"]) <= 1e-9, (t, ref)
            if plane == "XY":   # in-plane order (x, y) unambiguous here
                assert np.allclose(t["centre_offset_um"], ref["centre_offset_um"],
                                   atol=1e-6), (t, ref)
            if h is None:
                assert t.get("H_um") is None, t
            else:
                assert abs(t["H_um"] - h) <= 1e-9, (t["H_um"], h)
    # the planted backlash shows: H well above the noise
    assert _entries(doc, "xy.csv")[0]["H_um"] > 2.0


def test_diagnosis_recovers_squareness(tmp_path):
    """A clean XY circle (squareness, scale mismatch, noise; no reversal): the diagnosis
    computed from MB1's observation model gives EC0Y within 3 standard uncertainties."""
    m = S.Machine("MB1")
    b = S.concat([S.ballbar_circle(m, "sq.csv", "XY", PIVOT, 100.0, 120, d, "P1", u_um=0.3)
                  for d in (1, -1)])
    terms = [S.constant("EC0Y"), S.series("EXX", 1, 350.0, 550.0)]
    camp = Campaign(m, [b], terms, {"EC0Y": -22.0, "EXX@slope": 0.01},
                    {"sq.csv#P1:pivot_dy": -15.0, "sq.csv#P1:length": 3.0}, seed=9)
    paths = camp.write(tmp_path)
    r, doc = run_json(["ballbar", "evaluate", *paths, "--layout", "MB1"], tmp_path / "d.json")
    assert r.returncode == 0, r.stderr[-3000:]
    diag = {d["parameter"]: d for d in doc["diagnosis"]}
    assert "EC0Y" in diag, sorted(diag)
    e = diag["EC0Y"]
    assert e["unit"] == "urad" and e["std"] > 0, e
    assert abs(e["value"] - (-22.0)) <= K_SIGMA * e["std"], e
