"""Approach directions of the axes, block by block, for error tables with reversal.

An error table with an ``RV_<axis>_um`` column (ISO 230-2 reversal ``B_i``: the mean
deviation approaching in the positive direction minus the one approaching in the negative
direction; the tabulated error is the bidirectional mean) makes the positioning error depend
on the direction the axis last moved in (:meth:`volerr.tables.functions.ErrorFunctions.reversal`).
The direction of a block is the sign of the commanded move of each axis from the block
before; an axis that does not move keeps the direction of its last move (the backlash stays
taken up on that side); before an axis has moved its direction is unknown (0: the
bidirectional mean).

The commanded moves are those of the compensated program: an axis the program holds still may
move by a correction of a few um, and in either direction.  The directions are therefore
settled (:func:`settle`): first taken from the programmed moves (a still axis keeps its last
direction), the blocks compensated, then every block whose written move of an axis goes the
other way is compensated again with that direction, until the directions the written program
has are the ones it was compensated for (a few rounds).  With a positive ``B_i`` (the axis
overshoots in the positive direction) a correction smaller than ``B_i`` against the last
direction has no consistent direction: that axis is held where it was (no move), and the
prediction, which uses the directions of the written moves, reports what is left.
"""

from __future__ import annotations

import numpy as np

#: a move shorter than this (mm / deg) does not change the approach direction
STILL = 1e-9


class Directions:
    """The approach direction of every axis along a program, chunk by chunk: :meth:`rows`
    gives those of the next rows and remembers where the program stands."""

    def __init__(self, n_axes: int):
        self.last_q = np.full(n_axes, np.nan)
        self.last_dir = np.zeros(n_axes, dtype=np.int8)
        #: the last position written (the compensated program) and the directions it left
        self.last_out = np.full(n_axes, np.nan)
        self.last_dir_before = self.last_dir.copy()

    def rows(self, q: np.ndarray) -> np.ndarray:
        """Directions (n, n_axes) int8 of the positions ``q`` (n, n_axes), in program order."""
        n = len(q)
        if not n:
            return np.zeros((0, len(self.last_dir)), dtype=np.int8)
        step = np.diff(np.vstack([self.last_q, q]), axis=0)
        d = np.where(np.abs(step) > STILL, np.sign(step), 0.0)
        d = np.nan_to_num(d).astype(np.int8)
        out = along(d, self.last_dir)
        self.last_dir_before = self.last_dir.copy()
        self.last_q = q[-1].copy()
        self.last_dir = out[-1].copy()
        return out


def along(d: np.ndarray, start: np.ndarray) -> np.ndarray:
    """``d`` (n, k) with every 0 replaced by the last non-zero value above it (``start`` (k,)
    before the first row)."""
    n = len(d)
    idx = np.where(d != 0, np.arange(n)[:, None], -1)
    np.maximum.accumulate(idx, axis=0, out=idx)
    cols = np.arange(d.shape[1])
    return np.where(idx >= 0, d[np.maximum(idx, 0), cols], start[None, :]).astype(np.int8)


def moved(q: np.ndarray, before: np.ndarray, start: np.ndarray) -> np.ndarray:
    """Directions (n, k) of the moves through the positions ``q`` (n, k) from ``before`` (k,)
    (NaN: unknown), an axis that does not move keeping its direction (``start`` before)."""
    step = np.diff(np.vstack([before, q]), axis=0)
    d = np.nan_to_num(np.where(np.abs(step) > STILL, np.sign(step), 0.0)).astype(np.int8)
    return along(d, start)


#: rounds of :func:`settle` at most
SETTLE_ROUNDS = 4


def settle(state: Directions, direction: np.ndarray, q_out: np.ndarray, redo,
           mask=None) -> tuple:
    """Settle the directions of a chunk's rows with the moves as written (see the module
    docstring).  ``direction`` (n, n_axes): the directions the rows were compensated for;
    ``q_out`` (n, n_axes): the positions written; ``redo(rows, direction)`` -> the positions
    written when ``rows`` are compensated again for ``direction`` (len(rows), n_axes).
    ``mask`` (n_axes,): the axes whose direction matters (those with a reversal).  Returns
    (directions of the written moves, positions written, the (row, axis) pairs held where
    they were); ``state`` is advanced."""
    direction = direction.copy()
    q_out = q_out.copy()
    start = state.last_dir_before
    held = []
    for _ in range(SETTLE_ROUNDS):
        d_out = moved(q_out, state.last_out, start)
        diff = d_out != direction
        if mask is not None:
            diff &= mask[None, :]
        bad = np.flatnonzero(np.any(diff, axis=1))
        if not len(bad):
            break
        direction[bad] = d_out[bad]
        q_out[bad] = redo(bad, direction[bad])
    # what no direction can compensate (a positive B_i larger than the correction against
    # the last direction): the axis is held where it was, its direction kept
    if len(q_out):
        d_out = moved(q_out, state.last_out, start)
        diff = d_out != direction
        if mask is not None:
            diff &= mask[None, :]
        for r, j in zip(*np.nonzero(diff)):
            prev = q_out[r - 1, j] if r else state.last_out[j]
            if prev == prev:
                q_out[r, j] = prev
                held.append((int(r), int(j)))
    d_out = moved(q_out, state.last_out, start) if len(q_out) else direction
    if len(q_out):
        state.last_out = q_out[-1].copy()
        state.last_dir = d_out[-1].copy()
    return d_out, q_out, held

