"""The fitting steps that selection (:mod:`volerr.loop.select`) and the lag steps
(:mod:`volerr.loop.lags`) share: cross-validated residuals and bases on the training points of a
blockwise design (:mod:`volerr.estimate.blocks`).  Units: mm rows."""

from __future__ import annotations

import numpy as np

from ..estimate.blocks import BlockBase, cv_sq as _blocks_cv_sq

CV_T = 3.0           # minimum paired t of the held-out improvement


def cv_sq(design, y, folds, train, w_rows) -> np.ndarray:
    """Per-point squared cross-validated residual (weighted rows; blockwise)."""
    return _blocks_cv_sq(design, y, folds, train, w_rows[3 * np.asarray(train)])


def full_base(design, train, w_rows, y) -> BlockBase:
    """The base on all training points (blockwise: no copy of the rows)."""
    return BlockBase(design, train, w_rows[3 * np.asarray(train)], y)


def stack(A0, accepted):
    """The design ``A0`` with the columns of the ``accepted`` effects appended."""
    return A0.plus([s.cols for s in accepted])


def dense_group(cols):
    """A column group of dense columns: rows ``idx`` of ``cols``."""
    return lambda idx: cols[idx]
