"""Compensation of a whole NC program as named steps, streamed in chunks of lines.

One chunk (``CHUNK_LINES`` lines) goes through

1. :func:`interpret`   lines -> :class:`Blocks` (programmed positions of the motion blocks whose
   axes are all known, the decimals to write), the modal state carried by one
   :class:`~volerr.fiveaxis.gcode.Interpreter` from chunk to chunk;
2. :func:`check_positions`   travel and error-table ranges (bad input is refused);
3. :func:`solve_blocks`   the compensation (:func:`volerr.fiveaxis.compensate.solve` or the
   thesis strategy) -> :class:`Solution`;
4. :func:`round_positions`   the values actually written;
5. :func:`predict`   predicted tool-tip / tool-axis error before and after -> :class:`Prediction`;
6. :func:`write`   the output lines; a :class:`~volerr.fiveaxis.gcode.ControllerState` follows
   the program as written (the same rule the interpreter applies to the program as read).

Every step works row by row, so the output does not depend on the chunk size: a program of
any length runs in memory bounded by the chunk.  Before the chunks, :func:`prescan` reads the
program once more cheaply (no interpretation) for the two facts that need the whole program:
which rotary axes it never commands (taken at 0 deg) and how it separates words.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, require
from . import chunkscan, gcode
from .kinematics import is_five_axis, linear_axes

#: lines per chunk: large enough for the vectorised solve, small enough for the memory
CHUNK_LINES = 20000

#: False: every line is interpreted and written one by one (the reference the whole-chunk
#: path is tested and benchmarked against; the output is the same)
WHOLE_CHUNK = True

_COMMENTS = re.compile(r"\([^)\r\n]*\)|;[^\r\n]*")


@dataclass(frozen=True)
class Options:
    """Validated options of a compensation (see :func:`volerr.fiveaxis.compensate.compensate_program`)."""

    tool: tuple = (0.0, 0.0, 0.0)
    orientation: bool = False
    strategy: str = "full"
    tol_um: float = 0.1
    decimals: int = 4
    initial: dict = field(default_factory=dict)
    check_travel: bool = True
    max_iter: int = 50
    types: tuple | None = None

    def validated(self, model) -> "Options":
        from .compensate import STRATEGIES

        require(self.strategy in STRATEGIES,
                f"unknown strategy {self.strategy!r} ({' '.join(STRATEGIES)})")
        require(self.tol_um > 0 and math.isfinite(self.tol_um),
                "tolerance must be a positive number")
        require(0 <= self.decimals <= 9, "decimals must be 0..9")
        require(not (self.orientation and not is_five_axis(model)),
                f"{model.name}: orientation compensation needs two rotary axes")
        require(not (self.orientation and self.strategy == "thesis"),
                "the thesis strategy does not compensate the orientation")
        tool = np.asarray(self.tool, dtype=float)
        require(tool.shape == (3,) and np.all(np.isfinite(tool)), "tool offset must be 3 numbers")
        for a in self.initial or {}:
            require(a in model.axes, f"{model.name}: unknown axis {a!r} in the initial position")
        require(not (self.types is not None and self.strategy == "thesis"),
                "the thesis strategy has its own set of errors (L-POS L-STR L-SQU and the "
                "rotary-axis errors); --types applies to the full strategy")
        return Options(tuple(float(v) for v in tool), bool(self.orientation), self.strategy,
                       float(self.tol_um), int(self.decimals), dict(self.initial or {}),
                       bool(self.check_travel), int(self.max_iter),
                       None if self.types is None else tuple(self.types))


# ---------------------------------------------------------------------------------------
# step 0: what needs the whole program
@dataclass
class Prescan:
    """Rotary axes whose letter never appears as a word (outside comments), and the word
    separation of the program (:func:`volerr.fiveaxis.gcode.spaced_style`)."""

    absent_rotary: tuple
    spaced: bool


def prescan(open_source, model, chunk_lines: int = CHUNK_LINES) -> Prescan:
    rot = [a for a in model.rotary_axes]
    pats = {a: re.compile(rf"[{a}{a.lower()}][ \t]*[+-]?\.?\d") for a in rot}
    seen = set()
    spaced = None
    fh = open_source()
    try:
        first = 1
        while True:
            buf = list(itertools.islice(fh, chunk_lines))
            for n, seg in enumerate(buf if spaced is None else (), start=first):
                try:
                    spaced = gcode._spaced(gcode._kinds(gcode.Line.parse(n, seg.rstrip("\r\n"),
                                                                         "")))
                except InputError:
                    pass        # reported with its line number by the interpreter
                if spaced is not None:
                    break
            seen |= _letters(buf, pats, seen)
            first += len(buf)
            if len(buf) < chunk_lines or (len(seen) == len(rot) and spaced is not None):
                break           # the end, or nothing left to learn from the rest
    finally:
        if hasattr(fh, "close"):
            fh.close()
    return Prescan(tuple(a for a in rot if a not in seen), True if spaced is None else spaced)


def _letters(segs, pats, seen) -> set:
    text = _COMMENTS.sub("", "".join(segs))
    return {a for a, p in pats.items() if a not in seen and p.search(text)}


# ---------------------------------------------------------------------------------------
# step 1: interpret
@dataclass
class Blocks:
    """The lines of one chunk and its motion blocks.

    ``segs``: the lines as read (with their endings), ``first`` the number of the first;
    ``scan``: the plain lines found by :func:`volerr.fiveaxis.chunkscan.scan` and their words;
    ``runs``: (first, end) line indices of the plain lines interpreted together in absolute
    mode; ``slow``: line index -> (:class:`~volerr.fiveaxis.gcode.Line`, step) of the lines
    interpreted one by one (step None without words); ``row``: per line, the row of a motion
    block whose axes are all known in ``q_nom`` / ``nd``, else -1; ``numbers``: the line number
    of every row; ``pending``: per motion block with an unknown axis, (line, target);
    ``q_nom`` (n, n_axes) mm / deg; ``nd`` (n, n_axes) decimals to write (never fewer than the
    programmed word had)."""

    segs: list
    first: int
    scan: object
    runs: list
    slow: dict
    row: np.ndarray
    numbers: np.ndarray
    q_nom: np.ndarray
    nd: np.ndarray
    order: list          # per motion block in order: row (>= 0) or -(1 + index into pending)
    pending: list
    known_rotary: set
    motion: np.ndarray   # per line: a motion block

    def line(self, i: int) -> gcode.Line:
        """Line ``i`` of the chunk, parsed."""
        return self.slow[i][0] if i in self.slow else _parse_seg(self.segs, self.first, i)


def _parse_seg(segs, first: int, i: int) -> gcode.Line:
    seg = segs[i]
    body = seg.rstrip("\r\n")
    return gcode.Line.parse(first + i, body, seg[len(body):])


def _words(sc, i0: int, i1: int) -> slice:
    lo, hi = np.searchsorted(sc.line, [i0, i1])
    return slice(int(lo), int(hi))


def interpret(segs, first: int, interp: gcode.Interpreter, model, decimals: int) -> Blocks:
    """Interpret the lines ``segs`` (numbered from ``first``); ``interp`` carries the modal
    state from chunk to chunk.  Runs of plain lines in absolute mode are done together (the
    position of an axis is its last programmed value: a forward fill); every other line goes
    through ``interp`` one by one."""
    axes = model.axes
    nax = len(axes)
    n = len(segs)
    sc = chunkscan.scan(segs, axes)
    if not WHOLE_CHUNK:
        sc.fast[:] = False
    q = np.full((n, nax), np.nan)
    nd = np.full((n, nax), decimals, dtype=np.int64)
    motion = np.zeros(n, dtype=bool)
    slow, runs = {}, []
    pos = interp.state.position
    index = {a: i for i, a in enumerate(axes)}
    slow_idx = np.flatnonzero(~sc.fast)
    i = 0
    while i < n:
        if sc.fast[i] and not interp.incremental:
            k = np.searchsorted(slow_idx, i)
            j = int(slow_idx[k]) if k < len(slow_idx) else n
            w = _words(sc, i, j)
            wl, wa = sc.line[w] - i, sc.axis[w]
            ax = wa >= 0
            wl, wa = wl[ax], wa[ax]
            m = j - i
            v = np.full((m, nax), np.nan)
            v[wl, wa] = sc.value[w][ax]
            has = np.zeros((m, nax), dtype=bool)
            has[wl, wa] = True
            fr = sc.frac[w][ax]
            nd[i + wl, wa] = np.maximum(decimals, fr)
            last = np.where(has, np.arange(m)[:, None], -1)
            np.maximum.accumulate(last, axis=0, out=last)
            startv = np.array([np.nan if pos[a] is None else pos[a] for a in axes])
            cols = np.arange(nax)
            q[i:j] = np.where(last >= 0, v[np.maximum(last, 0), cols], startv)
            motion[i:j] = has.any(axis=1)
            for c, a in enumerate(axes):
                val = q[j - 1, c]
                pos[a] = None if val != val else float(val)
            runs.append((i, j))
            i = j
            continue
        seg = segs[i]
        body = seg.rstrip("\r\n")
        line = gcode.Line.parse(first + i, body, seg[len(body):])
        step = interp.step(line)
        slow[i] = (line, step)
        if step is not None:
            interp.state.apply(step)
            if step.kind == "motion":
                motion[i] = True
                q[i] = [np.nan if pos[a] is None else pos[a] for a in axes]
                for a, _, txt in line.items():
                    c = index.get(a)
                    if c is not None and "." in txt:
                        nd[i, c] = max(decimals, len(txt) - txt.index(".") - 1)
        i += 1
    known = motion & ~np.isnan(q).any(axis=1)
    row = np.where(known, np.cumsum(known) - 1, -1)
    known_rotary = {a for a in model.rotary_axes
                    if (motion & ~np.isnan(q[:, index[a]])).any()}
    unk = motion & ~known
    pend = np.cumsum(unk) - 1
    ml = np.flatnonzero(motion)
    order = np.where(known[ml], row[ml], -1 - pend[ml]).tolist()
    pending = []
    for li in np.flatnonzero(unk).tolist():
        line = slow[li][0] if li in slow else _parse_seg(segs, first, li)
        pending.append((line, {a: (None if q[li, c] != q[li, c] else float(q[li, c]))
                               for c, a in enumerate(axes)}))
    rows = np.flatnonzero(known)
    return Blocks(list(segs), first, sc, runs, slow, row, first + rows, q[rows], nd[rows], order,
                  pending, known_rotary, motion)


# ---------------------------------------------------------------------------------------
# step 2: check
def check_positions(blocks: Blocks, em, opts: Options) -> None:
    """Refuse positions outside the travel (unless not checked) or outside an error table's
    measured range (unless extrapolating)."""
    model, q_nom = em.model, blocks.q_nom
    if not len(q_nom):
        return
    axes = model.axes
    numbers = blocks.numbers
    if opts.check_travel:
        for i, a in enumerate(axes):
            lo, hi = model.travel[a]
            bad = (q_nom[:, i] < lo - 1e-9) | (q_nom[:, i] > hi + 1e-9)
            if bad.any():
                k = int(np.argmax(bad))
                raise InputError(f"line {numbers[k]}: {a} = {q_nom[k, i]:g} is outside "
                                 f"the travel {lo:g} .. {hi:g} of {model.name} "
                                 "(--ignore-travel to go on)")
    if em.funcs is not None and not em.funcs.extrapolate:
        ql = em.lookup(q_nom)
        for a, (lo, hi) in em.ranges.items():
            i = axes.index(a)
            bad = (ql[:, i] < lo - 1e-9) | (ql[:, i] > hi + 1e-9)
            if bad.any():
                k = int(np.argmax(bad))
                raise InputError(f"line {numbers[k]}: {a} = {q_nom[k, i]:g} is outside "
                                 f"the measured range {lo:g} .. {hi:g} of error table {a} "
                                 "(--extrapolate to evaluate beyond it)")


# ---------------------------------------------------------------------------------------
# step 3: solve
@dataclass
class Solution:
    """Corrected positions (n, n_axes), iterations (n,), orientation limited (n,)."""

    q: np.ndarray
    iterations: np.ndarray
    limited: np.ndarray


def solve_blocks(em, q_nom: np.ndarray, opts: Options) -> Solution:
    from .compensate import solve, solve_thesis

    n = len(q_nom)
    if not n:
        return Solution(q_nom.copy(), np.zeros(0, dtype=int), np.zeros(0, dtype=bool))
    if opts.strategy == "thesis":
        return Solution(solve_thesis(em, q_nom), np.ones(n, dtype=int), np.zeros(n, dtype=bool))
    q, it, lim = solve(em, q_nom, opts.orientation, opts.tol_um * 1e-3, opts.max_iter)
    return Solution(q, it, lim)


# ---------------------------------------------------------------------------------------
# step 4: round
def round_decimals(v: np.ndarray, nd: np.ndarray) -> np.ndarray:
    """``float(f"{v:.{nd}f}")`` element by element (correctly rounded decimal, ties to even on
    the exact binary value): vectorised, with the few values within 1e-6 of a tie done by
    Python's formatting."""
    scale = 10.0 ** nd
    x = v * scale
    out = np.rint(x) / scale
    frac = np.abs(x - np.floor(x) - 0.5)
    near = np.flatnonzero((frac < 1e-6) | ~(np.abs(x) < 2.0 ** 52))
    for i in near:
        out.flat[i] = float(f"{v.flat[i]:.{int(nd.flat[i])}f}")
    return out


