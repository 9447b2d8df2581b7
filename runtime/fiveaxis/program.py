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

import math
import re
from dataclasses import dataclass, field

import numpy as np

from volerr.errors import InputError, require
from volerr.fiveaxis import gcode
from volerr.fiveaxis.kinematics import is_five_axis, linear_axes

#: lines per chunk: large enough for the vectorised solve, small enough for the memory
CHUNK_LINES = 20000

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
        from volerr.fiveaxis.compensate import STRATEGIES

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
    buf = []
    fh = open_source()
    try:
        for n, seg in enumerate(fh, start=1):
            if spaced is None:
                body = seg.rstrip("\r\n")
                try:
                    own = gcode._spaced(gcode._kinds(gcode.Line.parse(n, body, "")))
                except InputError:
                    own = None      # reported with its line number by the interpreter
                spaced = own
            buf.append(seg)
            if len(buf) >= chunk_lines:
                seen |= _letters(buf, pats, seen)
                buf = []
        seen |= _letters(buf, pats, seen)
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

    ``steps``: what each line does (None without words); ``row``: per line, the row of a
    motion block whose axes are all known in ``q_nom`` / ``nd``, else -1; ``pending``: per
    motion block with an unknown axis, (line, target); ``q_nom`` (n, n_axes) mm / deg;
    ``nd`` (n, n_axes) decimals to write (never fewer than the programmed word had)."""

    lines: list
    steps: list
    row: list
    q_nom: np.ndarray
    nd: np.ndarray
    order: list          # per motion block in order: row (>= 0) or -(1 + index into pending)
    pending: list
    known_rotary: set


def interpret(lines, interp: gcode.Interpreter, model, decimals: int) -> Blocks:
    axes = model.axes
    index = {a: i for i, a in enumerate(axes)}
    state = interp.state.position
    steps, row, order, pending = [], [], [], []
    q_rows, nd_rows = [], []
    known_rotary = set()
    rot = model.rotary_axes
    for line in lines:
        step = interp.step(line)
        steps.append(step)
        if step is None:
            row.append(-1)
            continue
        interp.state.apply(step)
        if step.kind != "motion":
            row.append(-1)
            continue
        target = [state[a] for a in axes]
        for a in rot:
            if state[a] is not None:
                known_rotary.add(a)
        if None in target:
            row.append(-1)
            order.append(-1 - len(pending))
            pending.append((line, dict(state)))
            continue
        nd = [decimals] * len(axes)
        for a, _, txt in line.items():
            i = index.get(a)
            if i is not None and "." in txt:
                nd[i] = max(decimals, len(txt) - txt.index(".") - 1)
        row.append(len(q_rows))
        order.append(len(q_rows))
        q_rows.append(target)
        nd_rows.append(nd)
    q = np.array(q_rows, dtype=float).reshape(len(q_rows), len(axes))
    nd = np.array(nd_rows, dtype=int).reshape(len(q_rows), len(axes))
    return Blocks(list(lines), steps, row, q, nd, order, pending, known_rotary)


# ---------------------------------------------------------------------------------------
# step 2: check
def check_positions(blocks: Blocks, em, opts: Options) -> None:
    """Refuse positions outside the travel (unless not checked) or outside an error table's
    measured range (unless extrapolating)."""
    model, q_nom = em.model, blocks.q_nom
    if not len(q_nom):
        return
    axes = model.axes
    lines = [blocks.lines[i] for i, r in enumerate(blocks.row) if r >= 0]
    if opts.check_travel:
        for i, a in enumerate(axes):
            lo, hi = model.travel[a]
            bad = (q_nom[:, i] < lo - 1e-9) | (q_nom[:, i] > hi + 1e-9)
            if bad.any():
                k = int(np.argmax(bad))
                raise InputError(f"line {lines[k].number}: {a} = {q_nom[k, i]:g} is outside "
                                 f"the travel {lo:g} .. {hi:g} of {model.name} "
                                 "(--ignore-travel to go on)")
    if em.funcs is not None and not em.funcs.extrapolate:
        ql = em.lookup(q_nom)
        for a, (lo, hi) in em.ranges.items():
            i = axes.index(a)
            bad = (ql[:, i] < lo - 1e-9) | (ql[:, i] > hi + 1e-9)
            if bad.any():
                k = int(np.argmax(bad))
                raise InputError(f"line {lines[k].number}: {a} = {q_nom[k, i]:g} is outside "
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
    from volerr.fiveaxis.compensate import solve, solve_thesis

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
    from volerr.fiveaxis.compensate import resolve_linear

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
def _format(value: float, nd: int, template: str) -> str:
    return gcode.format_number(value, nd, template)


def write(blocks: Blocks, q_out: np.ndarray, written: gcode.ControllerState, axes,
          spaced: bool) -> str:
    """The chunk's output text: original bytes except the changed / added axis words.
    ``written`` (the positions the output program leaves the controller at) is updated."""
    out = []
    pos = written.position
    q_list = q_out.tolist()
    nd_list = blocks.nd.tolist()
    fmt = gcode.format_number
    for line, step, r in zip(blocks.lines, blocks.steps, blocks.row):
        if r < 0:
            out.append(line.body + line.ending)
            if step is not None:
                written.apply(step)
            continue
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
        out.append(gcode.rewrite_line(line, new_values, added, spaced) if (new_values or added)
                   else line.body + line.ending)
    return "".join(out)


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
    from volerr.fiveaxis.compensate import ErrorModel, parameters_for_types

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
            buf = []
            for line in gcode.iter_lines(fh):
                buf.append(line)
                if len(buf) >= chunk_lines:
                    chunk = _run_chunk(buf, interp, written, em, opts, pre.spaced, known)
                    summary.add(chunk)
                    sink.add(chunk)
                    if progress is not None:
                        progress(len(buf))
                    buf = []
            chunk = _run_chunk(buf, interp, written, em, opts, pre.spaced, known)
            summary.add(chunk)
            sink.add(chunk)
            if progress is not None:
                progress(len(buf))
        finally:
            if hasattr(fh, "close"):
                fh.close()
        late = tuple(a for a in model.rotary_axes if a not in known and a not in never)
        if not late:
            return summary.result(), never
        never = tuple(a for a in model.rotary_axes if a in never or a in late)


def _run_chunk(lines, interp, written, em, opts, spaced, known) -> Chunk:
    model = em.model
    b = interpret(lines, interp, model, opts.decimals)
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
    row_line = [b.lines[i] for i, r in enumerate(b.row) if r >= 0]
    for o in b.order:
        if o >= 0:
            uu = u[o]
            tail = ",".join(_g(v) for v in uu)
            rows.append(f"{row_line[o].number},{chunk.status(o).replace(',', ';')},"
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
        from volerr.fileio import AtomicFile

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
                np.array([b.lines[i].number for i, r in enumerate(b.row) if r >= 0]),
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
