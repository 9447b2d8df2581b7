"""Volumetric map and length tests (space/face diagonals, axis lines), example error sets, CLI."""

from __future__ import annotations

import itertools
import json
import subprocess
import sys

import numpy as np
import pytest

import volerr
from volerr.cli import main
from volerr.cmm.diagonals import box_lines, evaluate_lines
from volerr.cmm.examples import EXAMPLES, write_example_errors
from volerr.tables.functions import ErrorFunctions
from volerr.tables.table import read_constants, read_error_table

CMMS = ["MB1", "MB2", "FB1", "FB2", "MH1", "MH2", "FH1", "FH2", "CX", "CY"]


@pytest.fixture(scope="module")
def mb1_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("mb1")
    write_example_errors(d, "MB1")
    return d


@pytest.fixture(scope="module")
def mh2_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("mh2")
    write_example_errors(d, "MH2")
    return d


# ---------------------------------------------------------------------------------------------
# example sets: the printed figures of Pahk sec. 4
def test_example_mb1_printed_figures(mb1_dir):
    x = read_error_table(mb1_dir / "X.csv")
    y = read_error_table(mb1_dir / "Y.csv")
    assert np.ptp(x.values["EXX"]) * 1e3 == pytest.approx(6.15, abs=1e-3)
    assert np.ptp(y.values["EYY"]) * 1e3 == pytest.approx(23.0, abs=1e-3)
    assert np.ptp(x.values["EBX"]) * 1e6 == pytest.approx(11.18, abs=1e-3)
    assert 2 * x.s["EXX"].max() * 1e3 == pytest.approx(10.75, abs=1e-3)  # repeatability of one reading (_s)
    model = volerr.load("MB1")
    funcs = ErrorFunctions.from_dir(mb1_dir, model)
    n_params = len(funcs.functions) + len(funcs.constants)
    assert n_params == 17
    c = read_constants(mb1_dir / "constants.csv")
    # alpha, beta1, beta2 as printed, through the layout's paper symbols (EB0Z = -beta1)
    sym = model.paper_symbols
    printed = {"alpha": 14.1e-6, "beta1": 56.4e-6, "beta2": -32e-6}
    for iso, value in c.items():
        s = sym[iso]
        sign = -1 if s.startswith("-") else 1
        assert value == pytest.approx(sign * printed[s.lstrip("-")])


def test_example_mh2(mh2_dir):
    model = volerr.load("MH2")
    funcs = ErrorFunctions.from_dir(mh2_dir, model)
    assert len(funcs.functions) + len(funcs.constants) == 10
    assert funcs.has_random
    x = read_error_table(mh2_dir / "X.csv")
    assert np.ptp(x.values["EXX"]) * 1e3 == pytest.approx(71.0, abs=1e-3)
    sym = model.paper_symbols
    c = read_constants(mh2_dir / "constants.csv")
    inv = {sym[k].lstrip("-"): (-v if sym[k].startswith("-") else v) for k, v in c.items()}
    assert inv == pytest.approx({"alpha": 43.2e-6, "beta2": -48.9e-6, "beta1": 108.9e-6})


def test_examples_deterministic(tmp_path):
    for name in EXAMPLES:
        write_example_errors(tmp_path / "a" / name, name)
        write_example_errors(tmp_path / "b" / name, name)
        for f in (tmp_path / "a" / name).iterdir():
            assert f.read_bytes() == (tmp_path / "b" / name / f.name).read_bytes()


# ---------------------------------------------------------------------------------------------
# diagonals: independent geometry
def skewed_point(p, a, b, c):
    """Actual point of nominal axis readings p on a CMM whose only errors are squareness:
    Y line rotated by a about Z (EC0Y), Z line rotated by b about Y (EB0Z) and c about X (EA0Z),
    exact rotations, X the reference."""
    ey = np.array([-np.sin(a), np.cos(a), 0.0])
    ez = np.array([np.sin(b), 0.0, np.cos(b)])
    ez = np.array([ez[0], -np.sin(c) * ez[2], np.cos(c) * ez[2]])
    return p[0] * np.array([1.0, 0, 0]) + p[1] * ey + p[2] * ez


