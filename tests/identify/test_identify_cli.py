"""``volerr identify`` / ``volerr squareness`` command line: good runs and bad input (exit 2)."""

import json
import subprocess
import sys

import numpy as np
import pytest
from helpers.tracker_sim import simulate, smooth_errors, to_csv

from volerr.cli import main  # noqa: E402

REF = np.array([[60.0, 10.0, -150.0], [-40.0, 50.0, -100.0], [10.0, -60.0, -200.0]])
POS = np.linspace(0, 500, 6)


def good_csv(rounds=2, noise=0.0005, labels=("P", "Q", "K"), ref=REF, pos=POS):
    e = smooth_errors(pos, seed=1)
    rng = np.random.default_rng(0)
    R = [simulate("linear", ref, pos, e, noise_mm=noise, rng=rng) for _ in range(rounds)]
    return to_csv(R, pos, labels)


def run_cli(args, capsys):
    code = main([str(a) for a in args])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_good_run_writes_everything(tmp_path, capsys):
    f = tmp_path / "in.csv"
    f.write_text(good_csv())
    out, js, res, png = (tmp_path / n for n in ("X.csv", "s.json", "r.csv", "p.png"))
    code, so, se = run_cli(["identify", "MB1", "--axis", "X", f, "--out", out, "--json", js,
                            "--residuals", res, "--plot", png, "--fit", "poly"], capsys)
    assert code == 0, se
    head = out.read_text().splitlines()[0].split(",")
    assert head[:7] == ["X", "EXX_um", "EYX_um", "EZX_um", "EAX_urad", "EBX_urad", "ECX_urad"]
    assert "EXX_std_um" in head
    doc = json.loads(js.read_text())
    assert doc["n_rounds"] == 2 and doc["condition"] < 10 and len(doc["fit"]) == 6
    assert res.read_text().startswith("round,point,position,rx_um")
    assert png.stat().st_size > 10000


def test_thesis_format(tmp_path, capsys):
    e = smooth_errors(POS, seed=1)
    pts = simulate("linear", REF, POS, e)
    lines = [f"K{k},{pts[k, 2, 0]},{pts[k, 2, 1]},{pts[k, 2, 2]}" for k in range(6)]
    lines += [f"P{k},{pts[k, 0, 0]},{pts[k, 0, 1]},{pts[k, 0, 2]}" for k in range(6)]
    lines += [f"Q{k},{pts[k, 1, 0]},{pts[k, 1, 1]},{pts[k, 1, 2]}" for k in range(6)]
    f = tmp_path / "Round 1.csv"
    f.write_text("\n".join(lines) + "\n")
    out = tmp_path / "X.csv"
    code, so, se = run_cli(["identify", "MB1", "--axis", "X", f, "--out", out, "--format",
                            "thesis", "--positions", "0:500:6", "--points", "K,P,Q"], capsys)
    assert code == 0, se
    vals = np.loadtxt(out, delimiter=",", skiprows=1)
    assert np.allclose(vals[:, 1] * 1e-3, e[:, 0], atol=1e-6)


def _bad(tmp_path, capsys, text, extra=(), name="in.csv", layout="MB1", axis="X"):
    f = tmp_path / name
    f.write_text(text)
    out = tmp_path / "out.csv"
    code, so, se = run_cli(["identify", layout, "--axis", axis, f, "--out", out, *extra],
                           capsys)
    assert code == 2
    lines = se.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("volerr identify: error:"), se
    assert "Traceback" not in se
    assert not out.exists()
    assert f.read_text() == text
    return lines[0]


def test_missing_column(tmp_path, capsys):
    text = good_csv().replace("round,point,position,x,y,z", "round,point,position,x,y,q")
    assert "missing column" in _bad(tmp_path, capsys, text)


def test_fewer_than_three_points(tmp_path, capsys):
    text = "\n".join(l for l in good_csv().splitlines() if ",K," not in l) + "\n"
    assert "at least three" in _bad(tmp_path, capsys, text)


def test_rounds_with_different_positions(tmp_path, capsys):
    lines = good_csv().splitlines()
    text = "\n".join(l for l in lines if not (l.startswith("2,") and ",500," in l)) + "\n"
    assert "different positions" in _bad(tmp_path, capsys, text)


def test_nan(tmp_path, capsys):
    lines = good_csv().splitlines()
    parts = lines[5].split(",")
    parts[4] = "nan"
    lines[5] = ",".join(parts)
    assert "NaN" in _bad(tmp_path, capsys, "\n".join(lines) + "\n")


def test_not_a_number(tmp_path, capsys):
    text = good_csv().replace(",100,", ",1o0,", 1)
    assert "not a number" in _bad(tmp_path, capsys, text)


def test_missing_measurement(tmp_path, capsys):
    lines = good_csv().splitlines()
    del lines[3]
    assert "no measurement" in _bad(tmp_path, capsys, "\n".join(lines) + "\n")


