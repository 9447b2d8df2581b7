"""What post-processors of other controllers write (Fanuc, Haas, SINUMERIK, LinuxCNC lathes) and
changes what the axis words mean is refused naming the line, never compensated as plain
positions; a reference return without axis words makes every axis unknown (LinuxCNC and Haas
send all axes home) (acceptance run benchmarks/acceptance/nc_programs)."""

import pytest
from helpers.error_dirs import write_errors

import volerr
from volerr.fiveaxis.program import compensate_program
from volerr.nc import chunkscan, gcode
from volerr.tables.functions import ErrorFunctions

AXES = ("X", "Y", "Z", "B", "C")


@pytest.mark.parametrize("text,msg", [
    ("G16\nG1 X100. Y30.\n", "G16 polar"),
    ("G51.1 X0.\nG1 X350.\n", "G51.1 mirror"),
    ("G65 P9810 X320. Y320. Z120.\n", "G65 macro"),
    ("G66 P9000 X1.\n", "G66 modal macro"),
    ("G68.2 X0. Y0. Z0. I0. J30. K0.\n", "G68.2 tilted working plane"),
    ("G70 G90\nG1 X12.\n", "G70 inch"),
    ("G700\nG1 X12.\n", "G700 inch"),
    ("G90.1\nG2 X40. Y40. I40. J0.\n", "G90.1 absolute arc centres"),
    ("G7\nG1 X160.\n", "G7 lathe diameter"),
    ("G12 I10. Z-1. F100.\n", "G12 circle milling"),
    ("G75 X20. Z-5. P1. Q1.\n", "G75 grooving"),
    ("G1 X1.\nM97 P100\n", "M97 local subprogram"),
    ("G1 X1.\nM198 P100\n", "M198 subprogram"),
    ("G1 X0. Y0.\nG5 I0. J3. P0. Q-3. X1. Y1.\n", "G5 spline"),
    ("G1 X0. Y0.\nG5.1 X4. I2. J2.\n", "G5.1 spline"),
    ("G1 X0. Y0.\nG5.2 X0. Y1. P1. L3\n", "G5.2 spline"),
])
def test_constructs_that_change_axis_words_are_refused(text, msg):
    with pytest.raises(volerr.errors.InputError, match=msg):
        gcode.blocks(gcode.parse(text), AXES)


def test_refused_m_words_leave_the_whole_chunk_path():
    """A line ``M97 P100`` between plain lines is not a plain line (the interpreter refuses
    it): the whole-chunk scan hands every refused M function to the interpreter."""
    assert {97, 198, 98} <= gcode.SPECIAL_M
    text = "X1. Y2.\nM97 P100\nX3.\n"
    scan = chunkscan.scan(text.splitlines(keepends=True), ("X", "Y", "Z"))
    assert list(scan.fast) == [True, False, True]


def test_reference_return_without_axis_words_makes_every_axis_unknown(tmp_path):
    """``G28`` alone sends every axis to the reference: a later block naming X only is not
    compensated as if Y and Z were still where the program left them."""
    m = volerr.load("DMU50")
    funcs = ErrorFunctions.from_dir(write_errors(tmp_path / "err", m), m)
    text = "G0 X100. Y100. Z150. B0 C0\nG1 X120. F500.\nG28\nG1 X110.\nY50. Z100. B0 C0\n"
    res = compensate_program(m, funcs, text)
    status = [r.status for r in res.reports]
    assert status[:2] == ["compensated", "compensated"]
    assert status[2].startswith("not compensated: position of axis Y"), status
    assert status[3] == "compensated"
    assert res.text.splitlines()[3] == "G1 X110."


def test_arc_under_inverse_time_feed_is_refused():
    """Under G93 the F of a block is its time (1/min): an arc linearised into N lines would
    take N times as long, and rs274 refuses its G1 lines without F ("F word missing with
    inverse time g1 move"); straight moves under G93 and arcs after G94 stay."""
    with pytest.raises(volerr.errors.InputError, match="line 3: an arc .*G93 inverse-time"):
        gcode.blocks(gcode.parse("G0 X0 Y0 Z0\nG93\nG2 X40. Y40. I40. J0. F2.\n"), AXES)
    ok = "G0 X0 Y0 Z0\nG93\nG1 X10. F2.\nG94\nG2 X50. Y40. I40. J0. F500.\n"
    assert len(gcode.blocks(gcode.parse(ok), AXES)) == 3


def test_fanuc_machining_modes_g05_pass():
    """Fanuc's ``G05.1 Q1`` (AI contour control) and ``G05 P10000`` (high-speed machining)
    carry no axis words: modes, not moves; the moves after them are read as written."""
    steps = gcode.blocks(gcode.parse("G05.1 Q1\nG05 P10000\nG1 X10. Y5. F500.\n"), AXES)
    assert [(b.programmed, b.target["X"], b.target["Y"]) for b in steps] == \
        [(("X", "Y"), 10.0, 5.0)]
