"""``compensate --datum``: compensation relative to the work datum (issue 32, item 9).

A part set up by probing: the controller's work offset is set where the probe touched the part
zero, at the axis positions ``q_d``, so it has absorbed the tool-tip error there, ``e(q_d)``.
A compensated program must then land on the part's nominal points, i.e. the nominal tool tips
shifted by that same ``e(q_d)``.  Checked on an independent machine: the exact chain of
``tests/helpers/instrument_sim.py`` (never volerr's model) with error functions written here,
the program's blocks read by the independent controller ``tests/helpers/nc_sim.py``."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from tests.helpers import nc_sim
from tests.helpers.instrument_sim import Machine
from volerr.cli import main

AXES = ("X", "Y", "Z", "B", "C")
#: error functions of the linear axes: linear in the position (so that the tables' linear
#: interpolation is exact): name -> value at the travel's upper end (um or urad), zero at 0
SLOPES = {"X": {"EXX": 18.0, "EYX": -6.0, "EZX": 4.0, "EAX": 12.0, "EBX": -20.0, "ECX": 15.0},
          "Y": {"EXY": 5.0, "EYY": -14.0, "EZY": 3.0, "EAY": -10.0, "EBY": 8.0, "ECY": 6.0},
          "Z": {"EXZ": -4.0, "EYZ": 7.0, "EZZ": 11.0, "EAZ": 9.0, "EBZ": -7.0, "ECZ": 5.0}}
#: constant errors: squareness (urad) and location errors of the rotary axes (um / urad)
CONSTANTS = {"EC0Y": -23.0, "EB0Z": 36.0, "EA0Z": 10.0, "EX0B": -10.0, "EY0B": -6.0,
             "EA0B": -35.0, "EB0B": -17.0, "EX0C": 8.0, "EY0C": -10.0, "EA0C": 36.0,
             "EB0C": 31.0}
DATUM = (20.0, -10.0, 150.0, 0.0, 0.0)


def _unit(name):
    return "urad" if name[1] in "ABC" else "um"


def _si(name):
    """um -> mm, urad -> rad."""
    return 1e-6 if _unit(name) == "urad" else 1e-3


def _errors(m: Machine, pos: dict) -> dict:
    """The planted errors at positions (dict of (N,) arrays), mm / rad."""
    out = {}
    for axis, comps in SLOPES.items():
        hi = m.travel[axis][1]
        for name, v in comps.items():
            out[name] = _si(name) * v * np.asarray(pos[axis], float) / hi
    for name, v in CONSTANTS.items():
        out[name] = _si(name) * v
    return out


def _write_error_dir(d, m: Machine):
    d.mkdir()
    for axis, comps in SLOPES.items():
        lo, hi = m.travel[axis]
        grid = np.linspace(lo, hi, 11)
        errs = _errors(m, {a: grid if a == axis else np.zeros_like(grid) for a in AXES})
        with open(d / f"{axis}.csv", "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow([axis] + [f"{n}_{_unit(n)}" for n in comps])
            for i, q in enumerate(grid):
                w.writerow([f"{q:g}"] + [f"{errs[n][i] / _si(n):.9f}" for n in comps])
    with open(d / "constants.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["name", "value", "unit"])
        for n, v in CONSTANTS.items():
            w.writerow([n, f"{v:g}", _unit(n)])


def _program(rng, m: Machine, n=16) -> str:
    lines = ["%", "O1000 (datum test)", "G90 G21 G17"]
    for k in range(n):
        q = [rng.uniform(*(np.array(m.travel[a]) * (0.8 if a in "XY" else 1.0)))
             for a in "XY"] + [rng.uniform(60, 340), rng.uniform(5, 80), rng.uniform(-170, 170)]
        words = " ".join(f"{a}{v:.4f}" for a, v in zip(AXES, q))
        lines.append(f"N{10 * (k + 1)} G1 {words} F1000")
    return "\n".join(lines + ["M30", "%"]) + "\n"


def _block_ends(text: str) -> np.ndarray:
    """End positions (n_blocks, 5) of the motion blocks, read by the independent controller."""
    start = {a: 0.0 for a in AXES}     # the position before the program: any
    return np.array([[mv.end[a] for a in AXES]
                     for mv in nc_sim.moves(text, list(AXES), initial=start)])


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    d = tmp_path_factory.mktemp("datum")
    m = Machine("DMU50")
    _write_error_dir(d / "errors", m)
    prog = d / "part.nc"
    prog.write_text(_program(np.random.default_rng(7), m))
    return d, m, prog


def _compensate(d, prog, name, *extra):
    out, report = d / f"{name}.nc", d / f"{name}.csv"
    code = main(["compensate", "DMU50", "--errors", str(d / "errors"), str(prog), "--out",
                 str(out), "--report", str(report), "--json", str(d / f"{name}.json"), *extra])
    assert code == 0
    rows = list(csv.DictReader(report.read_text().splitlines()))
    return out.read_text(), rows, json.loads((d / f"{name}.json").read_text())


def _landing(m: Machine, q: np.ndarray) -> np.ndarray:
    pos = {a: q[:, i] for i, a in enumerate(AXES)}
    return m.tool_point(pos, _errors(m, pos))


def test_probed_part_lands_on_its_nominal_points(setup, capsys):
    d, m, prog = setup
    text, rows, doc = _compensate(d, prog, "datum", "--datum", ",".join(map(str, DATUM)))
    q_nom, q_out = _block_ends(prog.read_text()), _block_ends(text)
    assert len(q_nom) == len(q_out) == 16
    # the work offset, set by probing the part zero at the datum, absorbs the error there
    qd = np.array([DATUM])
    shift = _landing(m, qd)[0] - m.tool_point({a: qd[:, i] for i, a in enumerate(AXES)})[0]
    assert np.linalg.norm(shift) > 10e-3                 # a shift that matters (> 10 um)
    target = m.tool_point({a: q_nom[:, i] for i, a in enumerate(AXES)}) + shift
    miss_um = 1e3 * np.linalg.norm(_landing(m, q_out) - target, axis=1)
    residual_um = np.array([float(r["e_after_um"]) for r in rows])
    assert np.all(miss_um <= residual_um + 0.05), (miss_um, residual_um)
    assert miss_um.max() < 0.2
    # the datum's error is reported: JSON, report comment line, console
    assert np.allclose(doc["datum"]["error_um"], 1e3 * shift, atol=1e-3)
    for r in rows:
        got = [float(r[f"{c}_datum_um"]) for c in ("dx", "dy", "dz")]
        assert np.allclose(got, 1e3 * shift, atol=1e-3)
    assert "datum X=20" in capsys.readouterr().out


def test_without_datum_a_probed_part_is_compensated_twice(setup, capsys):
    """The default (no datum) compensates the full error: on a probed part every block misses
    by the datum's error; on a part placed by the machine's reference it lands."""
    d, m, prog = setup
    text, rows, doc = _compensate(d, prog, "absolute")
    assert doc["datum"] is None
    assert "dx_datum_um" not in rows[0]             # the report as before
    assert "datum: none" in capsys.readouterr().out
    q_nom, q_out = _block_ends(prog.read_text()), _block_ends(text)
    nominal = m.tool_point({a: q_nom[:, i] for i, a in enumerate(AXES)})
    land = _landing(m, q_out)
    assert 1e3 * np.linalg.norm(land - nominal, axis=1).max() < 0.2
    qd = np.array([DATUM])
    shift = _landing(m, qd)[0] - m.tool_point({a: qd[:, i] for i, a in enumerate(AXES)})[0]
    miss = 1e3 * np.linalg.norm(land - (nominal + shift), axis=1)
    assert np.allclose(miss, 1e3 * np.linalg.norm(shift), atol=0.2)


@pytest.mark.parametrize("text, fragment", [("1,2", "give 3 to 5 numbers"),
                                            ("a,b,c", "not a list of numbers"),
                                            ("0,0,900", "outside the travel"),
                                            ("0,0,10,0,0,0", "give 3 to 5 numbers")])
def test_bad_datum_refused(setup, capsys, text, fragment):
    d, m, prog = setup
    code = main(["compensate", "DMU50", "--errors", str(d / "errors"), str(prog), "--out",
                 str(d / "bad.nc"), "--datum", text])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and fragment in err, err
    assert not (d / "bad.nc").exists()