def round_positions(em, q_nom: np.ndarray, sol: Solution, nd: np.ndarray,
                    opts: Options) -> np.ndarray:
    """The positions written: rotary values rounded first, the linear axes solved again for
    them (orientation), then rounded; a value equal to the programmed one is kept as is."""
    from .compensate import resolve_linear

    model = em.model
    q_c = sol.q
    q_out = q_c.copy()
    if not len(q_nom):
        return q_out
    rot_idx = [model.axes.index(a) for a in model.rotary_axes]
    lin_idx = [model.axes.index(a) for a in linear_axes(model)]
    for j in rot_idx:
        q_out[:, j] = np.where(q_c[:, j] == q_nom[:, j], q_nom[:, j],
                               round_decimals(q_c[:, j], nd[:, j]))
    if opts.orientation and not np.array_equal(q_out[:, rot_idx], q_c[:, rot_idx]):
        q_out = resolve_linear(em, q_nom, q_out, opts.tol_um * 1e-3, opts.max_iter)
    for j in lin_idx:
        q_out[:, j] = np.where(q_out[:, j] == q_nom[:, j], q_nom[:, j],
                               round_decimals(q_out[:, j], nd[:, j]))
    return q_out


# ---------------------------------------------------------------------------------------
# step 5: predict
@dataclass
class Prediction:
    """Predicted tool-tip error before / after (n, 3) um, tool-axis error before / after (n,)
    urad, standard uncertainty of the remaining error (n, 3) um (NaN without std columns)."""

    before_um: np.ndarray
    after_um: np.ndarray
    orientation_before_urad: np.ndarray
    orientation_after_urad: np.ndarray
    u_after_um: np.ndarray


