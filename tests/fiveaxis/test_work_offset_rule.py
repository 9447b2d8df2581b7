"""The work-offset rule of the G-code subset: the program's numbers are the machine axis
positions (every work offset zero), so G53 words and work-offset words are compensated alike;
G92.3 (restores G92 offsets saved before the program, unknown to it) is refused, G92.1 / G92.2
pass (acceptance run benchmarks/acceptance/nc_programs2)."""

import pytest
from helpers.error_dirs import write_errors

import volerr
from volerr.fiveaxis.program import compensate_program
from volerr.nc import gcode
from volerr.tables.functions import ErrorFunctions

AXES = ("X", "Y", "Z")


def test_g92_3_restore_of_saved_offsets_is_refused():
    with pytest.raises(volerr.errors.InputError, match="line 2: G92.3 restore of saved G92"):
        gcode.blocks(gcode.parse("G21 G90\nG92.3\nG0 X300. Y400. Z150.\n"), AXES)


def test_g92_1_and_g92_2_keep_the_positions_as_written():
    text = "G92.1\nG0 X300. Y400. Z150.\nG92.2\nG1 X350. F500.\n"
    blocks = gcode.blocks(gcode.parse(text), AXES)
    assert [b.target for b in blocks] == [{"X": 300.0, "Y": 400.0, "Z": 150.0},
                                          {"X": 350.0, "Y": 400.0, "Z": 150.0}]


def test_g53_and_work_offset_words_are_compensated_alike(tmp_path):
    """The same positions written under G53, G55, G59.1 and Fanuc G54.1 P1 get the same
    numbers as without them (the rule: every offset zero)."""
    m = volerr.load("FB2")
    funcs = ErrorFunctions.from_dir(write_errors(tmp_path / "err", m), m)
    plain = "G0 X300. Y400. Z150.\nG1 Z100. F500.\nX350.\nY450.\n"
    marked = "G53 G0 X300. Y400. Z150.\nG55 G1 Z100. F500.\nG59.1 X350.\nG54.1 P1 Y450.\n"
    out_plain = compensate_program(m, funcs, plain).text.splitlines()
    out_marked = compensate_program(m, funcs, marked).text.splitlines()
    strip = ("G53 ", "G55 ", "G59.1 ", "G54.1 P1 ")
    for a, b, s in zip(out_plain, out_marked, strip):
        assert b == s + a
