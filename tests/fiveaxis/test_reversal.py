"""Reversal (RV_<axis>_um, ISO 230-2 B_i): a bidirectional program on a machine whose X and Y
positioning depends on the approach direction is compensated by each block's direction: run
on an independent controller and chain (its own direction bookkeeping, B_i interpolated by
numpy), the tool tip lands within rounding, while the same compensation without the reversal
columns leaves about B_i / 2; the approach directions against a hand-made sequence."""

import numpy as np
import pytest
from helpers import nc_sim
from helpers.error_dirs import write_errors
from helpers.fiveaxis_chain import tool2work

import volerr
from volerr.fiveaxis.compensate import ErrorModel
from volerr.fiveaxis.program import compensate_program
from volerr.fiveaxis.reversal import Directions
from volerr.tables.functions import ErrorFunctions
from volerr.tables.table import ErrorTable, read_error_table, write_error_table


def _with_reversal(d, m):
    """The X and Y tables of ``d`` get RV columns: X -6 um + 2 um sin, Y -4 um (lost motion:
    the axis stops short of the target in the direction it comes from)."""
    rv = {}
    for a, f in (("X", lambda x: -6e-3 + 2e-3 * np.sin(x / 80.0)), ("Y", lambda y: -4e-3 + 0 * y)):
        t = read_error_table(d / f"{a}.csv", a)
        rv[a] = (t.positions, f(t.positions))
        write_error_table(d / f"{a}.csv", ErrorTable(a, t.positions, t.values, reversal=rv[a][1]))
    return rv


def _program():
    lines = ["G90 G1 X-150 Y-100 Z200 B10 C20"]
    y = -100.0
    for k in range(14):
        x = 150.0 if k % 2 == 0 else -150.0
        lines.append(f"X{x:.3f} Y{y:.3f}")
        lines.append(f"X{x * 0.3:.3f}")               # a shorter move the same way
        y += 15.0 if k < 7 else -20.0                 # Y turns back halfway
        lines.append(f"Y{y:.3f}")
    return "\n".join(lines) + "\n"


def _actual(m, funcs, rv, text):
    """Tool tips of the program run on the independent controller; the reversal of an axis
    by the sign of its last move (numpy), the other errors from the tables."""
    moves = nc_sim.moves(text, m.axes)
    q = np.array([[mv.end[a] for a in m.axes] for mv in moves])
    last = np.zeros(2)
    known = []
    out = []
    e = funcs(ErrorModel(m, funcs).lookup(q))
    for r, mv in enumerate(moves):
        errs = {k: float(v[r]) for k, v in e.items()}
        for j, a in enumerate("XY"):
            step = mv.end[a] - mv.start[a]
            if abs(step) > 1e-9:
                last[j] = np.sign(step)
            pos, b = rv[a]
            errs[f"E{a}{a}"] += last[j] * np.interp(mv.end[a], pos, b) / 2
        known.append(bool(np.all(last != 0)))
        out.append(tool2work(m.name, dict(zip(m.axes, q[r])), errs)[:3, 3])
    nominal = np.array([tool2work(m.name, dict(zip(m.axes, row)), {})[:3, 3] for row in q])
    return np.array(out), nominal, np.array(known)


def test_bidirectional_program_lands_by_its_approach_directions(tmp_path):
    m = volerr.load("DMU50")
    d = write_errors(tmp_path / "err", m, seed=31)
    plain = ErrorFunctions.from_dir(d, m)          # the same tables without reversal
    rv = _with_reversal(d, m)
    funcs = ErrorFunctions.from_dir(d, m)
    assert funcs.has_reversal and not plain.has_reversal
    text = _program()
    with_rv = compensate_program(m, funcs, text)
    without = compensate_program(m, plain, text)
    act_in, nom_in, known = _actual(m, funcs, rv, text)
    act, nom, known = _actual(m, funcs, rv, with_rv.text)
    act0, _, _ = _actual(m, funcs, rv, without.text)
    want = nom_in                                      # the programmed tips
    err = np.linalg.norm(act - want, axis=1)[known] * 1e3
    err0 = np.linalg.norm(act0 - want, axis=1)[known] * 1e3
    before = np.linalg.norm(act_in - want, axis=1)[known] * 1e3
    assert before.max() > 10
    assert err.max() < 0.15, err.max()
    # without the reversal, the direction-dependent half of B_i stays (4..8 um / 2)
    assert err0.max() > 1.8 and np.median(err0) > 1.5
    # the report predicts the executed error with the directions
    rep_before = np.array([np.linalg.norm(r.before_um) for r in with_rv.reports[1:]])
    assert np.allclose(rep_before[known[:len(rep_before)]], before[:known.sum()], atol=1e-3)


