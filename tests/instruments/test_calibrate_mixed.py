"""``volerr calibrate`` on a mixed campaign in one solve (issue 19: "weighted least squares over
any mix of files"): a TT_AC ballbar file (XY circles, two radii), an R-test sphere file (three
placements, tilt x C grid) and a 3-D deviations file (random poses, two tool lengths, unknown
rigid placement of the instrument), simulated with the independent exact chain
(tests/helpers/instrument_sim.py).  Judged as the single-instrument campaigns: identifiability
equal to the rank analysis of the stacked design, every identifiable planted parameter within
3 standard uncertainties, each file's held-out residual at the floor of the true model fitted on
the same split (RMS per scalar reading, as docs/formats.md "calibrate-json" defines it)."""

import numpy as np
import pytest

from helpers import instrument_sim as S
from instruments._common import (FLOOR_FACTOR, K_SIGMA, Campaign, floor_fit, random_setup,
                                 reference_estimate, run_json, series_terms, true_design)

# module-scoped simulated data: keep the module on one xdist worker
pytestmark = pytest.mark.xdist_group("test_calibrate_mixed")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    m = S.Machine("TT_AC")
    rng = np.random.default_rng(51)
    pa = (0.0, 0.0, 50.0)
    bb = S.concat([S.ballbar_circle(m, "bb_xy.csv", "XY", pa, 100.0, 60, 1, "A", u_um=0.3),
                   S.ballbar_circle(m, "bb_xy.csv", "XY", pa, 100.0, 60, -1, "A",
                                    start_deg=1.5, u_um=0.3),
                   S.ballbar_circle(m, "bb_xy.csv", "XY", pa, 150.0, 60, 1, "A",
                                    start_deg=2.0, u_um=0.3)])
    grid = [{"A": a, "C": c} for a in (-30, 0, 30, 45) for c in np.arange(0.0, 360.0, 45.0)]
    sp = S.sphere_block(m, "rtest.csv", {"P1": (80, 0, 30), "P2": (-60, 60, 90),
                                         "P3": (0, -70, 130)}, grid, u_um=0.5)
    dev = S.deviations_block(m, "dev.csv", 150, rng, probes=((0, 0, 100.0), (0, 0, 200.0)),
                             rotary_choices={"A": (-30.0, 0.0, 30.0)}, u_um=0.5)
    blocks = [bb, sp, dev]
    loc = [n for a in m.rotary for n in m.layout.axes[a].location_errors]
    terms = series_terms(blocks, ["EXX", "EYY", "EZZ"], 1)
    terms += [S.constant(c) for c in ["EC0Y", "EB0Z", "EA0Z", *loc]]
    values = {"EXX@slope": 0.010, "EYY@slope": -0.012, "EZZ@slope": 0.008, "EC0Y": 20.0,
              "EB0Z": -25.0, "EA0Z": 15.0, "EY0A": 12.0, "EZ0A": -9.0, "EB0A": 30.0,
              "EC0A": -20.0, "EX0C": 15.0, "EY0C": -10.0, "EA0C": 25.0, "EB0C": -35.0}
    setup = random_setup(blocks, np.random.default_rng(52))
    setup.update({f"dev.csv:{k}": v for k, v in zip(S.DEVIATION_SETUP,
                                                     (20.0, -15.0, 8.0, 12.0, -9.0, 5.0))})
    camp = Campaign(m, blocks, terms, values, setup, seed=53)
    folder = tmp_path_factory.mktemp("mixed")
    files = camp.write(folder)
    r, doc = run_json(["calibrate", "TT_AC", *files, "--parameters",
                       ",".join(["EXX", "EYY", "EZZ", "EC0Y", "EB0Z", "EA0Z", *loc]),
                       "--degree", "1", "--seed", "4"], folder / "cal.json")
    ref_val, ref_std, d = reference_estimate(camp, terms)
    ok, rel = S.identifiability(d)
    return dict(camp=camp, r=r, doc=doc, ok=ok, rel=rel, ref_val=ref_val, ref_std=ref_std)


def _doc(run):
    assert run["r"].returncode == 0, run["r"].stderr[-3000:]
    return run["doc"]


def test_design_is_clear_cut(run):
    assert all(v > 1e-3 or v < 1e-8 for v in run["rel"].values()), run["rel"]
    for p, ident in run["ok"].items():
        if ident:
            z = (run["ref_val"][p] - run["camp"].values[p]) / run["ref_std"][p]
            assert abs(z) <= K_SIGMA, (p, z)


def test_kinds_detected_and_identifiability(run):
    doc = _doc(run)
    kinds = {i["file"]: i["kind"] for i in doc["instruments"]}
    assert kinds == {"bb_xy.csv": "ballbar", "rtest.csv": "sphere", "dev.csv": "deviations"}
    # "n": data rows; "n_readings": scalar readings (docs/formats.md, calibrate-json)
    for b in run["camp"].blocks:
        (e,) = [i for i in doc["instruments"] if i["file"] == b.name]
        assert e["n"] == b.n and e.get("n_readings", b.n * b.rows_per_reading) == (
            b.n * b.rows_per_reading), e
    mine_un = sorted(p for p, v in run["ok"].items() if not v)
    assert sorted(set(doc["unidentifiable"]) & set(run["ok"])) == mine_un, (
        doc["unidentifiable"], mine_un, doc.get("gauge_fixed"))
    for p, v in run["ok"].items():
        assert doc["identifiability"][p]["identifiable"] == v, (p, doc["identifiability"][p])


def test_parameters_within_3_sigma(run):
    doc = _doc(run)
    bad = []
    for p, v in run["ok"].items():
        if v:
            e = doc["parameters"][p]
            if abs(e["value"] - run["camp"].values[p]) > K_SIGMA * e["std"]:
                bad.append((p, e["value"], run["camp"].values[p], e["std"]))
    assert not bad, f"outside 3 std (name, value, planted, std): {bad}"


def test_heldout_at_the_floor_per_file(run):
    doc = _doc(run)
    camp = run["camp"]
    inst = {i["file"]: i for i in doc["instruments"]}
    split = {b.name: inst[b.name]["test_rows"] for b in camp.blocks}
    floor = floor_fit(camp, split, design=true_design(camp), per="reading")
    ratios = {b.name: (inst[b.name]["heldout_rms"], floor[b.name]) for b in camp.blocks}
    bad = {k: v for k, v in ratios.items()
           if not v[1] / FLOOR_FACTOR <= v[0] <= FLOOR_FACTOR * v[1]}
    assert not bad, f"held-out RMS (um) vs floor outside [1/1.15, 1.15]: {bad} (all: {ratios})"
