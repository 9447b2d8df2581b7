"""Mixed campaigns (issue 20): files of several instruments in one ``volerr calibrate`` run give
the same values as the separate fits of each file pooled (inverse-variance weighted mean of
the estimates of every file that determines the parameter), within the pooled uncertainty;
the joint values contain the planted ones within 3 standard uncertainties; the consistency
check names nothing on clean data and names a deliberately biased file (a step gauge whose
lengths are all 2 um long); ``volerr loop`` reads the same mixed files and finds no effect in
clean data.  Simulated with the independent exact chains
(tests/helpers/metrology_sim.py, tests/helpers/instrument_sim.py).

* MB1: a ball plate (4 placements), a step gauge (along X and along Y), an ISO 230-2
  positioning run of X;
* DMU50: multilateration (4 stations), ballbar (XY and ZX circles, a C sweep), sphere probing
  (two placements, B x C grid).

The separate fits run in-process (:func:`volerr.calibrate.calibrate`, the program itself: the
property checked is that stacking files is the statistics of pooling them)."""

import numpy as np
from scipy.spatial.transform import Rotation

from helpers import instrument_sim as S
from helpers import metrology_sim as M
from instruments._common import K_SIGMA, random_setup, run_json, series_terms

PLATES = {"XY": np.eye(3), "XZ": np.column_stack([(1.0, 0, 0), (0, 0, 1.0), (0, -1.0, 0)]),
          "YZ": np.column_stack([(0, 1.0, 0), (0, 0, 1.0), (1.0, 0, 0)])}


def _pooled(files, parameters, degree):
    """Per parameter: (inverse-variance weighted mean, its standard uncertainty) over the
    separate fits of ``files`` that determine it."""
    from volerr.calibrate import calibrate

    est = {}
    for f in files:
        cal = calibrate(*f, parameters=parameters, degree=degree, plan=False)
        for p, v in cal["parameters"].items():
            est.setdefault(p, []).append((v["value"], v["std"]))
    out = {}
    for p, vals in est.items():
        w = np.array([1.0 / s ** 2 for _, s in vals])
        out[p] = (float(np.sum(w * [v for v, _ in vals]) / w.sum()), float(1 / np.sqrt(w.sum())),
                  len(vals))
    return out


def _check_joint(doc, pooled, truth):
    assert set(doc["parameters"]) >= set(pooled), (sorted(pooled), doc["unidentifiable"])
    for p, (mean, u, n) in pooled.items():
        e = doc["parameters"][p]
        assert abs(e["value"] - mean) <= K_SIGMA * u, (p, e, mean, u, n)
    bad = [(p, e["value"], truth.get(p, 0.0), e["std"]) for p, e in doc["parameters"].items()
           if abs(e["value"] - truth.get(p, 0.0)) > K_SIGMA * e["std"]]
    assert not bad, bad


