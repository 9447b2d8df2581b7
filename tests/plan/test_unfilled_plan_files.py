"""A plan's files given before their readings are filled in (journey pass, 2026-12-07): the
manual's interim-check steps run ``volerr check plan ... --out chk`` and then ``volerr check
... chk/*.csv``; a user who skips the measuring got "row 77 repeats row 62 in every column (a
file or a block pasted twice?)" from check and "column dr_um is not numeric" from calibrate
and loop.  Now one line naming the empty reading column and the likely cause."""

from __future__ import annotations

from pathlib import Path

import pytest

from helpers import plan_designs
from volerr.cli import main
from volerr.example_files import shipped_path

# the module fixture once, on one xdist worker; the group of tests/api/test_api.py and
# tests/cli/test_readme_commands.py, whose commands plan the same MB1 ballbar plan (one design
# per process: helpers.plan_designs)
pytestmark = pytest.mark.xdist_group("api_examples")


@pytest.fixture(scope="module")
def planned(tmp_path_factory):
    d = tmp_path_factory.mktemp("planned")
    assert main(["calibrate", "DMU50", str(shipped_path("sphere_example_DMU50.csv")),
                 "--json", str(d / "cal.json")]) == 0
    assert main(["check", "plan", "DMU50", "--reference", str(d / "cal.json"), "--instrument",
                 "sphere:u_um=0.5", "--out", str(d / "chk")]) == 0
    with plan_designs.designed_once():
        assert main(["plan", "MB1", "--instrument", "ballbar", "--readings", "200", "--out",
                     str(d / "plan")]) == 0
    return d


def _one_line(capsys, code):
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def test_check_on_an_unfilled_check_plan(planned, capsys):
    capsys.readouterr()
    code = main(["check", "DMU50", "--reference", str(planned / "cal.json"),
                 str(planned / "chk" / "sphere.csv")])
    line = _one_line(capsys, code)
    assert "column dx_um is empty in every row" in line and "not filled in" in line, line
    assert "repeats row" not in line


@pytest.mark.parametrize("command", ["calibrate", "loop"])
def test_calibrate_and_loop_on_an_unfilled_plan(planned, capsys, command):
    files = sorted(str(p) for p in Path(planned / "plan").glob("*.csv"))
    capsys.readouterr()
    code = main([command, "MB1", *files])
    line = _one_line(capsys, code)
    assert "column dr_um is empty in every row" in line and "not filled in" in line, line
