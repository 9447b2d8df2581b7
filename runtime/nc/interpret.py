"""An NC program read chunk by chunk: what needs the whole program (:func:`prescan`) and the
motion blocks of one chunk (:func:`interpret` -> :class:`Blocks`).

:func:`interpret` reads runs of *plain* lines (:mod:`volerr.nc.chunkscan`: absolute, straight
moves, axis positions or TCPM) together, as arrays (:func:`interpret_run`: the position of an
axis is its last programmed value, a forward fill), and every other line through the modal
:class:`~volerr.nc.gcode.Interpreter` one by one (:func:`interpret_line`).  Both give the same
blocks; ``whole_chunk=False`` sends every line through the interpreter (the reference the
whole-chunk path is tested against).

The words of a block are what the program says: axis positions, or under TCPM the tool tip in
the workpiece frame with the rotary angles or the tool vector (:mod:`volerr.nc.tcpm`).  Turning
TCPM words into the axis positions the controller goes to is the machine's kinematics, done by
the caller (:mod:`volerr.fiveaxis.tcpm_kinematics`); this module knows axis names only.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from . import arcs, chunkscan, gcode, tcpm

#: lines per chunk: large enough for the vectorised solve, small enough for the memory
CHUNK_LINES = 20000

#: decimals of a tool-vector component at least (1e-7: 0.1 urad)
VECTOR_DECIMALS = 7

_COMMENTS = re.compile(r"\([^)\r\n]*\)|;[^\r\n]*")
#: a tool vector sets the rotary axes: G43.5 (I J K) or Siemens A3= B3= C3= (TRAORI)
_VECTOR_TCPM = re.compile(r"[Gg][ \t]*0*43\.5(?!\d)|[ABCabc]3[ \t]*=")


# ---------------------------------------------------------------------------------------
# what needs the whole program
@dataclass
class Prescan:
    """Rotary axes whose letter never appears as a word (outside comments) and that no tool
    vector sets, the word separation of the program (:func:`_first_spacing`)
    and its dialect's line parser (None: ISO; :func:`volerr.nc.dialect.parser`)."""

    absent_rotary: tuple
    spaced: bool
    dialect: object = None


def prescan(open_source, rotary_axes, chunk_lines: int = CHUNK_LINES,
            dialect: str = "auto", decimal_less: str = "auto") -> Prescan:
    """Read the program once, cheaply (no interpretation), for :class:`Prescan`;
    ``open_source()`` a fresh iterator over its lines, ``rotary_axes`` the machine's.
    ``decimal_less`` "auto": a Fanuc-style ISO program (:func:`volerr.nc.dialect.fanuc_style`)
    with an axis or arc number without a decimal point is refused
    (:func:`volerr.nc.dialect.refuse_decimal_less`; read to its end); "mm": read as mm."""
    from . import dialect as dialects

    rot = list(rotary_axes)
    pats = {a: re.compile(rf"[{a}{a.lower()}][ \t]*[+-]?\.?\d") for a in rot}
    seen = set()
    spaced = None
    check_points = None
    fh = open_source()
    try:
        first = 1
        while True:
            buf = list(itertools.islice(fh, chunk_lines))
            if dialect == "auto":
                dialect = dialects.detect(buf, first)
            if dialect == "heidenhain":
                spaced = True
            if check_points is None:
                check_points = (decimal_less == "auto" and dialect != "heidenhain"
                                and dialects.fanuc_style(buf))
            if check_points:
                dialects.refuse_decimal_less(buf, first)
            if spaced is None:
                spaced = _first_spacing(buf, first)
            seen |= _letters(buf, pats, seen)
            first += len(buf)
            if len(buf) < chunk_lines or (len(seen) == len(rot) and spaced is not None
                                          and not check_points):
                break           # the end, or nothing left to learn from the rest
    finally:
        if hasattr(fh, "close"):
            fh.close()
    return Prescan(tuple(a for a in rot if a not in seen), True if spaced is None else spaced,
                   dialects.parser(dialect))


def _first_spacing(buf, first: int):
    """The word separation of the first line that tells (None: none does)."""
    for n, seg in enumerate(buf, start=first):
        try:
            spaced = gcode._spaced(gcode._kinds(gcode.Line.parse(n, seg.rstrip("\r\n"), "")))
        except InputError:
            continue        # reported with its line number by the interpreter
        if spaced is not None:
            return spaced
    return None


def _letters(segs, pats, seen) -> set:
    """The rotary axes of ``pats`` written as words in ``segs``; all of them where a tool
    vector (which sets them) is written."""
    text = _COMMENTS.sub("", "".join(segs))
    if _VECTOR_TCPM.search(text):
        return set(pats) - seen
    return {a for a, p in pats.items() if a not in seen and p.search(text)}


