"""Axis compensation tables of SINUMERIK (LEC, CEC), Heidenhain (.CMA/.COM) and Fanuc (pitch
error compensation): export -> import gives the error values back within the format's
increment, inside the documented limits (points per table, equal spacing, modulo turn, Fanuc
steps); "what it leaves" equals an independent computation: the exact chain of
helpers.fiveaxis_chain.tool2work at the positions the controller commands after its own (numpy)
interpolation of the tables."""

import json
from pathlib import Path

import numpy as np
import pytest

from helpers import in_process
from helpers.error_dirs import write_errors
from helpers.fiveaxis_chain import tool2work

import volerr
from volerr.tables import comp_tables, controller_tables as ctl, fanuc
from volerr.tables.functions import ErrorFunctions
from volerr.tables.table import ErrorTable

INCREMENT = {"sinumerik-lec": 1e-4, "sinumerik-cec": 1e-4, "heidenhain": 1e-4,
             "fanuc": 1e-3, "linuxcnc": 1e-6}
LIMIT = {"sinumerik-lec": 200, "sinumerik-cec": 200, "heidenhain": 256, "fanuc": 128,
         "linuxcnc": 256}


def _write_and_read(m, tables, fmt, tmp_path):
    """Write the format's files under tmp_path and read them back (LinuxCNC: a folder of
    COMP_FILEs, read through its ini)."""
    out = tmp_path / ("lcnc" if fmt == "linuxcnc" else "comp.txt")
    files = ctl.write(m, tables, fmt, out)
    for p, text in files.items():
        Path(p).parent.mkdir(exist_ok=True)
        Path(p).write_text(text)
    return ctl.read(m, out / "compensation.ini" if fmt == "linuxcnc" else out, fmt)


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    m = volerr.load("DMU50")
    d = write_errors(tmp_path_factory.mktemp("err"), m, seed=41)
    return m, ErrorFunctions.from_dir(d, m), d


def _positioning(m, funcs, a, pos):
    """The error an axis table carries, independently: E<A><A>; for a rotary axis the
    rotation about its direction u, deg."""
    q = np.zeros((len(pos), 5))
    q[:, m.axes.index(a)] = pos
    e = funcs(q)
    if a in m.rotary_axes:
        u = np.asarray(m.layout.axes[a].direction, float)
        u = u / np.linalg.norm(u)
        return np.rad2deg(sum(u[k] * e.get(f"E{r}{a}", 0.0) for k, r in enumerate("ABC")))
    return e[f"E{a}{a}"]


@pytest.mark.parametrize("fmt", ctl.FORMATS)
def test_export_import_round_trip_within_the_increment(setup, tmp_path, fmt):
    m, funcs, _ = setup
    tables = ctl.build(funcs, fmt)
    back = _write_and_read(m, tables, fmt, tmp_path)
    assert len(back) == len(tables)
    inc = INCREMENT[fmt]
    for t in back:
        pos = t.positions
        assert len(pos) <= LIMIT[fmt] and np.allclose(np.diff(pos), t.step)
        if t.input == "C" and fmt != "linuxcnc":     # LinuxCNC's joint table has no modulo
            assert t.modulo and abs(pos[-1] - pos[0] - 360) < 1e-9
        lo, hi = funcs.tables[t.input].positions[[0, -1]]
        inside = np.mod(pos, 360.0) if t.modulo else np.clip(pos, lo, hi)
        if t.input == t.output:
            want = _positioning(m, funcs, t.input, inside)
        else:
            q = np.zeros((len(pos), 5))
            q[:, m.axes.index(t.input)] = inside
            want = funcs(q)[t.parameter]
        if fmt == "fanuc":
            # relative to the reference position (0 mm / deg), in steps of at most 7 units
            ref = int(np.argmin(np.abs(pos)))
            want = want - want[ref]
            assert t.values[ref] == 0
            steps = np.diff(np.round(t.values / inc))
            assert np.all(np.abs(steps) <= 7 * t.scale)
            if t.modulo:
                assert abs(t.values[-1] - t.values[0]) < 1e-12       # the turn closes
            tol = inc * t.scale / 2 + 1e-12
        else:
            tol = inc / 2 + 1e-12
        assert np.abs(t.values - want).max() <= tol, (t.parameter, np.abs(t.values - want).max())
    # into an error directory and back: the same values
    et = comp_tables.to_error_tables(back, m)
    for a, tab in et.items():
        assert np.all(np.diff(tab.positions) > 0)


