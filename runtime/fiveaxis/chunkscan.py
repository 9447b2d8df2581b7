"""Whole-chunk tokenising and number formatting for the streamed compensation (numpy).

:func:`scan` finds, in one pass over the bytes of a chunk of lines, the lines that are plain
address words (exactly the lines :data:`volerr.fiveaxis.gcode._SIMPLE` matches) without
``G``/``M`` words, without an axis of another machine and without an axis written twice: the
interpretation of such a line is known without the interpreter (a motion block in the distance
mode in force, or nothing).  Their words come back as arrays (line, axis, value, decimals,
``+`` sign, span in the chunk text); numbers are parsed exactly (integer mantissa / power of
ten, correctly rounded; Python's ``float`` for the few with more than 15 digits).
:func:`format_numbers` is :func:`volerr.fiveaxis.gcode.format_number` for arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import gcode

_OTHER, _LETTER, _DIGIT, _SIGN, _DOT, _BLANK, _EOL = range(7)
_CLS = np.full(256, _OTHER, dtype=np.int8)
for _c in range(ord("A"), ord("Z") + 1):
    _CLS[_c] = _CLS[_c + 32] = _LETTER
_CLS[ord("0"):ord("9") + 1] = _DIGIT
_CLS[ord("+")] = _CLS[ord("-")] = _SIGN
_CLS[ord(".")] = _DOT
_CLS[ord(" ")] = _CLS[ord("\t")] = _BLANK
_CLS[ord("\r")] = _CLS[ord("\n")] = _EOL
_POW10 = 10.0 ** np.arange(23)
_IPOW10 = 10 ** np.arange(19, dtype=np.int64)


@dataclass
class Scan:
    """``text``: the chunk; ``start`` (n,) offset of every line; ``fast`` (n,) bool: a plain
    line of the kind above; words of the fast lines, in text order: ``line`` (line index),
    ``axis`` (index into the axes, -1 for an ignored letter such as ``N`` or ``F``), ``value``,
    ``frac`` (digits after the dot, -1 without a dot), ``plus`` (written with ``+``),
    ``num_start`` / ``num_end`` (span of the number in ``text``)."""

    text: str
    start: np.ndarray
    fast: np.ndarray
    line: np.ndarray
    axis: np.ndarray
    value: np.ndarray
    frac: np.ndarray
    plus: np.ndarray
    num_start: np.ndarray
    num_end: np.ndarray


def _letter_table(axes) -> np.ndarray:
    """Per byte: axis index, -1 for a letter the interpreter ignores, -2 for a letter that
    needs it (G, M, an axis of another machine)."""
    t = np.full(256, -1, dtype=np.int64)
    for c in "GM" + "".join(sorted(gcode.Interpreter.FOREIGN_AXES)):
        t[ord(c)] = t[ord(c.lower())] = -2
    for i, a in enumerate(axes):
        t[ord(a)] = t[ord(a.lower())] = i
    return t


def scan(segs: list, axes) -> Scan:
    """Scan the lines ``segs`` (each with its own ending) of a chunk; see :class:`Scan`."""
    n = len(segs)
    text = "".join(segs)
    lens = np.fromiter(map(len, segs), dtype=np.int64, count=n)
    start = np.zeros(n, dtype=np.int64)
    np.cumsum(lens[:-1], out=start[1:])
    b = np.frombuffer(text.encode("latin-1", "replace"), dtype=np.uint8)
    cls = _CLS[b]
    lid = np.repeat(np.arange(n, dtype=np.int32), lens)
    bad = np.zeros(n, dtype=bool)
    bad[lid[cls == _OTHER]] = True
    sig = np.flatnonzero((cls >= _LETTER) & (cls <= _DOT)).astype(np.int32)
    c, ln = cls[sig], lid[sig]
    isnum = c >= _DIGIT
    isl = c == _LETTER
    same_prev = np.zeros(len(sig), dtype=bool)
    same_prev[1:] = ln[1:] == ln[:-1]
    adj_prev = np.zeros(len(sig), dtype=bool)
    adj_prev[1:] = (sig[1:] == sig[:-1] + 1) & same_prev[1:]
    prev_num = np.zeros(len(sig), dtype=bool)
    prev_num[1:] = isnum[:-1]
    prev_l = np.zeros(len(sig), dtype=bool)
    prev_l[1:] = isl[:-1]
    run0 = isnum & ~(prev_num & adj_prev)
    # a number starts right after its letter (blanks between allowed)
    bad[ln[run0 & ~(prev_l & same_prev)]] = True
    # a letter is followed by its number
    nxt_num = np.zeros(len(sig), dtype=bool)
    nxt_num[:-1] = isnum[1:] & same_prev[1:]
    bad[ln[isl & ~nxt_num]] = True
    # numbers: [+-]?(\d+\.?\d*|\.\d+); per run, counts from running sums at its ends
    rid = np.cumsum(run0, dtype=np.int32) - 1
    nr = int(run0.sum())
    rn = rid[isnum]
    cn = c[isnum]
    first = run0[isnum]
    run_first = np.flatnonzero(first)
    run_last = np.empty(nr, dtype=np.int64)
    run_last[:-1] = run_first[1:] - 1
    if nr:
        run_last[-1] = len(rn) - 1

    def per_run(mask):
        total = np.cumsum(mask, dtype=np.int32)
        return total[run_last] - total[run_first] + mask[run_first]

    ndot = per_run(cn == _DOT)
    dig = cn == _DIGIT
    ndig = per_run(dig)
    bad_run = per_run(cn == _SIGN) > (cn[run_first] == _SIGN)     # a sign inside the number
    bad_run |= (ndot > 1) | (ndig == 0)
    rline = ln[run0]
    bad[rline[bad_run]] = True
    # letters that need the interpreter; no words at all -> the interpreter too
    lt = _letter_table(axes)
    code = lt[b[sig[isl]]]
    bad[ln[isl][code == -2]] = True
    has_word = np.zeros(n, dtype=bool)
    has_word[ln[isl]] = True
    bad |= ~has_word
    # an axis programmed twice
    ax_line = ln[isl]
    m = code >= 0
    key = ax_line[m] * (len(axes) + 1) + code[m]
    if len(key):
        ks = np.sort(key)
        bad[ks[1:][ks[1:] == ks[:-1]] // (len(axes) + 1)] = True
    fast = ~bad
    # words of the fast lines (one number run per letter, in order)
    keep_run = fast[rline]
    wl = ax_line[fast[ax_line]]
    wa = code[fast[ax_line]]
    # digits: mantissa and digits after the dot per run
    pos_num = sig[isnum]
    ns, ne = pos_num[run_first], pos_num[run_last] + 1
    dpos = np.flatnonzero(dig)
    # digits after the dot: the characters of the run past its dot (more than one dot or a
    # sign there makes the line slow anyway)
    dot_at = np.full(nr, -1, dtype=np.int64)
    dots = np.flatnonzero(cn == _DOT)
    dot_at[rn[dots]] = dots
    frac = np.where(dot_at >= 0, run_last - dot_at, -1)
    # k-th digit from the end of the run (the digits of a run are contiguous in dpos)
    dcount = np.zeros(nr + 1, dtype=np.int64)
    np.cumsum(ndig, out=dcount[1:])
    drun_end = np.repeat(dcount[1:], ndig)
    k_from_end = drun_end - np.arange(1, len(dpos) + 1, dtype=np.int64)
    dval = b[pos_num[dpos]] - 48
    exact = ndig <= 15
    np.minimum(k_from_end, 18, out=k_from_end)
    # float sums of integers below 2**53 are exact (longer mantissas: Python below)
    mant = np.zeros(nr)
    has_dig = ndig > 0
    if len(dpos):
        mant[has_dig] = np.add.reduceat(_POW10[k_from_end] * dval, dcount[:-1][has_dig])
    fr = np.maximum(frac, 0)
    val = mant / _POW10[np.minimum(fr, 22)]
    neg = b[ns] == ord("-")
    val = np.where(neg, -val, val)
    exact &= fr <= 22
    for i in np.flatnonzero(~exact & keep_run):
        val[i] = float(text[ns[i]:ne[i]])
    plus = b[ns] == ord("+")
    sel = keep_run
    return Scan(text, start, fast, wl, wa, val[sel], frac[sel], plus[sel], ns[sel], ne[sel])


def format_numbers(values, nd, keep, plus, template=None) -> list:
    """``[format_number(v, d, t) ...]`` for arrays: ``nd`` decimals, ``keep`` the decimals of
    the template (-1 without a dot in it), ``plus`` the template starts with ``+``.
    ``template(i)`` gives the template text of value ``i`` for the few values within rounding
    noise of a decimal tie, which are formatted by Python (None: an empty template)."""
    flat, lens, _ = format_bytes(values, nd, keep, plus, template)
    return split_texts(flat, lens)


def split_texts(flat: np.ndarray, lens) -> list:
    """The texts of :func:`format_bytes` (ASCII bytes one after the other, their lengths) as
    strings."""
    text = flat.tobytes().decode("ascii")
    cut = np.concatenate([[0], np.cumsum(lens)]).tolist()
    return [text[a:b] for a, b in zip(cut[:-1], cut[1:])]


def format_bytes(values, nd, keep, plus, template=None):
    """:func:`format_numbers` as ASCII bytes, built digit column by digit column without a
    Python string per number: returns (all texts one after the other as a uint8 array, the
    length of each text (n,), the value of each text (n,) -- what ``float(text)`` gives)."""
    v = np.asarray(values, dtype=float)
    nd = np.asarray(nd, dtype=np.int64)
    keep = np.asarray(keep, dtype=np.int64)
    plus = np.asarray(plus, dtype=bool)
    if not len(v):
        return np.zeros(0, np.uint8), np.zeros(0, np.int64), np.zeros(0)
    x = v * _POW10[nd]
    ax = np.abs(x)
    ok = ax < 2.0 ** 52
    xs = np.where(ok, x, 0.0)
    tie = np.abs(xs - np.floor(xs) - 0.5) < ax * 4e-16 + 1e-9
    risky = ~ok | tie
    big = np.rint(xs)
    a = np.abs(big).astype(np.int64)
    neg = (big < 0) & (a != 0)
    p10 = _IPOW10[nd]
    ip, fp = a // p10, a % p10
    tz = np.zeros(len(v), dtype=np.int64)
    for k in range(1, int(nd.max()) + 1):
        tz += (k <= nd) & (fp % _IPOW10[k] == 0)
    keep_eff = np.where(keep < 0, 0, np.maximum(keep, 1))
    d = np.where(nd > 0, np.maximum(nd - tz, keep_eff), 0)
    shift = nd - d
    dg = np.where(shift >= 0, fp // _IPOW10[np.maximum(shift, 0)],
                  fp * _IPOW10[np.maximum(-shift, 0)])
    # the value of the text: integer / power of ten, one correctly rounded division as in
    # float(text); + 0.0 makes -0.0 (a negative number rounded to zero) plain 0.0
    val = np.where(neg, -a, a) / _POW10[np.minimum(nd, 22)] + 0.0
    # lengths: sign, integer digits, dot and decimals
    signed = neg | plus
    n_int = np.ones(len(v), dtype=np.int64)
    for k in range(1, 19):
        n_int += ip >= _IPOW10[k]
    lens = signed + n_int + np.where(d > 0, d + 1, 0)
    slow = np.flatnonzero(risky)
    slow_text = []
    for i in slow:
        t = gcode.format_number(float(v[i]), int(nd[i]),
                                template(i) if template is not None else "")
        slow_text.append(t.encode("ascii"))
        lens[i] = len(t)
        val[i] = float(t)
    start = np.zeros(len(v), dtype=np.int64)
    np.cumsum(lens[:-1], out=start[1:])
    flat = np.empty(int(lens.sum()), dtype=np.uint8)
    fast = ~risky
    at = start + signed
    m = fast & signed
    flat[start[m]] = np.where(neg[m], ord("-"), ord("+"))
    for k in range(int(n_int[fast].max()) if fast.any() else 0):
        m = fast & (k < n_int)
        flat[at[m] + k] = 48 + (ip[m] // _IPOW10[n_int[m] - 1 - k]) % 10
    at = at + n_int
    m = fast & (d > 0)
    flat[at[m]] = ord(".")
    for k in range(int(d[fast].max()) if fast.any() else 0):
        m = fast & (k < d)
        flat[at[m] + 1 + k] = 48 + (dg[m] // _IPOW10[d[m] - 1 - k]) % 10
    for i, t in zip(slow, slow_text):
        flat[start[i]:start[i] + len(t)] = np.frombuffer(t, dtype=np.uint8)
    return flat, lens, val
