"""The NC programs of ``volerr plan`` are safe along their whole path (issue 36 items 1-2;
contract: INTERFACE.md "Measurement programs a machine can run").

The programs are written for set-ups taken straight from the planner's candidates (every plane
of circle, sweeps of every rotary axis, plates in XY / YZ / ZX, lines along X, Y, Z, sphere
placements, stations) on MB1 and DMU50, in the ``iso`` and ``linuxcnc`` dialects, and walked by
this file's own reader of the text: every G0/G1/G38.2 a straight line in the axes, G2/G3 an arc
about the centre its I J K words give, sampled every 0.5 mm or 0.5 deg; the tool point of each
sample from the layout's nominal kinematics.  Checked: the bar within 0.1 mm of its length from
mounting to removal; no move but a probing move within 10 mm of a ball centre, every ball
probed towards its centre from outside at four points or more, nothing behind the balls'
plane on the plate; no rotary motion and no motion off the tool axis within 30 mm of a
sphere; every interferometer reading reached moving in its declared direction, each cycle
starting beyond its first target; the file's rows a subsequence of the end points; the first
motion a retract along Z alone; G21, G90, G54 before any motion; every end point inside the
travel; M30; lines under 254 characters.  Where LinuxCNC's ``rs274`` is installed it must
read every program without an error, and its canonical arcs turn the short way.  The other
dialects: their dwell, probing and comment words.
"""

from __future__ import annotations

import math
import re
import shutil
import subprocess

import numpy as np
import pytest
from helpers import in_process

from volerr.machine.model import load
from volerr.plan import _candidates, _files, _nc, _spec

# the module fixtures once, on one xdist worker (not once per worker)
pytestmark = pytest.mark.xdist_group("plan_nc")

#: (layout, kind spec, set-ups taken: every n-th candidate, readings per set-up)
CASES = {
    "MB1-ballbar": ("MB1", "ballbar:lengths=100,250", 40, 24),
    "DMU50-ballbar": ("DMU50", "ballbar:lengths=100,250", 25, 20),
    "DMU50-sphere": ("DMU50", "sphere", 30, 10),
    "MB1-artifact": ("MB1", "artifact:balls=3x3:pitch=150", 4, 9),
    "DMU50-artifact": ("DMU50", "artifact", 2, 25),
    "MB1-interferometer": ("MB1", "interferometer", 20, 44),
    "DMU50-interferometer": ("DMU50", "interferometer:optics=linear", 4, 44),
    "MB1-distances": ("MB1", "distances", 5, 14),
    "DMU50-distances": ("DMU50", "distances", 5, 14),
}
BALL_CLEAR_MM, SPHERE_ZONE_MM, BAR_RANGE_MM = 10.0, 30.0, 0.1
_WORD = re.compile(r"([A-Z])\s*([-+]?\d*\.?\d+)")


def _files_of(case):
    layout, spec, every, m = CASES[case]
    model = load(layout)
    inst = _spec.parse(spec)
    found = _candidates.setups(model, inst)
    picked = found[::every]
    if inst.kind in ("ballbar", "interferometer"):      # a file each: one of every shape
        shape = {}
        for s in found:
            g = s.geometry
            key = (g.get("plane"), g.get("sweep"), g.get("axis"), s.line and s.line.mode)
            shape.setdefault(key, s)
        picked = list(shape.values())
    files = _files.group([inst], [(0, s, m) for s in picked])
    return model, files


@pytest.fixture(scope="module")
def programs():
    out = {}
    for case in CASES:
        model, files = _files_of(case)
        for dialect in ("iso", "linuxcnc"):
            out[case, dialect] = (model, [(pf, _nc.program(model, pf, ["a header"], dialect))
                                          for pf in files])
    return out


