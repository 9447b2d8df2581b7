"""Vectorised CSV text of numeric columns: fixed decimals, trailing zeros dropped.

Python's per-value formatting costs 0.3-0.5 us a number (10^6 rows x 12 columns: 4-6 s); here
every column of a block of rows becomes a byte matrix by integer arithmetic on the whole column
(``rint(v * 10^d)``, then its decimal digits), and the rows are cut out of the concatenated
matrix at once.  A value prints as the shortest text of ``round(v, d)``: ``-12.5``, ``0``,
``3.000001`` (never ``-0``, never an exponent); the printed value is within ``0.5 * 10^-d``
(+ one rounding of ``v * 10^d``) of ``v``.
"""

from __future__ import annotations

import numpy as np

from ..errors import require

#: |value| * 10^decimals must stay below this: then floor(x / 10) of the rounded integer x is
#: exact in float64 (x / 10 = m + r/10, r >= 1 is at least 0.1 away from m + 1)
_LIMIT = 2.0 ** 49


def _column(v: np.ndarray, decimals: int) -> np.ndarray:
    """(width, n) uint8 characters of one column (transposed: contiguous writes), 0 where a character is absent.  Digits by
    float64 arithmetic on integers (exact below :data:`_LIMIT`; int64 division is 10x slower)."""
    x = np.rint(np.asarray(v, dtype=float) * 10.0 ** decimals)
    require(np.all(np.abs(x) < _LIMIT), f"value too large to print with {decimals} decimals")
    neg = x < 0
    a = np.abs(x)
    ip = np.floor(a / 10.0 ** decimals) if decimals else a
    n_int = max(1, len(str(int(ip.max())))) if len(ip) else 1
    n = len(x)
    out = np.zeros((1 + n_int + 1 + decimals, n), dtype=np.uint8)
    out[0, neg] = ord("-")
    # fractional digits (last first); trailing zeros absent, the point too when nothing follows
    keep = np.zeros(n, dtype=bool)  # a non-zero digit at or after this position
    rest = a
    for k in range(decimals - 1, -1, -1):
        q = np.floor(rest / 10.0)
        digit = rest - 10.0 * q
        rest = q
        keep |= digit != 0
        out[2 + n_int + k] = np.where(keep, digit + ord("0"), 0)
    if decimals:
        out[1 + n_int, keep] = ord(".")
    # integer digits, right-aligned; leading zeros absent (the units digit always present)
    for k in range(n_int - 1, -1, -1):
        q = np.floor(rest / 10.0)
        digit = rest - 10.0 * q
        col = (digit + ord("0")).astype(np.uint8)
        if k < n_int - 1:
            col[rest == 0] = 0
        rest = q
        out[1 + k] = col
    return out


def rows_text(columns, decimals) -> bytes:
    """CSV rows (``\n``-terminated, ASCII) of equal-length numeric ``columns``.

    A column is an (n,) array, a scalar (the same value in every row: formatted once), or a
    pair ``(values, codes)`` meaning ``values[codes]`` (e.g. the ticks of a grid axis and each
    row's tick index: only the ticks are formatted).  ``decimals``: one int for all columns or
    one per column."""
    if np.ndim(decimals) == 0:
        decimals = [int(decimals)] * len(columns)
    n = None
    for c in columns:
        if isinstance(c, tuple):
            n = len(c[1])
        elif np.ndim(c):
            n = len(c)
    require(n is not None, "at least one column must be an array")
    if n == 0:
        return b""
    parts = []
    for i, (c, d) in enumerate(zip(columns, decimals)):
        if isinstance(c, tuple):
            parts.append(np.take(_column(np.asarray(c[0], dtype=float), d), c[1], axis=1))
        elif np.ndim(c) == 0:
            one = _column(np.array([float(c)]), d)
            parts.append(np.broadcast_to(one, (one.shape[0], n)))
        else:
            parts.append(_column(np.asarray(c, dtype=float), d))
        parts.append(np.full((1, n), ord("," if i < len(columns) - 1 else "\n"), dtype=np.uint8))
    # (n, width): one row of text per row.  The rows of the (width, n) matrix are 64 bytes
    # longer than n: with a row stride of a power of two (the blocks of 2^16 rows) every byte
    # of a text row maps to the same cache set and the transposing copy runs 5x slower
    width = sum(len(p) for p in parts)
    m = np.empty((width, n + 64), dtype=np.uint8)[:, :n]
    np.concatenate(parts, axis=0, out=m)
    m = m.T.copy()
    return m[m != 0].tobytes()
