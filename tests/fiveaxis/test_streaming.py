"""Compensation streamed in chunks: the output does not depend on the chunk size, also where
modal state (G91, unknown axes after G28, the last written value an added word refers to)
crosses a chunk boundary; the command streams the same bytes to its file."""


import numpy as np
import pytest
from helpers import in_process
from helpers.error_dirs import write_errors

import volerr
from volerr.nc import gcode
from volerr.fiveaxis.program import compensate_program
from volerr.tables.functions import ErrorFunctions

#: an O number with decimal-less numbers: the reading (mm) stated, ``decimal_less="mm"``
PROGRAM = """%
O0001 (STREAM)
G90 G1 X10 Y20 Z100 B10 C5 F500
X12.5 Y-3
G91 X1.25
Y-0.5 Z0.25 (incremental across a boundary)
X0.001
G90
G28 Z0
X30 Y30
Z120.5 B12.5
x31.5y30.25
G4 X2
Y+40.125 ; plus sign kept
G91
C1.5
B-0.25 X0.1
G90 X0 Y0 Z150 B20 C30
"""


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    m = volerr.load("DMU50")
    d = write_errors(tmp_path_factory.mktemp("err"), m, seed=3)
    return m, ErrorFunctions.from_dir(d, m), d


@pytest.mark.parametrize("orientation", [False, True])
def test_chunked_output_equals_unchunked(setup, orientation):
    m, funcs, _ = setup
    whole = compensate_program(m, funcs, PROGRAM, orientation=orientation,
                               decimal_less="mm")
    assert whole.text != PROGRAM                                # something was compensated
    assert any(r.status.startswith("not compensated") for r in whole.reports)  # after G28
    for k in (1, 2, 3, 5, 7):
        part = compensate_program(m, funcs, PROGRAM, orientation=orientation, chunk_lines=k,
                                  decimal_less="mm")
        assert part.text == whole.text, k
        assert [(r.line, r.status, r.output) for r in part.reports] == \
            [(r.line, r.status, r.output) for r in whole.reports]
        assert part.summary()["max_after_um"] == whole.summary()["max_after_um"]


def test_written_program_replays_to_the_compensated_positions(setup):
    """Independent of the writer: interpret the OUTPUT program and compare its positions with
    the reported ones (G91 increments were re-derived from the written values)."""
    m, funcs, _ = setup
    res = compensate_program(m, funcs, PROGRAM, chunk_lines=3, decimal_less="mm")
    out_blocks = gcode.blocks(gcode.parse(res.text), m.axes)
    done = {r.line: r for r in res.reports if r.status == "compensated"}
    for b in out_blocks:
        if b.line.number in done:
            want = done[b.line.number].output
            for a in m.axes:
                assert abs(b.target[a] - want[a]) < 0.51e-4, (b.line.number, a)


def test_rotary_axis_known_only_after_the_prescan_is_taken_at_zero(setup):
    """C appears only in a G28 block: the prescan sees the letter, the interpretation never
    knows C, so the program is read again with C = 0 (as without the G28 word)."""
    m, funcs, _ = setup
    text = "G90 G1 X10 Y0 Z100 B10\nG28 C0\nX20\n"
    res = compensate_program(m, funcs, text, chunk_lines=1)
    assert res.assumed_zero == ("C",)
    ref = compensate_program(m, funcs, text, initial={"C": 0.0})
    assert res.text == ref.text


def test_cli_streams_the_same_bytes(setup, tmp_path):
    m, funcs, d = setup
    prog = tmp_path / "p.nc"
    rng = np.random.default_rng(1)
    lines = ["G90 G1 X0 Y0 Z100 B10 C0"] + [
        "X%.3f Y%.3f Z%.3f B%.3f C%.3f" % (rng.uniform(-200, 200), rng.uniform(-200, 200),
                                            rng.uniform(20, 380), rng.uniform(1, 100),
                                            rng.uniform(0, 359)) for _ in range(300)]
    text = "\r\n".join(lines) + "\r\n"
    prog.write_bytes(text.encode("latin-1"))
    out = tmp_path / "o.nc"
    r = in_process.volerr("compensate", "DMU50", prog, "--errors", d, "--out", out)
    assert r.returncode == 0, r.stderr
    assert out.read_bytes() == compensate_program(m, funcs, text).text.encode("latin-1")
