"""The plan executor of the acceptance tests (tests/helpers/plan_exec.py) checked on its own,
so that a failure of test_plan_acceptance.py points at the planner, not at the tester:

* its readings equal those of the earlier independent simulators (instrument_sim.readings for
  ballbar and sphere, metrology_sim for distances) at the same planted errors and set-ups;
* hand-made plan files (reading columns empty), filled by it and fed to ``volerr calibrate``
  give the planted parameters within 3 standard uncertainties (the documented reading models
  of docs/formats.md agree with it);
* its NC parser reads modal words, dwells and comments as ISO does, and refuses incremental
  or inch motion.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from helpers import instrument_sim as S
from helpers import metrology_sim as M
from helpers import plan_exec as P

LOCATION = ["EX0B", "EY0B", "EA0B", "EB0B", "EX0C", "EY0C", "EA0C", "EB0C"]
STATIONS = {"S1": (-180.0, -170.0, 10.0), "S2": (190.0, -160.0, 40.0),
            "S3": (170.0, 185.0, 5.0), "S4": (-160.0, 175.0, 60.0)}


def _write_empty(path, cols: dict, empty, header=()):
    """A plan-like file: ``cols`` with the columns ``empty`` present and empty."""
    cols = {**cols, **{c: [""] * len(next(iter(cols.values()))) for c in empty}}
    names = list(cols)
    lines = list(header) + [",".join(names)]
    for i in range(len(cols[names[0]])):
        lines.append(",".join(v if isinstance(v := cols[c][i], str) else repr(float(v))
                              for c in names))
    path.write_text("\n".join(lines) + "\n")
    return path


def _ballbar(m, folder, u=0.5):
    blk = S.concat([S.ballbar_circle(m, "bb.csv", "XY", (0.0, 0.0, 150.0), 100.0, 36,
                                     placement="P1", probe=(0, 0, 100), u_um=u),
                    S.ballbar_circle(m, "bb.csv", "ZX", (0.0, 0.0, 260.0), 150.0, 36,
                                     placement="P2", probe=(0, 0, 100), u_um=u, start_deg=200,
                                     rotary={"B": 0.0, "C": 0.0})])
    cols = S.columns(m, blk, np.zeros(blk.n), covariates=False)
    cols.pop("dr_um")
    cols["placement"] = [str(p) for p in cols["placement"]]
    cols["direction"] = [str(int(v)) for v in cols["direction"]]
    return blk, _write_empty(folder / "bb.csv", cols, ["dr_um"])


def _sphere(m, folder, u=1.0, tool_u=0.5):
    grid = [{"B": b, "C": c} for b in (0.0, 30.0, 60.0) for c in range(0, 360, 45)]
    blk = S.sphere_block(m, "sp.csv", {"A": (60.0, 40.0, 200.0), "B": (-50.0, -70.0, 230.0)},
                         grid, probe=(0, 0, 120), u_um=u)
    cols = S.columns(m, blk, np.zeros((blk.n, 3)), covariates=False, u_column=False)
    for c in ("dx_um", "dy_um", "dz_um"):
        cols.pop(c)
    cols["placement"] = [str(p) for p in cols["placement"]]
    cols["frame"] = [str(p) for p in cols["frame"]]
    cols["u_um"] = np.full(blk.n, u)
    cols["tool_u_um"] = np.full(blk.n, tool_u)
    return blk, _write_empty(folder / "sp.csv", cols, ["dx_um", "dy_um", "dz_um"])


def _distances(m, folder, rng, n=50, u=0.3):
    probe = np.array([0.0, 0.0, 100.0])
    t = rng.uniform([-120, -120, 20], [120, 120, 220], (4 * n, 3))
    rot = {"B": rng.choice([0.0, 30.0, 60.0, 90.0], 4 * n), "C": rng.uniform(0, 360, 4 * n)}
    q = m.inverse(t, rot, probe, check_travel=False)
    ok = np.ones(4 * n, bool)
    for a in m.axes:
        ok &= (q[a] >= m.travel[a][0]) & (q[a] <= m.travel[a][1])
    pos = {a: q[a][ok][:n] for a in m.axes}
    blk = M.distances_block("lt.csv", pos, probe, STATIONS, {k: 0.0 for k in STATIONS})
    cols = {a: blk.pos[a] for a in m.axes}
    cols.update({"Xp": blk.probe[:, 0], "Yp": blk.probe[:, 1], "Zp": blk.probe[:, 2],
                 "station": list(blk.station), "u_um": np.full(blk.n, u)})
    s = np.array([STATIONS[k] for k in blk.station])
    cols.update({"station_x": s[:, 0], "station_y": s[:, 1], "station_z": s[:, 2]})
    return blk, _write_empty(folder / "lt.csv", cols, ["d_mm"])


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    root = tmp_path_factory.mktemp("handmade")
    plan = root / "plan"
    plan.mkdir()
    m = S.Machine("DMU50")
    rng = np.random.default_rng(5)
    bb, bb_path = _ballbar(m, plan)
    sp, sp_path = _sphere(m, plan)
    lt, lt_path = _distances(m, plan, rng)
    files = [P.read_plan_file(bb_path, "ballbar"), P.read_plan_file(sp_path, "sphere"),
             P.read_plan_file(lt_path, "distances")]
    return m, root, plan, files, (bb, sp, lt)


def test_readings_equal_the_earlier_simulators(campaign, tmp_path):
    m, _, plan, files, (bb, sp, lt) = campaign
    rng = np.random.default_rng(11)
    truth = {k: P.planted_value(m, k, rng) for k in
             ["EC0Y", "EB0Z", "EA0Z", "EXX@slope", "EYY@slope", *LOCATION]}
    ranges = P.measured_ranges(m, files)
    terms = P.planted_terms(m, truth, ranges)
    for f, blk in zip(files, (bb, sp, lt)):
        # noise-free: the file's u_um set to 0
        f0 = P.PlanFile(f.path, f.kind, f.lines, f.column_line, f.columns, f.data_lines,
                        [[("0" if c == "u_um" else v) for c, v in zip(f.columns, r)]
                         for r in f.cells], f.meta)
        setup = {}
        got = P.FILL[f.kind](m, f0, terms, truth, np.random.default_rng(3), setup)
        if f.kind == "ballbar":
            s = {}
            for k, v in setup.items():
                owner, key = k.rsplit(":", 1)
                if key == "pivot":
                    s.update({f"{owner}:pivot_d{c}": v[i] for i, c in enumerate("xyz")})
                else:
                    s[k] = v
            ref = S.readings(m, blk, terms, truth, s)
            assert np.max(np.abs(got["dr_um"] - ref)) < 1e-6
        elif f.kind == "sphere":
            s = {}
            for k, v in setup.items():
                owner, key = k.rsplit(":", 1)
                if key == "centre":
                    s.update({f"{owner}:centre_d{c}": v[i] for i, c in enumerate("xyz")})
                else:
                    s[k] = v
            ref = S.readings(m, blk, terms, truth, s)
            got3 = np.column_stack([got[c] for c in ("dx_um", "dy_um", "dz_um")])
            assert np.max(np.abs(got3 - ref)) < 1e-6
        else:
            s = {}
            for k, v in setup.items():
                owner, key = k.rsplit(":", 1)
                if key == "station":
                    s.update({f"{owner}:station_d{c}": v[i] for i, c in enumerate("xyz")})
                else:
                    s[k] = v
            ref = M.distance_readings(m, blk, terms, truth, s)
            assert np.max(np.abs(1e3 * got["d_mm"] - ref)) < 1e-6


def test_filled_hand_made_plan_calibrates_to_the_truth(campaign):
    m, root, plan, files, _ = campaign
    rng = np.random.default_rng(17)
    names = ["EC0Y", "EB0Z", "EA0Z", "EXX@slope", "EYY@slope", "EZZ@slope", *LOCATION]
    truth = {k: P.planted_value(m, k, rng) for k in names}
    paths, setup = P.execute(m, files, truth, root / "filled", rng, plan)
    assert all(p.is_file() for p in paths) and len(setup) > 10
    out = root / "cal.json"
    # the command through volerr.cli.main in this process: its parser, JSON and exit code,
    # without a second interpreter importing numpy, scipy ... again
    from helpers.in_process import volerr

    r = volerr("calibrate", "DMU50", *paths, "--parameters", "EXX,EYY,EZZ,squareness,location",
               "--degree", "1", "--json", out)
    assert r.returncode == 0, r.stderr[-3000:]
    doc = json.loads(out.read_text())
    assert set(names) <= set(doc["parameters"]), doc["unidentifiable"]
    bad = [(k, e["value"], truth.get(k, 0.0), e["std"]) for k, e in doc["parameters"].items()
           if abs(e["value"] - truth.get(k, 0.0)) > 3 * e["std"]]
    assert not bad, bad
    assert 0.8 < doc["variance_factor"] < 1.25, doc["variance_factor"]


def test_plan_file_header_lines_and_empty_cells(tmp_path):
    p = tmp_path / "f.csv"
    p.write_text("# u_um: 0.7\n# tool_u_um : 0.5\n#comment\nX,Y,dr_um,placement\n"
                 "1,2,,P1\n3,4,,P2\n")
    f = P.read_plan_file(p, "ballbar")
    assert f.meta == {"u_um": "0.7", "tool_u_um": "0.5"} and f.n == 2
    assert f.declared("tool_u_um") == 0.5 and list(f.number("u_um")) == [0.7, 0.7]
    assert f.text("dr_um") == ["", ""]
    out = f.write_filled(tmp_path / "g.csv", {"dr_um": [1.5, -2.0]})
    assert out.read_text().splitlines() == ["# u_um: 0.7", "# tool_u_um : 0.5", "#comment",
                                            "X,Y,dr_um,placement", "1,2,1.500000,P1",
                                            "3,4,-2.000000,P2"]


def test_nc_parser():
    text = """%
