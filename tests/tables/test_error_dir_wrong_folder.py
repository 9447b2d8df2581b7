"""``--errors`` naming the folder above the error directory (journey pass, 2026-12-07):
``volerr compensate DMU50 --errors dmu50 dmu50/hemisphere.nc --out o.nc`` in the examples
folder read ``dmu50`` (holding ``errors/`` and the program) as an error directory without
tables, i.e. a machine without errors, and wrote the program unchanged with "181 of 181
motion blocks compensated ... max 0.000 -> 0.000 um", exit 0.  A folder that holds other
things but no table and no constants.csv is refused naming what it holds; an empty folder
stays a machine without errors (a missing table means zero errors, formats.md)."""

from __future__ import annotations

import pytest

from volerr.cli import main


@pytest.fixture(scope="module")
def examples(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ex")
    assert main(["examples", "--out", str(folder / "ex")]) == 0
    return folder / "ex"


def _one_line(capsys, code):
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def test_compensate_with_the_folder_above_the_tables(examples, monkeypatch, capsys):
    monkeypatch.chdir(examples)
    capsys.readouterr()
    code = main(["compensate", "DMU50", "--errors", "dmu50", "dmu50/hemisphere.nc", "--out",
                 "o.nc"])
    line = _one_line(capsys, code)
    assert "no error table" in line and "dmu50/errors?" in line, line
    assert not (examples / "o.nc").exists()


@pytest.mark.parametrize("command", [["map", "MB1"], ["iso10360", "MB1"]])
def test_a_folder_of_programs_and_plots_is_no_error_directory(examples, tmp_path, capsys,
                                                               command):
    d = tmp_path / "results"
    d.mkdir()
    (d / "map.png").write_bytes(b"png")
    (d / "part.nc").write_text("G0 X0\n")
    capsys.readouterr()
    line = _one_line(capsys, main([*command, "--errors", str(d)]))
    assert "no error table" in line and "not an error directory" in line, line


def test_an_empty_folder_is_still_a_machine_without_errors(tmp_path, capsys):
    (tmp_path / "none").mkdir()
    assert main(["map", "MB1", "--errors", str(tmp_path / "none")]) == 0
    assert "max |d| 0.00 um" in capsys.readouterr().out


def test_constants_alone_are_an_error_directory(tmp_path, capsys):
    d = tmp_path / "c"
    d.mkdir()
    (d / "constants.csv").write_text("name,value,unit\nEC0Y,20,urad\n")
    (d / "notes.txt").write_text("squareness from the ballbar\n")
    assert main(["map", "MB1", "--errors", str(d)]) == 0, capsys.readouterr().err
