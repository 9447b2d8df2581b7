"""Compensation of a whole NC program as named steps, streamed in chunks of lines.

One chunk (``CHUNK_LINES`` lines) goes through

1. :func:`volerr.nc.interpret.interpret`   lines -> :class:`~volerr.nc.interpret.Blocks`
   (programmed words of the motion blocks whose positions are all known, the decimals to
   write), the modal state carried by one :class:`~volerr.nc.gcode.Interpreter` from chunk to
   chunk; :func:`axes_of_blocks` the axis positions of TCPM blocks (the controller's inverse);
2. :func:`check_positions`   travel and error-table ranges (bad input is refused);
3. :func:`solve_blocks`   the compensation (:func:`volerr.fiveaxis.compensate.solve` or the
   thesis strategy) -> :class:`Solution`;
4. :func:`round_positions`   the values actually written;
5. :func:`predict`   predicted tool-tip / tool-axis error before and after -> :class:`Prediction`;
6. :class:`volerr.nc.writer.Writer`   the output lines; a
   :class:`~volerr.nc.gcode.ControllerState` follows the program as written (the same rule the
   interpreter applies to the program as read).

Every step works row by row, so the output does not depend on the chunk size: a program of
any length runs in memory bounded by the chunk.  Before the chunks,
:func:`volerr.nc.interpret.prescan` reads the
program once more cheaply (no interpretation) for the two facts that need the whole program:
which rotary axes it never commands (taken at 0 deg) and how it separates words.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, require, require_file
from ..nc import gcode, tcpm
from ..nc.interpret import CHUNK_LINES, Blocks, interpret, prescan
from ..nc.writer import Writer
from . import tcpm_kinematics
from .line_path import LinePaths
from .compensate import (STRATEGIES, ErrorModel, parameters_for_types, resolve_linear, solve,
                         solve_thesis)
from ..machine.kinematics import inverse, is_five_axis, linear_axes

#: False: every line is interpreted and written one by one (the reference the whole-chunk
#: path is tested and benchmarked against; the output is the same)
WHOLE_CHUNK = True



@dataclass(frozen=True)
class Options:
    """Validated options of a compensation (see :func:`compensate_program`)."""

    tool: tuple = (0.0, 0.0, 0.0)
    orientation: bool = False
    strategy: str = "full"
    tol_um: float = 0.1
    decimals: int = 4
    initial: dict = field(default_factory=dict)
    check_travel: bool = True
    max_iter: int = 50
    types: tuple | None = None
    #: arcs: the path tolerance (:mod:`volerr.nc.arcs`), um
    arc_tol_um: float = 1.0
    #: TCPM: the tool length (mm), or a tool table (tool number -> mm) for T / H / D words
    tool_length: float | None = None
    tool_table: dict | None = None
    #: "auto", "iso" or "heidenhain" (:mod:`volerr.nc.dialect`)
    dialect: str = "auto"
    #: the work datum: axis positions (layout order) where the work offset was set, or None
    #: (:meth:`volerr.fiveaxis.compensate.ErrorModel.relative_to`)
    datum: tuple | None = None
    #: numbers without a decimal point: "auto" or "mm" (:data:`volerr.nc.dialect.DECIMAL_LESS`)
    decimal_less: str = "auto"

    def validated(self, model) -> "Options":
        """The options checked (:class:`InputError` naming the option), ``tool`` the offset
        of axis-position blocks: with ``tool_length`` L, ``(0, 0, -L)``
        (:func:`_tool_of_length`)."""
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
        from ..tables.plausible import DEFAULT_SIZE_MM, machine_size
        from ..units import check_tool_offset

        check_tool_offset(tool, "--tool", machine_size(model) or DEFAULT_SIZE_MM)
        tool = _tool_of_length(tool, self.tool_length)
        for a in self.initial or {}:
            require(a in model.axes, f"{model.name}: unknown axis {a!r} in the initial position")
        require(not (self.types is not None and self.strategy == "thesis"),
                "the thesis strategy has its own set of errors (L-POS L-STR L-SQU and the "
                "rotary-axis errors); --types applies to the full strategy")
        require(self.arc_tol_um > 0 and math.isfinite(self.arc_tol_um),
                "the arc tolerance must be a positive number (um)")
        require(self.tool_length is None or (math.isfinite(self.tool_length)
                                             and self.tool_length >= 0),
                "the tool length must be a finite number >= 0 (mm)")
        from ..nc.dialect import DIALECTS
        require(self.dialect in DIALECTS, f"unknown dialect {self.dialect!r} "
                                          f"({' '.join(DIALECTS)})")
        from ..nc.dialect import DECIMAL_LESS
        require(self.decimal_less in DECIMAL_LESS, f"--decimal-less: {self.decimal_less!r} is "
                                                   f"not one of {' '.join(DECIMAL_LESS)}")
        return Options(tuple(float(v) for v in tool), bool(self.orientation), self.strategy,
                       float(self.tol_um), int(self.decimals), dict(self.initial or {}),
                       bool(self.check_travel), int(self.max_iter),
                       None if self.types is None else tuple(self.types),
                       float(self.arc_tol_um),
                       None if self.tool_length is None else float(self.tool_length),
                       None if self.tool_table is None else dict(self.tool_table),
                       self.dialect, None if self.datum is None else tuple(self.datum),
                       self.decimal_less)


def _tool_of_length(tool: np.ndarray, length) -> np.ndarray:
    """The tool offset (3,) mm of axis-position blocks: ``tool``, or with a tool length L
    (mm) the offset ``(0, 0, -L)`` of :func:`volerr.nc.tcpm.tool_offset` (the tip L from the
    point the axes refer to, against the tool axis), the one TCPM blocks use.  A non-zero
    ``tool`` other than that offset is refused: which of the two is meant cannot be told."""
    if length is None:
        return tool
    L = float(length)
    require(math.isfinite(L) and L >= 0, "the tool length must be a finite number >= 0 (mm)")
    off = tcpm.tool_offset([L])[0]
    require(not tool.any() or np.allclose(tool, off, rtol=0, atol=1e-9),
            f"--tool {' '.join(f'{v:g}' for v in tool)} and --tool-length {L:g} disagree (a "
            f"tool length L is the tool offset 0 0 -L mm in the tool frame): give one of them")
    return off


# ---------------------------------------------------------------------------------------
# step 1b: the axis positions of TCPM blocks
def axes_of_blocks(blocks: Blocks, interp: gcode.Interpreter, model) -> None:
    """``blocks.q_nom`` of TCPM rows: the axis positions the controller's inverse gives for
    their words (:func:`volerr.fiveaxis.tcpm_kinematics.axes_from_words`); tool-vector rows
    continue from the rotary positions the machine held before the chunk
    (``interp.rotary_actual``, kept here for the next chunk)."""
    b = blocks
    rot_idx = [model.axes.index(a) for a in model.rotary_axes]
    if (b.frame != tcpm.AXES).any():
        before = interp.rotary_actual
        if before is None:
            pos = interp.state.position
            before = np.array([pos[a] if pos[a] is not None else 0.0
                               for a in model.rotary_axes])
        b.q_nom = tcpm_kinematics.axes_from_words(model, b.w_nom, b.frame, b.length, before)
    if len(b.q_nom):
        interp.rotary_actual = b.q_nom[-1, rot_idx].copy()


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
    big = ~(np.abs(q_nom) <= 1e6)   # beyond any machine (mm / deg), travel checked or not
    if big.any():
        k, i = np.argwhere(big)[0]
        raise InputError(f"line {numbers[k]}: {axes[i]} = {q_nom[k, i]:g} is implausibly large "
                         f"(more than 1e6 mm or deg)")
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
                from ..tables.table import range_cause

                why = range_cause(a, lo, hi, float(ql[k, i]), getattr(em.funcs, "source", ""))
                raise InputError(f"{why}line {numbers[k]}: {a} = {q_nom[k, i]:g} is outside "
                                 f"the measured range {lo:g} .. {hi:g} of error table {a}"
                                 + ("" if why else " (--extrapolate to evaluate beyond it)"))


# ---------------------------------------------------------------------------------------
# step 3: solve
@dataclass
class Solution:
    """Corrected positions (n, n_axes), iterations (n,), orientation limited (n,); the
    nominal tool tip ``target`` (n, 3), the error at the programmed positions ``before``
    (n, 3) mm and the nominal tool axis ``tool_axis`` (n, 3) when the solve has them (else
    None: the prediction computes them)."""

    q: np.ndarray
    iterations: np.ndarray
    limited: np.ndarray
    target: np.ndarray | None = None
    before: np.ndarray | None = None
    tool_axis: np.ndarray | None = None


def tool_groups(em, blocks: Blocks, opts: Options) -> list:
    """The rows of a chunk by the tool offset they use: (error model with that offset, row
    index or ``slice(None)``).  Axis-position rows use the ``--tool`` offset; TCPM rows the
    offset of their tool length (:func:`volerr.nc.tcpm.tool_offset`)."""
    fr = blocks.frame
    if fr is None or not (fr != tcpm.AXES).any():
        return [(em, slice(None))]
    key = np.where(fr == tcpm.AXES, np.nan, blocks.length)
    out = []
    axis_rows = np.flatnonzero(fr == tcpm.AXES)
    if len(axis_rows):
        out.append((em, axis_rows))
    for length in np.unique(key[fr != tcpm.AXES]):
        rows = np.flatnonzero((fr != tcpm.AXES) & (key == length))
        out.append((em.with_tool(tcpm.tool_offset([length])[0]), rows))
    return out


def solve_positions(em, q_nom: np.ndarray, opts: Options, direction=None) -> Solution:
    """The compensation of the positions ``q_nom`` (one tool offset: ``em``'s; ``direction``
    the approach directions of the rows, or None)."""
    n = len(q_nom)
    if not n:
        return Solution(q_nom.copy(), np.zeros(0, dtype=int), np.zeros(0, dtype=bool))
    if opts.strategy == "thesis":
        return Solution(solve_thesis(em, q_nom, direction), np.ones(n, dtype=int),
                        np.zeros(n, dtype=bool))
    out = {}
    q, it, lim = solve(em, q_nom, opts.orientation, opts.tol_um * 1e-3, opts.max_iter,
                       direction, out)
    return Solution(q, it, lim, out.get("target"), out.get("before"), out.get("tool_axis"))


def solve_blocks(em, blocks: Blocks, opts: Options) -> Solution:
    """:func:`solve_positions` of every row, group by group (:func:`tool_groups`)."""
    q_nom = blocks.q_nom
    n = len(q_nom)
    sol = Solution(q_nom.copy(), np.zeros(n, dtype=int), np.zeros(n, dtype=bool))
    groups = tool_groups(em, blocks, opts)
    if len(groups) == 1 and isinstance(groups[0][1], slice):
        return solve_positions(em, q_nom, opts, blocks.direction)
    for g_em, rows in groups:
        part = solve_positions(g_em, q_nom[rows], opts, blocks.dir(rows))
        sol.q[rows], sol.iterations[rows], sol.limited[rows] = part.q, part.iterations, \
            part.limited
    return sol


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


def _keep_or_round(v: np.ndarray, programmed: np.ndarray, nd: np.ndarray) -> np.ndarray:
    """``v`` rounded to ``nd`` decimals; where it equals the programmed value, that value."""
    return np.where(v == programmed, programmed, round_decimals(v, nd))


def round_axes(em, q_nom: np.ndarray, q_c: np.ndarray, nd: np.ndarray,
               opts: Options, direction=None) -> np.ndarray:
    """Axis positions as written: rotary values rounded first, the linear axes solved again
    for them (orientation), then rounded; a value equal to the programmed one is kept."""
    model = em.model
    q_out = q_c.copy()
    if not len(q_nom):
        return q_out
    rot_idx = [model.axes.index(a) for a in model.rotary_axes]
    lin_idx = [model.axes.index(a) for a in linear_axes(model)]
    for j in rot_idx:
        q_out[:, j] = _keep_or_round(q_c[:, j], q_nom[:, j], nd[:, j])
    if opts.orientation and not np.array_equal(q_out[:, rot_idx], q_c[:, rot_idx]):
        q_out = resolve_linear(em, q_nom, q_out, opts.tol_um * 1e-3, opts.max_iter, direction)
    for j in lin_idx:
        q_out[:, j] = _keep_or_round(q_out[:, j], q_nom[:, j], nd[:, j])
    return q_out


def round_tcpm(em, q_nom: np.ndarray, w_nom: np.ndarray, q_c: np.ndarray, nd: np.ndarray,
               frame: np.ndarray, length: np.ndarray, opts: Options, direction=None):
    """TCPM rows as written -> (words (n, n_axes + 3), axis positions the controller's inverse
    gives for them).  The orientation words (angles, or the tool vector) are the programmed
    ones unless the orientation is compensated, then those of the corrected axes, rounded;
    the linear axes are solved again for the rotary positions the controller takes from
    them; the tool tip is the forward kinematics of the result, rounded."""
    model = em.model
    axes = model.axes
    nax = len(axes)
    rot_idx = [axes.index(a) for a in model.rotary_axes]
    lin_idx = [axes.index(a) for a in linear_axes(model)]
    w_c = tcpm_kinematics.words_from_axes(model, q_c, length)
    w_out = w_nom.copy()
    q_rot = q_c.copy()
    ang = frame == tcpm.ANGLES
    vec = frame == tcpm.VECTOR
    if opts.orientation:
        for j in rot_idx:
            w_out[ang, j] = _keep_or_round(w_c[ang, j], w_nom[ang, j], nd[ang, j])
        if vec.any():
            k = w_c[vec, nax:]
            w_out[vec, nax:] = np.where(
                np.abs(k - w_nom[vec, nax:]) < 1e-15, w_nom[vec, nax:],
                round_decimals(k, nd[vec, nax:]))
    # the rotary positions the controller takes from the written orientation
    q_rot[ang] = q_c[ang]
    q_rot[np.ix_(ang, rot_idx)] = w_out[np.ix_(ang, rot_idx)]
    if vec.any() and opts.orientation:
        target = np.column_stack([w_c[vec][:, lin_idx], w_out[vec, nax:]])
        q_rot[vec] = inverse(model, target, tcpm.tool_offset(length[vec]), near=q_c[vec])
    # (the programmed vectors written: the controller takes the rotary positions it took for
    # them, those of q_nom, which the solve kept in q_c; nothing to solve again)
    moved = ~np.all(q_rot[:, rot_idx] == q_c[:, rot_idx], axis=1)
    if moved.any():
        q_rot[moved] = resolve_linear(em, q_nom[moved], q_rot[moved], opts.tol_um * 1e-3,
                                      opts.max_iter,
                                      None if direction is None else direction[moved])
    tip = tcpm_kinematics.words_from_axes(model, q_rot, length)[:, lin_idx]
    for k, j in enumerate(lin_idx):
        w_out[:, j] = _keep_or_round(tip[:, k], w_nom[:, j], nd[:, j])
    # the rotary positions of the corrected axes are near those the controller takes from
    # the written vectors: the guess of their solve (which is exact whatever the guess)
    q_out = tcpm_kinematics.axes_from_words(model, w_out, frame, length, q_rot[0, rot_idx]
                                            if len(q_rot) else np.zeros(2), q_c[:, rot_idx])
    return w_out, q_out


def round_positions(em, blocks: Blocks, sol: Solution, opts: Options):
    """The values written -> (words (n, n_axes + 3), axis positions the controller goes to):
    :func:`round_axes` for axis rows, :func:`round_tcpm` for TCPM rows (each with the error
    model of its tool, :func:`tool_groups`)."""
    b = blocks
    q_out = sol.q.copy()
    w_out = b.w_nom.copy()
    nax = len(em.model.axes)
    for g_em, rows in tool_groups(em, b, opts):
        fr = b.frame[rows]
        if isinstance(rows, slice) or (fr == tcpm.AXES).all():
            q_out[rows] = round_axes(g_em, b.q_nom[rows], sol.q[rows], b.nd[rows, :nax], opts,
                                     b.dir(rows))
            w_out[rows, :nax] = q_out[rows]
        else:
            w_out[rows], q_out[rows] = round_tcpm(g_em, b.q_nom[rows], b.w_nom[rows],
                                                  sol.q[rows], b.nd[rows], fr, b.length[rows],
                                                  opts, b.dir(rows))
    return w_out, q_out


def compensate_arcs(em, blocks: Blocks, q_out: np.ndarray, opts: Options) -> dict:
    """Row -> (:class:`~volerr.nc.arcs.ArcPath`, :class:`~volerr.nc.arcs.ArcResult`)
    of the arc blocks (:func:`volerr.fiveaxis.arc_compensation.compensate`); the points of
    a linearised arc are rounded as every written position, its last point is the block's
    end as written.  With the orientation compensated an arc is always linearised (a corrected
    rotary position cannot move in an arc block)."""
    from .arc_compensation import compensate

    b = blocks
    if not b.arcs:
        return {}
    rows = sorted(b.arcs)
    paths = [b.arcs[r] for r in rows]
    nax = len(em.model.axes)
    starts = None
    if b.direction is not None:
        starts = [b.direction[r - 1] if r > 0 else b.dir_before for r in rows]
    results = compensate(em, paths, lambda q, d: solve_positions(em, q, opts, d).q,
                              opts.arc_tol_um * 1e-3, keep=not opts.orientation,
                              start_dirs=starts)
    out = {}
    for r, path, res in zip(rows, paths, results):
        if not res.kept:
            pts = round_decimals(res.points, np.broadcast_to(b.nd[r, :nax], res.points.shape))
            pts[-1] = q_out[r]
            res.points = pts
        out[r] = (path, res)
    return out


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


def predict_positions(em, q_nom: np.ndarray, q_out: np.ndarray, direction=None,
                      direction_before=None, target=None, before=None,
                      tool_axis=None) -> Prediction:
    """Predicted errors of the positions ``q_nom`` (programmed, approached in
    ``direction_before``) and ``q_out`` (written, approached in ``direction``), with ``em``'s
    tool offset (directions None: no reversal).  ``target`` / ``before`` / ``tool_axis``: the
    nominal tip, the error (mm) and the nominal tool axis at ``q_nom`` when the solve has
    them."""
    model, tool, funcs = em.model, em.tool, em.funcs
    n = len(q_nom)
    if not n:
        z = np.zeros((0, 3))
        return Prediction(z, z, np.zeros(0), np.zeros(0), z)
    if target is None:
        target = em.nominal_position(q_nom)
    d, d0 = direction, direction_before
    before = (em.position_error(q_nom, None, d0) if before is None else before) * 1e3
    after = (em.nominal_position(q_out) + em.position_error(q_out, None, d)
             - target) * 1e3
    if model.rotary_axes:
        k_nom = em.tool_axis(q_nom) if tool_axis is None else tool_axis
        ob = np.linalg.norm(em.orientation_error(q_nom, None, d0), axis=1) * 1e6
        k_after = em.tool_axis(q_out) + em.orientation_error(q_out, None, d)
        oa = np.linalg.norm(k_after - k_nom, axis=1) * 1e6
    else:
        ob = oa = np.zeros(n)
    u_after = np.full((n, 3), math.nan)
    if funcs is not None and funcs.has_random:
        u_after = model.random_error(q_out, funcs.sigmas(em.lookup(q_out)), probe=tool) * 1e3
    return Prediction(before, after, ob, oa, u_after)


def predict(em, blocks: Blocks, q_out: np.ndarray, opts: Options,
            sol: Solution | None = None) -> Prediction:
    """:func:`predict_positions` of every row, with the tool offset of its group (``sol``:
    the solution of a single group, whose target and error at the programmed positions are
    reused)."""
    groups = tool_groups(em, blocks, opts)
    if len(groups) == 1 and isinstance(groups[0][1], slice):
        reuse = sol is not None and blocks.direction is None
        return predict_positions(em, blocks.q_nom, q_out, blocks.direction,
                                 blocks.dir_program, sol.target if reuse else None,
                                 sol.before if reuse else None,
                                 sol.tool_axis if reuse else None)
    n = len(q_out)
    p = Prediction(np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n), np.zeros(n),
                   np.full((n, 3), math.nan))
    for g_em, rows in groups:
        part = predict_positions(g_em, blocks.q_nom[rows], q_out[rows], blocks.dir(rows),
                                 None if blocks.dir_program is None else
                                 blocks.dir_program[rows])
        for f in ("before_um", "after_um", "orientation_before_urad",
                  "orientation_after_urad", "u_after_um"):
            getattr(p, f)[rows] = getattr(part, f)
    return p


# ---------------------------------------------------------------------------------------
# the chunks together
@dataclass
class Chunk:
    """One chunk through all steps: ``q_out`` the axis positions the written program commands
    (for TCPM rows those of the controller's inverse), ``w_out`` the words written, ``arcs``
    row -> (ArcPath, ArcResult)."""

    blocks: Blocks
    solution: Solution
    q_out: np.ndarray
    prediction: Prediction
    text: str
    strategy: str
    w_out: np.ndarray = None
    arcs: dict = field(default_factory=dict)
    #: row -> predicted path deviation (um) of its G1 move (:mod:`volerr.fiveaxis.line_path`;
    #: key -1: the TCPM G1 moves not sampled)
    lines: dict = field(default_factory=dict)

    def status(self, r: int) -> str:
        if self.strategy == "thesis":
            s = "compensated (thesis strategy)"
        elif self.solution.limited[r]:
            s = ("compensated; orientation limited (rotary travel, error table or near a "
                 "singular orientation)")
        else:
            s = "compensated"
        fr = self.blocks.frame
        if fr is not None and fr[r] != tcpm.AXES:
            s += "; TCPM (tool tip in the workpiece frame)"
        if r in self.arcs:
            s += "; " + self.arcs[r][1].status
        return s


class Summary:
    """Running summary over the chunks (the dict of :meth:`Result.summary`)."""

    def __init__(self):
        self.n_blocks = self.n_done = 0
        self.not_compensated = []
        self.max_b = self.max_a = self.max_ob = self.max_oa = self.max_u = 0.0
        self.sum_b2 = self.sum_a2 = 0.0
        self.max_iter = 0
        self.arcs_kept = self.arcs_linearised = self.segments = self.tcpm = 0
        self.max_arc_dev = 0.0
        #: G1 moves sampled, the largest path deviation (um) and its line, TCPM G1 moves
        self.lines_sampled = self.lines_tcpm = 0
        self.max_line_dev, self.max_line_at = 0.0, None
        #: written minus programmed position per axis: max |.| and sum of squares (mm / deg)
        self.corr_max = self.corr_sq = None

    def add(self, chunk: Chunk) -> None:
        b, p = chunk.blocks, chunk.prediction
        self.n_blocks += len(b.order)
        n = len(b.q_nom)
        self.n_done += n
        for line, _, missing in b.pending:
            self.not_compensated.append({"line": line.number, "reason":
                                         f"not compensated: position of {missing} unknown"})
        for _, res in chunk.arcs.values():
            if res.kept:
                self.arcs_kept += 1
            else:
                self.arcs_linearised += 1
                self.segments += len(res.points)
            self.max_arc_dev = max(self.max_arc_dev, res.deviation_um)
        self.add_lines(chunk)
        if b.frame is not None:
            self.tcpm += int(np.count_nonzero(b.frame))
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
            d = chunk.q_out - b.q_nom
            if self.corr_max is None:
                self.corr_max, self.corr_sq = np.zeros(d.shape[1]), np.zeros(d.shape[1])
            self.corr_max = np.maximum(self.corr_max, np.abs(d).max(axis=0))
            self.corr_sq += np.einsum("ij,ij->j", d, d)

    def add_lines(self, chunk: Chunk) -> None:
        """The G1 path deviations of a chunk (the first largest kept: ties to the earlier
        line)."""
        for r, dev in chunk.lines.items():
            if r < 0:
                self.lines_tcpm += dev
                continue
            self.lines_sampled += 1
            if dev > self.max_line_dev or self.max_line_at is None:
                self.max_line_dev, self.max_line_at = dev, int(chunk.blocks.numbers[r])

    def corrections(self, axes) -> dict:
        """Axis -> (max |correction|, rms correction) over the compensated blocks, mm / deg
        (the written minus the programmed position; under TCPM the axis positions the
        controller goes to)."""
        n = self.n_done
        if not n or self.corr_max is None:
            return {a: (0.0, 0.0) for a in axes}
        return {a: (float(self.corr_max[i]), math.sqrt(float(self.corr_sq[i]) / n))
                for i, a in enumerate(axes)}

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
            "tcpm_blocks": self.tcpm,
            "arcs": {"kept": self.arcs_kept, "linearised": self.arcs_linearised,
                     "segments": self.segments,
                     "max_path_deviation_um": float(self.max_arc_dev)},
            "lines": {"sampled": self.lines_sampled, "tcpm_not_sampled": self.lines_tcpm,
                      "max_path_deviation_um": float(self.max_line_dev),
                      "line": self.max_line_at},
        }


def run(open_source, model, funcs, opts: Options, sink, chunk_lines: int = CHUNK_LINES,
        progress=None, corrections: bool = False) -> tuple:
    """Run the steps chunk by chunk -> (summary dict, rotary axes taken at 0 deg because the
    program never commands them), with ``corrections`` also the corrections per axis
    (:meth:`Summary.corrections`).

    ``open_source()``: a fresh iterator over the program's lines with their endings (an open
    text file, latin-1, ``newline=""``, or :class:`io.StringIO`).  ``sink.start()`` is called
    before the first chunk and ``sink.add(chunk)`` for every :class:`Chunk`.  The program is
    read a second time (``start`` called again) only when a rotary axis turns out never to be
    known although its letter appears (e.g. only in a G28 block), which the prescan cannot
    tell.  ``progress(n_lines)`` is called after every chunk."""
    from .reversal import Directions

    opts = opts.validated(model)
    pre = prescan(open_source, model.rotary_axes, chunk_lines, opts.dialect,
                  opts.decimal_less)
    never = tuple(a for a in pre.absent_rotary if a not in opts.initial)
    em = ErrorModel(model, funcs, opts.tool, parameters_for_types(model, opts.types))
    if opts.datum is not None:
        em = em.relative_to(opts.datum)
    rule = tcpm.length_rule(opts.tool_length, opts.tool_table)
    while True:
        initial = {**opts.initial, **{a: 0.0 for a in never}}
        interp = gcode.Interpreter(model.axes, initial, rule)
        written = gcode.ControllerState(model.axes, initial, interp.state.linear)
        writer = Writer(written, model.axes, pre.spaced,
                        plus="+" if getattr(pre.dialect, "signed", False) else "")
        directions = Directions(len(model.axes)) if funcs is not None and \
            funcs.has_reversal else None
        known = set(initial)
        summary = Summary()
        line_paths = LinePaths()
        sink.start()
        fh = open_source()
        try:
            first = 1
            while True:
                buf = list(itertools.islice(fh, chunk_lines))
                chunk = _run_chunk(buf, first, interp, writer, em, opts, known, pre.dialect,
                                   line_paths, directions)
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
            if corrections:
                return summary.result(), never, summary.corrections(model.axes)
            return summary.result(), never
        never = tuple(a for a in model.rotary_axes if a in never or a in late)


def _run_chunk(segs, first, interp, writer, em, opts, known, dialect=None, line_paths=None,
               directions=None) -> Chunk:
    model = em.model
    b = interpret(segs, first, interp, model, opts.decimals, dialect, WHOLE_CHUNK)
    axes_of_blocks(b, interp, model)
    known |= b.known_rotary
    if directions is not None:
        b.dir_before = directions.last_dir.copy()
        b.direction = b.dir_program = directions.rows(b.q_nom)
    check_positions(b, em, opts)
    sol = solve_blocks(em, b, opts)
    w_out, q_out = round_positions(em, b, sol, opts)
    if directions is not None:
        b.direction, q_out, w_out = _settle(em, b, sol, w_out, q_out, opts, directions)
    arc_res = compensate_arcs(em, b, q_out, opts)
    pred = predict(em, b, q_out, opts, sol)
    if interp.vector_words is not None:
        writer.vector_words = interp.vector_words
    text = writer.chunk(b, w_out, arc_res)
    lines = line_paths.chunk(em, b, q_out) if line_paths is not None else {}
    return Chunk(b, sol, q_out, pred, text, opts.strategy, w_out, arc_res, lines)


def _settle(em, b: Blocks, sol: Solution, w_out, q_out, opts, directions):
    """The approach directions settled with the moves as written
    (:func:`volerr.fiveaxis.reversal.settle`): rows compensated again where a written move
    goes the other way than assumed."""
    import dataclasses

    from .reversal import settle

    mask = np.array([a in em.funcs.reversal_functions for a in em.model.axes])

    def redo(rows, d):
        sub = dataclasses.replace(b, q_nom=b.q_nom[rows], w_nom=b.w_nom[rows], nd=b.nd[rows],
                                  frame=b.frame[rows], length=b.length[rows], direction=d,
                                  arcs={})
        s = solve_blocks(em, sub, opts)
        w, q = round_positions(em, sub, s, opts)
        sol.q[rows], sol.iterations[rows], sol.limited[rows] = s.q, s.iterations, s.limited
        w_out[rows] = w
        return q

    d, q, held = settle(directions, b.direction, q_out, redo, mask)
    for r, j in held:
        w_out[r, j] = q[r, j] if b.frame[r] == 0 else w_out[r, j]
    return d, q, w_out


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
            line, target, missing = b.pending[-1 - o]
            vals = [str(line.number), f"not compensated: position of {missing} unknown"]
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
            head = report_header(self.model)
            if self.constant_columns:
                head = head[:-1] + "," + ",".join(self.constant_columns) + "\n"
            self.report.write(head.encode("utf-8"))
        self.errors = []

    #: report columns of one value for every block, name -> text (the work datum's error)
    constant_columns: dict = {}

    def add(self, chunk: Chunk) -> None:
        self.out.write(chunk.text.encode("latin-1"))
        if self.report:
            rows = report_rows(self.model, chunk)
            if self.constant_columns:
                rows = rows.replace("\n", "," + ",".join(self.constant_columns.values()) + "\n")
            self.report.write(rows.encode("utf-8"))
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
    require_file(p, f"program not found: {path}")
    return lambda: open(p, encoding="latin-1", newline="")


# ---------------------------------------------------------------------------------------
# a program as text: the compensated text and a report per block
@dataclass
class LineReport:
    """Predicted error of one motion block before and after compensation."""

    line: int
    nominal: dict
    output: dict
    before_um: tuple
    after_um: tuple
    orientation_before_urad: float
    orientation_after_urad: float
    iterations: int
    status: str
    #: standard uncertainty (k = 1) of the remaining error, from the tables' Type A std,
    #: per axis x y z (NaN when the tables carry none)
    u_after_um: tuple = (math.nan,) * 3


@dataclass
class Result:
    text: str
    reports: list = field(default_factory=list)
    #: rotary axes the program never commands, taken at 0 deg (their zero, as after homing)
    assumed_zero: tuple = ()
    #: the summary of the run, computed once as the chunks stream through (the command's
    #: ``--json`` numbers: :class:`Summary`)
    streamed: dict = field(default_factory=dict)

    def summary(self) -> dict:
        """The summary dict (``motion_blocks``, ``compensated``, ``max_before_um`` ...,
        ``tcpm_blocks``, ``arcs``), a copy of the one :class:`Summary` computed."""
        import copy

        return copy.deepcopy(self.streamed)


class _Collect:
    """Sink of :func:`run` that keeps the text and a report per block."""

    def __init__(self, model):
        self.model = model

    def start(self):
        self.text, self.reports = [], []

    def add(self, chunk) -> None:
        axes = self.model.axes
        b, p = chunk.blocks, chunk.prediction
        self.text.append(chunk.text)
        q_nom, q_out = b.q_nom.tolist(), chunk.q_out.tolist()
        rows = b.numbers.tolist()
        for o in b.order:
            if o >= 0:
                self.reports.append(LineReport(
                    rows[o], dict(zip(axes, q_nom[o])), dict(zip(axes, q_out[o])),
                    tuple(p.before_um[o]), tuple(p.after_um[o]),
                    float(p.orientation_before_urad[o]), float(p.orientation_after_urad[o]),
                    int(chunk.solution.iterations[o]), chunk.status(o), tuple(p.u_after_um[o])))
            else:
                line, target, missing = b.pending[-1 - o]
                self.reports.append(LineReport(
                    line.number, dict(target), dict(target), (math.nan,) * 3, (math.nan,) * 3,
                    math.nan, math.nan, 0, f"not compensated: position of {missing} unknown"))


def compensate_program(model, funcs, text: str, tool=(0.0, 0.0, 0.0), orientation: bool = False,
                       strategy: str = "full", tol_um: float = 0.1, decimals: int = 4,
                       initial: dict | None = None, check_travel: bool = True,
                       max_iter: int = 50, types=None, chunk_lines: int | None = None,
                       arc_tol_um: float = 1.0, tool_length: float | None = None,
                       tool_table: dict | None = None, dialect: str = "auto",
                       datum=None, decimal_less: str = "auto") -> Result:
    """Compensate a G-code program (text decoded as latin-1) -> :class:`Result`.

    ``types``: ISO/TR 16907 compensation types to apply (e.g. ``("L-VOL",)`` for a controller
    that compensates the linear axes only); the report still predicts the error of the full
    model, so it shows what the other types leave.  Default: all (L-VOL + R-VOL).
    ``chunk_lines``: lines per chunk (the output does not depend on it; :func:`run` also
    streams a program file of any length).  ``arc_tol_um``: path tolerance of arcs
    (:mod:`volerr.fiveaxis.arc_compensation`); ``tool_length`` (mm) or ``tool_table`` (tool
    number -> mm): the tool length of TCPM blocks (:mod:`volerr.nc.tcpm`); ``dialect``:
    "auto", "iso" or "heidenhain".  ``datum``: the work datum, the axis positions (layout
    order, mm / deg) where the work offset was set (by probing the part), or None: the
    corrections are then relative to the error at the datum, which the work offset absorbs
    (:meth:`volerr.fiveaxis.compensate.ErrorModel.relative_to`; ``volerr compensate
    --datum``).  ``decimal_less``: "auto" (a Fanuc-style program's axis or arc number without
    a decimal point is refused) or "mm" (``volerr compensate --decimal-less``)."""
    import io

    opts = Options(tool, orientation, strategy, tol_um, decimals, dict(initial or {}),
                   check_travel, max_iter, None if types is None else tuple(types),
                   arc_tol_um, tool_length, tool_table, dialect,
                   None if datum is None else tuple(float(v) for v in datum), decimal_less)
    sink = _Collect(model)
    s, never = run(lambda: io.StringIO(text, newline=""), model, funcs, opts, sink,
                   chunk_lines or CHUNK_LINES)
    return Result("".join(sink.text), sink.reports, never, s)