# ---- the reader --------------------------------------------------------------------------
def walk(text: str, axes):
    """[(kind, start, end, arc)] of the program's motion blocks in axis positions (kind G0 G1
    G2 G3 G38.2 or ``stop``/``mount``/``remove`` markers with start = end); ``arc`` (normal
    axis, centre {axis: value}, ccw) for G2/G3.  Also the modes seen before the first motion."""
    where = {a: 0.0 for a in axes}
    motion, plane, segs, modes = None, "Z", [], set()
    for raw in text.splitlines():
        comment = " ".join(re.findall(r"\(([^)]*)\)", raw))
        line = re.sub(r"\([^)]*\)", " ", raw).split(";")[0].strip().upper()
        if not line or line.startswith("%"):
            if "mount the ballbar" in comment:
                segs.append(("mount", dict(where), dict(where), None))
            elif "remove the ballbar" in comment:
                segs.append(("remove", dict(where), dict(where), None))
            continue
        words = [(k, float(v)) for k, v in _WORD.findall(line)]
        g = [v for k, v in words if k == "G"]
        for v in g:
            if v in (0, 1, 2, 3) or math.isclose(v, 38.2):
                motion = v
            plane = {17: "Z", 18: "Y", 19: "X"}.get(v, plane)
            if not segs:
                modes.add(v)
        if any(k == "M" and v in (0, 30) for k, v in words):
            segs.append(("M0" if ("M", 0.0) in words else "M30", dict(where), dict(where), None))
        to = {**where, **{k: v for k, v in words if k in axes}}
        if not any(k in axes for k, _ in words):
            continue
        kind = {0: "G0", 1: "G1", 2: "G2", 3: "G3"}.get(motion, "G38.2")
        arc = None
        if kind in ("G2", "G3"):
            off = {k: v for k, v in words if k in "IJK"}
            a, b = {"Z": "XY", "Y": "ZX", "X": "YZ"}[plane]     # right-handed about it
            arc = (plane, {a: where[a] + off.get("IJK"["XYZ".index(a)], 0.0),
                           b: where[b] + off.get("IJK"["XYZ".index(b)], 0.0)}, kind == "G3")
        segs.append((kind, dict(where), to, arc))
        where = to
    return segs, modes


def samples(seg, axes, rotary) -> np.ndarray:
    """(k, n_axes) positions along one block, every 0.5 mm / 0.5 deg (ends included)."""
    kind, s, e, arc = seg
    p0 = np.array([s[a] for a in axes])
    p1 = np.array([e[a] for a in axes])
    if arc is None:
        k = max(int(np.max(np.abs(p1 - p0)) / 0.5), 1)
        return p0 + np.linspace(0, 1, k + 1)[:, None] * (p1 - p0)
    normal, c, ccw = arc
    a, b = [x for x in c]
    ia, ib = axes.index(a), axes.index(b)
    t0 = math.atan2(s[b] - c[b], s[a] - c[a])
    t1 = math.atan2(e[b] - c[b], e[a] - c[a])
    sweep = (t1 - t0) % (2 * math.pi) if ccw else -((t0 - t1) % (2 * math.pi))
    assert abs(sweep) <= math.pi, ("an arc the long way round: wrong G2/G3", seg)
    r = math.hypot(s[a] - c[a], s[b] - c[b])
    k = max(int(abs(sweep) * r / 0.5), 4)
    t = t0 + np.linspace(0, 1, k + 1) * sweep
    out = p0 + np.linspace(0, 1, k + 1)[:, None] * (p1 - p0)
    out[:, ia] = c[a] + r * np.cos(t)
    out[:, ib] = c[b] + r * np.sin(t)
    return out


def tool_points(model, q, pf) -> np.ndarray:
    probe = tuple(float(pf.columns[c][0]) for c in ("Xp", "Yp", "Zp"))
    return model.nominal_position({a: q[:, j] for j, a in enumerate(model.axes)}, probe)


# ---- every program -----------------------------------------------------------------------
@pytest.mark.parametrize("dialect", ["iso", "linuxcnc"])
@pytest.mark.parametrize("case", list(CASES))
def test_frame_of_every_program(programs, case, dialect):
    model, progs = programs[case, dialect]
    for pf, text in progs:
        lines = text.splitlines()
        assert max(len(ln) for ln in lines) < 254, (case, pf.name)
        segs, modes = walk(text, model.axes)
        assert {21.0, 90.0}.issubset(modes), (case, pf.name, modes)
        assert any(ln.startswith("G54") for ln in lines[:6]), (case, pf.name)
        first = next(s for s in segs if s[0].startswith("G"))
        moved = {a for a in model.axes if first[1][a] != first[2][a]}
        assert moved == {"Z"} and first[2]["Z"] == model.travel["Z"][1], (case, first)
        assert segs[-1][0] == "M30" and lines[-2:] == ["M30", "%"], (case, pf.name)
        for seg in segs[1:]:
            for a in model.axes:
                lo, hi = model.travel[a]
                assert lo - 1e-9 <= seg[2][a] <= hi + 1e-9, (case, pf.name, a, seg)