@pytest.mark.parametrize("layout", CMMS)
def test_squareness_lengths_match_skewed_axes(layout):
    model = volerr.load(layout)
    a, b, c = 40e-6, -70e-6, 25e-6
    funcs = ErrorFunctions({}, {"EC0Y": a, "EB0Z": b, "EA0Z": c}, model)
    lines = box_lines(model.travel)
    assert len(lines) == 4 + 12 + 15
    res = evaluate_lines(model, funcs, lines, profile_points=2)
    for r in res:
        p1, p2 = np.array(r.line.start), np.array(r.line.end)
        true = (np.linalg.norm(skewed_point(p2, a, b, c) - skewed_point(p1, a, b, c))
                - np.linalg.norm(p2 - p1)) * 1e3
        second_order = 1e3 * r.length_mm * 70e-6 ** 2  # um: neglected by the first-order model
        assert r.deviation_um == pytest.approx(true, abs=second_order), r.line.name
        assert abs(true) > 50 * second_order or r.line.kind == "axis"  # a meaningful test


def test_space_diagonals_vs_exact_end_points(mb1_dir):
    """dL (first order) = distance between the actual end points (exact chain) - nominal."""
    model = volerr.load("MB1")
    funcs = ErrorFunctions.from_dir(mb1_dir, model, method="cubic")
    probe = (10.0, -20.0, -150.0)
    (lx0, lx1), (ly0, ly1), (lz0, lz1) = (model.travel[a] for a in "XYZ")
    corners = {code: np.array([(lx0, lx1)[int(code[0])], (ly0, ly1)[int(code[1])],
                               (lz0, lz1)[int(code[2])]]) for code in
               ("".join(t) for t in itertools.product("01", repeat=3))}
    res = {r.line.name: r for r in evaluate_lines(model, funcs, box_lines(model.travel, kinds=("space",)),
                                                  probe=probe, profile_points=5)}
    assert set(res) == {"000-111", "100-011", "010-101", "110-001"}
    for name, r in res.items():
        a, b = corners[name[:3]], corners[name[4:]]
        pts = np.stack([a, b])
        pos = {ax: pts[:, i] for i, ax in enumerate("XYZ")}
        actual = model.nominal_position(pts, probe) + model.exact_error(pts, funcs(pos), probe)
        true = (np.linalg.norm(actual[1] - actual[0]) - np.linalg.norm(b - a)) * 1e3
        assert r.deviation_um == pytest.approx(true, abs=1e-3)
        assert r.exact_um == pytest.approx(true, abs=1e-9)
        assert r.profile_um[-1] == pytest.approx(r.deviation_um)
        assert r.profile_um[0] == 0.0


def test_length_random_component_monte_carlo(mh2_dir):
    """u(dL) against simulation: independent random table errors at each measured position,
    one common draw for constants and for points sharing an axis position."""
    model = volerr.load("MH2")
    funcs = ErrorFunctions.from_dir(mh2_dir, model)
    lines = [ln for ln in box_lines(model.travel) if ln.name in ("100-011", "000-100", "X@centre",
                                                                   "000-011")]
    res = evaluate_lines(model, funcs, lines, profile_points=2)
    rng = np.random.default_rng(3)
    n = 20000
    for r in res:
        p = np.array([r.line.start, r.line.end])
        pos = {ax: p[:, i] for i, ax in enumerate("XYZ")}
        mean, sig = funcs(pos), funcs.sigmas(pos)
        draws = {}
        for name, s in sig.items():
            ax = model.parameter_axis[name]
            z0 = rng.standard_normal(n)
            same = ax is None or pos[ax][0] == pos[ax][1]
            z1 = z0 if same else rng.standard_normal(n)
            draws[name] = (mean[name][0] + s[0] * z0, mean[name][1] + s[1] * z1)
        pts = np.repeat(p, n, axis=0)  # n copies of the start, then n of the end
        errs = {k: np.repeat(mean[k], n) for k in mean}
        errs.update({k: np.concatenate(v) for k, v in draws.items()})
        e = model.volumetric_error(pts, errs)
        u = (p[1] - p[0]) / np.linalg.norm(p[1] - p[0])
        dl = (e[n:] - e[:n]) @ u * 1e3
        assert dl.mean() == pytest.approx(r.deviation_um, abs=0.05 + 4 * r.random_um / np.sqrt(n))
        assert dl.std() == pytest.approx(r.random_um, rel=0.04), r.line.name