def _controller_left(m, funcs, tables, grid=5):
    """The independent computation: grid over the tables' box, rotary axes at 0; the
    controller commands q - v (v: np.interp of each table, modulo for a turn, summed per
    output axis); the exact chain with all errors there, minus the nominal tip at q."""
    box = {a: funcs.tables[a].positions[[0, -1]] for a in ("X", "Y", "Z")}
    for a in box:
        lo, hi = m.travel[a]
        box[a] = (max(lo, box[a][0]), min(hi, box[a][1]))
    ticks = [np.linspace(*box[a], grid) for a in "XYZ"]
    mesh = np.meshgrid(*ticks, indexing="ij")
    q = np.column_stack([g.ravel() for g in mesh] + [np.zeros(mesh[0].size)] * 2)
    v = np.zeros_like(q)
    for t in tables:
        x = q[:, m.axes.index(t.input)]
        if t.modulo:
            x = t.start + np.mod(x - t.start, 360.0)
        val = np.interp(x, t.start + t.step * np.arange(len(t.values)), t.values)
        v[:, m.axes.index(t.output)] += val * (0.5 if t.direction else 1.0)
    qc = q - v
    # the errors where the axes are (a table's end value a hair beyond its end)
    qe = qc.copy()
    for a, (lo, hi) in funcs.ranges().items():
        j = m.axes.index(a)
        qe[:, j] = np.clip(qe[:, j], lo, hi)
    e = funcs(qe)
    before, after = [], []
    e0 = funcs(q)
    for r in range(len(q)):
        nominal = tool2work(m.name, dict(zip(m.axes, q[r])), {})[:3, 3]
        act = tool2work(m.name, dict(zip(m.axes, qc[r])),
                        {k: float(val[r]) for k, val in e.items()})[:3, 3]
        act0 = tool2work(m.name, dict(zip(m.axes, q[r])),
                         {k: float(val[r]) for k, val in e0.items()})[:3, 3]
        after.append(np.linalg.norm(act - nominal) * 1e3)
        before.append(np.linalg.norm(act0 - nominal) * 1e3)
    return np.array(before), np.array(after)


@pytest.mark.parametrize("fmt", ctl.FORMATS)
def test_what_the_tables_leave_equals_an_independent_computation(setup, tmp_path, fmt):
    m, funcs, _ = setup
    tables = ctl.build(funcs, fmt)
    back = _write_and_read(m, tables, fmt, tmp_path)
    from volerr.fiveaxis.tables_left import left

    s = left(m, funcs, tables, grid=5).summary()
    before, after = _controller_left(m, funcs, back)
    assert s["before_um"]["max"] == pytest.approx(before.max(), abs=0.01)
    assert s["left_um"]["max"] == pytest.approx(after.max(), abs=0.01)
    assert s["left_um"]["rms"] == pytest.approx(np.sqrt(np.mean(after ** 2)), abs=0.01)
    # the tables do something: what they carry is gone
    assert abs(s["left_um"]["rms"] - s["before_um"]["rms"]) > 0.5


