"""Cutter radius compensation in the forms posts write besides G41 / G42 -- LinuxCNC's dynamic
G41.1 / G42.1, Fanuc's 3-D G41.2-G41.6 / G42.2-G42.6 -- moves the tool off the written
positions: refused naming the line (acceptance run benchmarks/acceptance/nc_programs2)."""

import pytest

import volerr
from volerr.nc import gcode


@pytest.mark.parametrize("g", ["G41.1", "G42.1", "G41.2", "G42.2", "G41.6", "g42.6"])
def test_cutter_compensation_forms_are_refused(g):
    text = f"G0 X300. Y400. Z150.\nG1 Z100. F500.\n{g} D10. X320.\nY420.\n"
    with pytest.raises(volerr.errors.InputError,
                       match=rf"line 3: {g.upper()} cutter radius compensation"):
        gcode.blocks(gcode.parse(text), ("X", "Y", "Z"))
