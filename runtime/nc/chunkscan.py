"""Whole-chunk tokenising and number formatting for the streamed compensation (numpy).

:func:`scan` finds, in one pass over the bytes of a chunk of lines, the lines whose
interpretation is known without the interpreter, and their words.  Such a *plain* line holds
address words (``X-12.5``, ``n0010``, blanks between letter and number allowed), blanks and
comments (``( ... )`` and ``;`` to the end of the line) only, as post-processors write them:

* ``G`` words only ``G0``/``G1`` (``G00``, ``G01``): straight moves in the mode in force;
* ``M`` words other than those the interpreter acts on (:data:`volerr.nc.gcode.SPECIAL_M`);
* ``T``, ``H``, ``D`` words (tool and offset numbers; the run keeps the last of each);
* the tool-vector words ``I J K`` and Siemens ``A3= B3= C3=`` (read as ``I J K``);
* ``N F S`` and every other letter that is not an axis of another machine;
* no axis or tool-vector component written twice.

Such a line is a motion block in the distance mode in force, or nothing; the caller lets the
interpreter do every other line (and plain lines in a mode where axis words mean more than a
straight move: incremental, arc, TCPM).  Its words come back as arrays (line, axis, value,
decimals, ``+`` sign, span in the chunk text); numbers are parsed exactly (integer mantissa /
power of ten, correctly rounded; Python's ``float`` for the few with more than 15 digits).
:func:`format_numbers` is :func:`volerr.nc.gcode.format_number` for arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import gcode

#: byte classes; those up to _DOT make numbers, those up to _EOL are the significant bytes of
#: the scan (from _LETTER to _EOL those that are tokens by themselves), from _OTHER on a byte a
#: plain line cannot hold (outside comments)
_DIGIT, _SIGN, _DOT, _LETTER, _SEP, _EOL, _BLANK, _OTHER, _OPEN, _CLOSE = range(1, 11)
_CLS = np.full(256, _OTHER, dtype=np.int8)
for _c in range(ord("A"), ord("Z") + 1):
    _CLS[_c] = _CLS[_c + 32] = _LETTER
_CLS[ord("0"):ord("9") + 1] = _DIGIT
_CLS[ord("+")] = _CLS[ord("-")] = _SIGN
_CLS[ord(".")] = _DOT
_CLS[ord(" ")] = _CLS[ord("\t")] = _BLANK
_CLS[ord("\r")] = _CLS[ord("\n")] = _EOL
_CLS[ord("(")] = _CLS[ord(";")] = _OPEN
_CLS[ord(")")] = _CLOSE
#: the class of every byte value, for ``bytes.translate``
_TRANSLATE = _CLS.tobytes()
_POW10 = 10.0 ** np.arange(23)
#: the longest number run read by the scan: a sign, 15 digits and a dot
_LONGEST = 17
_IPOW10 = 10 ** np.arange(19, dtype=np.int64)

#: letter codes of :func:`_letter_table` below the axis indices
IGNORED, NEEDS_INTERPRETER, G_WORD, M_WORD = -1, -2, -3, -4
#: tool and offset numbers: the last of each in a run of plain lines is kept
TRACKED = {"T": -5, "H": -6, "D": -7}

@dataclass
class Scan:
    """``text``: the chunk; ``start`` (n,) offset of every line; ``fast`` (n,) bool: a plain
    line of the kind above; the words of the fast lines that matter (not those the
    interpreter ignores, such as ``N`` or ``F``), in text order: ``line`` (line index),
    ``axis`` (index into the axes, ``n_axes + 0 .. 2`` for the tool vector ``I J K``, or a
    negative letter code: :data:`G_WORD`, :data:`M_WORD`, a :data:`TRACKED` code),
    ``value``, ``frac`` (digits after the dot, -1 without a dot), ``plus`` (written with
    ``+``), ``num_start`` / ``num_end`` (span of the number in ``text``)."""

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

    def words(self, i0: int, i1: int) -> slice:
        """The words of the lines ``i0 .. i1 - 1``."""
        lo, hi = np.searchsorted(self.line, [i0, i1])
        return slice(int(lo), int(hi))

    def last_tracked(self, w: slice) -> dict:
        """Letter -> value of the last ``T``/``H``/``D`` word among the words ``w``."""
        out = {}
        ax = self.axis[w]
        for letter, code in TRACKED.items():
            k = np.flatnonzero(ax == code)
            if len(k):
                out[letter] = float(self.value[w][k[-1]])
        return out


def _letter_table(axes) -> np.ndarray:
    """Per byte: the axis index of an axis letter (``n_axes + k`` for the tool-vector
    component ``I J K``), else a negative code: G and M words (their values decide), tracked
    tool numbers, letters that need the interpreter (an axis of another machine), letters it
    ignores."""
    t = np.full(256, IGNORED, dtype=np.int64)
    for c in sorted(gcode.Interpreter.FOREIGN_AXES):
        t[ord(c)] = t[ord(c.lower())] = NEEDS_INTERPRETER
    for c, code in (("G", G_WORD), ("M", M_WORD), *TRACKED.items()):
        t[ord(c)] = t[ord(c.lower())] = code
    for i, a in enumerate((*axes, *gcode.VECTOR)):
        t[ord(a)] = t[ord(a.lower())] = i
    return t


#: blanks between the parts of a Siemens tool-vector word read by the scan at most (more:
#: the line goes to the interpreter)
_SIEMENS_BLANKS = 4


def _siemens_words(b: np.ndarray, cls: np.ndarray) -> np.ndarray:
    """The tool-vector words ``A3= B3= C3=`` (Siemens, TRAORI) outside comments read as
    ``I J K``: their ``3=`` (with the blanks around ``=``) become blanks, so that the number
    follows the letter -> the bytes with those letters changed to ``I J K`` (``b`` itself
    when there is none).  ``cls`` changed in place."""
    eq = np.flatnonzero((b == 61) & (cls == _OTHER))
    if not len(eq):
        return b
    blank = (b == 32) | (b == 9)
    last = len(b) - 1
    back, ahead = eq - 1, np.minimum(eq + 1, last)
    for _ in range(_SIEMENS_BLANKS):
        back = np.where((back > 0) & blank[np.maximum(back, 0)], back - 1, back)
        ahead = np.where((ahead < last) & blank[ahead], ahead + 1, ahead)
    letter = back - 1
    ok = (back >= 1) & (b[np.maximum(back, 0)] == 51) & (cls[ahead] <= _DOT) & (ahead > eq)
    ok &= cls[np.maximum(letter, 0)] == _LETTER
    ok &= np.isin(b[np.maximum(letter, 0)] | 32, (97, 98, 99))          # a b c, any case
    ok &= (letter == 0) | (cls[np.maximum(letter - 1, 0)] != _LETTER)
    if not ok.any():
        return b
    letter, back, ahead = letter[ok], back[ok], ahead[ok]
    out = b.copy()
    out[letter] = (b[letter] | 32) - 97 + ord("I")
    cls[_spans(back, ahead)] = _BLANK
    return out


def _spans(s: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Every index of the half-open spans [s, e) (s, e arrays, e >= s), in order."""
    ln = e - s
    total = int(ln.sum())
    if not total:
        return np.zeros(0, np.int64)
    off = np.repeat(s - (np.cumsum(ln) - ln), ln)
    return np.arange(total, dtype=np.int64) + off