# ---------------------------------------------------------------------------------------
# the motion blocks of a chunk
@dataclass
class Blocks:
    """The lines of one chunk and its motion blocks.

    ``segs``: the lines as read (with their endings), ``first`` the number of the first;
    ``scan``: the plain lines found by :func:`volerr.nc.chunkscan.scan` and their words;
    ``runs``: (first, end, columns) line indices of the plain lines interpreted together in
    absolute mode, the columns of their words (the axes, or with the tool vector); ``slow``:
    line index -> (:class:`~volerr.nc.gcode.Line`, step) of the lines interpreted one by one
    (step None without words); ``row``: per line, the row of a motion block whose positions
    are all known, else -1; ``numbers``: the line number of every row; ``pending``: per
    motion block with an unknown position, (line, target, the first unknown letter);
    ``q_nom`` (n, n_axes) the axis positions, mm / deg (under TCPM those the controller's
    inverse gives, filled in by the caller); ``w_nom``
    (n, n_axes + 3) the words as programmed (axes, then the tool vector ``I J K``; NaN where
    a row has none; under TCPM the linear columns are the tool tip in the workpiece frame);
    ``nd`` (n, n_axes + 3) decimals to write (never fewer than the programmed word had);
    ``frame`` (n,) :data:`volerr.nc.tcpm.AXES` / ``ANGLES`` / ``VECTOR``; ``length``
    (n,) the tool length of TCPM rows (NaN elsewhere), mm; ``arcs`` row -> the
    :class:`~volerr.nc.arcs.ArcPath` of an arc block; ``direction`` (n, n_axes) the
    approach directions (:mod:`volerr.fiveaxis.reversal`) when the tables carry a reversal,
    else None (set by the caller)."""

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
    w_nom: np.ndarray = None
    frame: np.ndarray = None
    length: np.ndarray = None
    arcs: dict = field(default_factory=dict)
    direction: np.ndarray | None = None
    dir_before: np.ndarray | None = None
    #: the approach directions of the program as read (its own moves), for "before"
    dir_program: np.ndarray | None = None
    #: (n,) per row: a straight feed move (G1; not G0, not an arc)
    feed: np.ndarray | None = None

    def dir(self, rows):
        """The directions of ``rows`` (None without reversal)."""
        return None if self.direction is None else self.direction[rows]

    def line(self, i: int) -> gcode.Line:
        """Line ``i`` of the chunk, parsed."""
        return self.slow[i][0] if i in self.slow else _parse_seg(self.segs, self.first, i)


def _parse_seg(segs, first: int, i: int) -> gcode.Line:
    seg = segs[i]
    body = seg.rstrip("\r\n")
    return gcode.Line.parse(first + i, body, seg[len(body):])


class Sheet:
    """The words of the lines of one chunk as they are interpreted, one row per line:
    ``w`` (n, n_axes + 3) the positions after the line (axes, then ``I J K``; NaN unknown or
    not the row's frame), ``nd`` the decimals to write, ``motion`` (n,) a motion block,
    ``frame`` / ``length`` the TCPM frame and tool length, ``paths`` line -> ArcPath,
    ``slow`` line -> (Line, Step) of the lines interpreted one by one, ``runs`` the runs of
    plain lines."""

    def __init__(self, n: int, axes, rotary_axes, decimals: int):
        self.axes = tuple(axes)
        self.letters = (*self.axes, *gcode.VECTOR)
        self.index = {a: i for i, a in enumerate(self.letters)}
        self.nax = len(self.axes)
        self.rot_idx = [self.axes.index(a) for a in rotary_axes]
        self.decimals = decimals
        self.w = np.full((n, len(self.letters)), np.nan)
        self.nd = np.full((n, len(self.letters)), decimals, dtype=np.int64)
        self.nd[:, self.nax:] = max(decimals, VECTOR_DECIMALS)
        self.motion = np.zeros(n, dtype=bool)
        #: per line: a straight move under G1 (feed; G0 rapids and arcs are not)
        self.feed = np.zeros(n, dtype=bool)
        self.frame = np.zeros(n, dtype=np.int8)
        self.length = np.full(n, np.nan)
        self.paths, self.slow, self.runs = {}, {}, []


