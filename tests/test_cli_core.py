"""Command line basics: layouts, derive, load, and bad input (exit 2, one line, no traceback)."""

import subprocess
import sys

import pytest

import volerr


def run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "volerr", *args], capture_output=True,
                          text=True, cwd=cwd)


def assert_clean_failure(proc, fragment=""):
    assert proc.returncode == 2, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, proc.stderr
    assert "Traceback" not in proc.stderr
    assert fragment.lower() in lines[0].lower()


def test_layouts_lists_the_ten_cmms():
    names = run("layouts").stdout.split()
    for n in ["MB1", "MB2", "FB1", "FB2", "MH1", "MH2", "FH1", "FH2", "CX", "CY"]:
        assert n in names
    assert names == volerr.layouts()


def test_unknown_layout():
    assert_clean_failure(run("derive", "MB9", "--out", "x"), "unknown layout")
    with pytest.raises(volerr.InputError):
        volerr.load("MB9")


BAD_LAYOUTS = {
    "unknown axis": ('name = "T"\n[axes.Q]\nkind = "linear"\ndirection = [1,0,0]\n'
                     'travel = [0, 1]\n[chain]\ntool = ["Q"]\n', "unknown axis"),
    "cycle": ('name = "T"\n[axes.X]\nkind = "linear"\ndirection = [1,0,0]\ntravel = [0, 1]\n'
              '[chain]\ntool = ["X", "X"]\n', "twice"),
    "missing transform": ('name = "T"\n[axes.X]\nkind = "linear"\ndirection = [1,0,0]\n'
                          'travel = [0, 1]\n[chain]\ntool = ["X", "spindle"]\n', "missing"),
    "not toml": ("name = [", "TOML"),
    "zero direction": ('name = "T"\n[axes.X]\nkind = "linear"\ndirection = [0,0,0]\n'
                       'travel = [0, 1]\n[chain]\ntool = ["X"]\n', "zero"),
    "bad squareness": ('name = "T"\n[axes.X]\nkind = "linear"\ndirection = [1,0,0]\n'
                       'travel = [0, 1]\n[chain]\ntool = ["X"]\n[squareness]\nEC0Y = "Z"\n',
                       "squareness"),
}


@pytest.mark.parametrize("case", sorted(BAD_LAYOUTS))
def test_malformed_layout_files(tmp_path, case):
    text, fragment = BAD_LAYOUTS[case]
    path = tmp_path / "bad.toml"
    path.write_text(text)
    out = tmp_path / "out"
    assert_clean_failure(run("derive", str(path), "--out", str(out)), fragment)
    assert path.read_text() == text and not out.exists()


def test_derive_layout_file_on_the_fly(tmp_path):
    src = (volerr.layout.shipped_layout_dir() / "MB1.toml").read_text()
    path = tmp_path / "mine.toml"
    path.write_text(src.replace('name = "MB1"', 'name = "MINE"'))
    m = volerr.load(str(path))
    assert m.parameters == volerr.load("MB1").parameters
    proc = run("derive", str(path), "--out", str(tmp_path / "gen"))
    assert proc.returncode == 0 and (tmp_path / "gen" / "mine.py").exists()


def test_bad_positions_and_errors_raise_input_error():
    import numpy as np

    m = volerr.load("MB1")
    with pytest.raises(volerr.InputError, match="NaN"):
        m.volumetric_error(np.array([[np.nan, 0, 0]]), {})
    with pytest.raises(volerr.InputError, match="unknown error parameter"):
        m.volumetric_error(np.zeros((1, 3)), {"EXQ": 1.0})
    with pytest.raises(volerr.InputError, match="columns"):
        m.volumetric_error(np.zeros((1, 2)), {})
    with pytest.raises(volerr.InputError, match="unknown axis"):
        m.volumetric_error({"X": 0, "Y": 0, "Z": 0, "B": 0}, {})


def test_help_for_every_command():
    from volerr.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    assert {"layouts", "derive"} <= set(sub.choices)
    for name in sub.choices:
        proc = run(name, "--help")
        assert proc.returncode == 0 and "usage" in proc.stdout.lower()


@pytest.mark.parametrize("argv", [["layouts", "--bogus"], [], ["map"],
                                  ["identify", "MB1", "x.csv"], ["derive", "--nope"]])
def test_usage_errors_are_one_line(argv):
    assert_clean_failure(run(*argv), "error")
