"""The drift reader's speedup gives what the code it replaced gave: ``_csv._floats`` (one
comprehension, the per-cell loop only on a failure) against the per-cell loop it replaced:
the values (byte-equal), nan for a non-number, the index of the first one."""

import math

import numpy as np
import pytest

from volerr.instruments import _csv


def _loop_rule(raw):
    vals, bad = [], None
    for i, s in enumerate(raw):
        try:
            vals.append(float(s))
        except ValueError:
            bad = bad if bad is not None else i
            vals.append(math.nan)
    return vals, bad


@pytest.mark.parametrize("raw", [["1.5", "-2e-3", "nan", "inf", "1_0", "0.1"],
                                 ["1", "x", "2", "y"], ["a", "b"], []])
def test_floats_is_the_per_cell_loop(raw):
    got, want = _csv._floats(raw), _loop_rule(raw)
    assert got[1] == want[1]
    assert np.array(got[0], dtype=float).tobytes() == np.array(want[0], dtype=float).tobytes()