def test_unknown_axis(tmp_path, capsys):
    assert "not an axis" in _bad(tmp_path, capsys, good_csv(), axis="C")


def test_unknown_layout(tmp_path, capsys):
    assert "unknown layout" in _bad(tmp_path, capsys, good_csv(), layout="NOPE")


def test_collinear_points(tmp_path, capsys):
    ref = np.array([[0, 0, 0], [50, 50, 50], [100, 100, 100.0]])
    line = _bad(tmp_path, capsys, good_csv(ref=ref, noise=0))
    assert "condition number" in line


def test_wrong_units_detected(tmp_path, capsys):
    """Coordinates in m instead of mm: the nominal motion does not fit."""
    lines = good_csv().splitlines()
    out = [lines[0]]
    for l in lines[1:]:
        c = l.split(",")
        out.append(",".join(c[:3] + [str(float(v) / 1000) for v in c[3:]]))
    assert "deviate" in _bad(tmp_path, capsys, "\n".join(out) + "\n")


def test_thesis_format_needs_positions(tmp_path, capsys):
    assert "--positions" in _bad(tmp_path, capsys, "K,1,2,3\n", extra=["--format", "thesis"])


def test_thesis_format_bad_block_count(tmp_path, capsys):
    text = "\n".join(f"K,{i},0,0" for i in range(7)) + "\n"
    assert "blocks" in _bad(tmp_path, capsys, text,
                            extra=["--format", "thesis", "--positions", "0:10:3"])


def test_bad_tracker_option(tmp_path, capsys):
    assert "three" in _bad(tmp_path, capsys, good_csv(), extra=["--tracker", "1,2"])


def test_output_equal_to_input_refused(tmp_path, capsys):
    f = tmp_path / "in.csv"
    text = good_csv()
    f.write_text(text)
    code, so, se = run_cli(["identify", "MB1", "--axis", "X", f, "--out", f], capsys)
    assert code == 2 and "overwrite" in se and f.read_text() == text


def test_subprocess_no_traceback(tmp_path):
    f = tmp_path / "in.csv"
    f.write_text("round,point\n1,P\n")
    cp = subprocess.run([sys.executable, "-m", "volerr", "identify", "MB1", "--axis", "X",
                         str(f), "--out", str(tmp_path / "o.csv")], capture_output=True,
                        text=True)
    assert cp.returncode == 2 and len(cp.stderr.strip().splitlines()) == 1
    assert "Traceback" not in cp.stderr


# ---------------------------------------------------------------------------------------------
# squareness command
def _square_dir(tmp_path, ec0y=30e-6):
    from volerr.tables.table import ErrorTable, write_error_table

    d = tmp_path / "errs"
    d.mkdir()
    x = np.linspace(0, 500, 6)
    # X carries -EC0Y (tool side): EYX = -EC0Y * x; Y straight
    write_error_table(d / "X.csv", ErrorTable("X", x, {"EXX": 0 * x, "EYX": -ec0y * x}))
    write_error_table(d / "Y.csv", ErrorTable("Y", x, {"EYY": 0 * x, "EXY": 0 * x}))
    return d


def test_squareness_command(tmp_path, capsys):
    from volerr.tables.table import read_constants, read_error_table

    d = _square_dir(tmp_path)
    out = tmp_path / "out"
    code, so, se = run_cli(["squareness", "MB1", d, "--out", out], capsys)
    assert code == 0, se
    c = read_constants(out / "constants.csv")
    assert c["EC0Y"] == pytest.approx(30e-6, abs=1e-12)
    t = read_error_table(out / "X.csv")
    assert np.allclose(t.values["EYX"], 0, atol=1e-12)


def test_squareness_bad_input(tmp_path, capsys):
    d = _square_dir(tmp_path)
    code, so, se = run_cli(["squareness", "MB1", d, "--out", d], capsys)
    assert code == 2 and len(se.strip().splitlines()) == 1
    (d / "Y.csv").unlink()
    code, so, se = run_cli(["squareness", "MB1", d, "--out", tmp_path / "o"], capsys)
    assert code == 2 and "no pair" in se


def test_json_summary_strict_on_noise_free_data(tmp_path, capsys):
    """Noise-free data make ratios 0/0: the summary has null there, never NaN (not JSON), and
    no warning reaches stderr."""
    f = tmp_path / "in.csv"
    pts = simulate("linear", REF, POS, np.zeros((POS.size, 6)))   # a perfect axis
    f.write_text(to_csv([pts, pts], POS, ("P", "Q", "K")))
    js = tmp_path / "s.json"
    code, so, se = run_cli(["identify", "MB1", "--axis", "X", f, "--out", tmp_path / "X.csv",
                            "--json", js], capsys)
    assert code == 0 and se == "", se

    def refuse(c):
        raise ValueError(f"non-JSON constant {c}")

    doc = json.loads(js.read_text(), parse_constant=refuse)
    assert doc["n_rounds"] == 2