def predict(em, q_nom: np.ndarray, q_out: np.ndarray) -> Prediction:
    model, tool, funcs = em.model, em.tool, em.funcs
    n = len(q_nom)
    if not n:
        z = np.zeros((0, 3))
        return Prediction(z, z, np.zeros(0), np.zeros(0), z)
    target = model.nominal_position(q_nom, tool)
    before = em.position_error(q_nom) * 1e3
    after = (model.nominal_position(q_out, tool) + em.position_error(q_out) - target) * 1e3
    if model.rotary_axes:
        k_nom = em.tool_axis(q_nom)
        ob = np.linalg.norm(em.orientation_error(q_nom), axis=1) * 1e6
        k_after = em.tool_axis(q_out) + em.orientation_error(q_out)
        oa = np.linalg.norm(k_after - k_nom, axis=1) * 1e6
    else:
        ob = oa = np.zeros(n)
    u_after = np.full((n, 3), math.nan)
    if funcs is not None and funcs.has_random:
        u_after = model.random_error(q_out, funcs.sigmas(em.lookup(q_out)), probe=tool) * 1e3
    return Prediction(before, after, ob, oa, u_after)


# ---------------------------------------------------------------------------------------
# step 6: write
def _write_line(line, step, r, q_list, nd_list, written, axes, spaced) -> str:
    """One line written block by block (the exact rule; :func:`_write_run` does the same for
    a run of plain lines in absolute mode at once)."""
    fmt = gcode.format_number
    pos = written.position
    if r < 0:
        if step is not None:
            written.apply(step)
        return line.body + line.ending
    words = {a: (v, txt) for a, v, txt in line.items() if a in pos}
    new_values, added, values = {}, {}, []
    want_row, nd_row = q_list[r], nd_list[r]
    if step.incremental:
        for a, want, nd in zip(axes, want_row, nd_row):
            half = 0.5 * 10.0 ** (-nd)
            prev = pos[a]
            inc = want - prev
            w = words.get(a)
            if w is not None:
                if abs(inc - w[0]) >= half:
                    txt = fmt(inc, nd, w[1])
                    new_values[a] = txt
                    values.append((a, float(txt)))
                else:
                    values.append((a, w[0]))
            elif abs(inc) >= half:
                txt = fmt(inc, nd)
                added[a] = txt
                values.append((a, float(txt)))
    else:
        for a, want, nd in zip(axes, want_row, nd_row):
            half = 0.5 * 10.0 ** (-nd)
            w = words.get(a)
            if w is not None:
                if abs(want - w[0]) >= half:
                    txt = fmt(want, nd, w[1])
                    new_values[a] = txt
                    values.append((a, float(txt)))
                else:
                    values.append((a, w[0]))
            elif pos[a] is None or abs(want - pos[a]) >= half:
                txt = fmt(want, nd)
                added[a] = txt
                values.append((a, float(txt)))
    written.apply(gcode.Step("motion", values, step.incremental))
    return (gcode.rewrite_line(line, new_values, added, spaced) if (new_values or added)
            else line.body + line.ending)


