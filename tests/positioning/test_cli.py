"""``volerr iso230-2`` end to end: formats, outputs, error-table round trip, bad input."""

from __future__ import annotations

import csv
import json
import re

import numpy as np
import pytest

from volerr.cli import main
from volerr.positioning import read_run
from volerr.positioning._io import wide_column
from volerr.tables import ErrorFunctions, read_error_dir

TARGETS = np.arange(0.0, 901.0, 112.5)     # 9 targets over MB1's X travel 0 .. 900 mm


def simulated(seed=3, n=5, reversal_um=2.5):
    """Deviations (m, 2, n) um: smooth lead error, reversal, noise."""
    rng = np.random.default_rng(seed)
    base = 6.0 * np.sin(TARGETS / 250.0) + 0.004 * TARGETS
    dev = base[:, None, None] + np.array([0.5, -0.5])[None, :, None] * reversal_um
    return np.round(dev + rng.normal(0.0, 0.4, (TARGETS.size, 2, n)), 4)


def write_long(path, dev, T=None, sep=",", dev_header="deviation_um", scale=1.0):
    head = ["target_mm", "cycle", "direction", dev_header] + (["T_C"] if T is not None else [])
    lines = [sep.join(head)]
    for i, t in enumerate(TARGETS):
        for j in range(dev.shape[2]):
            for d, word in ((0, "+1"), (1, "-1")):
                row = [f"{t:g}", str(j + 1), word, repr(float(dev[i, d, j]) * scale)]
                if T is not None:
                    row.append(f"{T:g}")
                lines.append(sep.join(row))
    path.write_text("\n".join(lines) + "\n")
    return path


def write_wide(path, dev, names=("fwd_{}_um", "bwd_{}_um")):
    n = dev.shape[2]
    head = ["target_mm"] + [names[d].format(j + 1) for j in range(n) for d in (0, 1)]
    lines = [",".join(head)]
    for i, t in enumerate(TARGETS):
        lines.append(",".join([f"{t:g}"] + [repr(float(dev[i, d, j])) for j in range(n)
                                            for d in (0, 1)]))
    path.write_text("\n".join(lines) + "\n")
    return path


def run_cli(*args):
    return main(["iso230-2", *map(str, args)])


def test_long_and_wide_give_identical_json(tmp_path):
    dev = simulated()
    a = write_long(tmp_path / "long.csv", dev)
    b = write_wide(tmp_path / "wide.csv", dev)
    c = write_wide(tmp_path / "wide2.csv", dev, names=("Run{} fwd (um)", "run {} BWD (um)"))
    outs = []
    for f in (a, b, c):
        out = tmp_path / f"{f.stem}.json"
        assert run_cli(f, "--json", out) == 0
        outs.append(json.loads(out.read_text()))
    strip = {"file", "format", "identification"}   # the report id hashes the file's bytes
    ref = {k: v for k, v in outs[0].items() if k not in strip}
    for o in outs[1:]:
        assert {k: v for k, v in o.items() if k not in strip} == ref
    # the JSON figures against an independent computation from the simulated readings
    xm, s = dev.mean(axis=2), dev.std(axis=2, ddof=1)
    assert ref["E_um"] == pytest.approx(xm.max() - xm.min())
    assert ref["B_avg_um"] == pytest.approx(np.mean(xm[:, 0] - xm[:, 1]))
    assert ref["A_um"] == pytest.approx((xm + 2 * s).max() - (xm - 2 * s).min())
    assert ref["n_cycles"] == 5 and ref["axis"] == "X"
    assert ref["temperature_correction"] == {"applied": False}
    assert ref["targets_mm"] == list(TARGETS)


def test_wide_header_variants():
    for name, spec in [("fwd_1_um", (0, "1", 1e-3)), ("bwd_12_um", (1, "12", 1e-3)),
                       ("Fwd1", (0, "1", 1e-3)), ("forward_2_mm", (0, "2", 1.0)),
                       ("run3_bwd", (1, "3", 1e-3)), ("1+", (0, "1", 1e-3)),
                       ("2-", (1, "2", 1e-3)), ("down_4 (um)", (1, "4", 1e-3)),
                       ("cycle_2_up", (0, "2", 1e-3))]:
        assert wide_column(name) == spec, name
    for name in ("T_C", "target_mm", "comment", "c1", "fwd"):
        assert wide_column(name) is None, name


def test_semicolon_export_and_mm_deviations(tmp_path):
    dev = simulated()
    a = read_run(write_long(tmp_path / "a.csv", dev))
    b = read_run(write_long(tmp_path / "b.csv", dev, sep=";", dev_header="deviation_mm",
                            scale=1e-3))
    assert np.allclose(a.deviation, b.deviation, atol=1e-15)
    assert np.allclose(a.deviation, dev * 1e-3)