@pytest.mark.parametrize("case", [c for c in CASES if "artifact" not in c])
def test_rows_are_end_points_in_order(programs, case):
    model, progs = programs[case, "iso"]
    for pf, text in progs:
        ends = [s[2] for s in walk(text, model.axes)[0] if s[0].startswith("G")]
        k = 0
        for e in ends:
            if k < pf.n and all(abs(e[a] - float(pf.columns[a][k])) < 1e-9 for a in model.axes):
                k += 1
        assert k == pf.n, (case, pf.name, k, pf.n)


@pytest.mark.parametrize("case", ["MB1-ballbar", "DMU50-ballbar"])
def test_bar_stays_at_its_length_once_mounted(programs, case):
    model, progs = programs[case, "iso"]
    kinds = set()
    for pf, text in progs:
        pivot = np.array([float(pf.columns[c][0]) for c in ("pivot_x", "pivot_y", "pivot_z")])
        length = float(pf.columns["length_mm"][0])
        segs = walk(text, model.axes)[0]
        names = [s[0] for s in segs]
        assert names.count("mount") == 1 and names.count("remove") == 1, (case, pf.name)
        on = segs[names.index("mount") + 1:names.index("remove")]
        worst = 0.0
        for seg in on:
            if seg[0].startswith("G"):
                t = tool_points(model, samples(seg, model.axes, model.rotary_axes), pf)
                worst = max(worst, float(np.max(np.abs(np.linalg.norm(t - pivot, axis=1)
                                                        - length))))
        assert worst <= BAR_RANGE_MM, (case, pf.name, worst)
        kinds |= {s[0] for s in on}
        circle = "C" in pf.setups[0][0].label
        if circle:          # ISO 230-4: arcs, and a run-in before the first reading
            assert {"G2", "G3"} <= kinds, (case, pf.name)
            first = np.array([float(pf.columns[a][0]) for a in model.axes])
            start, end = (np.array([p[a] for a in model.axes]) for p in on[0][1:3])
            assert on[0][0] in ("G2", "G3") and np.allclose(end, first), "no run-in arc"
            assert np.linalg.norm(start - first) > 10.0, "no run-in arc"


def _balls(pf):
    return np.column_stack([np.asarray(pf.columns[f"{c}_nom_mm"], float) for c in "xyz"])


def _placements(pf, segs):
    """[(label, its balls (n, 3), its motion blocks)]: one plate mounted at a time, the
    placements in the file's order separated by program stops."""
    labels = np.asarray(pf.columns["placement"]).astype(str)
    order = list(dict.fromkeys(labels))
    groups, cur = [], []
    first = next(i for i, seg in enumerate(segs) if seg[0].startswith("G"))
    for seg in segs[first + 1:]:        # the retract from where the machine stood: not known
        if seg[0] == "M0":
            groups.append(cur)
            cur = []
        elif seg[0].startswith("G"):
            cur.append(seg)
    groups.append(cur)
    assert len(groups) == len(order), (len(groups), order)
    return [(lab, _balls(pf)[labels == lab], g) for lab, g in zip(order, groups)]


@pytest.mark.parametrize("case", ["MB1-artifact", "DMU50-artifact"])
def test_probe_clear_of_every_ball_and_every_ball_probed(programs, case):
    model, progs = programs[case, "linuxcnc"]
    for pf, text in progs:
        for lab, balls, segs in _placements(pf, walk(text, model.axes)[0]):
            probed = np.zeros(len(balls), int)
            for seg in segs:
                t = tool_points(model, samples(seg, model.axes, ()), pf)
                d = np.linalg.norm(t[:, None, :] - balls[None, :, :], axis=2)
                if seg[0] != "G38.2":
                    assert d.min() >= BALL_CLEAR_MM, (case, lab, seg, d.min())
                    continue
                v = t[-1] - t[0]
                near = int(np.argmin(d[-1]))
                to_centre = balls[near] - t[0]
                assert np.linalg.norm(np.cross(v, to_centre)) < 1e-3 * np.linalg.norm(v) * \
                    np.linalg.norm(to_centre), (case, "probing move not towards the centre")
                assert d[0, near] > 0.5 * (_nc.BALL_D_MM + _nc.STYLUS_D_MM), "starts inside"
                probed[near] += 1
            assert probed.min() >= 4, (case, lab, probed)