def _write_run(b: Blocks, i0: int, i1: int, q_out: np.ndarray, written, axes, spaced,
               edits: list) -> None:
    """The plain lines ``i0 .. i1 - 1`` (absolute mode) written together: ``edits`` gets
    (start, end, text) replacements of the chunk text; ``written`` is updated.

    A programmed word is rewritten where the value to write differs from it by half a step or
    more; an axis the line does not program gets a word where the controller (as written so
    far) holds another value -- a chain along the lines, followed one entry at a time for the
    (line, axis) pairs without a word only."""
    sc = b.scan
    pos = written.position
    nax = len(axes)
    m = i1 - i0
    w = _words(sc, i0, i1)
    ax = sc.axis[w] >= 0
    wl = sc.line[w][ax] - i0
    wa = sc.axis[w][ax]
    wv = sc.value[w][ax]
    row = b.row[i0:i1]
    wr = row[wl]
    known = wr >= 0
    # programmed words of known blocks: rewritten where the value moves by half a step
    kr, ka = wr[known], wa[known]
    want = q_out[kr, ka]
    nd = b.nd[kr, ka]
    change = np.abs(want - wv[known]) >= 0.5 * 10.0 ** (-nd.astype(float))
    ci = np.flatnonzero(known)[change]
    span_s, span_e = sc.num_start[w][ax][ci], sc.num_end[w][ax][ci]
    fr, pl = sc.frac[w][ax][ci], sc.plus[w][ax][ci]
    text = sc.text
    flat, lens, new_vals = chunkscan.format_bytes(want[change], nd[change], fr, pl,
                                                  lambda k: text[span_s[k]:span_e[k]])
    wvals = wv.copy()
    wvals[ci] = new_vals
    # positions held after every line from the programmed words (as written)
    val = np.full((m, nax), np.nan)
    val[wl, wa] = wvals
    has = np.zeros((m, nax), dtype=bool)
    has[wl, wa] = True
    last = np.where(has, np.arange(m)[:, None], -1)
    np.maximum.accumulate(last, axis=0, out=last)
    # axes without a word in a known block: the chain
    absent = np.argwhere((row >= 0)[:, None] & ~has)
    added = {}
    if len(absent):
        cand_w = q_out[row[absent[:, 0]], absent[:, 1]]
        cand_nd = b.nd[row[absent[:, 0]], absent[:, 1]]
        li_prev = last[absent[:, 0], absent[:, 1]]
        held = val[np.maximum(li_prev, 0), absent[:, 1]]
        start = [pos[a] for a in axes]
        last_add = {}
        fmt = gcode.format_number
        for (li, c), want_a, nd_a, pi, h in zip(absent.tolist(), cand_w.tolist(),
                                                cand_nd.tolist(), li_prev.tolist(),
                                                held.tolist()):
            la = last_add.get(c)
            if la is not None and la[0] > pi:
                prev = la[1]
            elif pi >= 0:
                prev = h
            else:
                prev = start[c] if la is None else la[1]
            if prev is None or abs(want_a - prev) >= 0.5 * 10.0 ** (-nd_a):
                txt = fmt(want_a, nd_a)
                added.setdefault(li, {})[axes[c]] = txt
                last_add[c] = (li, float(txt))
    else:
        last_add = {}
    for c, a in enumerate(axes):
        li = int(last[m - 1, c]) if m else -1
        la = last_add.get(c)
        if la is not None and la[0] > li:
            pos[a] = la[1]
        elif li >= 0:
            pos[a] = float(val[li, c])
    # the edits: a line that gets a word is rewritten whole, else its numbers are replaced
    if not added:
        edits.add_bytes(span_s, span_e, flat, lens)
        return
    texts = chunkscan.split_texts(flat, lens)
    line_of = wl[ci]
    by_line = {}
    for k, li in enumerate(line_of.tolist()):
        if li in added:
            by_line.setdefault(li, {})[axes[int(wa[ci[k]])]] = texts[k]
    own = [(s0, e0, t) for k, (s0, e0, t) in enumerate(zip(span_s.tolist(), span_e.tolist(),
                                                          texts))
           if int(line_of[k]) not in added]
    for li, add in added.items():
        i = i0 + li
        line = _parse_seg(b.segs, b.first, i)
        s0 = int(sc.start[i])
        own.append((s0, s0 + len(b.segs[i]),
                    gcode.rewrite_line(line, by_line.get(li, {}), add, spaced)))
    own.sort()
    for s0, e0, t in own:
        edits.add(s0, e0, t)