def test_directions_follow_the_last_move_of_each_axis():
    d = Directions(3)
    q = np.array([[0, 0, 5], [10, 0, 5], [10, 0, 6], [4, 2, 6], [4, 2, 6.0]])
    got = d.rows(q[:3])
    got = np.vstack([got, d.rows(q[3:])])            # across a chunk boundary
    want = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1], [-1, 1, 1], [-1, 1, 1]])
    assert np.array_equal(got, want)


def test_reversal_needs_a_linear_axis_with_its_positioning_error(tmp_path):
    m = volerr.load("DMU50")
    t = ErrorTable("C", [0.0, 90.0], {"EXC": [0.0, 1e-3]}, reversal=[1e-3, 1e-3])
    with pytest.raises(volerr.errors.InputError, match="RV_C needs a linear axis"):
        ErrorFunctions({"C": t}, {}, m)


def test_map_and_tcpmap_use_the_approach_direction(tmp_path):
    """A positioning error EXX is a translation along X: approaching in + instead of - moves
    the tip by B_i(x) along X (map of a CMM: in dx; tcp map of a five-axis machine: by
    |B_i| whatever the rotary axes do to the direction)."""
    from volerr.cmm.volmap import volumetric_map
    from volerr.fiveaxis.tcpmap import tcp_map
    from volerr.tables.functions import parse_approach

    cmm = volerr.load("MB1")
    lo, hi = cmm.travel["X"]
    x = np.linspace(lo, hi, 7)
    rv = -5e-3 + 2e-3 * np.cos(x / 100.0)
    t = ErrorTable("X", x, {"EXX": 1e-3 * np.sin(x / 50.0)}, reversal=rv)
    funcs = ErrorFunctions({"X": t}, {}, cmm)
    plus = volumetric_map(cmm, funcs, 4, approach=parse_approach("X+", cmm, funcs))
    minus = volumetric_map(cmm, funcs, 4, approach=parse_approach("-", cmm, funcs))
    mean = volumetric_map(cmm, funcs, 4)
    xs = plus.positions["X"]
    assert np.allclose(plus.error[:, 0] - minus.error[:, 0], np.interp(xs, x, rv), atol=1e-12)
    assert np.allclose(plus.error + minus.error, 2 * mean.error, atol=1e-12)
    m = volerr.load("DMU50")
    lo, hi = m.travel["X"]
    x = np.linspace(lo, hi, 9)
    rv = -6e-3 + 0 * x
    funcs = ErrorFunctions({"X": ErrorTable("X", x, {"EXX": 0 * x}, reversal=rv)}, {}, m)
    a = tcp_map(m, funcs, (10, 20, 30), (0, 0, -100), 9, 9, approach={"X": 1})
    b = tcp_map(m, funcs, (10, 20, 30), (0, 0, -100), 9, 9, approach={"X": -1})
    s = tcp_map(m, funcs, (10, 20, 30), (0, 0, -100), 9, 9, approach="sweep")
    ok = a.valid
    assert ok.sum() > 20
    assert np.allclose(np.linalg.norm(a.err - b.err, axis=2)[ok], 6e-3, atol=1e-9)
    # the sweep: every point is one of the two, by the sign of X's move along its row
    X = a.linear[..., 0]
    step = np.diff(X, axis=1)
    sign = np.sign(np.concatenate([step[:, :1], step], axis=1))
    want = np.where(sign[..., None] > 0, a.err, b.err)
    assert np.allclose(s.err[ok], want[ok], atol=1e-12)
