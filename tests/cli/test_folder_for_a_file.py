"""A folder given where a file is expected (journey pass, 2026-12-07): exit 2 and one line
saying it is a folder.  Before, the line called the existing folder missing ("data file not
found: d", "tracker file not found: d", "program not found: d", "d: no such file", "layout
file not found: d.toml", "--reference d: no such file"), which sends a user looking for a
file that is there."""

from __future__ import annotations

import pytest

from volerr.cli import main


@pytest.fixture(scope="module")
def examples(tmp_path_factory):
    folder = tmp_path_factory.mktemp("examples")
    assert main(["examples", "--out", str(folder / "ex")]) == 0
    (folder / "ex" / "d").mkdir()
    (folder / "ex" / "d.toml").mkdir()
    return folder / "ex"


CASES = {
    "calibrate": ["calibrate", "DMU50", "d"],
    "loop": ["loop", "MB1", "d"],
    "loop drift": ["loop", "DMU50", "drift:d"],
    "ballbar evaluate": ["ballbar", "evaluate", "d"],
    "iso230-2": ["iso230-2", "d"],
    "iso230-3": ["iso230-3", "d"],
    "drift convert": ["drift", "convert", "d", "--out", "x.csv"],
    "identify": ["identify", "MB1", "--axis", "X", "d", "--errors-out", "t"],
    "probe-cal": ["probe-cal", "d", "--sphere-radius", "25.006", "--out", "p.csv"],
    "compensate": ["compensate", "DMU50", "--errors", "dmu50/errors", "d", "--out", "o.nc"],
    "controller import": ["controller", "import", "DMU50", "d", "--errors-out", "imp"],
    "uncertainty": ["uncertainty", "MH2", "--task", "d", "--evaluate", "distance",
                    "--noise-um", "0.5"],
    "derive": ["derive", "d.toml"],
    "check": ["check", "DMU50", "--reference", "d", "sphere_example_DMU50.csv"],
    "identification": ["calibrate", "DMU50", "sphere_example_DMU50.csv", "--identification",
                       "d"],
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_a_folder_is_named_a_folder(name, examples, monkeypatch, capsys):
    monkeypatch.chdir(examples)
    capsys.readouterr()
    code = main(CASES[name])
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2, err
    assert len(lines) == 1 and "Traceback" not in err, err
    assert "is a folder, not a file" in lines[0], lines[0]
    assert "not found" not in lines[0] and "no such file" not in lines[0], lines[0]
