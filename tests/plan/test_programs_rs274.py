"""Acceptance test of issue 36 item 3: every NC program ``volerr plan`` writes, read by LinuxCNC's
stand-alone interpreter (``rs274``) and followed along its whole path by the independent checker
``tests/helpers/rs274_path.py`` (written by a tester who did not write the programs).

Plans: MB1 and DMU50 over ballbar, sphere / R-test (DMU50), artifact (MB1 ball plate),
interferometer and distances, each with ``--dialect linuxcnc`` and ``--dialect iso`` (``iso`` is
RS274NGC-compatible: rs274 reads it too).  Checks (INTERFACE.md "Measurement programs a machine
can run"): accepted by rs274; lines < 254 characters; G21, G90, a work offset, the tool-length
compensation state and M30 stated; the first motion a retract along Z alone to the top of the
Z travel; ballbar within +-1.0 mm of its length from the first to the last reading of a set-up;
no non-probing move within 10 mm of a ball centre and every ball probed radially at 4+ points;
no rotary motion and no motion off the tool axis within 30 mm of a sphere; every
interferometer reading reached from its declared direction with an overshoot of 1 mm or more
before every reversal; the reading positions exactly the plan's rows.

The first block of tests checks the checker itself on small hand-written programs against
closed-form values (a chord's squeeze ``L (1 - cos(pi/8))``, a programmed overshoot).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import volerr
from helpers import reference_chain
from helpers import plan_designs
from helpers import rs274_path as R
from volerr.cli import main
from volerr.machine.layout import read_layout

needs_rs274 = pytest.mark.skipif(R.rs274() is None, reason=R.SKIP_REASON)

#: plan cases: small readings counts (the suite's time), every kind of issue 36
CASES = {
    "MB1-ballbar": ["MB1", "--instrument", "ballbar:lengths=150,250", "--readings", "60"],
    "DMU50-ballbar": ["DMU50", "--instrument", "ballbar:lengths=150", "--readings", "300"],
    "DMU50-sphere": ["DMU50", "--instrument", "sphere:tool=100", "--readings", "40"],
    "MB1-artifact": ["MB1", "--instrument", "artifact:balls=3x3:pitch=150:places=6",
                     "--readings", "54", "--parameters", "squareness,EXX@slope,EYY@slope,EZZ@slope"],
    "MB1-interferometer": ["MB1", "--instrument", "interferometer:optics=linear", "--readings",
                           "150", "--parameters", "EXX@slope,EYY@slope,EZZ@slope"],
    "DMU50-interferometer": ["DMU50", "--instrument", "interferometer:optics=linear",
                             "--readings", "150", "--parameters", "EXX@slope,EYY@slope,EZZ@slope"],
    "MB1-distances": ["MB1", "--instrument", "distances:stations=3", "--readings", "40",
                      "--parameters", "squareness,EXX@slope,EYY@slope,EZZ@slope"],
    "DMU50-distances": ["DMU50", "--instrument", "distances:stations=3", "--readings", "40",
                        "--parameters", "squareness,EXX@slope,EYY@slope,EZZ@slope"],
}
DIALECTS = ("linuxcnc", "iso")
#: the tests of a plan case on one xdist worker, both dialects: the plan designed once (the
#: design does not depend on the dialect, only the programs written from it do:
#: ``helpers.plan_designs``) and each program read by rs274 once (the module's ``planned`` and
#: ``_READ`` caches live in each worker); the cases spread over the workers.  DMU50-ballbar is
#: tests/planning/test_plan.py's SWEEPS plan (the same design): in that module's group
PLANS = [pytest.param(c, d, id=f"{c}-{d}", marks=pytest.mark.xdist_group(
    "planning_plans" if c == "DMU50-ballbar" else f"rs274_{c}")) for c in CASES for d in DIALECTS]


# ---------------------------------------------------------------------------------------------
# the checker checked on hand-written programs

def _write(tmp_path, text, name="p.ngc"):
    path = tmp_path / name
    path.write_text(text)
    return path


HEAD = "%\nG21 G90 G94 G17 G49\nG53 G0 Z400\nG54\n"


def _ballbar_cols(pts, pivot, length):
    n = len(pts)
    cols = {a: [str(v) for v in pts[:, k]] for k, a in enumerate("XYZ")}
    cols.update({c: ["0"] * n for c in ("Xp", "Yp", "Zp")})
    cols.update({f"pivot_{c}": [str(pivot[k])] * n for k, c in enumerate("xyz")})
    cols.update(length_mm=[str(length)] * n, placement=["C1"] * n, direction=["1"] * n)
    return cols


@needs_rs274
def test_checker_finds_a_chord_squeeze_and_passes_an_arc(tmp_path):
    model, pivot, L = volerr.load("MB1"), np.array([450.0, 287.5, 200.0]), 150.0
    ang = np.arange(9) * math.pi / 4
    pts = pivot + L * np.column_stack([np.cos(ang), np.sin(ang), 0 * ang])
    chords = "".join(f"G1 X{p[0]:.4f} Y{p[1]:.4f} Z200 F1000\n" for p in pts[1:])
    text = HEAD + f"G0 X{pts[0, 0]:.4f} Y{pts[0, 1]:.4f}\nG0 Z200\n" + chords + "M30\n%\n"
    bad, worst = R.ballbar_check(R.load(_write(tmp_path, text)), _ballbar_cols(pts, pivot, L),
                                 model)
    assert len(bad) == 1 and "squeezed" in bad[0]
    assert worst["C1"] == pytest.approx(-L * (1 - math.cos(math.pi / 8)), abs=2e-3)
    arc = (HEAD + f"G0 X{pts[0, 0]:.4f} Y{pts[0, 1]:.4f}\nG0 Z200\n"
           f"G3 X{pts[0, 0]:.4f} Y{pts[0, 1]:.4f} I{-L:g} J0 F1000\nM30\n%\n")
    bad, worst = R.ballbar_check(R.load(_write(tmp_path, arc, "a.ngc")),
                                 _ballbar_cols(pts, pivot, L), model)
    assert bad == [] and abs(worst["C1"]) < 1e-3
    longway = (HEAD + f"G0 X{pts[0, 0]:.4f} Y{pts[0, 1]:.4f}\nG0 Z200\n" + "".join(
        f"G2 X{p[0]:.4f} Y{p[1]:.4f} I{c[0]:.4f} J{c[1]:.4f} F1000\n"
        for p, c in zip(pts[1:], pivot[:2] - pts[:-1, :2])) + "M30\n%\n")
    bad, _ = R.ballbar_check(R.load(_write(tmp_path, longway, "w.ngc")),
                             _ballbar_cols(pts, pivot, L), model)
    assert bad and all("more than half a turn" in b or "not on the path" in b for b in bad)


@needs_rs274
def test_checker_reads_the_program_rules(tmp_path):
    long = "(" + "x" * 260 + ")\n"
    bad = R.program_text_checks(_write(tmp_path, "%\nG20 G90\nG0 X1 Y1\n" + long + "M2\n%\n"))
    assert any("262 characters" in b for b in bad)
    assert {"G21", "G54..G59", "G43", "M30"} <= {b.split()[1] for b in bad if
                                                       b.startswith("no ")}
    with pytest.raises(R.Rejected, match="too long"):
        R.load(_write(tmp_path, "G21 G90\n" + long + "M30\n", "l.ngc"))
    path = R.load(_write(tmp_path, "G20 G90\nG0 X1 Y1 Z2\nM30\n", "i.ngc"))
    bad = R.path_checks(path, 400.0)
    assert any("not metric" in b for b in bad) and any("not a retract" in b for b in bad)
    assert R.path_checks(R.load(_write(tmp_path, HEAD + "G0 X1\nM30\n", "ok.ngc")), 400.0) == []


@needs_rs274
def test_checker_finds_a_missing_overshoot(tmp_path):
    model = volerr.load("MB1")
    comments = ["axis: X", "at: Y=50, Z=40"]
    cols = {"target_mm": ["100", "200", "200", "100"], "direction": ["1", "1", "-1", "-1"]}
    body = "G0 X90 Y50 Z40\nG1 X100 F2000\nG4 P3\nG1 X200\nG4 P3\n"
    no = HEAD + body + "G1 X200.0001\nG1 X200\nG4 P3\nG1 X100\nG4 P3\nM30\n"
    bad, shoots = R.interferometer_check(R.load(_write(tmp_path, no)), comments, cols, model)
    assert shoots == [pytest.approx(1e-4)] and len(bad) == 1 and "overshoot" in bad[0]
    yes = HEAD + body + "G1 X205\nG1 X200\nG4 P3\nG1 X100\nG4 P3\nM30\n"
    bad, shoots = R.interferometer_check(R.load(_write(tmp_path, yes, "y.ngc")), comments, cols,
                                         model)
    assert bad == [] and shoots == [pytest.approx(5.0)]
    wrong = HEAD + "G0 X110 Y50 Z40\nG1 X100 F2000\nG4 P3\n" + "G1 X200\nG4 P3\n" * 3 + "M30\n"
    bad, _ = R.interferometer_check(R.load(_write(tmp_path, wrong, "w.ngc")), comments, cols,
                                    model)
    assert any("reading 0" in b and "reached by" in b for b in bad)


def _plate_cols(centres):
    n = len(centres)
    cols = {f"{c}_nom_mm": [str(v) for v in centres[:, k]] for k, c in enumerate("xyz")}
    cols.update({c: ["0"] * n for c in ("Xp", "Yp", "Zp")}, placement=["P1"] * n)
    return cols


@needs_rs274
def test_checker_finds_a_move_through_a_ball_and_passes_five_point_probing(tmp_path):
    model = volerr.load("MB1")
    centres = np.array([[300.0, 200.0, 100.0], [400.0, 200.0, 100.0]])
    r = 14.0                                   # ball radius 12.5 + stylus ball 1.5, mm
    text = HEAD
    for c in centres:
        text += f"G0 X{c[0]:g} Y{c[1]:g}\nG0 Z{c[2] + r + 10:g}\n"
        text += f"G38.2 Z{c[2] + r - 2:g} F100\nG0 Z{c[2] + r + 10:g}\n"
        for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            p = c + (r + 10) * np.array([dx, dy, 0])
            text += (f"G0 X{p[0]:g} Y{p[1]:g}\nG0 Z{c[2]:g}\n"
                     f"G38.2 X{c[0] + (r - 2) * dx:g} Y{c[1] + (r - 2) * dy:g} F100\n"
                     f"G0 X{p[0]:g} Y{p[1]:g}\nG0 Z{c[2] + r + 10:g}\n")
    good = text + "G53 G0 Z400\nM30\n"
    assert R.artifact_check(R.load(_write(tmp_path, good)), _plate_cols(centres), model) == []
    bad_text = good.replace("G53 G0 Z400\nM30", "G0 X300 Y200 Z100\nM30")
    bad = R.artifact_check(R.load(_write(tmp_path, bad_text, "b.ngc")), _plate_cols(centres),
                           model)
    assert any("passes 0.0 mm from ball 0" in b for b in bad)
    few = HEAD + "G0 X300 Y200\nG0 Z124\nG38.2 Z112 F100\nG0 Z124\nM30\n"
    bad = R.artifact_check(R.load(_write(tmp_path, few, "f.ngc")), _plate_cols(centres[:1]),
                           model)
    assert bad == ["ball 0 of P1: 1 radial probing moves, directions of affine rank 0 (a centre "
                   "needs 4 not coplanar)"]


@needs_rs274
def test_checker_finds_a_move_behind_the_plate(tmp_path):
    model = volerr.load("MB1")
    centres = np.array([[300.0, 200.0, 100.0], [450.0, 200.0, 100.0], [300.0, 350.0, 100.0]])
    probes = "".join(f"G0 X{c[0]:g} Y{c[1]:g}\nG0 Z124\nG38.2 Z112 F100\nG0 Z124\n"
                     for c in centres)
    ok = HEAD + probes + "G53 G0 Z400\nM30\n"
    path = R.load(_write(tmp_path, ok))
    assert R.plate_check(path, _plate_cols(centres), model) == []
    under = HEAD + probes + "G0 X520 Y420\nG0 Z90\nG0 X400 Y300\nG53 G0 Z400\nM30\n"
    bad = R.plate_check(R.load(_write(tmp_path, under, "u.ngc")), _plate_cols(centres), model)
    assert len(bad) == 2 and all("10.0 mm behind plate P1" in b for b in bad)
    assert "[0.0, 0.0, 1.0]" in bad[0]


@needs_rs274
def test_checker_finds_a_turn_near_the_sphere(tmp_path):
    model = volerr.load("DMU50")
    cols = {"X": ["0"], "Y": ["0"], "Z": ["160"], "B": ["0"], "C": ["0"], "Xp": ["0"],
            "Yp": ["0"], "Zp": ["100"], "sphere_x": ["0"], "sphere_y": ["0"],
            "sphere_z": ["260"], "placement": ["S1"]}
    ok = HEAD + "G0 X0 Y0 B0 C0\nG0 Z180\nG1 Z160 F1000\nG4 P2\nG1 Z180\nG53 G0 Z400\nM30\n"
    path = R.load(_write(tmp_path, ok))
    assert R.sphere_check(path, cols, model) == [] and R.dwell_check(path, cols, model.axes) == []
    turn = ok.replace("G1 Z180\nG53", "G1 Z180 C30\nG53")
    bad = R.sphere_check(R.load(_write(tmp_path, turn, "t.ngc")), cols, model)
    assert len(bad) == 1 and "turns the rotary axes by 30 deg" in bad[0]


def test_forward_kinematics_agree_with_the_reference_chain():
    """The checker's tool point (``volerr.load(LAYOUT).forward``, nominal) equals the
    independent numpy chain of ``tests/helpers/reference_chain.py`` on DMU50 poses."""
    model, layout = volerr.load("DMU50"), read_layout("DMU50")
    rng = np.random.default_rng(36)
    q = np.column_stack([rng.uniform(*model.travel[a], 6) for a in model.axes])
    probe = (0.0, 0.0, 100.0)
    got = model.forward(q, probe=probe)[:, :3]
    rad = [math.radians(1.0) if a in model.rotary_axes else 1.0 for a in model.axes]
    ref = [reference_chain.tool_point(layout, dict(zip(model.axes, row * rad)), {}, probe)
           for row in q]
    np.testing.assert_allclose(got, np.array(ref), atol=1e-9)


# ---------------------------------------------------------------------------------------------
# every program of the plans

@pytest.fixture(scope="module")
def planned(tmp_path_factory):
    cache = {}

    def run(case, dialect):
        if (case, dialect) not in cache:
            tmp = tmp_path_factory.mktemp(f"{case}-{dialect}")
            argv = ["plan", *CASES[case], "--dialect", dialect, "--out", str(tmp / "plan"),
                    "--json", str(tmp / "plan.json")]
            with plan_designs.designed_once():     # the two dialects: one design
                try:
                    rc = main(argv)
                except SystemExit as exc:        # argparse refusing an option
                    rc = exc.code
            cache[(case, dialect)] = (rc, tmp)
        rc, tmp = cache[(case, dialect)]
        if rc != 0:
            pytest.fail(f"volerr plan {' '.join(CASES[case])} --dialect {dialect}: exit {rc}")
        doc = json.loads((tmp / "plan.json").read_text())
        return tmp / "plan", doc
    return run


_READ: dict = {}


def _load(nc: Path):
    """rs274's reading of ``nc``, once per program (both tests use it)."""
    if nc not in _READ:
        try:
            _READ[nc] = R.load(nc)
        except R.Rejected as exc:
            _READ[nc] = exc
    if isinstance(_READ[nc], R.Rejected):
        raise _READ[nc]
    return _READ[nc]


