"""Positions given as one (N, n_axes) array are checked block by block inside the evaluation:
a NaN or infinity anywhere, also in the last (ragged) block and also where no error parameter
reaches that axis, is one InputError naming the axis."""

import numpy as np
import pytest

import volerr
from volerr.errors import InputError
from volerr.machine import model as model_mod

MB1 = volerr.load("MB1")


@pytest.mark.parametrize("errors", [{}, {"EXX": 1e-3, "EBY": 2e-6}])
@pytest.mark.parametrize("where", [0, model_mod.BLOCK + 7, -1])
@pytest.mark.parametrize("axis, bad", [("Y", np.nan), ("Z", np.inf), ("X", -np.inf)])
def test_bad_position_in_any_block_names_the_axis(errors, where, axis, bad):
    n = 2 * model_mod.BLOCK + 5
    pos = np.random.default_rng(0).random((n, 3)) * 100
    pos[where, MB1.axes.index(axis)] = bad
    with pytest.raises(InputError, match=f"position {axis} has NaN or infinite values"):
        MB1.volumetric_error(pos, errors)


def test_checked_and_unchecked_paths_agree():
    """A C-contiguous array (checked in the blocks) and its Fortran-ordered copy (checked up
    front) give the same values."""
    n = model_mod.BLOCK + 3
    rng = np.random.default_rng(1)
    pos = rng.random((n, 3)) * 500
    errs = {p: rng.normal(size=n) * 1e-5 for p in MB1.parameters}
    a = MB1.volumetric_error(pos, errs)
    b = MB1.volumetric_error(np.asfortranarray(pos), errs)
    assert np.array_equal(a, b)
