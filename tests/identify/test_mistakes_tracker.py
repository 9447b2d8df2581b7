"""Tracker files with a technician's mistake: ``volerr identify`` refuses each (exit 2, one line
naming the file and the likely cause, nothing written).

The data come from the exact rigid-body simulator of the tests (helpers.tracker_sim, full
rotations, independent of volerr.identify); each mistake is then made to the file as a user
would: columns swapped, another unit, the file of another axis, points that do not move,
rotary positions in rad, error motions beyond what the machine can have.
"""

import numpy as np
import pytest
from helpers.tracker_sim import simulate, smooth_errors, to_csv

from volerr.cli import main

REF = np.array([[60.0, 10.0, -150.0], [-40.0, 50.0, -100.0], [10.0, -60.0, -200.0]])
POS = np.linspace(0, 500, 6)


def _rounds(direction=(1, 0, 0), errors=None, kind="linear", pos=POS, ref=REF, origin=(0, 0, 0)):
    e = smooth_errors(pos, seed=1) if errors is None else errors
    rng = np.random.default_rng(0)
    return [simulate(kind, ref, pos, e, direction=direction, origin=origin, noise_mm=0.0005,
                     rng=rng) for _ in range(2)]


def _run(tmp_path, capsys, rounds, axis="X", layout="MB1", pos=POS, extra=()):
    f = tmp_path / "tracker.csv"
    f.write_text(to_csv(rounds, pos, ("P", "Q", "K")))
    before = f.read_bytes()
    out = tmp_path / "out" / f"{axis}.csv"
    code = main(["identify", layout, "--axis", axis, str(f), "--errors-out",
                 str(tmp_path / "out"), *extra])
    err = capsys.readouterr().err
    assert f.read_bytes() == before
    return code, err, out


def _refused(tmp_path, capsys, rounds, *needles, **kw):
    code, err, out = _run(tmp_path, capsys, rounds, **kw)
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert "tracker.csv" in err
    for n in needles:
        assert n in err, (n, err)
    assert not out.exists()


def test_x_and_y_columns_swapped(tmp_path, capsys):
    R = [r[..., [1, 0, 2]] for r in _rounds()]
    _refused(tmp_path, capsys, R, "x and y columns swapped")


def test_coordinates_in_inches(tmp_path, capsys):
    R = [r / 25.4 for r in _rounds()]
    _refused(tmp_path, capsys, R, "coordinates in inches")


def test_coordinates_in_metres(tmp_path, capsys):
    R = [r / 1000.0 for r in _rounds()]
    _refused(tmp_path, capsys, R, "coordinates in m,")


def test_points_that_do_not_move(tmp_path, capsys):
    """Points on the fixed part (the table of a moving-bridge machine): only noise."""
    R = [np.broadcast_to(r[:1], r.shape).copy() for r in _rounds()]
    _refused(tmp_path, capsys, R, "hardly move")


def test_file_of_another_axis(tmp_path, capsys):
    """The Y run given as --axis X: the points move along y."""
    _refused(tmp_path, capsys, _rounds(direction=(0, 1, 0)), "a file of axis Y")


def test_rotary_positions_in_radians(tmp_path, capsys):
    """A C-axis run of the DMU50 whose position column holds radians."""
    deg = np.linspace(0.0, 150.0, 6)
    R = _rounds(direction=(0, 0, 1), kind="rotary", pos=deg,
                ref=np.array([[120.0, 0.0, 10.0], [-60.0, 100.0, 20.0], [-60.0, -100.0, 40.0]]))
    _refused(tmp_path, capsys, R, "positions in rad", axis="C", layout="DMU50",
             pos=np.radians(deg))


def test_identified_errors_beyond_the_machine(tmp_path, capsys):
    """A positioning error of 1.5 mm over 500 mm (within the nominal-motion check, beyond
    500 um + 500 ppm of MB1's 900 mm = 950 um): refused, and used with --accept-implausible."""
    e = smooth_errors(POS, seed=1)
    e[:, 0] = 1.5 * (POS / 500.0) ** 2
    R = _rounds(errors=e)
    _refused(tmp_path, capsys, R, "EXX_um", "950 um", "--accept-implausible")
    code, err, out = _run(tmp_path, capsys, R, extra=("--accept-implausible",))
    assert code == 0, err
    exx = np.loadtxt(out, delimiter=",", skiprows=1)[:, 1]
    assert exx[-1] == pytest.approx(1500.0, abs=5.0)


def test_a_good_file_still_passes(tmp_path, capsys):
    code, err, out = _run(tmp_path, capsys, _rounds())
    assert code == 0, err
    assert out.exists()


def test_one_stray_reading_named(tmp_path, capsys):
    """One coordinate mistyped by 5 m (every other reading follows the axis): the line names
    that reading -- its point and its position from the round's first -- instead of the
    general advice."""
    R = [r.copy() for r in _rounds()]
    R[0][3, 1, 0] += 5000.0                 # round 1, position 300 mm, the second point
    _refused(tmp_path, capsys, R, "one reading alone", "point 2 in file order at +300 mm",
             "stray measurement")


def test_positions_with_the_wrong_sign_named(tmp_path, capsys):
    """Positions written negated (0 .. -500 on MB1's X, travel 0 .. 900): outside the travel,
    and every one inside it negated -- the line names the sign."""
    _refused(tmp_path, capsys, _rounds(), "column position", "positions with the wrong sign",
             pos=-POS)


def test_positions_of_another_machine_not_called_a_sign(tmp_path, capsys):
    """Positions beyond the travel either way (1000 .. 1500 mm) are not called a sign."""
    code, err, out = _run(tmp_path, capsys, _rounds(), pos=POS + 1000.0)
    assert code == 2 and "another machine" in err and "wrong sign" not in err, err
    assert not out.exists()