def interpret(segs, first: int, interp: gcode.Interpreter, model, decimals: int,
              dialect=None, whole_chunk: bool = True) -> Blocks:
    """Interpret the lines ``segs`` (numbered from ``first``); ``interp`` carries the modal
    state from chunk to chunk; ``model`` gives the axis names (``axes``, ``rotary_axes``).
    Runs of plain lines in a plain mode go through :func:`interpret_run`, every other line
    through :func:`interpret_line`.  ``dialect``: the line parser of another dialect
    (:mod:`volerr.nc.heidenhain`; its lines are all interpreted one by one)."""
    n = len(segs)
    sc = chunkscan.scan(segs, model.axes)
    if not whole_chunk or dialect is not None:
        sc.fast[:] = False
    sheet = Sheet(n, model.axes, model.rotary_axes, decimals)
    parse = dialect.parse_line if dialect is not None else gcode.Line.parse
    ends = _run_ends(sc, sheet)
    i = 0
    while i < n:
        kind = ("axes" if interp.frame == "axes" else "angles") if interp.plain else \
            "vector" if interp.plain_vector else None
        if kind is not None and not ends[kind][0][i]:
            stop = ends[kind][1]
            k = np.searchsorted(stop, i)
            j = int(stop[k]) if k < len(stop) else n
            interpret_run(sheet, sc, i, j, interp, kind == "vector")
            i = j
        else:
            interpret_line(sheet, segs, first, i, interp, parse)
            i += 1
    return _blocks(sheet, segs, first, sc, interp, model.rotary_axes)


def _run_ends(sc, sheet: Sheet) -> dict:
    """Per kind of run ("axes"; TCPM with rotary "angles" or a tool "vector"): (per line, it
    cannot be in such a run; the indices of those lines).  Every kind needs a plain line
    (:func:`volerr.nc.chunkscan.scan`); with rotary angles it holds no tool vector (the
    interpreter refuses one), with a tool vector no rotary axis word."""
    n = len(sc.fast)
    has_vec = np.zeros(n, dtype=bool)
    has_rot = np.zeros(n, dtype=bool)
    has_vec[sc.line[sc.axis >= sheet.nax]] = True
    has_rot[sc.line[np.isin(sc.axis, sheet.rot_idx)]] = True
    out = {}
    for kind, other in (("axes", None), ("angles", has_vec), ("vector", has_rot)):
        stop = ~sc.fast if other is None else ~sc.fast | other
        out[kind] = (stop, np.flatnonzero(stop))
    return out


def interpret_run(sheet: Sheet, sc, i: int, j: int, interp: gcode.Interpreter,
                  vector: bool = False) -> None:
    """Lines ``i .. j - 1``, plain (:func:`volerr.nc.chunkscan.scan`) and in a plain mode
    (``interp.plain``; ``vector``: ``interp.plain_vector``, its tool-vector words read too),
    at once: the position of an axis (of a vector component) is its last programmed
    value."""
    pos = interp.state.position
    cols = len(sheet.letters) if vector else sheet.nax
    letters = sheet.letters[:cols]
    ws = sc.words(i, j)
    interp.tools.update(sc.last_tracked(ws))
    wl, wa = sc.line[ws] - i, sc.axis[ws]
    ax = (wa >= 0) & (wa < cols)
    wl, wa = wl[ax], wa[ax]
    m = j - i
    v = np.full((m, cols), np.nan)
    v[wl, wa] = sc.value[ws][ax]
    has = np.zeros((m, cols), dtype=bool)
    has[wl, wa] = True
    sheet.nd[i + wl, wa] = np.maximum(sheet.nd[i + wl, wa], sc.frac[ws][ax])
    last = np.where(has, np.arange(m)[:, None], -1)
    np.maximum.accumulate(last, axis=0, out=last)
    startv = np.array([np.nan if pos[a] is None else pos[a] for a in letters])
    sheet.w[i:j, :cols] = np.where(last >= 0, v[np.maximum(last, 0), np.arange(cols)], startv)
    sheet.motion[i:j] = has.any(axis=1)
    _feed_of_run(sheet, sc, ws, i, j, interp)
    if interp.frame == "tcpm":          # TCPM: the tip, and the angles or the vector
        mrows = i + np.flatnonzero(has.any(axis=1))
        sheet.frame[mrows] = tcpm.VECTOR if vector else tcpm.ANGLES
        sheet.length[mrows] = interp.length
        if vector:
            sheet.w[np.ix_(mrows, sheet.rot_idx)] = np.nan
        if len(mrows):
            interp._last_orientation = "vector" if vector else "angles"
    for c, a in enumerate(letters):
        val = sheet.w[j - 1, c]
        pos[a] = None if val != val else float(val)
    sheet.runs.append((i, j, cols))


def _feed_of_run(sheet: Sheet, sc, ws: slice, i: int, j: int, interp) -> None:
    """The modal G0 / G1 of every line of a run (its last G word so far, else the mode in
    force before the run) -> ``sheet.feed``; the mode after the run left in ``interp``."""
    g = np.flatnonzero(sc.axis[ws] == chunkscan.G_WORD)
    mode = np.full(j - i, interp.motion, dtype=np.int64)
    if len(g):
        at = np.full(j - i, -1, dtype=np.int64)
        at[sc.line[ws][g] - i] = sc.value[ws][g].astype(np.int64)
        last = np.where(at >= 0, np.arange(j - i), -1)
        np.maximum.accumulate(last, out=last)
        mode = np.where(last >= 0, at[np.maximum(last, 0)], mode)
        interp.motion = int(mode[-1])
    sheet.feed[i:j] = sheet.motion[i:j] & (mode == 1)