def test_cli_export_json_plot_and_import(setup, tmp_path):
    m, funcs, d = setup
    out = tmp_path / "ctl" / "comp.cma"
    out.parent.mkdir()            # an output's folder must exist (a typo is never created)
    r = in_process.volerr("controller", "export", "DMU50", "--errors", d, "--format",
                          "heidenhain", "--out", out, "--json", tmp_path / "s.json", "--plot",
                          tmp_path / "m.png", "--grid", "4", "--points", "30")
    assert r.returncode == 0, r.stderr
    s = json.loads((tmp_path / "s.json").read_text())
    assert s["format"] == "heidenhain" and set(s["left_um"]) == {"max", "rms"}
    assert {p.name for p in out.parent.iterdir()} == {"comp.cma"} | {
        f"comp_{a}.com" for a in m.axes}
    assert all(t["points"] <= 30 for t in s["tables"])
    assert (tmp_path / "m.png").stat().st_size > 10000
    r = in_process.volerr("controller", "import", "DMU50", out, "--format", "heidenhain",
                          "--out", tmp_path / "back")
    assert r.returncode == 0, r.stderr
    back = ErrorFunctions.from_dir(tmp_path / "back", m)
    x = back.tables["X"].positions
    q = np.zeros((len(x), 5))
    q[:, 0] = x
    inside = q.copy()
    inside[:, 0] = np.clip(x, *funcs.ranges()["X"])     # the last point a hair beyond
    assert np.abs(back(q)["EYX"] - funcs(inside)["EYX"]).max() <= 0.5e-4 + 1e-12
    # beyond the format's limit: exit 2, one line, nothing written
    r = in_process.volerr("controller", "export", "DMU50", "--errors", d, "--format", "fanuc",
                          "--out", tmp_path / "f.txt", "--points", "500")
    assert r.returncode == 2 and "2 .. 128 for fanuc" in r.stderr and \
        len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not (tmp_path / "f.txt").exists()


def test_reversal_goes_into_direction_tables(tmp_path):
    """A table with RV_X: Heidenhain writes the positive-direction values in X and the
    negative-direction ones in BACKLASH, SINUMERIK CEC two direction tables; both read back
    as the mean and the reversal."""
    m = volerr.load("DMU50")
    x = np.linspace(-250, 250, 11)
    rv = -4e-3 + 1e-3 * np.sin(x / 60)
    funcs = ErrorFunctions({"X": ErrorTable("X", x, {"EXX": 2e-3 * np.cos(x / 90),
                                                     "EYX": 1e-3 * x / 250},
                                            reversal=rv)}, {}, m)
    for fmt in ("heidenhain", "sinumerik-cec"):
        tables = ctl.build(funcs, fmt)
        assert {t.direction for t in tables if t.parameter == "EXX"} == {1, -1}
        files = ctl.write(m, tables, fmt, tmp_path / f"{fmt}.txt")
        for p, text in files.items():
            Path(p).write_text(text)
        if fmt == "heidenhain":
            assert "BACKLASH" in (tmp_path / f"{fmt}_X.com").read_text()
        back = comp_tables.to_error_tables(ctl.read(m, tmp_path / f"{fmt}.txt", fmt), m)
        t = back["X"]
        assert np.abs(t.reversal - np.interp(t.positions, x, rv)).max() <= 1e-4 + 1e-12
        assert np.abs(t.values["EXX"] - 2e-3 * np.cos(t.positions / 90)).max() < 2e-4


def test_fanuc_tape_numbers():
    """The tape's parameters name the points: reference at 0 mm, 1024 numbers shared."""
    m = volerr.load("DMU50")
    x = np.linspace(-250, 250, 11)
    funcs = ErrorFunctions({"X": ErrorTable("X", x, {"EXX": 5e-3 * x / 250})}, {}, m)
    (t,) = fanuc.build(funcs)
    tape = fanuc.write("DMU50", [t], m.axes)
    lines = tape.splitlines()
    assert lines[0] == "%" and lines[-1] == "%"
    par = {ln[1:5]: ln for ln in lines if ln.startswith("N36")}
    ref = int(par["3620"].split("P")[1])
    step = int(par["3624"].split("P")[1])
    assert abs(t.start + (ref - 0) * t.step) < 1e-9 and step == round(t.step * 1000)
    data = [int(ln.split("P")[1]) for ln in lines if ln.startswith("N1")]
    # compensation = -error: the sum of the increments up to the end is -E(end) + E(0)
    assert sum(data[ref + 1:]) == round(-(5e-3 * t.end / 250) * 1000)
