"""A program in work-offset and machine coordinates with the modes posts write (G53, G55,
G59.1, G92.1, G64 P Q, G61.1, G96/G97, G98/G99, G4, M1, T M6, G43 H, text after M30),
compensated, and both programs read by LinuxCNC's interpreter rs274 (default parameters:
every offset zero -- the work-offset rule of the G-code subset -- and every axis at 0 at the
start, as the run is told): the input's move ends are the report's nominal positions and the
output's its written ones (acceptance run benchmarks/acceptance/nc_programs2).  Skipped with
the reason when rs274 is absent."""

import numpy as np
import pytest
from helpers import rs274_path as R
from helpers.error_dirs import write_errors

import volerr
from volerr.fiveaxis.program import compensate_program
from volerr.tables.functions import ErrorFunctions

needs_rs274 = pytest.mark.skipif(R.rs274() is None, reason=R.SKIP_REASON)

PROGRAM = """%
(WORK OFFSETS, MACHINE COORDINATES AND POST MODES)
G21 G90 G17 G54 G40 G49 G80 G94
G64 P0.01 Q0.01
T1 M6
G0 G43 H1 Z150.
G53 G0 Z550.
G53 X10. Y10.
G0 X300. Y400.
G92.1
G1 Z100. F500.
G55 X320.
G61.1
G59.1 Y420.
G96 D3000 S200
G98 X340.
G97 S8000
G4 P0.5
M1
G54 Y440.
G99 G0 Z150.
M30
(END)
%
"""


@needs_rs274
def test_rs274_reads_the_nominal_and_the_written_positions(tmp_path):
    m = volerr.load("FB2")
    funcs = ErrorFunctions.from_dir(write_errors(tmp_path / "err", m), m)
    res = compensate_program(m, funcs, PROGRAM, initial={"X": 0.0, "Y": 0.0, "Z": 0.0})
    assert all(r.status == "compensated" for r in res.reports), [r.status for r in res.reports]
    nominal = np.array([[r.nominal[a] for a in "XYZ"] for r in res.reports])
    written = np.array([[r.output[a] for a in "XYZ"] for r in res.reports])
    assert np.abs(written - nominal).max() > 1e-3            # something was compensated
    for text, want, tol in ((PROGRAM, nominal, 1e-9), (res.text, written, 0.5e-4 + 1e-9)):
        prog = tmp_path / "p.ngc"
        prog.write_text(text)
        ends = np.array([s.end[:3] for s in R.load(prog).segments])
        assert ends.shape == want.shape
        assert np.abs(ends - want).max() <= tol
