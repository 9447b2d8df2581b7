"""Arcs G2/G3: the compensated program, run on an independent controller (tests/helpers/nc_sim:
its own arc interpolation) and an independent exact chain (helpers.fiveaxis_chain.tool2work),
keeps the actual tool tip within the tolerance (+ the rounding of the written numbers) of the
nominal arc, in the three planes, for arcs kept as arcs and arcs linearised; the geometry
against closed forms; arcs whose end is off the circle are refused naming the line."""

import math

import numpy as np
import pytest
from helpers import nc_sim
from scipy.spatial import cKDTree
from helpers.error_dirs import write_errors
from test_compensate import cli
from helpers.fiveaxis_chain import tool2work

import volerr
from volerr.errors import InputError
from volerr.nc import arcs, gcode
from volerr.fiveaxis.compensate import ErrorModel
from volerr.fiveaxis.program import compensate_program
from volerr.tables.functions import ErrorFunctions

PROGRAM = """%
G90 G17 G1 X20 Y0 Z100 B10 C30 F800
G3 X0 Y20 I-20 J0 (G17 quarter, linearised)
G2 X-0.5 Y19.5 R0.5 (small: kept)
G18 G1 X0 Y10 Z100
G2 X20 Z120 I0 K20 (G18 quarter)
G3 X21 Z121 I1 K0
G19 G1 X0 Y0 Z150
G3 Y-20 Z170 Z175 J0 K20
"""
# the last arc: a helix in G19 (X moves with the angle) -- written below without the
# duplicate Z
PROGRAM = PROGRAM.replace("G3 Y-20 Z170 Z175 J0 K20", "G3 X5 Y-20 Z170 J0 K20 (G19 helix)")
PROGRAM += "G3 Y-20.8 Z170.8 J-0.8 K0\nG1 X0 Y0 Z120\n"
TOL_UM = 1.0


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    m = volerr.load("DMU50")
    d = write_errors(tmp_path_factory.mktemp("err"), m, seed=11)
    return m, ErrorFunctions.from_dir(d, m)


def _actual_tips(m, funcs, q):
    em = ErrorModel(m, funcs)
    e = funcs(em.lookup(q))
    out = np.empty((len(q), 3))
    for r, row in enumerate(q):
        t = tool2work(m.name, dict(zip(m.axes, row)), {k: float(v[r]) for k, v in e.items()})
        out[r] = t[:3, 3]
    return out


def _nominal_tips(m, q):
    """Nominal tips of positions that share their rotary positions: the exact chain is affine
    in the linear axes there, so four evaluations give it all."""
    assert np.ptp(q[:, 3:], axis=0).max() == 0
    base = q[0].copy()
    base[:3] = 0.0
    pts = [base] + [base + np.eye(5)[k] for k in range(3)]
    tips = np.array([tool2work(m.name, dict(zip(m.axes, p)), {})[:3, 3] for p in pts])
    a = (tips[1:] - tips[0]).T
    return q[:, :3] @ a.T + tips[0]


def test_compensated_arcs_stay_within_the_tolerance_of_the_nominal_arcs(setup):
    m, funcs = setup
    res = compensate_program(m, funcs, PROGRAM, arc_tol_um=TOL_UM)
    s = res.summary()
    assert s["arcs"]["kept"] >= 2 and s["arcs"]["linearised"] >= 3, s["arcs"]
    statuses = {r.line: r.status for r in res.reports}
    assert "arc kept" in statuses[4] and "arc linearised" in statuses[3]
    # the nominal arcs of the input program and the moves of the output program, both
    # interpreted by the independent controller
    nominal = {mv.line: mv for mv in nc_sim.moves(PROGRAM, m.axes) if mv.arc is not None}
    assert len(nominal) == 6
    out_moves = iter(nc_sim.moves(res.text, m.axes))
    # the output moves of each input block: up to the one that ends where the report says
    # the block was written to (a linearised arc is several moves)
    groups = {}
    for rep in res.reports[1:]:         # the first block has no start: not a move
        want = np.array([rep.output[a] for a in m.axes])
        g = []
        for o in out_moves:
            g.append(o)
            if np.abs(np.array([o.end[a] for a in m.axes]) - want).max() < 1e-9:
                break
        groups[rep.line] = g
    worst_before = 0.0
    for ln, mv in nominal.items():
        # the tip path of the nominal arc, densely: a curve to measure distances from
        dense = _nominal_tips(m, mv.sample(m.axes, np.linspace(0, 1, 4001)))
        tree = cKDTree(dense)
        q = np.concatenate([o.sample(m.axes, np.linspace(0, 1, 5)) for o in groups[ln]])
        assert len(groups[ln]) == (1 if "kept" in statuses[ln] else
                                   int(statuses[ln].split("into ")[1].split()[0]))
        act = _actual_tips(m, funcs, q)
        d, idx = tree.query(act)
        # refine: distance to the segments of the dense curve next to the nearest point
        d = np.minimum(d, _segment_distance(act, dense, idx))
        worst = d.max() * 1e3
        assert worst < TOL_UM + 0.1, (ln, worst)
        # uncompensated, the same arc would be far off
        q0 = mv.sample(m.axes, np.linspace(0, 1, 33))
        worst_before = max(worst_before,
                           np.linalg.norm(_actual_tips(m, funcs, q0) - _nominal_tips(m, q0),
                                          axis=1).max() * 1e3)
    assert worst_before > 5.0


