"""Table positions in the other usual unit (hostile-input acceptance, RULE.md in
benchmarks/acceptance/hostile_inputs): a rotary table in radians (C 0 .. 6.28 of a
-360 .. 360 deg axis) and a linear table in inches (X 0 .. 35.4 of a 900 mm axis) were read
as degrees and millimetres (the rotary one closed over the turn and used); both are refused
naming the unit, while a table over the travel and ``--accept-implausible`` pass."""

import math

import pytest

import volerr
from volerr.errors import InputError
from volerr.tables.table import read_error_dir


def _table(d, axis, positions, name):
    d.mkdir(exist_ok=True)
    rows = [f"{axis},{name}"] + [f"{p!r},{v}" for p, v in zip(positions, (0, 1.5, -2.0, 3.1, 0.7))]
    (d / f"{axis}.csv").write_text("\n".join(rows) + "\n")
    return d


def test_rotary_table_in_radians_refused(tmp_path):
    deg = [0, 90, 180, 270, 360]
    model = volerr.load("DMU50")
    read_error_dir(_table(tmp_path / "ok", "C", deg, "EXC_um"), machine=model)
    bad = _table(tmp_path / "rad", "C", [math.radians(x) for x in deg], "EXC_um")
    with pytest.raises(InputError) as e:
        read_error_dir(bad, machine=model)
    line = str(e.value)
    assert "\n" not in line and "C.csv" in line and "likely radians" in line
    read_error_dir(bad, machine=model, accept_implausible=True)


def test_linear_table_in_inches_refused(tmp_path):
    mm = [0, 225, 450, 675, 900]
    model = volerr.load("MB1")
    read_error_dir(_table(tmp_path / "ok", "X", mm, "EXX_um"), machine=model)
    bad = _table(tmp_path / "in", "X", [x / 25.4 for x in mm], "EXX_um")
    with pytest.raises(InputError) as e:
        read_error_dir(bad, machine=model)
    assert "likely inches, not mm" in str(e.value)


def test_a_short_table_unexplained_by_a_unit_passes(tmp_path):
    """0 .. 60 mm of MB1's 900 mm X: in inches 1524 mm, beyond the travel: not a unit."""
    read_error_dir(_table(tmp_path / "s", "X", [0, 15, 30, 45, 60], "EXX_um"),
                   machine=volerr.load("MB1"))