class _Edits:
    """Replacements (start, end, new text) of a chunk's text, in text order; most come as
    arrays of spans with their new texts as ASCII bytes (:func:`_write_run`), the others one
    by one as strings (lines written by the rule, lines that get a word)."""

    def __init__(self):
        self.batches = []   # (starts, ends, new texts: (flat uint8, lengths) or list of str)
        self.one = []       # pending single edits (start, end, str)

    def add(self, start: int, end: int, text: str) -> None:
        self.one.append((start, end, text))

    def add_bytes(self, starts, ends, flat, lens) -> None:
        self._flush()
        self.batches.append((np.asarray(starts, np.int64), np.asarray(ends, np.int64),
                             (flat, np.asarray(lens, np.int64))))

    def _flush(self) -> None:
        if self.one:
            s0, e0, t = zip(*self.one)
            self.batches.append((np.array(s0, np.int64), np.array(e0, np.int64), list(t)))
            self.one = []

    def apply(self, text: str) -> str:
        """``text`` with the replacements made (spans in text order, not overlapping)."""
        self._flush()
        if not self.batches:
            return text
        starts = np.concatenate([s0 for s0, _, _ in self.batches])
        ends = np.concatenate([e0 for _, e0, _ in self.batches])
        try:
            b = np.frombuffer(text.encode("latin-1"), np.uint8)
            new = [t if isinstance(t, tuple) else
                   (np.frombuffer("".join(t).encode("latin-1"), np.uint8),
                    np.array([len(x) for x in t], np.int64))
                   for _, _, t in self.batches]
        except UnicodeEncodeError:      # a str program with characters beyond latin-1
            return self._apply_str(text, starts, ends)
        flat = np.concatenate([f for f, _ in new])
        lens = np.concatenate([n for _, n in new])
        keep = np.ones(len(b), dtype=bool)
        keep[chunkscan._spans(starts, ends)] = False
        removed = np.zeros(len(starts), dtype=np.int64)
        np.cumsum((ends - starts)[:-1], out=removed[1:])
        out = np.insert(b[keep], np.repeat(starts - removed, lens), flat)
        return out.tobytes().decode("latin-1")

    def _apply_str(self, text: str, starts, ends) -> str:
        new = []
        for _, _, t in self.batches:
            if isinstance(t, tuple):
                new += chunkscan.split_texts(*t)
            else:
                new += t
        out, prev = [], 0
        for s0, e0, t in zip(starts.tolist(), ends.tolist(), new):
            out += [text[prev:s0], t]
            prev = e0
        out.append(text[prev:])
        return "".join(out)