def test_outputs_and_table_round_trip(tmp_path):
    dev = simulated()
    f = write_long(tmp_path / "run.csv", dev, T=20.0)
    tab = tmp_path / "errors"
    out, png, page = tmp_path / "r.json", tmp_path / "r.png", tmp_path / "r.html"
    assert run_cli(f, "--json", out, "--plot", png, "--html", page, "--table-out", tab) == 0
    rep = json.loads(out.read_text())
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = page.read_text()
    assert "data:image/png;base64," in text and "run.csv" in text
    assert re.search(r"(src|href)\s*=\s*[\"']?(https?:|//)", text) is None   # no network
    tables, _ = read_error_dir(tab, ("X", "Y", "Z"))
    t = tables["X"]
    xm, s = dev.mean(axis=2), dev.std(axis=2, ddof=1)
    assert np.allclose(t.positions, TARGETS)
    assert np.allclose(t.values["EXX"] * 1e3, xm.mean(axis=1), atol=1e-9)
    S = np.sqrt((s[:, 0] ** 2 + s[:, 1] ** 2) / 2)          # pooled single-reading S_i
    # _std = u of the bidirectional mean of 2 x 5 readings; _s = S_i of one reading
    assert np.allclose(t.std["EXX"] * 1e3, S / np.sqrt(2 * 5), atol=1e-9)
    assert np.allclose(t.s["EXX"] * 1e3, S, atol=1e-9)
    with open(tab / "X.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert np.allclose([float(r["EXX_s_um"]) for r in rows], S, atol=1e-9)
    assert np.allclose(t.reversal * 1e3, xm[:, 0] - xm[:, 1], atol=1e-9)
    assert np.allclose(t.values["EXX"] * 1e3, rep["mean_um"], atol=1e-9)
    funcs = ErrorFunctions.from_dir(tab, "MB1")
    mid = 0.5 * (TARGETS[2] + TARGETS[3])
    assert funcs({"X": [mid], "Y": [0.0], "Z": [0.0]})["EXX"][0] * 1e3 == pytest.approx(
        0.5 * (xm[2].mean() + xm[3].mean()))
    # volerr map reads the directory: dx at X = 0, 450, 900 is the mean bidirectional deviation
    mp = tmp_path / "map.csv"
    assert main(["map", "MB1", "--errors", str(tab), "--volume", "measured", "--grid", "3",
                 "--out", str(mp)]) == 0
    with open(mp, newline="") as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        i = int(np.flatnonzero(np.isclose(TARGETS, float(r["X"])))[0])
        assert float(r["dx_um"]) == pytest.approx(xm[i].mean(), abs=1e-6)


def test_cte_correction_from_the_command_line(tmp_path):
    dev = simulated(reversal_um=0.0)
    warm = dev + 11.5 * 4.0 * TARGETS[:, None, None] * 1e-3      # +4 K, steel scale, P_ref 0
    f = write_long(tmp_path / "warm.csv", warm, T=24.0)
    g = write_long(tmp_path / "cold.csv", dev)
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    assert run_cli(f, "--json", a, "--cte-ppm-per-K", 11.5) == 0
    assert run_cli(g, "--json", b) == 0
    ra, rb = json.loads(a.read_text()), json.loads(b.read_text())
    for k in ("A_um", "E_um", "M_um", "R_um", "B_um"):
        assert ra[k] == pytest.approx(rb[k], abs=1e-6)
    assert np.allclose(ra["mean_um"], rb["mean_um"], atol=1e-6)
    tc = ra["temperature_correction"]
    assert tc["applied"] and tc["cte_ppm_per_K"] == 11.5
    assert tc["correction_um"]["min"] == pytest.approx(-11.5 * 4.0 * 0.9)


def test_several_runs_side_by_side(tmp_path):
    f = write_long(tmp_path / "x.csv", simulated(seed=1))
    g = write_wide(tmp_path / "y.csv", simulated(seed=2, reversal_um=-1.0))
    out, tab = tmp_path / "r.json", tmp_path / "tab"
    assert run_cli(f, g, "--axis", "X,Y", "--json", out, "--table-out", tab,
                   "--plot", tmp_path / "p.png") == 0
    rep = json.loads(out.read_text())
    assert "runs" in rep and [r["axis"] for r in rep["runs"]] == ["X", "Y"]
    single = tmp_path / "single.json"
    assert run_cli(g, "--axis", "Y", "--json", single) == 0
    assert json.loads(single.read_text())["E_um"] == rep["runs"][1]["E_um"]
    tables, _ = read_error_dir(tab, ("X", "Y", "Z"))
    assert set(tables) == {"X", "Y"} and "EYY" in tables["Y"].values


def _bad(tmp_path, capsys, text, *extra):
    f = tmp_path / "bad.csv"
    f.write_text(text)
    out, tab = tmp_path / "o.json", tmp_path / "tab"
    code = run_cli(f, "--json", out, "--table-out", tab, "--plot", tmp_path / "p.png", *extra)
    err = capsys.readouterr().err
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not out.exists() and not tab.exists() and not (tmp_path / "p.png").exists()
    return err


def _long(rows):
    return "target_mm,cycle,direction,deviation_um\n" + "\n".join(rows) + "\n"


GOOD = [f"{t},{c},{d},{0.1 * c}" for t in (0, 100) for c in (1, 2) for d in ("+1", "-1")]


@pytest.mark.parametrize("rows, message", [
    ([r for r in GOOD if ",2," not in r], "at least 2 cycles"),
    ([r for r in GOOD if not r.startswith("100,")], "at least 2 target"),
    ([r for r in GOOD if not (r.startswith("100,") and r.split(",")[2] == "-1")],
     "forward direction only"),
    ([r for r in GOOD if r != "100,2,-1,0.2"], "cycle 2 missing at target 100"),
    (GOOD + ["100,2,-1,0.3"], "duplicate reading"),
    ([r if r != "0,1,+1,0.1" else "0,1,+1,abc" for r in GOOD], "not a number"),
    ([r if r != "0,1,+1,0.1" else "0,1,+1,nan" for r in GOOD], "NaN"),
    ([r if r != "0,1,+1,0.1" else "0,1,+1,0,1" for r in GOOD], "fields"),
    ([r if r != "0,1,+1,0.1" else "0,1,0,0.1" for r in GOOD], "direction"),
    ([r if r != "0,1,+1,0.1" else "0,1.5,+1,0.1" for r in GOOD],
     "cycle = '1.5': cycle must be an integer"),
])
def test_bad_long_input(tmp_path, capsys, rows, message):
    assert message in _bad(tmp_path, capsys, _long(rows))


def test_bad_wide_input(tmp_path, capsys):
    head = "target_mm,fwd_1_um,bwd_1_um,fwd_2_um,bwd_2_um\n"
    assert "cycle 2 missing at target 100" in _bad(tmp_path, capsys,
                                                   head + "0,1,2,3,4\n100,1,2,3,\n")
    assert "duplicate target" in _bad(tmp_path, capsys, head + "0,1,2,3,4\n0,1,2,3,4\n")
    assert "both give cycle 1" in _bad(tmp_path, capsys,
                                       "target_mm,fwd_1_um,fwd1,bwd_1_um,fwd_2_um,bwd_2_um\n"
                                       "0,1,1,2,3,4\n100,1,1,2,3,4\n")
    assert "decimal comma" in _bad(tmp_path, capsys,
                                   "target_mm;fwd_1_um;bwd_1_um;fwd_2_um;bwd_2_um\n"
                                   "0;1,5;2;3;4\n100;1;2;3;4\n")
    assert "backward direction only" in _bad(tmp_path, capsys,
                                             "target_mm,bwd_1_um,bwd_2_um\n0,1,2\n100,1,2\n")


def test_bad_options(tmp_path, capsys):
    good = _long(GOOD)
    assert "material temperature" in _bad(tmp_path, capsys, good, "--cte-ppm-per-K", "11.5")
    assert "linear axis" in _bad(tmp_path, capsys, good, "--axis", "C")
    f = tmp_path / "in.csv"
    f.write_text(good)
    before = f.read_text()
    assert run_cli(f, "--json", f) == 2
    assert f.read_text() == before
    assert run_cli(f, "--json", tmp_path / "a.json", "--plot", tmp_path / "a.jpg") == 2
    assert not (tmp_path / "a.json").exists()
    assert run_cli(f, f, "--json", tmp_path / "a.json") == 2
    g = tmp_path / "in2.csv"
    g.write_text(good)
    assert run_cli(f, g, "--json", tmp_path / "a.json", "--table-out", tmp_path / "t") == 2
    assert "one table per axis" in capsys.readouterr().err
    assert not (tmp_path / "a.json").exists()


def test_help_documents_both_formats(capsys):
    assert main(["iso230-2", "--help"]) == 0
    out = capsys.readouterr().out
    assert "target_mm,cycle,direction,deviation_um" in out
    assert "target_mm,fwd_1_um,bwd_1_um" in out
    # what the table's uncertainty columns hold (one meaning: volerr formats tables)
    assert "S_i / sqrt(2 n)" in out and "EXX_s" in out
    assert main(["uncertainty", "--help"]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "_std" in out and "_s" in out and "--repeatability" in out


def test_two_outputs_the_same_file_refused(tmp_path, capsys):
    f = write_long(tmp_path / "run.csv", simulated())
    assert run_cli(f, "--json", tmp_path / "a.out", "--html", tmp_path / "a.out") == 2
    assert "two outputs are the same file" in capsys.readouterr().err
    assert not (tmp_path / "a.out").exists()


@pytest.mark.parametrize("head, factor", [("Target (mm)", 1.0), ("target", 1.0),
                                          ("Target [mm]", 1.0), ("position_mm", 1.0),
                                          ("target position (mm)", 1.0), ("Target [um]", 1e3),
                                          ("TARGET_MM", 1.0)])
def test_target_column_unit_spellings(tmp_path, head, factor):
    """The target column takes the unit spellings of the reading columns, in both formats."""
    dev = simulated()
    ref = read_run(write_wide(tmp_path / "ref.csv", dev))
    wide = write_wide(tmp_path / "w.csv", dev)
    lines = wide.read_text().splitlines()
    body = [",".join([f"{float(r.split(',')[0]) * factor:g}"] + r.split(",")[1:])
            for r in lines[1:]]
    wide.write_text("\n".join([lines[0].replace("target_mm", head, 1)] + body) + "\n")
    long = write_long(tmp_path / "l.csv", dev)
    ll = long.read_text().splitlines()
    lbody = [",".join([f"{float(r.split(',')[0]) * factor:g}"] + r.split(",")[1:])
             for r in ll[1:]]
    long.write_text("\n".join([ll[0].replace("target_mm", head, 1)] + lbody) + "\n")
    for f in (wide, long):
        r = read_run(f)
        assert np.allclose(r.targets, TARGETS) and np.array_equal(r.deviation, ref.deviation)


def test_deviation_column_unit_spellings(tmp_path):
    dev = simulated()
    ref = read_run(write_long(tmp_path / "a.csv", dev))
    for head, scale in (("Deviation (um)", 1.0), ("deviation [mm]", 1e-3), ("deviation", 1.0)):
        r = read_run(write_long(tmp_path / "b.csv", dev, dev_header=head, scale=scale))
        assert np.allclose(r.deviation, ref.deviation, atol=1e-15), head


def test_two_target_columns_refused_target_preferred_to_position(tmp_path, capsys):
    assert "both give the target position" in _bad(
        tmp_path, capsys, "target_mm,Target (mm),fwd_1,bwd_1,fwd_2,bwd_2\n"
                          "0,0,1,2,3,4\n100,100,1,2,3,4\n")
    f = tmp_path / "p.csv"      # an extra 'position' column (e.g. actual) loses to 'target'
    f.write_text("position_mm,target_mm,fwd_1,bwd_1,fwd_2,bwd_2\n5,0,1,2,3,4\n"
                 "105,100,1,2,3,4\n")
    assert np.allclose(read_run(f).targets, [0.0, 100.0])


def test_table_std_is_the_uncertainty_of_the_mean_deviation():
    """Statistical check of the chain iso230-2 -> uncertainty (--table-std systematic): over
    many simulated runs of one machine (fixed error function + N(0, sigma) per reading, fixed
    reversal), the scatter of the tabulated mean deviation EXX is what _std states, sigma /
    sqrt(2 n), not the single-reading sigma."""
    from volerr.positioning import PositioningRun, error_table, evaluate

    rng = np.random.default_rng(11)
    n, sigma, runs = 4, 0.8e-3, 600
    truth = 1e-3 * (5.0 * np.sin(TARGETS / 200.0))
    base = truth[:, None, None] + np.array([1.5e-3, -1.5e-3])[None, :, None]
    exx, std = [], []
    for _ in range(runs):
        dev = base + rng.normal(0.0, sigma, (TARGETS.size, 2, n))
        t = error_table(evaluate(PositioningRun("X", TARGETS, tuple("1234"), dev)))
        exx.append(t.values["EXX"])
        std.append(t.std["EXX"])
    scatter = np.std(np.array(exx) - truth, axis=0, ddof=1)      # per target, over runs
    expected = sigma / np.sqrt(2 * n)
    # the std of a std estimate from 600 runs: relative 1/sqrt(2*599) ~ 3 %; pooled targets
    assert np.mean(scatter) == pytest.approx(expected, rel=0.05)
    assert np.sqrt(np.mean(np.array(std) ** 2)) == pytest.approx(expected, rel=0.05)
    assert np.mean(scatter) < 0.5 * sigma      # clearly not the single-reading repeatability
