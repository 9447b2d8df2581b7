"""A laser-tracker file given to ``calibrate`` / ``loop`` (hostile-input acceptance, RULE.md in
benchmarks/acceptance/hostile_inputs, case b2_tracker_to_calibrate): its ``position`` column
made it an interferometer run, refused asking for an ``# axis`` header line (the wrong
mistake).  Now the line names tracker data and ``volerr identify``; an interferometer run
with a ``position`` column is still detected as one."""

import pytest

from volerr.errors import InputError
from volerr.instruments import detect


def test_tracker_file_named(tmp_path):
    f = tmp_path / "t.csv"
    f.write_text("round,point,position,x,y,z\n1,P,0,80,0,-120\n1,Q,0,0,80,-120\n")
    with pytest.raises(InputError) as e:
        detect(f)
    assert "laser-tracker three-point data" in str(e.value)
    assert "volerr identify" in str(e.value)


def test_interferometer_run_still_detected(tmp_path):
    f = tmp_path / "r.csv"
    f.write_text("# axis: X\nposition,cycle,direction,deviation_um\n0,1,+1,0.5\n")
    assert detect(f) == "interferometer"