def _comments(b: np.ndarray, cls: np.ndarray, start: np.ndarray, body_end: np.ndarray, lid,
              bad: np.ndarray) -> None:
    """Comments ``( ... )`` and ``;`` to the end of the line, as the tokenizer reads them: the
    first byte of each becomes a separator (a word cannot run through it), the others blanks;
    a line with a ``(`` not closed on it is marked ``bad``.  ``cls`` and ``bad`` are changed in
    place.  Lines are resolved opener by opener, all lines at once per round (a round per
    comment of the line with the most)."""
    opens = np.flatnonzero(cls == _OPEN)
    if not len(opens):
        return
    closes = np.flatnonzero(cls == _CLOSE)
    lines = lid(opens)                       # sorted: keep the first of each line
    lines = lines[np.r_[True, lines[1:] != lines[:-1]]]
    pos = start[lines]
    s_all, e_all = [], []
    last_open = len(opens) - 1
    while len(lines):
        k = np.searchsorted(opens, pos)
        o = opens[np.minimum(k, last_open)]
        has = (k <= last_open) & (o < body_end[lines])
        lines, o = lines[has], o[has]
        if not len(lines):
            break
        semi = b[o] == 59
        end = body_end[lines].copy()
        paren = np.flatnonzero(~semi)
        if len(paren):
            kc = np.searchsorted(closes, o[paren])
            c = closes[np.minimum(kc, len(closes) - 1)] if len(closes) else np.zeros(len(kc),
                                                                                   np.int64)
            closed = (kc < len(closes)) & (c < end[paren])
            bad[lines[paren[~closed]]] = True
            end[paren[closed]] = c[closed] + 1
        s_all.append(o)
        e_all.append(end)
        more = ~semi & (end < body_end[lines])
        lines, pos = lines[more], end[more]
    s_all, e_all = np.concatenate(s_all), np.concatenate(e_all)
    cls[_spans(s_all + 1, e_all)] = _BLANK
    cls[s_all] = _SEP


