"""Issue 42 item 4 (branch cli-b): what the commands calibrate, check, plan, identify, loop,
ballbar and simulate did themselves is the API's now -- the same refusals, the same text, the
same extra outputs, for a Python user as for the command."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import volerr
from volerr.cli import main
from volerr.errors import InputError
from volerr.example_files import shipped_path

pytestmark = pytest.mark.xdist_group("api_examples")

SPHERE = str(shipped_path("sphere_example_DMU50.csv"))
TRACKER_X = str(shipped_path("tracker_example_X.csv"))


@pytest.fixture(scope="module")
def cal():
    return volerr.calibrate("DMU50", SPHERE)


def test_calibrate_summary_names_the_accepted_changes(cal):
    """A reference whose EX0C lies 10 um from today's value, a limit of 1 um, the change
    accepted: the summary (what the command prints) ends with the change, old -> new."""
    ref = cal.to_dict()
    old = ref["parameters"]["EX0C"]["value"] + 10.0
    ref["parameters"]["EX0C"] = {**ref["parameters"]["EX0C"], "value": old}
    again = volerr.calibrate("DMU50", SPHERE, reference=ref, max_change="EX0C=1 um",
                             accept_change=True)
    new = cal.to_dict()["parameters"]["EX0C"]["value"]
    last = again.summary().splitlines()[-1]
    assert last == ("  changes beyond --max-change, accepted (--accept-change): "
                    f"EX0C {old:.4g} -> {new:.4g} um")
    assert "beyond --max-change" not in cal.summary()
    with pytest.raises(InputError):
        volerr.calibrate("DMU50", SPHERE, reference=ref, max_change="EX0C=1 um")


def test_calibrate_write_map_grid_checked_and_counted(cal, tmp_path):
    with pytest.raises(InputError, match=r"^--map-grid must be between 2 and 60$"):
        cal.write_map(tmp_path / "m.csv", grid=1)
    assert not (tmp_path / "m.csv").exists()
    cal.write_map(tmp_path / "m.csv", grid=3)
    rows = [ln for ln in (tmp_path / "m.csv").read_text().splitlines()
            if ln and not ln.startswith("#")]
    assert rows[0].startswith("X,Y,Z,")
    assert len(rows) - 1 == 3 ** 3          # 3 points along each of the three linear axes


@pytest.mark.parametrize("kwargs, message", [
    ({"readings": 0}, "--readings must be between 1 and 10000000"),
    ({"readings": 10, "minutes": -1.0}, "--minutes must be positive"),
    ({"readings": 10, "parameters": " "}, "--parameters: empty; give names, axes or groups"),
])
def test_plan_refuses_as_the_command(kwargs, message):
    n = kwargs.pop("readings")
    with pytest.raises(InputError) as e:
        volerr.plan("MB1", "ballbar", n, **kwargs)
    assert str(e.value) == message


def test_plan_folder_check(tmp_path):
    from volerr.plan.api import check_plan_folder, check_options

    with pytest.raises(InputError, match="--dialect bogus: not a dialect; give one of iso"):
        check_options(10, dialect="bogus")
    check_plan_folder(tmp_path / "new")                       # a folder still to be made
    (tmp_path / "b.nc").write_text("")
    (tmp_path / "a.csv").write_text("")
    with pytest.raises(InputError) as e:
        check_plan_folder(tmp_path)
    assert str(e.value) == (f"--out {tmp_path}: holds a.csv already; give --force to replace "
                            f"plan files there, or another folder")
    check_plan_folder(tmp_path, force=True)
    with pytest.raises(InputError, match="a file, not a folder"):
        check_plan_folder(tmp_path / "a.csv")


@pytest.mark.parametrize("kwargs, message", [
    ({"specs": []}, "check plan: give at least one --instrument"),
    ({"readings": 0}, "--readings must be between 1 and 100000"),
    ({"minutes": 0.0}, "--minutes must be positive"),
    ({"detect_um": -5.0}, "--detect-um must be positive"),
])
def test_check_plan_refuses_as_the_command(kwargs, message, tmp_path):
    from volerr.check import plan_check

    specs = kwargs.pop("specs", ["sphere"])
    with pytest.raises(InputError) as e:       # before the reference is read
        plan_check("DMU50", tmp_path / "missing.json", specs, **kwargs)
    assert str(e.value) == message


def test_identify_fit_is_the_commands_json_and_text(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    capsys.readouterr()
    assert main(["identify", "MB1", "--axis", "X", TRACKER_X, "--out", "X.csv", "--fit",
                 "poly", "--json", "id.json", "--residuals", "r.csv"]) == 0
    printed = capsys.readouterr().out
    r = volerr.identify("MB1", "X", TRACKER_X, fit="poly")
    doc = json.loads(Path("id.json").read_text())
    doc.pop("identification", None)
    assert r.to_dict() == doc
    names = [f["name"] for f in doc["fit"]]
    assert sorted(names) == sorted(r.errors.values)       # one fit per error motion
    assert r.summary("X.csv") + "\n" == printed
    assert sum(ln.startswith("fit ") for ln in printed.splitlines()) == len(names)
    r.write_residuals(tmp_path / "api_r.csv")
    assert (tmp_path / "api_r.csv").read_text() == Path("r.csv").read_text()
    r.write_table(tmp_path / "api_X.csv")
    assert (tmp_path / "api_X.csv").read_text() == Path("X.csv").read_text()
    assert "fit" not in volerr.identify("MB1", "X", TRACKER_X).to_dict()


def test_ballbar_simulated_trace_checks_and_summary(tmp_path):
    from volerr.cmm.examples import write_example_errors
    from volerr.instruments.ballbar import parse_rotary, simulated_trace
    from volerr.machine.model import load
    from volerr.tables.functions import ErrorFunctions

    assert parse_rotary("b=0, C=0:360") == {"B": 0.0, "C": (0.0, 360.0)}
    with pytest.raises(InputError, match=r"^--rotary 'C=x': not a number$"):
        parse_rotary("C=x")
    model = load("MB1")
    write_example_errors(tmp_path / "e", "MB1")
    funcs = ErrorFunctions.from_dir(tmp_path / "e", model)
    for kw, opt in [({"radius": 0.0}, "--radius"), ({"points": 7}, "--points"),
                    ({"noise_um": -1.0}, "--noise-um")]:
        args = {"radius": 100.0, "points": 40, "noise_um": 0.0, **kw}
        with pytest.raises(InputError, match=f"^{opt}"):
            simulated_trace(model, funcs, "XY", args.pop("radius"), (200, 200, 200), **args)
    t = simulated_trace(model, funcs, "XY", 100.0, (200, 200, 200), points=40)
    dr = np.asarray(t.columns["dr_um"])
    assert len(dr) == 80                                   # both directions
    assert t.summary("t.csv") == (f"MB1: ballbar trace XY, radius 100 mm, 80 readings -> t.csv "
                                  f"(dr {dr.min():.3f} .. {dr.max():.3f} um)")


def test_simulate_refuses_options_the_instrument_does_not_use():
    from volerr.instruments.simulated_files import refuse_unused

    refuse_unused("deviations", {"probe": [(0, 0, -100)], "rounds": 2, "effect": ["x"]})
    refuse_unused("sphere", {"probe": None, "rounds": 1, "effect": [], "steps": 3})
    for instrument, options, message in [
            ("sphere", {"probe": [(0, 0, 1)]}, "--probe is for --instrument deviations"),
            ("ballbar", {"magnitude_um": 2.0}, "--magnitude-um is for --instrument deviations"),
            ("ballbar", {"steps": 3}, "--steps is for --instrument sphere"),
            ("deviations", {"plant": "EC0Y=3"}, "--plant is for --instrument sphere / ballbar"),
            ("sphere", {"radius": 50.0}, "--radius is for --instrument ballbar")]:
        with pytest.raises(InputError) as e:
            refuse_unused(instrument, options)
        assert str(e.value) == message


def test_loop_written_in_is_a_new_result():
    from volerr.loop.api import Loop

    r = Loop({"augmented_layout": "/stage/x/MB1_aug.toml", "generated_module": "", "n": 1})
    moved = r.written_in("out")
    assert moved.data["augmented_layout"] == str(Path("out") / "MB1_aug.toml")
    assert moved.data["generated_module"] == ""             # not written: stays empty
    assert r.data["augmented_layout"] == "/stage/x/MB1_aug.toml"      # not changed