def write(blocks: Blocks, q_out: np.ndarray, written: gcode.ControllerState, axes,
          spaced: bool) -> str:
    """The chunk's output text: original bytes except the changed / added axis words.
    ``written`` (the positions the output program leaves the controller at) is updated."""
    b = blocks
    edits = _Edits()
    q_list = nd_list = None
    starts = b.scan.start
    runs = iter(b.runs)
    nxt = next(runs, None)
    i, n = 0, len(b.segs)
    while i < n:
        if nxt is not None and nxt[0] == i:
            _write_run(b, nxt[0], nxt[1], q_out, written, axes, spaced, edits)
            i = nxt[1]
            nxt = next(runs, None)
            continue
        line, step = b.slow[i]
        r = int(b.row[i])
        if r >= 0 and q_list is None:
            q_list, nd_list = q_out.tolist(), b.nd.tolist()
        t = _write_line(line, step, r, q_list, nd_list, written, axes, spaced)
        if r >= 0 and t != b.segs[i]:
            edits.add(int(starts[i]), int(starts[i]) + len(b.segs[i]), t)
        i += 1
    return edits.apply(b.scan.text)


# ---------------------------------------------------------------------------------------
# the chunks together
@dataclass
class Chunk:
    """One chunk through all steps."""

    blocks: Blocks
    solution: Solution
    q_out: np.ndarray
    prediction: Prediction
    text: str
    strategy: str

    def status(self, r: int) -> str:
        if self.strategy == "thesis":
            return "compensated (thesis strategy)"
        if self.solution.limited[r]:
            return ("compensated; orientation limited (rotary travel, error table or near a "
                    "singular orientation)")
        return "compensated"


