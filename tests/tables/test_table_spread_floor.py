"""The lower bound of an error table read from a file (hostile-input acceptance, RULE.md in
benchmarks/acceptance/hostile_inputs): a table whose ``_um`` columns span less than any
machine shows (mm written under ``_um``), or whose ``_urad`` columns do (mrad / rad under
``_urad``), is refused with one line naming the file, the column and the likely unit; the
same table in its right unit, zero columns and ``--accept-implausible`` pass."""

import pytest

from volerr.errors import InputError
from volerr.tables.table import read_error_dir

#: a plausible X table of a CMM: positioning a few um, straightness, pitch and yaw in urad
GOOD = {"X": [0, 100, 200, 300], "EXX_um": [0, 1.8, 3.2, 4.1], "EYX_um": [0, 0.5, 0.9, 0.4],
        "EBX_urad": [0, 3.2, 5.3, 4.0], "ECX_urad": [0, 0.2, 0.7, 0.5],
        "EXX_std_um": [0.01, 0.01, 0.01, 0.01]}


def _write(d, scale_um=1.0, scale_urad=1.0):
    d.mkdir()
    cols = list(GOOD)
    rows = [",".join(cols)]
    for i in range(4):
        cells = []
        for c in cols:
            f = scale_um if c.endswith("_um") and "_std" not in c else \
                scale_urad if c.endswith("_urad") else 1.0
            cells.append(repr(GOOD[c][i] * f))
        rows.append(",".join(cells))
    (d / "X.csv").write_text("\n".join(rows) + "\n")
    return d


def test_right_units_pass(tmp_path):
    tables, _ = read_error_dir(_write(tmp_path / "e"))
    assert tables["X"].values["EXX"][-1] == pytest.approx(4.1e-3)


@pytest.mark.parametrize("scale", [1e-3, 1e-6])
def test_mm_under_um_refused(tmp_path, scale):
    with pytest.raises(InputError) as e:
        read_error_dir(_write(tmp_path / "e", scale_um=scale))
    line = str(e.value)
    assert "\n" not in line and "X.csv" in line and "EXX_um" in line
    assert "mm written under _um" in line


@pytest.mark.parametrize("scale", [1e-3, 1e-6])
def test_rad_under_urad_refused(tmp_path, scale):
    with pytest.raises(InputError) as e:
        read_error_dir(_write(tmp_path / "e", scale_urad=scale))
    line = str(e.value)
    assert "EBX_urad" in line and "mrad or rad written under _urad" in line


def test_zero_columns_and_the_option_pass(tmp_path):
    d = tmp_path / "z"
    d.mkdir()
    (d / "X.csv").write_text("X,EXX_um,EBX_urad\n0,0,0\n100,0,0\n")
    read_error_dir(d)                                    # no errors at all: a perfect axis
    read_error_dir(_write(tmp_path / "e", scale_um=1e-3), accept_implausible=True)