def scan(segs: list, axes) -> Scan:
    """Scan the lines ``segs`` (each with its own ending) of a chunk; see :class:`Scan`."""
    n = len(segs)
    text = "".join(segs)
    lens = np.fromiter(map(len, segs), dtype=np.int64, count=n)
    start = np.zeros(n, dtype=np.int64)
    np.cumsum(lens[:-1], out=start[1:])
    raw = text.encode("latin-1", "replace")
    b = np.frombuffer(raw, dtype=np.uint8)
    cls = np.frombuffer(bytearray(raw.translate(_TRANSLATE)), dtype=np.int8)

    line_of = np.repeat(np.arange(n, dtype=np.int32), lens)     # the line of every byte

    def lid(pos):
        """The line of byte positions ``pos``."""
        return line_of[pos].astype(np.int64)

    bad = np.zeros(n, dtype=bool)
    # the body of a line ends where its ending (CRLF, LF or CR: the only CR / LF bytes of the
    # line) begins
    end = start + lens
    last = np.where(lens > 0, b[np.maximum(end - 1, 0)], 0)
    ending = (last == 10) | (last == 13)
    ending = ending + (ending & (last == 10) & (lens > 1)
                       & (b[np.maximum(end - 2, 0)] == 13))
    _comments(b, cls, start, end - ending, lid, bad)
    letters = _siemens_words(b, cls)
    bad[lid(np.flatnonzero(cls >= _OTHER))] = True
    ns, ne, tok, is_run = _number_runs(cls, lid, bad)
    frac, ndig, mant = _read_runs(raw, text, ns, ne, lid(ns), bad)
    # the letter of each run: the token before it (in a line that is not bad)
    rline = lid(ns)
    rs = np.flatnonzero(is_run)
    code = _letter_table(axes)[letters[tok[np.maximum(rs - 1, 0)]]]
    bad[rline[code == NEEDS_INTERPRETER]] = True
    # an axis programmed twice
    m = code >= 0
    key = rline[m] * (len(axes) + 4) + code[m]
    if len(key):
        ks = np.sort(key)
        bad[ks[1:][ks[1:] == ks[:-1]] // (len(axes) + 4)] = True
    # values of the words that matter (not N F S ...)
    sel = np.flatnonzero(code != IGNORED)
    ns, ne, rline, code, frac, ndig = ns[sel], ne[sel], rline[sel], code[sel], frac[sel], \
        ndig[sel]
    fr = np.maximum(frac, 0)
    val = mant[sel] / _POW10[np.minimum(fr, 22)]
    val = np.where(b[ns] == 45, -val, val)
    exact = (ndig <= 15) & (fr <= 22)
    for i in np.flatnonzero(~exact & ~bad[rline]):
        val[i] = float(text[ns[i]:ne[i]])
    # G words: only G0 / G1; M words: not those the interpreter acts on
    gm = np.flatnonzero((code == G_WORD) | (code == M_WORD))
    if len(gm):
        v = val[gm]
        refused = np.where(code[gm] == G_WORD, (v != 0.0) & (v != 1.0),
                           np.isin(np.round(v), list(gcode.SPECIAL_M)))
        bad[rline[gm[refused]]] = True
    fast = ~bad
    keep = fast[rline]
    return Scan(text, start, fast, rline[keep], code[keep], val[keep], frac[keep],
                b[ns[keep]] == 43, ns[keep], ne[keep])


def _number_runs(cls: np.ndarray, lid, bad: np.ndarray):
    """Runs of adjacent number bytes ``[+-]?(\\d+\\.?\\d*|\\.\\d+)`` -> (their starts, ends, the
    tokens of the chunk: letters, run starts, comment starts and line endings, which of
    them are runs); a line with a number without its letter or a letter without its number
    is marked ``bad`` (in place)."""
    nm = cls <= _DOT
    start_m = nm.copy()
    start_m[1:] &= ~nm[:-1]
    end_m = nm.copy()
    end_m[:-1] &= ~nm[1:]
    ns = np.flatnonzero(start_m)
    ne = np.flatnonzero(end_m) + 1
    # tokens: neighbouring tokens are in the same line unless an ending lies between them
    tok = np.flatnonzero(((cls >= _LETTER) & (cls <= _EOL)) | start_m)
    is_run = start_m[tok]
    isl = cls[tok] == _LETTER
    # a number starts right after its letter (blanks between allowed) ...
    no_letter = is_run.copy()
    no_letter[1:] &= ~isl[:-1]
    # ... and a letter is followed by its number
    no_number = isl.copy()
    no_number[:-1] &= ~is_run[1:]
    bad[lid(tok[np.flatnonzero(no_letter | no_number)])] = True
    return ns, ne, tok, is_run


def _read_runs(raw: bytes, text: str, ns, ne, rline, bad: np.ndarray):
    """The number runs ``[ns, ne)`` read column by column (their first, second ... bytes at
    once): digits, dots, signs behind the first byte, and the mantissa (mant * 10 + digit:
    exact for integers below 2**53) -> (digits after the dot, -1 without one; digit count;
    mantissa).  Only the first _LONGEST bytes (a sign, 15 digits and a dot): a longer run has
    more digits than a double holds and is checked here and read by Python later.  A line
    with a sign inside a number, two dots or no digit is marked ``bad`` (in place)."""
    nr = len(ns)
    length = ne - ns
    width = min(int(length.max()), _LONGEST) if nr else 0
    padded = np.frombuffer(raw + bytes(width), np.uint8)
    ndig = np.zeros(nr, dtype=np.int8)
    ndot = np.zeros(nr, dtype=np.int8)
    dot_at = np.full(nr, -1, dtype=np.int64)
    misplaced = np.zeros(nr, dtype=bool)
    mant = np.zeros(nr)
    for c in range(width):
        byte = padded[c:][ns]                   # (no array ns + c)
        inside = c < length
        digit = (byte - 48 < 10) & inside       # (uint8: the bytes below "0" wrap round)
        dot = (byte == 46) & inside
        ndig += digit
        ndot += dot
        dot_at[dot] = c
        if c:
            misplaced |= ((byte == 43) | (byte == 45)) & inside
        mant = np.where(digit, mant * 10 + (byte - 48), mant)
    ndig, ndot = ndig.astype(np.int64), ndot.astype(np.int64)
    frac = np.where(dot_at >= 0, length - 1 - dot_at, -1)
    for i in np.flatnonzero(length > width):
        t = text[ns[i]:ne[i]]
        ndot[i], misplaced[i] = t.count("."), "+" in t[1:] or "-" in t[1:]
        frac[i] = len(t) - 1 - t.rindex(".") if "." in t else -1
        ndig[i] = sum(ch.isdigit() for ch in t)
    # a sign only in front, at most one dot, at least one digit
    bad[rline[misplaced | (ndot > 1) | (ndig == 0)]] = True
    return frac, ndig, mant


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
    # trailing zeros of the decimals (``x // p * p == x``: numpy divides by a scalar with
    # vectorised code, not so ``%`` and ``divmod``, which take 4-5 times longer)
    tz = np.zeros(len(v), dtype=np.int64)
    for k in range(1, int(nd.max()) + 1):
        p = int(_IPOW10[k])
        tz += (k <= nd) & (fp // p * p == fp)
    keep_eff = np.where(keep < 0, 0, np.maximum(keep, 1))
    d = np.where(nd > 0, np.maximum(nd - tz, keep_eff), 0)
    shift = nd - d
    dg = np.where(shift >= 0, fp // _IPOW10[np.maximum(shift, 0)],
                  fp * _IPOW10[np.maximum(-shift, 0)])
    # the value of the text: integer / power of ten, one correctly rounded division as in
    # float(text); + 0.0 makes -0.0 (a negative number rounded to zero) plain 0.0
    val = np.where(neg, -a, a) / _POW10[np.minimum(nd, 22)] + 0.0
    # lengths: sign, integer digits (1 + the number of powers 10 .. 10**18 not above the
    # integer part), dot and decimals
    signed = neg | plus
    n_int = np.searchsorted(_IPOW10[1:], ip, side="right") + 1
    lens = signed + n_int + np.where(d > 0, d + 1, 0)
    slow = np.flatnonzero(risky)
    slow_text = []
    for i in slow:
        t = gcode.format_number(float(v[i]), int(nd[i]),
                                template(i) if template is not None else "")
        slow_text.append(t.encode("ascii"))
        lens[i] = len(t)
        val[i] = float(t)
    # every text as a row of a byte table [sign | integer digits, right-aligned | dot |
    # decimals, right-aligned]; a mask keeps the bytes each text has, and the table read row
    # by row through the mask is the texts one after the other (the texts of the risky values,
    # formatted above, stand left-aligned in their rows)
    fast = ~risky
    n_i = int(n_int[fast].max()) if fast.any() else 0
    n_d = int(d[fast].max()) if fast.any() else 0
    width = max(2 + n_i + n_d, max(map(len, slow_text), default=0))
    table = np.empty((len(v), width), dtype=np.uint8)
    mask = np.zeros((len(v), width), dtype=bool)
    table[:, 0] = np.where(neg, ord("-"), ord("+"))
    mask[:, 0] = signed
    rest = ip
    for k in range(n_i):        # integer digits from the right
        higher = rest // 10
        table[:, n_i - k] = 48 + (rest - 10 * higher)
        rest = higher
        mask[:, n_i - k] = k < n_int
    table[:, 1 + n_i] = ord(".")
    mask[:, 1 + n_i] = d > 0
    rest = dg
    for k in range(n_d):        # decimals from the right
        higher = rest // 10
        table[:, 1 + n_i + n_d - k] = 48 + (rest - 10 * higher)
        rest = higher
        mask[:, 1 + n_i + n_d - k] = k < d
    for i, t in zip(slow, slow_text):
        mask[i] = False
        mask[i, :len(t)] = True
        table[i, :len(t)] = np.frombuffer(t, dtype=np.uint8)
    return table[mask], lens, val
