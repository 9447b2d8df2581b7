"""The reversal column RV_<axis>_um of an error table (volerr.tables), written by iso230-2."""

from __future__ import annotations

import numpy as np
import pytest

from volerr.errors import InputError
from volerr.tables import ErrorTable, read_error_table, table_to_csv


def test_reversal_column_round_trip_and_units(tmp_path):
    f = tmp_path / "X.csv"
    f.write_text("X,EXX_um,RV_X_mm\n0,1.0,0.002\n100,2.0,-0.0015\n")
    t = read_error_table(f, "X")
    assert np.allclose(t.reversal, [0.002, -0.0015])          # mm in memory
    text = table_to_csv(t)
    assert text.splitlines()[0] == "X,EXX_um,RV_X_um"
    assert text.splitlines()[1:] == ["0,1,2", "100,2,-1.5"]


def test_table_without_reversal_and_bad_reversal(tmp_path):
    f = tmp_path / "X.csv"
    f.write_text("X,EXX_um\n0,1.0\n100,2.0\n")
    assert read_error_table(f, "X").reversal is None
    f.write_text("X,EXX_um,RV_Y_um\n0,1.0,1\n100,2.0,1\n")
    with pytest.raises(InputError, match="names axis Y"):
        read_error_table(f, "X")
    f.write_text("X,EXX_um,RV_X_um\n0,1.0,1\n100,2.0,nan\n")
    with pytest.raises(InputError, match="NaN"):
        read_error_table(f, "X")
    with pytest.raises(InputError, match="reversal"):
        ErrorTable("X", [0.0, 1.0], {"EXX": [0.0, 0.0]}, reversal=[0.0])
