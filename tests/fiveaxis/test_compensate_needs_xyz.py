"""``volerr compensate`` on a layout without the linear axes X, Y and Z (a lathe) is refused in
one line (acceptance run benchmarks/acceptance/nc_programs: a numpy traceback before)."""

from helpers import in_process
from helpers.error_dirs import write_errors

import volerr


def test_layout_without_x_y_z_is_refused_in_one_line(tmp_path):
    """A lathe (TC_XZ: X Z C) cannot have its tool tip compensated by X and Z alone; the
    command said so with a numpy traceback (LinAlgError) before."""
    m = volerr.load("TC_XZ")
    err = write_errors(tmp_path / "err", m)
    prog = tmp_path / "p.nc"
    prog.write_text("G21 G18 G90\nG0 X100. Z300.\nG1 X80. F0.2\n")
    out = tmp_path / "out.nc"
    r = in_process.volerr("compensate", "TC_XZ", "--errors", str(err), str(prog),
                          "--out", str(out))
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.returncode == 2 and len(lines) == 1, r.stderr
    assert "X, Y and Z" in lines[0] and "Traceback" not in r.stderr
    assert not out.exists()