def test_plate_gauge_interferometer_on_mb1(tmp_path):
    m = S.Machine("MB1")
    rng = np.random.default_rng(61)
    mid = np.array([0.5 * sum(m.travel[a]) for a in "XYZ"])
    pts = np.column_stack([np.repeat(np.arange(5) * 80.0, 5), np.tile(np.arange(5) * 80.0, 5),
                           np.zeros(25)])
    poses = {}
    for label, plane, dz in (("XYlow", "XY", -100.0), ("XYhigh", "XY", 100.0),
                             ("XZ", "XZ", 0.0), ("YZ", "YZ", 0.0)):
        R = PLATES[plane] @ Rotation.from_rotvec(rng.normal(0, 2e-3, 3)).as_matrix()
        poses[label] = (R, mid + (0, 0, dz) - R @ (160.0, 160.0, 0.0))
    plate = M.artifact_block(m, "plate.csv", pts, poses, u_um=0.5)
    faces = np.column_stack([np.arange(12) * 45.0, np.zeros(12), np.zeros(12)])
    gauge = M.artifact_block(m, "gauge.csv", faces, {
        "GX": (np.eye(3), np.array([120.0, 290.0, 150.0])),
        "GY": (np.column_stack([(0, 1.0, 0), (-1.0, 0, 0), (0, 0, 1.0)]),
               np.array([450.0, 40.0, 150.0]))}, feature="face", u_um=0.3)
    run = M.line_block(m, "run.csv", "positioning", "X", {"Y": 290.0, "Z": 200.0},
                       (0, 0, 0), np.linspace(0, 900, 10), cycles=2)
    blocks = [plate, gauge, run]
    terms = series_terms(blocks, ["EXX", "EYY", "EZZ"], 1)
    terms += [S.constant(c) for c in ("EC0Y", "EB0Z", "EA0Z")]
    truth = {"EXX@slope": 0.012, "EYY@slope": -0.008, "EZZ@slope": 0.010, "EC0Y": 15.0,
             "EB0Z": -12.0, "EA0Z": 10.0}
    setup = {"run.csv:zero": 0.7}
    out = {}
    for b in blocks:
        out[b.name] = M.simulate(m, b, terms, truth, setup, rng)[1]
    M.write_csv(tmp_path / "plate.csv", M.artifact_columns(plate, out["plate.csv"]))
    M.write_csv(tmp_path / "gauge.csv", M.artifact_columns(gauge, out["gauge.csv"]))
    M.write_run(tmp_path / "run.csv", run, out["run.csv"])
    files = [tmp_path / f for f in ("plate.csv", "gauge.csv", "run.csv")]
    params = "EXX,EYY,EZZ,EC0Y,EB0Z,EA0Z"
    r, doc = run_json(["calibrate", "MB1", *files, "--parameters", params, "--degree", "1"],
                      tmp_path / "joint.json")
    assert r.returncode == 0, r.stderr[-3000:]
    kinds = {i["file"]: i["kind"] for i in doc["instruments"]}
    assert kinds == {"plate.csv": "artifact", "gauge.csv": "artifact",
                     "run.csv": "interferometer"}
    pooled = _pooled([("MB1", [str(f)]) for f in files], params, 1)
    # determined by several files alone: the X scale by the plate and the run (the gauge
    # alone cannot tell it from the squareness its own micro-radian tilt reads), the Y scale
    # by the plate and the gauge
    assert pooled["EXX@slope"][2] == 2 and pooled["EYY@slope"][2] == 2
    _check_joint(doc, pooled, truth)
    assert doc["consistency"]["inconsistent"] == [], doc["consistency"]
    # the step gauge's measured lengths compared with the identified model's
    g = {e["placement"]: e for e in doc["iso10360"]["step_gauges"]}
    assert set(g) == {"GX", "GY"} and max(e["max_abs_En"] for e in g.values()) < 3.5
    # the loop on the same files: every kind read, nothing found on clean data
    r, loop = run_json(["loop", "MB1", *files], tmp_path / "loop.json")
    assert r.returncode == 0, r.stderr[-3000:]
    assert {i["file"]: i["kind"] for i in loop["instruments"]} == kinds
    assert loop["effects"] == [], loop["effects"]

    # the same step gauge with every length 2 um long: named inconsistent, the others not
    biased = out["gauge.csv"].copy()
    for label, (R, _) in gauge.poses.items():
        sel = np.flatnonzero(gauge.placement == label)[1:]          # all but the first face
        biased[sel] += 2e-3 * R[:, 0]
    folder = tmp_path / "biased"
    folder.mkdir()
    M.write_csv(folder / "gauge.csv", M.artifact_columns(gauge, biased))
    r, doc = run_json(["calibrate", "MB1", files[0], folder / "gauge.csv", files[2],
                       "--parameters", params, "--degree", "1"], tmp_path / "biased.json")
    assert r.returncode == 0, r.stderr[-3000:]
    assert doc["consistency"]["inconsistent"] == ["gauge.csv"], doc["consistency"]
    entry = {i["file"]: i for i in doc["instruments"]}
    assert entry["gauge.csv"]["consistent"] is False and entry["plate.csv"]["consistent"]
    assert "inconsistent" in r.stdout and "gauge.csv" in r.stdout


