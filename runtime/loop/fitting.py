"""The fitting steps that selection (:mod:`volerr.loop.select`) and the lag steps
(:mod:`volerr.loop.lags`) share: cross-validated residuals and bases on the training points of a
blockwise design (:mod:`volerr.estimate.blocks`).  Units: mm rows."""

from __future__ import annotations

import numpy as np

from ..estimate.blocks import BlockBase, cv_sq as _blocks_cv_sq
from ..selection.rules import CV_T, TIE_BIC_ABS as TIE_ABS, TIE_BIC_REL as TIE_REL, tied

__all__ = ["CV_T", "TIE_ABS", "TIE_REL", "cv_sq", "dense_group", "full_base", "rank", "stack",
           "tied"]


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


def rank(scored: list, order: dict, dbic=lambda x: x.dbic, name=lambda x: x.cand.name) -> None:
    """Sort scored candidates (in place) by BIC change, best first; candidates of one fit
    (:func:`volerr.selection.rules.tied` to the first of their run) in the order of ``order`` (candidate name ->
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
