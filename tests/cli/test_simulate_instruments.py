"""``volerr simulate --instrument sphere|ballbar``: files of the layout's model with planted
errors (issue 32, item 8).  The readings are checked against the independent exact chain of
``tests/helpers/instrument_sim.py`` (never volerr's model), and ``calibrate`` on the file
finds what was planted."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from tests.helpers.instrument_sim import Machine
from volerr.cli import main


def _read(path):
    lines = [ln for ln in path.read_text().splitlines() if not ln.startswith("#")]
    rows = list(csv.DictReader(lines))
    return {k: np.array([r[k] for r in rows], dtype=object if k == "placement" else float)
            for k in rows[0]}


def _errors(m: Machine, planted: dict, pos: dict) -> dict:
    """Planted errors (report units) at the positions, mm / rad (slopes zero at mid-travel)."""
    out = {}
    for name, v in planted.items():
        base = name.split("@")[0]
        si = 1e-6 if base[1] in "ABC" else 1e-3
        if name.endswith("@slope"):
            lo, hi = m.travel[base[2]]
            out[base] = si * v * (np.asarray(pos[base[2]], float) - 0.5 * (lo + hi))
        else:
            out[base] = si * v
    return out


SPHERE = {"EX0B": 14.0, "EA0B": 30.0, "EX0C": -12.0, "EY0C": 9.0, "EA0C": 20.0, "EB0C": -25.0}


def test_sphere_file_holds_the_planted_errors(tmp_path, capsys):
    f = tmp_path / "s.csv"
    spec = ",".join(f"{k}={v:g}" for k, v in SPHERE.items())
    assert main(["simulate", "DMU50", "--instrument", "sphere", "--plant", spec,
                 "--noise-um", "0", "--out", str(f)]) == 0
    c = _read(f)
    m = Machine("DMU50")
    pos = {a: c[a] for a in m.axes}
    probe = (c["Xp"][0], c["Yp"][0], c["Zp"][0])
    actual = m.tool_point(pos, _errors(m, SPHERE, pos), probe)
    centre = np.column_stack([c["sphere_x"], c["sphere_y"], c["sphere_z"]])
    reading = 1e-3 * np.column_stack([c["dx_um"], c["dy_um"], c["dz_um"]])
    # reading = actual - (centre + the placement's unknown centre offset): constant per placement
    left = reading - (actual - centre)
    for p in set(c["placement"]):
        mine = left[c["placement"] == p]
        assert np.abs(mine - mine.mean(axis=0)).max() < 2e-5          # 0.02 um
        assert 1e-4 < np.linalg.norm(mine.mean(axis=0)) < 0.05           # a real sphere's
    assert len(set(c["placement"])) == 2 and len(c["X"]) > 50
    # the travel is kept and calibrate, with no options, finds what was planted
    for a in m.axes:
        lo, hi = m.travel[a]
        assert c[a].min() >= lo - 1e-9 and c[a].max() <= hi + 1e-9
    capsys.readouterr()
    assert main(["calibrate", "DMU50", str(f), "--json", str(tmp_path / "r.json")]) == 0
    rep = json.loads((tmp_path / "r.json").read_text())["parameters"]
    for name, v in SPHERE.items():
        if name in rep:
            assert abs(rep[name]["value"] - v) < 0.05, (name, rep[name])


BALLBAR = {"EC0Y": 25.0, "EB0Z": -15.0, "EA0Z": 10.0, "EXX@slope": 0.012, "EYY@slope": -0.008}


def test_ballbar_file_holds_the_planted_errors(tmp_path, capsys):
    f = tmp_path / "b.csv"
    spec = ",".join(f"{k}={v:g}" for k, v in BALLBAR.items())
    assert main(["simulate", "MB1", "--instrument", "ballbar", "--plant", spec,
                 "--noise-um", "0", "--radius", "120", "--out", str(f)]) == 0
    c = _read(f)
    m = Machine("MB1")
    pos = {a: c[a] for a in m.axes}
    actual = m.tool_point(pos, _errors(m, BALLBAR, pos), (0.0, 0.0, 0.0))
    pivot = np.column_stack([c["pivot_x"], c["pivot_y"], c["pivot_z"]])
    dr = np.linalg.norm(actual - pivot, axis=1) - c["length_mm"]
    assert np.abs(1e3 * dr - c["dr_um"]).max() < 0.01
    assert np.allclose(c["length_mm"], 120.0)
    assert sorted(set(c["placement"])) == ["XY", "YZ", "ZX"]
    assert sorted(set(c["direction"])) == [-1.0, 1.0]
    capsys.readouterr()
    assert main(["calibrate", "MB1", str(f), "--parameters", "EC0Y,EB0Z,EA0Z,EXX,EYY",
                 "--degree", "1", "--json", str(tmp_path / "r.json")]) == 0
    rep = json.loads((tmp_path / "r.json").read_text())["parameters"]
    for name in ("EC0Y", "EB0Z", "EA0Z"):
        assert abs(rep[name]["value"] - BALLBAR[name]) < 0.05


@pytest.mark.parametrize("argv, fragment", [
    (["MB1", "--instrument", "sphere"], "no rotary axis"),
    (["MB1", "--instrument", "ballbar", "--plant", "EXX=3"], "NAME@slope"),
    (["MB1", "--instrument", "ballbar", "--plant", "EQQ=3"], "not an error parameter"),
    (["MB1", "--instrument", "ballbar", "--plant", "EC0Y=x"], "not a number"),
    (["MB1", "--instrument", "ballbar", "--effect", "thermal:axis=X"], "--effect"),
    (["MB1", "--instrument", "ballbar", "--radius", "900"], "--radius"),
    (["DMU50", "--instrument", "sphere", "--errors", "nowhere"], "error directory"),
])
def test_bad_options_refused(tmp_path, capsys, argv, fragment):
    code = main(["simulate", *argv, "--out", str(tmp_path / "x.csv")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and fragment in err, err
    assert not (tmp_path / "x.csv").exists()


@pytest.mark.parametrize("argv, fragment", [
    (["MB1", "--plant", "EC0Y=3"], "--plant is for --instrument sphere / ballbar"),
    (["DMU50", "--instrument", "ballbar", "--steps", "3"], "--steps is for --instrument sphere"),
    (["DMU50", "--instrument", "sphere", "--radius", "50"], "--radius is for --instrument"),
])
def test_an_option_the_instrument_does_not_use_is_refused(tmp_path, capsys, argv, fragment):
    code = main(["simulate", *argv, "--out", str(tmp_path / "x.csv")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and fragment in err, err