# ---------------------------------------------------------------------------------------------
# map
def test_map_csv_and_plots(mh2_dir, tmp_path):
    out, png = tmp_path / "map.csv", tmp_path / "map.png"
    before = {f.name: f.read_bytes() for f in mh2_dir.iterdir()}
    assert main(["map", "MH2", "--errors", str(mh2_dir), "--grid", "3", "4", "2", "--out", str(out),
                 "--plot", str(png), "--probe", "0", "50", "0"]) == 0
    rows = out.read_text().splitlines()
    header = rows[0].split(",")
    assert header[:9] == ["X", "Y", "Z", "Xp", "Yp", "Zp", "dx_um", "dy_um", "dz_um"]
    assert header[9:] == ["rx_um", "ry_um", "rz_um"]
    data = np.array([[float(v) for v in r.split(",")] for r in rows[1:]])
    assert data.shape == (3 * 4 * 2, 12)
    assert sorted(set(data[:, 0])) == pytest.approx([0, 550, 1100])
    assert sorted(set(data[:, 2])) == pytest.approx([0, 1100])
    # independent: linear interpolation of the tables by np.interp, then the model
    model = volerr.load("MH2")
    tabs = {a: read_error_table(mh2_dir / f"{a}.csv") for a in "XYZ"}
    errs = {}
    for a, t in tabs.items():
        for k, v in t.values.items():
            errs[k] = np.interp(data[:, "XYZ".index(a)], t.positions, v)
    errs.update(read_constants(mh2_dir / "constants.csv"))
    d = model.volumetric_error(data[:, :3], errs, probe=(0, 50, 0)) * 1e3
    np.testing.assert_allclose(data[:, 6:9], d, atol=1e-6)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rnd = tmp_path / "map_random.png"
    assert rnd.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert before == {f.name: f.read_bytes() for f in mh2_dir.iterdir()}


# ---------------------------------------------------------------------------------------------
# command line: good and bad input
def test_diagonals_cli_json(mb1_dir, tmp_path, capsys):
    js = tmp_path / "d.json"
    assert main(["diagonals", "MB1", "--errors", str(mb1_dir), "--json", str(js),
                 "--plot", str(tmp_path / "d.png")]) == 0
    text = capsys.readouterr().out
    doc = json.loads(js.read_text())
    assert [ln["name"] for ln in doc["lines"][:4]] == ["000-111", "100-011", "010-101", "110-001"]
    for ln in doc["lines"][:4]:
        assert f"{ln['deviation_um']:8.2f}" in text
        assert "random_um" in ln  # the MB1 example has repeatability columns
    assert (tmp_path / "d.png").stat().st_size > 1000


def _clean_failure(capsys, argv, fragment):
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    assert fragment.lower() in lines[0].lower(), lines[0]


def _bad_dir(tmp_path, text, name="X.csv"):
    d = tmp_path / "bad"
    d.mkdir(exist_ok=True)
    (d / name).write_text(text)
    return d