@pytest.mark.parametrize("case", ["MB1-artifact", "DMU50-artifact"])
def test_nothing_passes_behind_the_balls_plane_on_the_plate(programs, case):
    """The plate lies behind its balls' plane (the balls stand on its free side, +w): no
    sample inside the plate's outline (its balls' extent + 30 mm) and 1-40 mm behind it."""
    model, progs = programs[case, "iso"]
    for pf, text in progs:
        for lab, b, segs in _placements(pf, walk(text, model.axes)[0]):
            pts = np.vstack([tool_points(model, samples(s, model.axes, ()), pf) for s in segs])
            k = int(np.argmin(np.ptp(b, axis=0)))       # the plate's normal
            inplane = [j for j in range(3) if j != k]
            lo, hi = b[:, inplane].min(axis=0) - 30, b[:, inplane].max(axis=0) + 30
            inside = np.all((pts[:, inplane] >= lo) & (pts[:, inplane] <= hi), axis=1)
            behind = (pts[:, k] < b[0, k] - 1.0) & (pts[:, k] > b[0, k] - 40.0)
            assert not np.any(inside & behind), (case, lab)


def test_sphere_approached_along_the_tool_axis(programs):
    model, progs = programs["DMU50-sphere", "linuxcnc"]
    rot = [model.axes.index(a) for a in model.rotary_axes]
    for pf, text in progs:
        centres = np.column_stack([np.asarray(pf.columns[c], float)
                                   for c in ("sphere_x", "sphere_y", "sphere_z")])
        centre = centres[0]
        for seg in [s for s in walk(text, model.axes)[0] if s[0].startswith("G")]:
            q = samples(seg, model.axes, model.rotary_axes)
            t = tool_points(model, q, pf)
            near = np.linalg.norm(t - centre, axis=1) < SPHERE_ZONE_MM
            if not near.any():
                continue
            assert np.ptp(q[:, rot], axis=0).max() < 1e-9, ("rotary motion near the sphere", seg)
            axis = model.tool_axis({a: q[:1, j] for j, a in enumerate(model.axes)})[0]
            move = t[-1] - t[0]
            if np.linalg.norm(move) > 1e-9:
                assert np.linalg.norm(np.cross(move, axis)) < 1e-6 * np.linalg.norm(move), \
                    ("motion off the tool axis near the sphere", seg)


@pytest.mark.parametrize("case", ["MB1-interferometer", "DMU50-interferometer"])
def test_interferometer_targets_reached_from_their_direction(programs, case):
    model, progs = programs[case, "iso"]
    for pf, text in progs:
        axis = pf.setups[0][0].line.axis
        segs = [s for s in walk(text, model.axes)[0] if s[0].startswith("G")]
        d = np.asarray(pf.columns["direction"], float)
        k = 0
        for s in segs:
            if k < pf.n and all(abs(s[2][a] - float(pf.columns[a][k])) < 1e-9
                                for a in model.axes):
                move = s[2][axis] - s[1][axis]
                assert np.sign(move) == d[k], (case, pf.name, k, move)
                k += 1
        assert k == pf.n


def test_dialect_words():
    """fanuc: G4 P in ms, G31; sinumerik: G4 F s, MEAS=1, ';' comments; heidenhain: numbered
    plain-language blocks, CYCL DEF 9 dwell, TCH PROBE 0, CC/C circles; iso: G4 P s, G38.2."""
    model, files = _files_of("MB1-artifact")
    pf = files[0]
    texts = {d: _nc.program(model, pf, ["x" * 600], d) for d in
             ("iso", "fanuc", "sinumerik", "heidenhain")}
    assert "G38.2 " in texts["iso"] and "G31 " in texts["fanuc"]
    assert "MEAS=1 G1 " in texts["sinumerik"] and "TCH PROBE 0.0 REF. PLANE" in texts["heidenhain"]
    for d, text in texts.items():
        assert max(map(len, text.splitlines())) < 254, d
    assert not any(ln.startswith("(") for ln in texts["sinumerik"].splitlines())
    hh = texts["heidenhain"].splitlines()
    assert hh[0] == "0 BEGIN PGM PLAN MM" and hh[-1].endswith("END PGM PLAN MM")
    assert all(ln.split(" ", 1)[0] == str(n) for n, ln in enumerate(hh))
    model, files = _files_of("DMU50-sphere")
    texts = {d: _nc.program(model, files[0], [], d) for d in
             ("iso", "fanuc", "sinumerik", "heidenhain")}
    s = _spec.DWELL_S["sphere"]
    assert f"G4 P{s:g}\n" in texts["iso"] and f"G4 P{int(s * 1000)}\n" in texts["fanuc"]
    assert f"G4 F{s:g}\n" in texts["sinumerik"] and f"DWELL {s:g}\n" in texts["heidenhain"]
    model, files = _files_of("MB1-ballbar")
    hh = _nc.program(model, files[0], [], "heidenhain")
    assert " CC X" in hh and re.search(r" C X\S+ Y\S+ DR[+-] R0 F1000", hh)