def _segment_distance(p, curve, idx):
    best = np.full(len(p), np.inf)
    for off in (-1, 0):
        i0 = np.clip(idx + off, 0, len(curve) - 2)
        a, b = curve[i0], curve[i0 + 1]
        ab = b - a
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
        best = np.minimum(best, np.linalg.norm(p - (a + t[:, None] * ab), axis=1))
    return best


@pytest.mark.parametrize("plane", [17, 18, 19])
@pytest.mark.parametrize("ccw", [False, True])
def test_arc_geometry_against_closed_form(plane, ccw):
    """Start on a circle, end after a known signed angle: the path from I J K and from R is
    the closed-form circle, in every plane and direction."""
    axes = ("X", "Y", "Z", "B", "C")
    a, b, nrm = {17: "XYZ", 18: "ZXY", 19: "YZX"}[plane]
    rng = np.random.default_rng(plane + 10 * ccw)
    for _ in range(5):
        r = rng.uniform(1, 50)
        centre = rng.uniform(-100, 100, 2)
        a0 = rng.uniform(-math.pi, math.pi)
        sweep = rng.uniform(0.1, 1.9 * math.pi) * (1 if ccw else -1)
        start = {ax: 0.0 for ax in axes}
        start.update({a: centre[0] + r * math.cos(a0), b: centre[1] + r * math.sin(a0),
                      nrm: 5.0})
        end = dict(start)
        end.update({a: centre[0] + r * math.cos(a0 + sweep),
                    b: centre[1] + r * math.sin(a0 + sweep), nrm: 9.0})
        words = {"X": "I", "Y": "J", "Z": "K"}
        arc = gcode.Arc(plane, ccw, {words[a]: centre[0] - start[a],
                                     words[b]: centre[1] - start[b]}, None)
        p = arcs.arc_path(axes, start, end, arc, "line 1")
        t = np.linspace(0, 1, 7)
        want = np.column_stack([centre[0] + r * np.cos(a0 + t * sweep),
                                centre[1] + r * np.sin(a0 + t * sweep), 5.0 + 4.0 * t])
        got = p.points(t)[:, [axes.index(a), axes.index(b), axes.index(nrm)]]
        assert np.allclose(got, want, atol=1e-9)
        # the same arc by its radius: negative for more than half a turn
        rad = gcode.Arc(plane, ccw, {}, r if abs(sweep) <= math.pi else -r)
        got_r = arcs.arc_path(axes, start, end, rad, "line 1").points(t)
        assert np.allclose(got_r[:, [axes.index(a), axes.index(b)]], want[:, :2], atol=1e-7)


def test_arc_with_its_end_off_the_circle_is_refused_naming_the_line(tmp_path):
    axes = ("X", "Y", "Z", "B", "C")
    start = dict(zip(axes, (10.0, 0, 0, 0, 0)))
    end = dict(zip(axes, (0.0, 10.05, 0, 0, 0)))        # 50 um off a radius of 10 mm
    with pytest.raises(InputError, match="line 7: the end point is not on the arc's circle"):
        arcs.arc_path(axes, start, end, gcode.Arc(17, True, {"I": -10.0}, None), "line 7")
    ok = dict(zip(axes, (0.0, 10.005, 0, 0, 0)))        # within 10 um: a spiral
    p = arcs.arc_path(axes, start, ok, gcode.Arc(17, True, {"I": -10.0}, None), "line 7")
    assert abs(p.points([1.0])[0, 1] - 10.005) < 1e-12
    err = write_errors(tmp_path / "err", volerr.load("DMU50"), seed=1)
    prog = tmp_path / "p.nc"
    prog.write_text("G90 G1 X10 Y0 Z100 B0 C0\nN20 G3 X0 Y10.2 I-10 J0\n")
    rc, so, se = cli("compensate", "DMU50", "--errors", err, prog, "--out", tmp_path / "o")
    assert rc == 2 and se.strip().count("\n") == 0 and "line 2" in se and "circle" in se, se
    assert not (tmp_path / "o").exists()


def test_console_says_how_many_arcs_were_linearised_into_how_many_lines(tmp_path):
    """The console line counts the arcs kept and linearised and the G1 lines written for them,
    as counted here in the written program (an arc block's line plus the new G1 lines)."""
    err = write_errors(tmp_path / "err", volerr.load("DMU50"), seed=11)
    prog = tmp_path / "p.nc"
    prog.write_text(PROGRAM)
    rc, so, se = cli("compensate", "DMU50", "--errors", err, prog, "--out", tmp_path / "o",
                     "--json", tmp_path / "s.json")
    assert rc == 0, se
    out = (tmp_path / "o").read_text().splitlines()
    n_in = len(PROGRAM.splitlines())
    arc_lines = [ln for ln in PROGRAM.splitlines() if ln.startswith(("G2", "G3"))]
    kept = sum(1 for ln in out if ln.startswith(("G2", "G3")))
    linearised = len(arc_lines) - kept
    lines = len(out) - n_in + linearised        # each linearised arc: its line + new lines
    assert linearised > 0 and kept > 0
    assert (f"arcs: {linearised} linearised into {lines} G1 lines (predicted path within 1 um "
            f"of the arc, max ") in so and f"; {kept} kept as arcs" in so, so