def interpret_line(sheet: Sheet, segs, first: int, i: int, interp: gcode.Interpreter,
                   parse) -> None:
    """Line ``i`` through the modal interpreter (``parse``: the dialect's line parser)."""
    seg = segs[i]
    body = seg.rstrip("\r\n")
    line = parse(first + i, body, seg[len(body):])
    step = interp.step(line)
    sheet.slow[i] = (line, step)
    if step is None:
        return
    pos = interp.state.position
    start = None
    if step.kind == "arc":
        start = dict(pos)
        start.update({a: None for a in step.forget})
    interp.state.apply(step)
    if step.kind not in ("motion", "arc"):
        return
    nax, w = sheet.nax, sheet.w
    sheet.motion[i] = True
    sheet.feed[i] = step.kind == "motion" and interp.motion == 1
    w[i] = [np.nan if pos[a] is None else pos[a] for a in sheet.letters]
    if step.frame == "tcpm":
        vec = step.orientation == "vector"
        sheet.frame[i] = tcpm.VECTOR if vec else tcpm.ANGLES
        sheet.length[i] = step.tool_length
        if vec:
            w[i, sheet.rot_idx] = np.nan
        else:
            w[i, nax:] = np.nan
    else:
        w[i, nax:] = np.nan
    for a, _, txt in line.items():
        c = sheet.index.get(a)
        if c is not None and "." in txt and not (step.kind == "arc" and c >= nax):
            sheet.nd[i, c] = max(sheet.nd[i, c], len(txt) - txt.index(".") - 1)
    axes = sheet.axes
    if start is not None and all(start[a] is not None for a in axes) and \
            all(pos[a] is not None for a in axes):
        sheet.paths[i] = arcs.arc_path(axes, start, pos, step.arc, f"line {line.number}")


def _blocks(sheet: Sheet, segs, first: int, sc, interp, rotary_axes) -> Blocks:
    """The :class:`Blocks` of an interpreted chunk: a row is known when the words its frame
    needs are (axes; under TCPM the tip and the angles or the vector)."""
    w, frame, motion, nax = sheet.w, sheet.frame, sheet.motion, sheet.nax
    letters, axes = sheet.letters, sheet.axes
    n, ncol = w.shape
    need = np.ones((n, ncol), dtype=bool)
    need[:, nax:] = False
    vec_rows = frame == tcpm.VECTOR
    need[np.ix_(vec_rows, sheet.rot_idx)] = False
    need[vec_rows, nax:] = True
    known = motion & ~(np.isnan(w) & need).any(axis=1)
    _refuse_zero_vectors(w, known & vec_rows, nax, first)
    row = np.where(known, np.cumsum(known) - 1, -1)
    rows = np.flatnonzero(known)
    known_rotary = {a for a in rotary_axes
                    if (motion & ~np.isnan(w[:, sheet.index[a]])).any()}
    if vec_rows.any():
        known_rotary |= set(rotary_axes)
    unk = motion & ~known
    pend = np.cumsum(unk) - 1
    ml = np.flatnonzero(motion)
    order = np.where(known[ml], row[ml], -1 - pend[ml]).tolist()
    pending = []
    for li in np.flatnonzero(unk).tolist():
        line = sheet.slow[li][0] if li in sheet.slow else _parse_seg(segs, first, li)
        miss = [letters[c] for c in range(ncol) if need[li, c] and w[li, c] != w[li, c]]
        pending.append((line, {a: (None if w[li, c] != w[li, c] else float(w[li, c]))
                               for c, a in enumerate(axes)},
                        f"axis {miss[0]}" if miss[0] in axes else
                        f"tool-vector component {miss[0]}"))
    return Blocks(list(segs), first, sc, sheet.runs, sheet.slow, row, first + rows,
                  w[rows, :nax].copy(), sheet.nd[rows], order, pending, known_rotary, motion,
                  w[rows], frame[rows], sheet.length[rows],
                  {int(row[i]): p for i, p in sheet.paths.items() if row[i] >= 0},
                  feed=sheet.feed[rows])


def _refuse_zero_vectors(w, rows, nax: int, first: int) -> None:
    """A tool vector of length zero gives no direction: refused naming its line."""
    zero = rows & np.all(w[:, nax:] == 0.0, axis=1)
    if zero.any():
        raise InputError(f"line {first + int(np.argmax(zero))}: the tool vector is zero "
                         "(I J K or A3 B3 C3 all 0): it gives no tool direction")