class Summary:
    """Running summary over the chunks (the dict of :meth:`Result.summary`)."""

    def __init__(self):
        self.n_blocks = self.n_done = 0
        self.not_compensated = []
        self.max_b = self.max_a = self.max_ob = self.max_oa = self.max_u = 0.0
        self.sum_b2 = self.sum_a2 = 0.0
        self.max_iter = 0

    def add(self, chunk: Chunk) -> None:
        b, p = chunk.blocks, chunk.prediction
        self.n_blocks += len(b.order)
        n = len(b.q_nom)
        self.n_done += n
        for line, target in b.pending:
            missing = [a for a, v in target.items() if v is None]
            self.not_compensated.append({"line": line.number, "reason":
                                         f"not compensated: position of axis {missing[0]} unknown"})
        if n:
            eb = np.linalg.norm(p.before_um, axis=1)
            ea = np.linalg.norm(p.after_um, axis=1)
            self.max_b, self.max_a = max(self.max_b, eb.max()), max(self.max_a, ea.max())
            self.sum_b2 += float(np.sum(eb ** 2))
            self.sum_a2 += float(np.sum(ea ** 2))
            self.max_ob = max(self.max_ob, float(p.orientation_before_urad.max()))
            self.max_oa = max(self.max_oa, float(p.orientation_after_urad.max()))
            self.max_iter = max(self.max_iter, int(chunk.solution.iterations.max()))
            u = p.u_after_um[np.all(np.isfinite(p.u_after_um), axis=1)]
            if len(u):
                self.max_u = max(self.max_u, float(np.linalg.norm(u, axis=1).max()))

    def result(self) -> dict:
        n = self.n_done
        return {
            "motion_blocks": self.n_blocks, "compensated": n,
            "not_compensated": self.not_compensated,
            "max_before_um": float(self.max_b), "max_after_um": float(self.max_a),
            "rms_before_um": math.sqrt(self.sum_b2 / n) if n else 0.0,
            "rms_after_um": math.sqrt(self.sum_a2 / n) if n else 0.0,
            "max_orientation_before_urad": float(self.max_ob),
            "max_orientation_after_urad": float(self.max_oa),
            "max_iterations": self.max_iter, "max_u_after_um": float(self.max_u),
        }


def run(open_source, model, funcs, opts: Options, sink, chunk_lines: int = CHUNK_LINES,
        progress=None) -> tuple[dict, tuple]:
    """Run the steps chunk by chunk -> (summary dict, rotary axes taken at 0 deg because the
    program never commands them).

    ``open_source()``: a fresh iterator over the program's lines with their endings (an open
    text file, latin-1, ``newline=""``, or :class:`io.StringIO`).  ``sink.start()`` is called
    before the first chunk and ``sink.add(chunk)`` for every :class:`Chunk`.  The program is
    read a second time (``start`` called again) only when a rotary axis turns out never to be
    known although its letter appears (e.g. only in a G28 block), which the prescan cannot
    tell.  ``progress(n_lines)`` is called after every chunk."""
    from .compensate import ErrorModel, parameters_for_types

    opts = opts.validated(model)
    pre = prescan(open_source, model, chunk_lines)
    never = tuple(a for a in pre.absent_rotary if a not in opts.initial)
    em = ErrorModel(model, funcs, opts.tool, parameters_for_types(model, opts.types))
    while True:
        initial = {**opts.initial, **{a: 0.0 for a in never}}
        interp = gcode.Interpreter(model.axes, initial)
        written = gcode.ControllerState(model.axes, initial)
        known = set(initial)
        summary = Summary()
        sink.start()
        fh = open_source()
        try:
            first = 1
            while True:
                buf = list(itertools.islice(fh, chunk_lines))
                chunk = _run_chunk(buf, first, interp, written, em, opts, pre.spaced, known)
                summary.add(chunk)
                sink.add(chunk)
                if progress is not None:
                    progress(len(buf))
                first += len(buf)
                if len(buf) < chunk_lines:
                    break
        finally:
            if hasattr(fh, "close"):
                fh.close()
        late = tuple(a for a in model.rotary_axes if a not in known and a not in never)
        if not late:
            return summary.result(), never
        never = tuple(a for a in model.rotary_axes if a in never or a in late)


def _run_chunk(segs, first, interp, written, em, opts, spaced, known) -> Chunk:
    model = em.model
    b = interpret(segs, first, interp, model, opts.decimals)
    known |= b.known_rotary
    check_positions(b, em, opts)
    sol = solve_blocks(em, b.q_nom, opts)
    q_out = round_positions(em, b.q_nom, sol, b.nd, opts)
    pred = predict(em, b.q_nom, q_out)
    text = write(b, q_out, written, model.axes, spaced)
    return Chunk(b, sol, q_out, pred, text, opts.strategy)


# ---------------------------------------------------------------------------------------
# report rows
def report_header(model) -> str:
    unit = {a: ("deg" if a in model.rotary_axes else "mm") for a in model.axes}
    cols = ["line", "status"] + [f"{a}_nominal_{unit[a]}" for a in model.axes] + \
        [f"{a}_out_{unit[a]}" for a in model.axes] + \
        ["dx_before_um", "dy_before_um", "dz_before_um", "e_before_um",
         "dx_after_um", "dy_after_um", "dz_after_um", "e_after_um",
         "orientation_before_urad", "orientation_after_urad", "iterations",
         "ux_after_um", "uy_after_um", "uz_after_um"]
    return ",".join(cols) + "\n"