O1000 (plan)
N10 G21 G90 G17
N20 G0 X10 Y20 Z30 B0 C0 (approach)
N30 G1 X11.0004 F500
N40 G04 P0.5
N50 Y21 ; comment X99
N60 M5
N70 G4 X2.0
N80 G91 G1 X1
N90 G90 G20 X2
N95 G21 A10
%"""
    blocks = P.nc_blocks(text, ("X", "Y", "Z", "B", "C"))
    moves = [b for b in blocks if b.end is not None]
    assert [b.line for b in moves] == [4, 5, 7, 10, 11, 12]
    assert moves[1].end == {"X": 11.0004, "Y": 20.0, "Z": 30.0, "B": 0.0, "C": 0.0}
    assert moves[2].end["Y"] == 21.0 and moves[2].end["X"] == 11.0004
    assert [b.dwell for b in blocks if b.dwell is not None] == [0.5, 2.0]
    assert moves[3].errors == ["G91"] and moves[4].errors == ["G20"]
    assert moves[5].errors == ["axis A not in the layout"]
    rows = [{"X": 10.0, "Y": 20.0}, {"X": 11.0, "Y": 21.0}]
    hits = P.match_rows(blocks, rows)
    assert [blocks[h].line for h in hits] == [4, 7]
    assert P.match_rows(blocks, rows[::-1])[1] is None      # order matters


def test_motion_signs_and_reversal(tmp_path):
    """The sign of the motion that brought each axis to a reading, per trace; a reversal
    planted on X shifts the readings by +-RV/2 along the bar's x component."""
    p = tmp_path / "b.csv"
    p.write_text("X,Y,Z,placement,direction\n0,0,0,P1,1\n1,0,0,P1,1\n1,0,0,P1,1\n0,1,0,P1,1\n"
                 "5,0,0,P2,1\n4,0,0,P2,1\n")
    f = P.read_plan_file(p, "ballbar")
    m = S.Machine("MB1")
    v = P.motion_signs(m, f, f.labels("placement"))
    assert list(v["X"]) == [1, 1, 1, -1, -1, -1] and list(v["Y"]) == [1, 1, 1, 1, 0, 0]
    assert list(v["Z"]) == [0] * 6
    (term,) = P.planted_terms(m, ["RV_X"], {})
    assert term.target == "EXX"
    err = S.errors_at(P.View(f.positions(m.axes), v), [term], {"RV_X": 4.0})
    assert np.allclose(err["EXX"], 2e-3 * v["X"])


