"""Every command of the README's command table runs in its shortest form -- its required
arguments only -- on the example files (``volerr examples``): exit 0, no traceback (issue 32,
item 4).  The table is read from README.md, so a command added there without a case here
fails the test.  The table moved from README.md into the manual's ``docs/commands.md`` (issue 38)."""

from __future__ import annotations

import contextlib
import re
from pathlib import Path

import pytest

from helpers import plan_designs
from volerr.cli import main

# the module fixtures once, on one xdist worker (not once per worker); the group of
# tests/api/test_api.py, whose command plans the shortest plan's design (helpers.plan_designs)
pytestmark = pytest.mark.xdist_group("api_examples")

#: the command table lives in the manual's page of every command (the README links it)
README = Path(__file__).resolve().parents[2] / "docs" / "commands.md"

#: command -> the required arguments (paths relative to the examples folder); None: not run
SHORTEST = {
    "layouts": [],
    "derive": ["MB1"],                     # into ./generated of the (temporary) folder
    "formats": [],
    "audit": ["MB1"],                      # no argument audits every document (25 s): one
    "map": ["MB1", "--errors", "errors_MB1"],
    "diagonals": ["MB1", "--errors", "errors_MB1"],
    "identify": ["MB1", "--axis", "X", "tracker_example_X.csv", "--errors-out", "id_X"],
    "squareness": ["MB1", "identified", "--errors-out", "square"],
    "probe-cal": ["probe_sphere.csv", "--sphere-radius", "25.006", "--out", "probe_map.csv"],
    "compensate": ["DMU50", "--errors", "dmu50/errors", "dmu50/hemisphere.nc", "--out",
                   "hemisphere_out.nc"],
    "tcpmap": ["DMU50", "--errors", "dmu50/errors", "--point", "30", "20", "60", "--plot",
               "tcpmap.png"],
    "controller export": ["DMU50", "--errors", "dmu50/errors", "--format", "isg", "--out",
                          "dmu50.isg.csv"],
    "controller import": ["DMU50", "dmu50.isg.csv", "--errors-out", "imported"],
    "calibrate": ["DMU50", "sphere_example_DMU50.csv"],
    "ballbar simulate": ["MB1", "--errors", "errors_MB1", "--plane", "XY", "--radius", "100",
                         "--centre", "450,287.5,200", "--out", "trace.csv"],
    "ballbar evaluate": ["ballbar_example_XY.csv"],
    "simulate": ["MB1", "--out", "simulated.csv"],
    "loop": ["MB1", "deviations_MB1.csv"],
    "iso230-2": ["iso230_2_run_X.csv"],
    "iso230-3": ["drift_spindle.csv"],
    "drift convert": ["drift_logger_raw.csv", "--out", "drift.csv"],
    "check plan": None,                    # tests/check and tests/history run them
    "check": None,
    "history add": None,
    "history show": None,
    "uncertainty": ["MH2", "--task", "task_distance.csv", "--evaluate", "distance",
                    "--noise-um", "0.5"],
    "iso10360": ["MB1", "--errors", "errors_MB1"],
    "demo": None,                          # tests/cli/test_demo.py runs it
    "examples": ["--out", "more_examples"],
    "plan": ["MB1", "--instrument", "ballbar", "--readings", "200", "--out", "plan_MB1"],
}


def readme_commands() -> list:
    """The commands of the first table under '## Commands' ('controller export|import' is
    two)."""
    text = README.read_text(encoding="utf-8").split("\n## Commands", 1)[1]
    rows = re.findall(r"^\| `volerr ([^`]*)` \|", text.split("\n## ", 1)[0], re.M)
    out = []
    for row in rows:
        words = []
        for w in row.split():
            if not re.fullmatch(r"[a-z][a-z0-9\-]*(\\\|[a-z\-]+)*", w):
                break
            words.append(w)
        name = " ".join(words)
        if "\\|" in name:
            head, alts = name.rsplit(" ", 1) if " " in name else ("", name)
            out += [f"{head} {a}".strip() for a in alts.split("\\|")]
        else:
            out.append(name)
    return out


def test_every_readme_command_has_a_case():
    names = readme_commands()
    assert len(names) >= 20
    assert sorted(names) == sorted(SHORTEST)


@pytest.fixture(scope="module")
def examples(tmp_path_factory):
    d = tmp_path_factory.mktemp("readme") / "ex"
    assert main(["examples", "--out", str(d)]) == 0
    for axis in "XYZ":                    # squareness reads an identified X, Y, Z
        assert main(["identify", "MB1", "--axis", axis, str(d / f"tracker_example_{axis}.csv"),
                     "--errors-out", str(d / "identified")]) == 0
    return d


@pytest.mark.parametrize("command", [c for c, v in SHORTEST.items() if v is not None])
def test_shortest_form_runs(examples, command, monkeypatch, capsys):
    monkeypatch.chdir(examples)
    if command == "controller import" and not (examples / "dmu50.isg.csv").exists():
        assert main(["controller", "export", *SHORTEST["controller export"]]) == 0
    # the plan: the design test_api's command made for the same request in this process
    with plan_designs.designed_once() if command == "plan" else contextlib.nullcontext():
        code = main([*command.split(), *SHORTEST[command]])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "Traceback" not in captured.err + captured.out