def test_multilateration_ballbar_sphere_on_dmu50(tmp_path):
    m = S.Machine("DMU50")
    rng = np.random.default_rng(71)
    # multilateration: 4 stations x 60 poses (reflector 100 mm out)
    probe = np.array([0.0, 0.0, 100.0])
    pos = {a: [] for a in m.axes}
    while len(pos["X"]) < 60:
        t = rng.uniform([-150, -150, 20], [150, 150, 250], (200, 3))
        rot = {"B": rng.choice([0.0, 30.0, 60.0, 90.0], 200), "C": rng.uniform(0, 360, 200)}
        q = m.inverse(t, rot, probe, check_travel=False)
        ok = np.all([(q[a] >= m.travel[a][0]) & (q[a] <= m.travel[a][1]) for a in m.axes], 0)
        for a in m.axes:
            pos[a] += list(q[a][ok])
    pos = {a: np.asarray(v[:60]) for a, v in pos.items()}
    lt = M.distances_block("lt.csv", pos, probe, {
        "S1": (-180.0, -170.0, 10.0), "S2": (190.0, -160.0, 40.0), "S3": (170.0, 185.0, 5.0),
        "S4": (-160.0, 175.0, 60.0)}, {"S1": 0.01})
    bb = S.concat([S.ballbar_circle(m, "bb.csv", "XY", (0, 0, 100.0), 100.0, 72, 1, "XY"),
                   S.ballbar_circle(m, "bb.csv", "ZX", (0, 0, 150.0), 100.0, 72, 1, "ZX"),
                   S.ballbar_sweep(m, "bb.csv", "C", 0, 360, 60, (100.0, 0, 20.0),
                                   (80.0, 0, 0), "sweep")])
    grid = [{"B": b, "C": c} for b in (0, 30, 60, 90) for c in (0, 90, 180, 270)]
    sp = S.sphere_block(m, "sp.csv", {"P1": (80, 0, 250.0), "P2": (-60, 60, 300.0)}, grid,
                        probe=(0, 0, 120.0), u_um=0.5)
    blocks = [lt, bb, sp]
    loc = ["EX0B", "EY0B", "EA0B", "EB0B", "EX0C", "EY0C", "EA0C", "EB0C"]
    terms = series_terms(blocks, ["EXX", "EYY", "EZZ"], 1)
    terms += [S.constant(c) for c in ("EC0Y", "EB0Z", "EA0Z", *loc)]
    # constants only: a separate fit of one file has its own measured range, and the offset
    # a linear error has over another range would reappear in the location errors
    truth = {"EC0Y": 20.0, "EB0Z": -15.0, "EA0Z": 12.0, "EX0B": 12.0, "EY0B": -8.0,
             "EA0B": 35.0, "EB0B": -20.0, "EX0C": 15.0, "EY0C": -10.0, "EA0C": 25.0,
             "EB0C": -30.0}
    setup = random_setup([bb, sp], np.random.default_rng(72))
    y = {b.name: M.simulate(m, b, terms, truth, setup, rng)[1] for b in blocks}
    M.write_csv(tmp_path / "lt.csv", M.distance_columns(m, lt, y["lt.csv"], relative=False))
    for b in (bb, sp):
        S.write_csv(tmp_path / b.name, S.columns(m, b, y[b.name]))
    files = [tmp_path / f for f in ("lt.csv", "bb.csv", "sp.csv")]
    params = "EXX,EYY,EZZ,EC0Y,EB0Z,EA0Z," + ",".join(loc)
    r, doc = run_json(["calibrate", "DMU50", *files, "--parameters", params, "--degree", "1"],
                      tmp_path / "joint.json")
    assert r.returncode == 0, r.stderr[-3000:]
    pooled = _pooled([("DMU50", [str(f)]) for f in files], params, 1)
    assert max(n for _, _, n in pooled.values()) >= 2, pooled
    _check_joint(doc, pooled, truth)
    assert doc["consistency"]["inconsistent"] == [], doc["consistency"]