def test_reversal_as_calibrate_reads_it(tmp_path):
    """A reversal planted by the executor on an MB1 ballbar plan (XY circle both directions)
    is found by calibrate's reversal term (the documented ``RV_<axis>``: half of it on the
    axis' positioning error with the sign of the motion, from the order of the readings)."""
    from volerr.calibrate import calibrate

    m = S.Machine("MB1")
    blk = S.concat([S.ballbar_circle(m, "bb.csv", "XY", (450.0, 287.0, 200.0), 150.0, 60,
                                     direction=d, placement="P1") for d in (1, -1)])
    cols = S.columns(m, blk, np.zeros(blk.n), covariates=False)
    cols.pop("dr_um")
    cols["placement"] = [str(p) for p in cols["placement"]]
    cols["direction"] = [str(int(v)) for v in cols["direction"]]
    plan = tmp_path / "plan"
    plan.mkdir()
    f = P.read_plan_file(_write_empty(plan / "bb.csv", cols, ["dr_um"]), "ballbar")
    rng = np.random.default_rng(23)
    truth = {"EC0Y": 18.0, "RV_X": 3.0, "RV_Y": -2.5}
    (path,), _ = P.execute(m, [f], truth, tmp_path / "filled", rng, plan)
    cal = calibrate("MB1", [str(path)], parameters="EC0Y", degree=1, plan=False,
                    extra_terms=[("RV_X", "EXX", "dir_X/2", (1e3, "um")),
                                 ("RV_Y", "EYY", "dir_Y/2", (1e3, "um"))])
    got = cal["parameters"]
    for k, v in truth.items():
        assert abs(got[k]["value"] - v) <= 3 * got[k]["std"], (k, got[k], v)
    assert got["RV_X"]["std"] < 0.5, got["RV_X"]
