"""The fitting steps that selection (:mod:`volerr.loop.select`) and the lag steps
(:mod:`volerr.loop.lags`) share: cross-validated residuals and bases on the training points of a
blockwise design (:mod:`volerr.estimate.blocks`).  Units: mm rows."""

from __future__ import annotations

import numpy as np

from ..estimate.blocks import BlockBase, cv_sq as _blocks_cv_sq

CV_T = 3.0           # minimum paired t of the held-out improvement
TIE_REL = 1e-7       # BIC changes equal within TIE_REL |dBIC| + TIE_ABS are one fit (a tie)
TIE_ABS = 1e-9


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


def tied(d0: float, d1: float) -> bool:
    """Whether two BIC changes are one fit: equal within ``TIE_REL |d0| + TIE_ABS``.  Columns
    that span the same space on these data (a tool that grows and a Z error of the axis
    holding it, seen at one tool length) give the same residual up to the last bits of the
    arithmetic, which differ between BLAS kernels; the tolerance is far above those bits and
    far below any difference the data can show."""
    return abs(d1 - d0) <= TIE_REL * abs(d0) + TIE_ABS


def rank(scored: list, order: dict, dbic=lambda x: x.dbic, name=lambda x: x.cand.name) -> None:
    """Sort scored candidates (in place) by BIC change, best first; candidates of one fit
    (:func:`tied` to the first of their run) in the order of ``order`` (candidate name ->
    position in :func:`volerr.loop.candidates.build`'s list, whose order the docstring of
    :mod:`volerr.loop.symbols` states): which of two explanations the data cannot tell apart
    is named is the stated rule's choice, never rounding's."""
    s = sorted(scored, key=dbic)
    out, i = [], 0
    while i < len(s):
        j = i + 1
        while j < len(s) and tied(dbic(s[i]), dbic(s[j])):
            j += 1
        out += sorted(s[i:j], key=lambda x: order.get(name(x), len(order)))
        i = j
    scored[:] = out