def test_nc_program_of_own_set_ups_is_the_plan_program():
    """The writer for a caller with its own set-ups (issue 37's check programs)."""
    from volerr.plan import nc_program

    model, files = _files_of("DMU50-sphere")
    pf = files[0]
    text = nc_program(model, "sphere", pf.setups, "linuxcnc", ["a header"])
    assert text == _nc.program(model, pf, ["a header"], "linuxcnc")


@pytest.mark.skipif(shutil.which("rs274") is None, reason="LinuxCNC's rs274 not installed")
def test_linuxcnc_interpreter_reads_every_program(programs, tmp_path):
    table = tmp_path / "tool.tbl"
    table.write_text("T1 P1 Z0 D3 ;probe\n")
    for (case, dialect), (model, progs) in programs.items():
        for pf, text in progs:
            path = tmp_path / "p.ngc"
            path.write_text(text)
            run = subprocess.run(["rs274", "-g", "-t", str(table), str(path)],
                                 capture_output=True, text=True, timeout=60)
            bad = [ln for ln in (run.stdout + run.stderr).splitlines()
                   if re.search(r"error|too long|unknown", ln, re.IGNORECASE)]
            assert not bad, (case, dialect, pf.name, bad[:3])
            assert _short_arcs(run.stdout), (case, dialect, pf.name)


#: rs274's canonical arc planes: (first axis, second axis) of ARC_FEED's end and centre
_CANON = {"XY": (0, 1), "XZ": (2, 0), "YZ": (1, 2)}


def _short_arcs(canonical: str) -> bool:
    """Every ARC_FEED of rs274's canonical output turns less than half a turn from where the
    move before ended (the plan's arcs join readings at most 45 deg apart: an arc the long way
    round is a G2 written for a G3).  rotation +1: counter-clockwise, first axis towards the
    second."""
    at, plane = np.zeros(3), "XY"
    for ln in canonical.splitlines():
        m = re.search(r"(SELECT_PLANE\(CANON_PLANE_(\w+)\)|(STRAIGHT_\w+|ARC_FEED)\(([^)]*)\))",
                      ln)
        if not m:
            continue
        if m.group(2):
            plane = m.group(2)
            continue
        v = [float(x) for x in m.group(4).split(",")]
        if m.group(3) != "ARC_FEED":
            at = np.array(v[:3])
            continue
        i, j = _CANON[plane]
        end, c = np.array(v[:2]), np.array(v[2:4])
        t0 = math.atan2(at[j] - c[1], at[i] - c[0])
        t1 = math.atan2(end[1] - c[1], end[0] - c[0])
        turn = (t1 - t0) % (2 * math.pi) if v[4] > 0 else (t0 - t1) % (2 * math.pi)
        if turn > math.pi:
            return False
        at[i], at[j], at[3 - i - j] = end[0], end[1], v[5]
    return True


# ---- the command line ----------------------------------------------------------------------
# test_dialect_option_writes_that_dialect: in tests/planning/test_plan_interferometer.py (the
# same plan in another dialect: one design for both)


@pytest.mark.parametrize("bad", ["ISO"])
def test_bad_dialect_one_line_exit_2_nothing_written(tmp_path, bad):
    run = in_process.volerr("plan", "MB1", "--instrument", "ballbar", "--readings", "100",
                            "--dialect", bad, "--out", tmp_path / "p")
    assert run.returncode == 2
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and "--dialect" in lines[0], run.stderr
    assert not (tmp_path / "p").exists()
