"""Values that would be silently wrong are refused with one line: duplicated columns, a tracker
file counted twice, non-finite or absurd numbers, an empty program, unbounded expressions."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from volerr.cli import main
from volerr.errors import InputError

PACKAGE = Path(__import__("volerr").__file__).parent


def refused(capsys, *argv, match: str):
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert match in err, err
    return err


def test_isg_duplicate_column_is_refused(tmp_path, capsys):
    f = tmp_path / "c.csv"
    f.write_text("X EXX EYX EXX\n0 0.001 0 0.002\n100 0.002 0 0.003\n")
    refused(capsys, "controller", "import", "MB1", f, "--out", tmp_path / "e",
            match="appears twice")
    assert not (tmp_path / "e").exists()


def test_tracker_duplicate_x_column_is_refused(inputs, tmp_path, capsys):
    lines = Path(inputs["tracker"]).read_text().splitlines()
    head = [i for i, ln in enumerate(lines) if ln and not ln.startswith("#")][0]
    lines[head] += ",x"
    for i in range(head + 1, len(lines)):
        if lines[i] and not lines[i].startswith("#"):
            lines[i] += ",999"
    f = tmp_path / "t.csv"
    f.write_text("\n".join(lines) + "\n")
    refused(capsys, "identify", "MB1", "--axis", "X", f, "--out", tmp_path / "X.csv",
            match="appears twice")


def test_same_tracker_file_twice_is_refused(inputs, tmp_path, capsys):
    refused(capsys, "identify", "MB1", "--axis", "X", inputs["tracker"],
            Path(inputs["tracker"]).parent / "." / Path(inputs["tracker"]).name,
            "--out", tmp_path / "X.csv", match="given twice")


def test_huge_tracker_coordinate_is_named_not_called_collinear(inputs, tmp_path, capsys):
    lines = Path(inputs["tracker"]).read_text().splitlines()
    i = next(k for k, ln in enumerate(lines) if ln and ln[0].isdigit())
    cells = lines[i].split(",")
    cells[-1] = "1e300"
    lines[i] = ",".join(cells)
    f = tmp_path / "t.csv"
    f.write_text("\n".join(lines) + "\n")
    refused(capsys, "identify", "MB1", "--axis", "X", f, "--out", tmp_path / "X.csv",
            match="implausibly large")


@pytest.mark.parametrize("value", ["1e300", "inf", "-1e12"])
@pytest.mark.parametrize("where", ["table", "constants"])
def test_absurd_numbers_in_tables_and_constants(value, where, tmp_path, capsys):
    d = tmp_path / "e"
    d.mkdir()
    if where == "table":
        (d / "X.csv").write_text(f"X,EXX_um\n0,0\n100,{value}\n")
    else:
        (d / "constants.csv").write_text(f"name,value,unit\nEC0Y,{value},urad\n")
    err = refused(capsys, "map", "MB1", "--errors", d, "--json", tmp_path / "s.json",
                  match="")
    assert "implausibly large" in err or "infinite" in err
    assert not (tmp_path / "s.json").exists()


@pytest.mark.parametrize("edit, match", [
    (("travel = [0, 900]", "travel = [0, inf]"), "finite"),
    (("travel = [0, 900]", "travel = [0, 1e300]"), "finite"),
    (("[axes.X]", "[axes.X]\npoint = [0, 0, 1e300]"), "finite"),
])
def test_absurd_numbers_in_a_layout(edit, match, tmp_path, capsys):
    text = (PACKAGE / "layouts" / "MB1.toml").read_text()
    assert edit[0] in text
    lay = tmp_path / "lay.toml"
    lay.write_text(text.replace(edit[0], edit[1], 1))
    refused(capsys, "derive", lay, "--out", tmp_path / "g", match=match)


@pytest.mark.parametrize("argv, match", [
    (["--magnitude-um", "1e300"], "--magnitude-um"),
    (["--noise-um", "inf"], "--noise-um"),
    (["--effect", "thermal:axis=Q"], "not an axis"),
    (["--effect", "thermal:ppm_per_K=abc"], "not a number"),
    (["--effect", "periodic:period_mm=inf"], "finite"),
    (["--probe", "0", "0", "1e300"], "finite"),
])
def test_simulate_values(argv, match, tmp_path, capsys):
    refused(capsys, "simulate", "MB1", "--out", tmp_path / "d.csv", "--points", 20, *argv,
            match=match)
    assert not (tmp_path / "d.csv").exists()


def test_map_magnify_inf(inputs, tmp_path, capsys):
    refused(capsys, "map", "MB1", "--errors", inputs["errors"], "--plot", tmp_path / "m.png",
            "--magnify", "inf", match="--magnify")


@pytest.mark.parametrize("program", ["", "( only a comment )\n%\n", "G90\nM30\n"])
def test_program_without_motion_is_not_compensated(program, inputs, tmp_path, capsys):
    f = tmp_path / "p.nc"
    f.write_text(program)
    refused(capsys, "compensate", "DMU50", f, "--errors", inputs["dmu_errors"], "--out",
            tmp_path / "c.nc", match="no motion block")
    assert not (tmp_path / "c.nc").exists()


def test_expression_size_and_exponent_are_bounded(tmp_path, capsys):
    from volerr.machine import expressions

    t = time.perf_counter()
    for text in ("9**9**9**9", "X**(2**10)", "X**100", "1e300*X", "+".join(["X"] * 300)):
        with pytest.raises(InputError):
            expressions.parse(text)
    assert time.perf_counter() - t < 1.0
    for text in ("X**2", "sin(2*pi*X/25.4)", "X*(T_C - 20)", "legendre(3, X/450)"):
        expressions.parse(text)  # ordinary bases stay valid
    # and in a layout: refused at once, not a derivation that never ends
    text = (PACKAGE / "layouts" / "DMU50.toml").read_text()
    lay = tmp_path / "h.toml"
    lay.write_text(text.replace('point = [0, 0, "d"]', 'point = [0, 0, "9**9**9**9"]'))
    t = time.perf_counter()
    refused(capsys, "derive", lay, "--out", tmp_path / "g", match="exponent")
    assert time.perf_counter() - t < 5.0
