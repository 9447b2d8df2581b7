"""``volerr plan --instrument artifact``: ball-plate placements (XY, YZ, ZX, turned 0 / 90 deg,
three levels) chosen for the budget.  The plan's file is filled by the exact simulator of
tests/helpers/metrology_sim.py (never volerr's model): the true plate poses are the plan's
nominal ones (fitted here, Kabsch), perturbed per placement, the balls' calibration errors drawn
from the declared ``u_std_um``, probing noise of ``probe_u_um``; calibrated with no options:
every parameter within 3 std of the planted value and the realised std within 0.7-1.4 x the
plan's ``predicted_std``; every ball inside the travel; the NC program probes every ball, in
order, with probing moves aimed at its centre."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from helpers import instrument_sim as S
from helpers import metrology_sim as M
from helpers import plan_fill
from volerr.calibrate.run import calibrate
from volerr.cli import main
from volerr.machine.layout import read_layout

# the module fixtures once, on one xdist worker (not once per worker)
pytestmark = pytest.mark.xdist_group("planning_artifact")

PLAN = ["MB1", "--instrument", "artifact:balls=3x3:pitch=150:places=6", "--readings", "54",
        "--parameters", "squareness,EXX@slope,EYY@slope,EZZ@slope"]
PLANTED = {"EA0Z": 12.0, "EB0Z": -8.0, "EC0Y": 15.0, "EXX@slope": 0.010, "EYY@slope": -0.008,
           "EZZ@slope": 0.006}


@pytest.fixture(scope="module")
def plan(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("artifact")
    out, js = tmp / "plan", tmp / "plan.json"
    assert main(["plan", *PLAN, "--out", str(out), "--json", str(js)]) == 0
    return out, json.loads(js.read_text())


def _kabsch(p, x):
    pc, xc = p - p.mean(axis=0), x - x.mean(axis=0)
    U, _, Vt = np.linalg.svd(xc.T @ pc)
    R = U @ np.diag([1.0, 1.0, np.linalg.det(U @ Vt)]) @ Vt
    return R, x.mean(axis=0) - R @ p.mean(axis=0)


def _terms(nominal):
    out = []
    for name in PLANTED:
        if "@" in name:
            k = "XYZ".index(name[2])
            out.append(S.series(name.split("@")[0], 1, nominal[:, k].min(),
                                nominal[:, k].max()))
        else:
            out.append(S.constant(name))
    return out


@pytest.fixture(scope="module")
def executed(plan, tmp_path_factory):
    folder, doc = plan
    (f,) = doc["files"]
    machine = S.Machine(doc["layout"])
    comments, cols = plan_fill.read(folder / f["file"])
    place = np.array(cols["placement"])
    ball = np.array(cols["ball"])
    points = np.column_stack([np.array(cols[k], float) for k in ("u_mm", "v_mm", "w_mm")])
    nominal = np.column_stack([np.array(cols[k], float) for k in ("x_nom_mm", "y_nom_mm",
                                                                  "z_nom_mm")])
    labels = list(dict.fromkeys(place))
    first = place == labels[0]
    poses = {p: _kabsch(points[place == p], nominal[place == p]) for p in labels}
    u = float(cols["probe_u_um"][0])
    u_std = float(cols["u_std_um"][0])
    blk = M.artifact_block(machine, "artifact", points[first], poses, probe=(0, 0, 0), u_um=u,
                           u_std_um=u_std, labels=list(ball[first]))
    rng = np.random.default_rng(21)
    setup = {}
    for p in labels:
        for k in ("du", "dv", "dw"):
            setup[f"artifact#{p}:{k}"] = rng.normal(0, 5.0)
        for k in ("eu", "ev", "ew"):
            setup[f"artifact#{p}:{k}"] = rng.normal(0, 10.0)
    for b in ball[first]:
        for k in ("cu", "cv", "cw"):
            setup[f"artifact@{b}:{k}"] = rng.normal(0, u_std)
    x = M.reported_points(machine, blk, _terms(nominal), PLANTED, setup)
    x = x + rng.normal(0, u * 1e-3, x.shape)
    row = {(p, b): i for i, (p, b) in enumerate(zip(blk.placement, blk.ball))}
    order = [row[(p, b)] for p, b in zip(place, ball)]
    for k, name in enumerate(("x_mm", "y_mm", "z_mm")):
        cols[name] = [repr(float(v)) for v in x[order, k]]
    path = tmp_path_factory.mktemp("filled") / f["file"]
    plan_fill.write(path, comments, cols)
    return calibrate(doc["layout"], [str(path)], plan=False).data


def test_executed_plan_gives_the_planted_errors_and_the_predicted_std(plan, executed):
    _, doc = plan
    cal = executed
    assert set(cal["parameters"]) == set(doc["parameters"]) == set(PLANTED)
    ratios = []
    for n, pred in doc["parameters"].items():
        got = cal["parameters"][n]
        assert got["unit"] == pred["unit"]
        assert pred["determined_alone_by"] == ["artifact"]
        assert abs(got["value"] - PLANTED[n]) < 3 * got["std"], (n, got)
        ratios.append(got["std"] / pred["predicted_std"])
        assert 0.7 <= ratios[-1] <= 1.4, (n, got, pred)
    print(f"realised / predicted std: {min(ratios):.3f} .. {max(ratios):.3f}")


def test_file_lists_the_balls_inside_the_travel_with_empty_readings(plan):
    folder, doc = plan
    layout = read_layout(doc["layout"])
    (f,) = doc["files"]
    comments, cols = plan_fill.read(folder / f["file"])
    assert f["kind"] == "artifact" and f["readings"] == len(cols["ball"]) == 54
    for k in ("x_mm", "y_mm", "z_mm"):
        assert all(c == "" for c in cols[k])
    assert not set(layout.axis_names) & set(cols)       # the reader refuses axis columns
    for k, a in zip(("x_nom_mm", "y_nom_mm", "z_nom_mm"), layout.axis_names):
        q = np.array(cols[k], float)
        lo, hi = layout.axes[a].travel
        assert np.all((q >= lo) & (q <= hi))
    assert len(set(cols["placement"])) == 6
    assert {c.split(",")[0] for c in comments if c.startswith("# set-up")}


def test_nc_program_probes_every_ball_towards_its_centre_in_order(plan):
    """Issue 36: a ball is measured by probing moves (``G38.2``) aimed at its centre from
    outside, at least four per ball (a centre and a radius), not all in one plane; the balls
    in the file's order."""
    folder, doc = plan
    axes = read_layout(doc["layout"]).axis_names
    (f,) = doc["files"]
    _, cols = plan_fill.read(folder / f["file"])
    centres = np.array([[float(cols[k][i]) for k in ("x_nom_mm", "y_nom_mm", "z_nom_mm")]
                        for i in range(len(cols["ball"]))])
    where, probes = {}, []
    for ln in (folder / f["nc"]).read_text().splitlines():
        code = re.sub(r"\(.*?\)", "", ln).split()
        if not code or code[0] not in ("G0", "G1", "G38.2"):
            continue
        to = {**where, **{w[0]: float(w[1:]) for w in code[1:] if w[0] in "XYZ"}}
        if code[0] == "G38.2":
            probes.append((np.array([where[a] for a in axes]), np.array([to[a] for a in axes])))
        where = to
    def aimed(p0, p1, c):
        d = (p1 - p0) / np.linalg.norm(p1 - p0)
        along = (c - p0) @ d
        return (np.linalg.norm(c - p0 - along * d) < 1e-3
                and along > np.linalg.norm(p1 - p0) > 0)   # stops short of the centre

    owner, b = [], 0            # the balls in the file's order (placements may share places)
    for p0, p1 in probes:
        while b < len(centres) and not aimed(p0, p1, centres[b]):
            b += 1
        assert b < len(centres), (p0, p1, "a probing move not aimed at the next ball's centre")
        owner.append(b)
    for b in range(len(centres)):
        starts = np.array([p0 for (p0, _), o in zip(probes, owner) if o == b])
        assert len(starts) >= 4, (b, "fewer than four probing points")
        rel = starts - starts.mean(axis=0)
        assert np.linalg.svd(rel, compute_uv=False)[-1] > 1.0, (b, "points in one plane")