def _g(v) -> str:
    return "" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.10g}"


def report_rows(model, chunk: Chunk) -> str:
    """CSV rows (see ``volerr compensate --report``) of the motion blocks of one chunk."""
    b, p = chunk.blocks, chunk.prediction
    n_ax = len(model.axes)
    rows = []
    if len(b.q_nom):
        be, af = p.before_um, p.after_um
        eb = np.sqrt(be[:, 0] * be[:, 0] + be[:, 1] * be[:, 1] + be[:, 2] * be[:, 2])
        ea = np.sqrt(af[:, 0] * af[:, 0] + af[:, 1] * af[:, 1] + af[:, 2] * af[:, 2])
        num = np.column_stack([b.q_nom, chunk.q_out, be, eb, af, ea,
                               p.orientation_before_urad, p.orientation_after_urad]).tolist()
        fmt = ",".join(["%.10g"] * (2 * n_ax + 10))
        its = chunk.solution.iterations.tolist()
        u = p.u_after_um.tolist()
    row_line = b.numbers.tolist()
    for o in b.order:
        if o >= 0:
            uu = u[o]
            tail = ",".join(_g(v) for v in uu)
            rows.append(f"{row_line[o]},{chunk.status(o).replace(',', ';')},"
                        f"{fmt % tuple(num[o])},{its[o]},{tail}")
        else:
            line, target = b.pending[-1 - o]
            missing = [a for a in model.axes if target[a] is None]
            vals = [str(line.number), f"not compensated: position of axis {missing[0]} unknown"]
            vals += [_g(target[a]) for a in model.axes] * 2 + [""] * 10 + ["0", "", "", ""]
            rows.append(",".join(vals))
    return "".join(r + "\n" for r in rows)


# ---------------------------------------------------------------------------------------
# a program file streamed to output files
@dataclass
class ProgramErrors:
    """What :func:`volerr.fiveaxis.plots.plot_program_errors` draws: per compensated motion
    block its line (n,), tool-tip error |e| before / after (n,) um, tool-axis error before /
    after (n,) urad."""

    line: np.ndarray
    before_um: np.ndarray
    after_um: np.ndarray
    orientation_before_urad: np.ndarray
    orientation_after_urad: np.ndarray

    @classmethod
    def from_reports(cls, reports) -> "ProgramErrors":
        done = [r for r in reports if r.status.startswith("compensated")]
        return cls(np.array([r.line for r in done], dtype=int),
                   np.array([np.linalg.norm(r.before_um) for r in done]),
                   np.array([np.linalg.norm(r.after_um) for r in done]),
                   np.array([r.orientation_before_urad for r in done]),
                   np.array([r.orientation_after_urad for r in done]))


class FileSink:
    """Sink of :func:`run` writing the program and the report CSV to temporary files (put in
    place by :meth:`commit`) and keeping the plot data only when asked for."""

    def __init__(self, model, out, report=None, inputs=(), keep_errors: bool = False):
        from ..fileio import AtomicFile

        self.model = model
        self.files = []
        try:
            self.out = AtomicFile(out, inputs)
            self.files.append(self.out)
            self.report = AtomicFile(report, inputs) if report else None
            if self.report:
                self.files.append(self.report)
        except BaseException:
            self.discard()
            raise
        self.keep_errors = keep_errors

    def start(self) -> None:
        for f in self.files:
            f.truncate()
        if self.report:
            self.report.write(report_header(self.model).encode("utf-8"))
        self.errors = []

    def add(self, chunk: Chunk) -> None:
        self.out.write(chunk.text.encode("latin-1"))
        if self.report:
            self.report.write(report_rows(self.model, chunk).encode("utf-8"))
        if self.keep_errors and len(chunk.blocks.q_nom):
            b, p = chunk.blocks, chunk.prediction
            self.errors.append((
                b.numbers,
                np.linalg.norm(p.before_um, axis=1), np.linalg.norm(p.after_um, axis=1),
                p.orientation_before_urad, p.orientation_after_urad))

    def program_errors(self) -> ProgramErrors:
        cols = list(zip(*self.errors)) if self.errors else [np.zeros(0)] * 5
        return ProgramErrors(*(np.concatenate(c) if len(c) else np.zeros(0) for c in cols))

    def commit(self) -> None:
        for f in self.files:
            f.commit()

    def discard(self) -> None:
        for f in self.files:
            f.discard()


def open_program(path):
    """A function that opens the program file ``path`` for :func:`run` (latin-1, every line
    with its own ending)."""
    from pathlib import Path

    p = Path(path)
    if not p.is_file():
        raise InputError(f"program not found: {path}")
    return lambda: open(p, encoding="latin-1", newline="")
