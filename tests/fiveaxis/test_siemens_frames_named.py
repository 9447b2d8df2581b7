"""SINUMERIK frame instructions (TRANS ATRANS ROT AROT SCALE ASCALE MIRROR AMIRROR) and SUPA
change which machine position a word means: refused naming the instruction (acceptance run
benchmarks/acceptance/nc_programs2)."""

import pytest

import volerr
from volerr.nc import gcode


@pytest.mark.parametrize("line,name", [
    ("TRANS X10 Y20", "TRANS frame"), ("ATRANS X10", "ATRANS frame"), ("ROT Z30", "ROT frame"),
    ("AROT RPL=30", "AROT frame"), ("SCALE X2 Y2", "SCALE frame"), ("ASCALE X2", "ASCALE frame"),
    ("MIRROR X0", "MIRROR frame"), ("amirror y0", "AMIRROR frame"),
    ("SUPA G0 Z550", "SUPA machine coordinates"), ("N20 G0 TRANS X1", "TRANS frame"),
])
def test_frames_are_refused_naming_the_instruction(line, name):
    with pytest.raises(volerr.errors.InputError, match=f"line 2: SINUMERIK {name}"):
        gcode.blocks(gcode.parse(f"G0 X300 Y400 Z150\n{line}\nG1 X350 F500\n"),
                     ("X", "Y", "Z"))


def test_traori_is_still_a_keyword():
    assert gcode.tokenize("TRAORI")[0].kind == "keyword"