@pytest.mark.parametrize("command", ["map", "diagonals"])
@pytest.mark.parametrize("text,fragment", [
    ("X,EXX\n0,1\n900,2\n", "unit suffix"),
    ("X,EXX_um\n0,nan\n900,2\n", "NaN"),
    ("X,EXX_um\n900,1\n0,2\n", "increasing"),
    ("Q,EXX_um\n0,1\n900,2\n", "header mismatch"),
    ("EXX_um,EYX_um\n0,1\n900,2\n", "first column"),
    ("X,EXX_um\n0,1\n450,2\n", "outside the measured range"),
    ("X,EXY_um\n0,1\n900,2\n", "not a component error of axis X"),
])
def test_bad_tables_exit_2(tmp_path, capsys, command, text, fragment):
    d = _bad_dir(tmp_path, text)
    before = (d / "X.csv").read_text()
    _clean_failure(capsys, [command, "MB1", "--errors", str(d)], fragment)
    assert (d / "X.csv").read_text() == before


def test_bad_cli_input(tmp_path, capsys, mb1_dir):
    _clean_failure(capsys, ["map", "MB9", "--errors", str(mb1_dir)], "unknown layout")
    _clean_failure(capsys, ["map", "MB1", "--errors", str(tmp_path / "nope")], "does not exist")
    _clean_failure(capsys, ["map", "MB1", "--errors", str(mb1_dir), "--grid", "1"], "grid")
    _clean_failure(capsys, ["map", "MB1", "--errors", str(mb1_dir), "--grid", "2", "3"], "grid")
    _clean_failure(capsys, ["map", "MB1", "--errors", str(mb1_dir), "--magnify", "-1"], "magnify")
    _clean_failure(capsys, ["map", "MB1", "--errors", str(mb1_dir), "--plot", str(tmp_path / "a.jpg")],
                   ".png")
    before = (mb1_dir / "X.csv").read_bytes()
    _clean_failure(capsys, ["map", "MB1", "--errors", str(mb1_dir), "--out", str(mb1_dir / "X.csv")],
                   "refusing to overwrite")
    _clean_failure(capsys, ["diagonals", "MB1", "--errors", str(mb1_dir), "--json",
                            str(mb1_dir / "X.csv")], "refusing to overwrite")
    assert (mb1_dir / "X.csv").read_bytes() == before
    d = _bad_dir(tmp_path, "name,value,unit\nEC0Y,14.1,deg\n", "constants.csv")
    _clean_failure(capsys, ["diagonals", "MB1", "--errors", str(d)], "wrong units")


def test_bad_plot_name_writes_nothing(tmp_path, capsys, mb1_dir):
    """The plot name is checked with the other outputs, before the CSV / JSON are written."""
    out, js = tmp_path / "m.csv", tmp_path / "d.json"
    _clean_failure(capsys, ["map", "MB1", "--errors", str(mb1_dir), "--out", str(out),
                            "--plot", str(tmp_path / "m.txt")], ".png")
    _clean_failure(capsys, ["map", "MB1", "--errors", str(mb1_dir), "--out", str(out),
                            "--plot", str(tmp_path / "m.png"), "--plot-random",
                            str(tmp_path / "r.jpg")], ".png")
    _clean_failure(capsys, ["diagonals", "MB1", "--errors", str(mb1_dir), "--json", str(js),
                            "--plot", str(tmp_path / "d.txt")], ".png")
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_cli_subprocess_exit_code(tmp_path):
    d = _bad_dir(tmp_path, "X,EXX_um\n0,1\n0,2\n")
    p = subprocess.run([sys.executable, "-m", "volerr", "diagonals", "MB1", "--errors", str(d)],
                       capture_output=True, text=True)
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert len(p.stderr.strip().splitlines()) == 1


def test_extrapolate_flag(tmp_path, capsys):
    d = _bad_dir(tmp_path, "X,EXX_um\n0,0\n450,4.5\n")
    assert main(["diagonals", "MB1", "--errors", str(d), "--lines", "axis", "--extrapolate"]) == 0
    out = capsys.readouterr().out
    # EXX = 0.01 um/mm extended linearly: the X edges grow by 9 um over 900 mm
    assert "000-100" in out and "9.00" in out.split("000-100")[1].splitlines()[0]
