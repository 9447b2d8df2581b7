"""``--volume measured``: map and length tests inside the range the error tables cover."""

import json

import numpy as np

from volerr.cli import main
from volerr.tables.table import ErrorTable, write_error_table


def _errors(tmp_path):
    d = tmp_path / "err"
    d.mkdir()
    x = np.linspace(100.0, 500.0, 5)
    write_error_table(d / "X.csv", ErrorTable("X", x, {"EXX": 1e-2 * (x - 100.0) / 400.0}))
    return d


def test_diagonals_inside_the_measured_volume(tmp_path, capsys):
    d = _errors(tmp_path)
    assert main(["diagonals", "MB1", "--errors", str(d)]) == 2
    assert "outside the measured range" in capsys.readouterr().err
    out = tmp_path / "d.json"
    assert main(["diagonals", "MB1", "--errors", str(d), "--volume", "measured",
                 "--lines", "axis", "--json", str(out)]) == 0
    lines = json.loads(out.read_text())["lines"]
    starts = np.array([ln["start_mm"] for ln in lines])
    ends = np.array([ln["end_mm"] for ln in lines])
    assert starts[:, 0].min() == 100.0 and ends[:, 0].max() == 500.0
    assert ends[:, 1].max() == 575.0 and ends[:, 2].max() == 400.0   # no table: full travel
    # EXX grows 10 um per 400 mm: every X-parallel line is 10 um long
    x_lines = [ln for ln in lines if ln["start_mm"][1:] == ln["end_mm"][1:]
               and ln["start_mm"][0] != ln["end_mm"][0]]
    assert x_lines and all(abs(ln["deviation_um"] - 10.0) < 1e-6 for ln in x_lines)


def test_map_inside_the_measured_volume(tmp_path):
    d = _errors(tmp_path)
    out = tmp_path / "m.csv"
    assert main(["map", "MB1", "--errors", str(d), "--volume", "measured", "--grid", "3",
                 "--out", str(out)]) == 0
    rows = np.genfromtxt(out, delimiter=",", names=True)
    assert rows["X"].min() == 100.0 and rows["X"].max() == 500.0
    np.testing.assert_allclose(rows["dx_um"], (rows["X"] - 100.0) / 40.0, atol=1e-9)