def _programs(folder: Path, doc: dict):
    """(plan file, program, kind) of every file of the plan."""
    return [(folder / f["file"], folder / f["nc"], f["kind"]) for f in doc["files"]]


def _report(bad: dict) -> str:
    lines = [f"{name}: {v}" for name, vs in bad.items() for v in vs[:8]]
    return f"{sum(map(len, bad.values()))} violations:\n" + "\n".join(lines[:40])


@needs_rs274
@pytest.mark.slow
@pytest.mark.parametrize("case, dialect", PLANS)
def test_programs_accepted_and_stated(planned, case, dialect):
    """Accepted by rs274; lines < 254; G21 G90 G54 G43/G49 M30; first a retract along Z."""
    folder, doc = planned(case, dialect)
    model = volerr.load(doc["layout"])
    bad = {}
    for _, nc, _ in _programs(folder, doc):
        v = R.program_text_checks(nc)
        try:
            v += R.path_checks(_load(nc), model.travel["Z"][1])
        except R.Rejected as exc:
            v.append(str(exc))
        if v:
            bad[nc.name] = v
    assert not bad, _report(bad)


def _kind_check(kind, path, comments, cols, model):
    if kind == "ballbar":
        return R.ballbar_check(path, cols, model)[0]
    if kind == "sphere":
        return R.sphere_check(path, cols, model) + R.dwell_check(path, cols, model.axes)
    if kind == "artifact":
        return R.artifact_check(path, cols, model)
    if kind == "interferometer":
        return R.interferometer_check(path, comments, cols, model)[0]
    if kind == "distances":
        return R.dwell_check(path, cols, model.axes)
    raise AssertionError(f"no check for kind {kind}")


@needs_rs274
@pytest.mark.slow
@pytest.mark.parametrize("case, dialect", PLANS)
def test_programs_safe_along_the_path_and_read_where_planned(planned, case, dialect):
    """The kind's path checks and the reading positions of the plan's files."""
    folder, doc = planned(case, dialect)
    model = volerr.load(doc["layout"])
    bad = {}
    for csv, nc, kind in _programs(folder, doc):
        try:
            path = _load(nc)
        except R.Rejected as exc:
            bad[nc.name] = [str(exc)]
            continue
        comments, cols = R.read_csv(csv)
        v = _kind_check(kind, path, comments, cols, model)
        if v:
            bad[nc.name] = v
    assert not bad, _report(bad)
