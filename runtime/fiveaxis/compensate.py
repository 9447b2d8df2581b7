"""Compensation of NC programs: rewrite axis positions so the actual tool tip lands on the nominal.

Problem
-------
A motion block commands axis positions ``q`` (mm / deg).  Without compensation the tool tip
lands at ``p(q) + e(q)`` in the workpiece frame, with ``p`` the nominal forward kinematics and
``e`` the volumetric error of the layout's model evaluated with the error functions of the
error directory (component errors of every axis, linear and rotary, squareness, location
errors).  Compensation finds ``q'`` with ``p(q') + e(q') = p(q)``: the tool tip lands where the
program meant it to be.

Strategies
----------
``full`` (default)
    Solve the equation above on the complete model -- the angular errors of the linear axes
    included, the exact (not linearised) chain, errors re-evaluated at the corrected position
    -- by the iteration ``X' <- X' - M^-1 (p(q') + e(q') - p(q))`` on the linear axes, with
    ``M = dp/d(X, Y, Z)`` (exact: ``p`` is affine in the linear axes), until the correction
    changes by less than ``tol`` (default 0.1 um).  The rotary axes keep their programmed
    values (the tool orientation is not changed), as in ISO/TR 16907 L-VOL + R-VOL.
    With ``orientation=True`` the rotary axes are also corrected so that the actual tool axis
    equals the nominal one (functional orientation, L-VOL+ / R-VOL+), then the linear axes
    restore the tool tip.  Two rotary axes can turn the tool axis about two directions; near a
    singular orientation (e.g. B = 0 on the DMU 50, where C does not tilt the tool) only the
    component they can reach is corrected (truncated SVD, :data:`ORIENTATION_RCOND`) and the
    rest is reported.
``thesis``
    The strategy of Ellingsdalen (2021) sec. 3.5 (Figure 3.9), for comparison: the deviation
    caused by the rotary-axis errors is computed at the programmed position and subtracted
    from X Y Z; then the deviation caused by the translational errors and squareness of the
    linear axes (their angular errors neglected) is computed at these coordinates and
    subtracted; no iteration.  The report shows what it leaves on the full model.

Rounding: corrected positions are written with at least ``decimals`` decimals (default 4:
0.1 um, 0.0001 deg) and never fewer than the programmed word had; rotary values are rounded
first and the linear axes solved again for the rounded rotary values.  The "after" error in
the report is that of the values actually written.  Since the tip moves with the linear axes
through an orthogonal matrix (for orthogonal linear axes), rounding each axis to the nearest
step is already the best grid point: at 4 decimals the written program leaves at most
sqrt(3)/2 x 0.1 um = 0.087 um of rounding error (use ``decimals=5`` where the controller takes
it).

ISO/TR 16907 types: ``types`` restricts the compensation to some of the types of the thesis'
sec. 2.9.1 (``L-POS L-STR L-SQU L-ANG R-POS R-RAX R-POR R-ANG``, groups ``L-VOL R-VOL``; FOR is
``orientation``), e.g. to predict what a controller that only does L-VOL leaves; the report
always evaluates the full model (:func:`parameter_types` says which parameter is which).

Error tables: positions outside a table's measured range are refused unless extrapolation is
asked for.  An endless rotary axis (travel >= 720 deg) whose table covers less than a turn is
closed over the turn (:func:`close_periodic`): the gap, e.g. 340..360 deg, is interpolated
towards the value at 0 deg; a position such as C = 400 deg is looked up at 40 deg.

Bytes: only the numbers of axis words change.  A word is added to a block only where an axis
that the block does not program needs a value different from the one the controller holds
(in ``G91``, a non-zero increment).  With zero errors the output is byte-identical.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, require
from ..machine.kinematics import linear_axes, linear_jacobian, rotary_jacobian
from ..machine import iso_names

STRATEGIES = ("full", "thesis")

#: ISO/TR 16907 compensation types (thesis sec. 2.9.1) and the groups that combine them
TYPES = ("L-POS", "L-STR", "L-SQU", "L-ANG", "R-POS", "R-RAX", "R-POR", "R-ANG")
TYPE_GROUPS = {"L-VOL": ("L-POS", "L-STR", "L-SQU", "L-ANG"),
               "R-VOL": ("R-POS", "R-RAX", "R-POR", "R-ANG")}


def parameter_types(model) -> dict:
    """ISO name -> the ISO/TR 16907 compensation types that address it.

    Linear axis ``A``: ``EAA``-like positioning (``EXX``) L-POS, straightness L-STR, angular
    L-ANG; squareness L-SQU.  Rotary axis ``R``: translational error motions R-RAX (radial and
    axial), location and orientation errors R-POR, angular positioning R-POS, tilt R-ANG.  For
    a rotary axis not aligned with x, y or z (the DMU 50's B) the angular error motions about
    x, y, z each mix positioning and tilt: they belong to both R-POS and R-ANG."""
    out = {}
    paxis = model.parameter_axis
    lin = linear_axes(model)
    for p in model.parameters:
        a, iso = paxis[p], iso_names.parse(p)
        if iso.kind == "effect":
            out[p] = ()            # effect parameters of augmented layouts: no ISO/TR 16907 type
        elif a is None:
            out[p] = ("L-SQU",) if iso.axis in lin else ("R-POR",)
        elif a not in model.rotary_axes:
            out[p] = ("L-POS",) if iso.direction == a else \
                ("L-STR",) if iso.is_length else ("L-ANG",)
        elif iso.is_length:
            out[p] = ("R-RAX",)
        else:
            u = np.abs(np.asarray(model.layout.axes[a].direction, dtype=float))
            aligned = abs(u.max() - 1.0) < 1e-12
            own = "ABC"[int(np.argmax(u))] if aligned else None
            out[p] = ("R-POS", "R-ANG") if own is None else \
                ("R-POS",) if iso.direction == own else ("R-ANG",)
    return out


def parameters_for_types(model, types) -> set | None:
    """The parameters compensated by the ISO/TR 16907 ``types`` (names or groups L-VOL,
    R-VOL); None (all) when ``types`` is None."""
    if types is None:
        return None
    wanted = set()
    for t in types:
        t = t.strip().upper()
        require(t in TYPES or t in TYPE_GROUPS,
                f"unknown compensation type {t!r} (use {' '.join(TYPES)} or L-VOL R-VOL)")
        wanted.update(TYPE_GROUPS.get(t, (t,)))
    return {p for p, ts in parameter_types(model).items() if wanted.intersection(ts)}


# ---------------------------------------------------------------------------------------
# error functions with endless rotary axes closed over the full turn
def endless_axes(model) -> tuple[str, ...]:
    """Rotary axes that turn endlessly: travel of at least one turn each way (>= 720 deg)."""
    return tuple(a for a in model.rotary_axes
                 if model.travel[a][1] - model.travel[a][0] >= 720.0 - 1e-9)


def close_periodic(tables_: dict, model) -> tuple[dict, list[str]]:
    """For an endless rotary axis whose table covers less than a turn (e.g. 0..340 deg in 20 deg
    steps), add the first row again one turn later (360 deg): the error at 360 deg is the error
    at 0 deg, so positions in the gap are interpolated between measured values, not
    extrapolated.  Returns the tables and a note per closed axis."""
    from ..tables.table import ErrorTable

    out, notes = dict(tables_), []
    for a in endless_axes(model):
        t = tables_.get(a)
        if t is None:
            continue
        lo, hi = float(t.positions[0]), float(t.positions[-1])
        if hi - lo >= 360.0 - 1e-9:
            continue
        out[a] = ErrorTable(a, np.r_[t.positions, lo + 360.0],
                            {k: np.r_[v, v[0]] for k, v in t.values.items()},
                            {k: np.r_[v, v[0]] for k, v in t.std.items()},
                            {k: np.r_[v, v[0]] for k, v in t.u95.items()})
        notes.append(f"table {a} ({lo:g}..{hi:g} deg) closed over the full turn: "
                     f"{hi:g}..{lo + 360:g} deg interpolated towards the value at {lo:g} deg")
    return out, notes


def error_functions(directory, model, method: str = "linear", degree=None,
                    extrapolate: bool = False, accept_implausible: bool = False):
    """:class:`volerr.tables.functions.ErrorFunctions` of an error directory, endless rotary axes closed
    over the full turn (:func:`close_periodic`).  Returns (functions, notes).  Values beyond
    what a machine of ``model``'s travel can have are refused unless ``accept_implausible``
    (:mod:`volerr.tables.plausible`)."""
    from ..tables.functions import ErrorFunctions
    from ..tables.table import read_error_dir

    tabs, (consts, cstd, cu95) = read_error_dir(directory, model.axes, machine=model,
                                                accept_implausible=accept_implausible)
    tabs, notes = close_periodic(tabs, model)
    cstd = {**{k: v / 2.0 for k, v in cu95.items()}, **cstd}
    return ErrorFunctions(tabs, consts, model, method, degree, extrapolate, constants_std=cstd,
                          source=str(directory)), notes


# ---------------------------------------------------------------------------------------
# the error model on axis positions
class ErrorModel:
    """Actual tool tip and tool axis of a model with error functions (mm, deg at the API)."""

    def __init__(self, model, funcs=None, tool=(0.0, 0.0, 0.0), compensated=None):
        self.model, self.funcs = model, funcs
        #: the parameters the compensation acts on (None: all); the report uses all
        self.compensated = compensated
        self.tool = np.asarray(tool, dtype=float)
        self.rot = model.rotary_axes
        self.lin = linear_axes(model)
        self.ranges = funcs.ranges() if funcs is not None else {}

    def with_tool(self, tool) -> "ErrorModel":
        """The same model with another tool offset (3,) mm (error values shared)."""
        import copy

        other = copy.copy(self)
        other.tool = np.asarray(tool, dtype=float)
        other.__dict__["_memo"] = self.__dict__.setdefault("_memo", [])
        return other

    def lookup(self, q: np.ndarray) -> np.ndarray:
        """Positions for the error tables: a rotary axis is taken modulo 360 deg where that
        brings it into its table's range (a C table 0..340 serves C = 400)."""
        q = np.array(q, dtype=float, copy=True)
        for a in self.rot:
            if a in self.ranges:
                lo, hi = self.ranges[a]
                i = self.model.axes.index(a)
                inside = (q[:, i] >= lo) & (q[:, i] <= hi)
                if inside.all():
                    continue        # (the usual case: nothing to take modulo 360)
                w = lo + np.mod(q[:, i] - lo, 360.0)
                q[:, i] = np.where(~inside & (w <= hi), w, q[:, i])
        return q

    def admissible(self, q: np.ndarray) -> np.ndarray:
        """Rows whose rotary positions lie inside the travel and (unless extrapolating) inside
        the range of their error tables."""
        ok = np.ones(len(q), dtype=bool)
        ql = self.lookup(q)
        for a in self.rot:
            i = self.model.axes.index(a)
            lo, hi = self.model.travel[a]
            ok &= (q[:, i] >= lo) & (q[:, i] <= hi)
            if a in self.ranges and not self.funcs.extrapolate:
                lo, hi = self.ranges[a]
                ok &= (ql[:, i] >= lo) & (ql[:, i] <= hi)
        return ok

    #: how far (mm, deg) a compensated position may pass the end of its error table: the
    #: nominal positions are checked against the tables' ranges, the correction (um) may then
    #: push a block at the end of a table just past it; the end value is used there
    EDGE_MARGIN = {"linear": 1.0, "rotary": 0.1}

    def _clip_edges(self, q: np.ndarray) -> np.ndarray:
        if self.funcs is None or self.funcs.extrapolate:
            return q
        if self._inside_ranges(q):
            return q                # (the usual case: no position beyond the tables)
        q = q.copy()
        for a, (lo, hi) in self.ranges.items():
            i = self.model.axes.index(a)
            m = self.EDGE_MARGIN["rotary" if a in self.rot else "linear"]
            v = q[:, i]
            if not len(v) or (v.min() >= lo and v.max() <= hi):
                continue            # (the usual case: no position beyond the table)
            near = ((v < lo) & (v >= lo - m)) | ((v > hi) & (v <= hi + m))
            q[:, i] = np.where(near, np.clip(v, lo, hi), v)
        return q

    def _inside_ranges(self, q: np.ndarray) -> bool:
        """Whether every position of ``q`` (N, n_axes) lies inside its table's range (the
        bounds as columns, built once)."""
        b = self.__dict__.get("_bounds")
        if b is None or b[0] is not self.ranges:
            axes = self.model.axes
            b = self.__dict__["_bounds"] = (
                self.ranges, [axes.index(a) for a in self.ranges],
                np.array([lo for lo, _ in self.ranges.values()]),
                np.array([hi for _, hi in self.ranges.values()]))
        sub = q[:, b[1]]
        return bool((sub >= b[2]).all() and (sub <= b[3]).all())

    def errors(self, q: np.ndarray, subset=None, direction=None) -> dict:
        """Error functions at ``q`` (the last three evaluations are remembered: the position and
        the orientation error of the same positions share one table look-up, and the
        prediction after a solve of two iterations finds the programmed positions still
        there).  ``direction`` (N, n_axes) -1 / 0 / +1: the approach direction of every axis,
        for tables with a reversal column
        (:meth:`volerr.tables.functions.ErrorFunctions.reversal`)."""
        if self.funcs is None:
            return {}
        if direction is not None and not self.funcs.has_reversal:
            direction = None
        e = _recall(self.__dict__.setdefault("_memo", []), (q, direction),
                    lambda: self._evaluate_tables(q, direction))
        if subset is not None:
            e = {k: v for k, v in e.items() if k in subset}
        return e

    def prepared(self, q: np.ndarray):
        """``q`` validated with the sines and cosines of its rotary axes
        (:meth:`volerr.machine.model.Model.prepared`), shared by the evaluations at the same
        positions (the last three are remembered, as in :meth:`errors`)."""
        return _recall(self.__dict__.setdefault("_prepared", []), (q,),
                       lambda: self.model.prepared(q))

    def _evaluate_tables(self, q: np.ndarray, direction) -> dict:
        """The error functions at ``q`` (see :meth:`errors`), not remembered."""
        ql = self._clip_edges(self.lookup(q))
        tables = getattr(self.funcs, "table_values", None)
        e = tables(ql)[0] if tables is not None else self.funcs(ql)
        # constants as scalars: the generated code then takes their sin/cos once
        e.update({k: float(v) for k, v in self.funcs.constants.items()})
        if direction is not None:
            for k, v in self.funcs.reversal(ql, direction).items():
                e[k] = e[k] + v if k in e else v
        return e

    def nominal_position(self, q) -> np.ndarray:
        """Nominal tool tip with the tool offset, (N, 3) mm."""
        return self.model.nominal_position(self.prepared(q), self.tool)

    def position_error(self, q, subset=None, direction=None) -> np.ndarray:
        """Exact error of the tool tip, (N, 3) mm (``direction``: see :meth:`errors`); with a
        work datum (:meth:`relative_to`) minus the error at the datum."""
        e = self.model.exact_error(self.prepared(q), self.errors(q, subset, direction),
                                   probe=self.tool)
        if self.datum is not None:
            e = e - self.datum_error(subset)
        return e

    # -- the work datum -------------------------------------------------------------------
    #: axis positions (1, n_axes) where the work offset was set by probing the part zero, or
    #: None (errors relative to the machine's reference, the tables' own zero)
    datum = None

    def relative_to(self, datum) -> "ErrorModel":
        """The same model with errors relative to the work datum ``datum`` (n_axes,) mm / deg:
        the work offset, set by probing the part zero there, has absorbed the tool-tip error
        at the datum (a translation of the workpiece frame), so only ``e(q) - e(datum)`` is
        left to compensate.  The datum's error is evaluated with the model's tool offset
        (the part zero touched with the tool point) and without reversal (the approach of
        the probing is not known); the tool axis error is not changed by a work offset."""
        other = self.with_tool(self.tool)
        other.datum = np.asarray(datum, dtype=float).reshape(1, -1)
        other._datum_errors = {}
        return other

    def datum_error(self, subset=None) -> np.ndarray:
        """Tool-tip error at the work datum, (3,) mm, of the parameters ``subset`` (None:
        all); zeros without a datum."""
        if self.datum is None:
            return np.zeros(3)
        key = (None if subset is None else frozenset(subset), tuple(self.tool))
        cache = self.__dict__.setdefault("_datum_errors", {})
        if key not in cache:
            d = self.datum
            cache[key] = self.model.exact_error(self.prepared(d), self.errors(d, subset),
                                                probe=self.tool)[0]
        return cache[key]

    def orientation_error(self, q, subset=None, direction=None) -> np.ndarray:
        """First-order error of the tool axis, (N, 3) rad."""
        if not self.rot:
            return np.zeros((len(q), 3))
        return self.model.orientation_error(self.prepared(q),
                                            self.errors(q, subset, direction))

    def tool_axis(self, q) -> np.ndarray:
        """Nominal unit tool axis, (N, 3) (it does not depend on the tool offset)."""
        return self.model.tool_axis(self.prepared(q))


def _same(a, b) -> bool:
    """Both None, or arrays of one shape with equal values."""
    if a is None or b is None:
        return a is b
    if type(a) is np.ndarray and type(b) is np.ndarray:    # (np.array_equal without its checks)
        return a.shape == b.shape and bool((a == b).all())
    return np.shape(a) == np.shape(b) and np.array_equal(a, b)


def _recall(memo: list, keys: tuple, compute):
    """``compute()``, or its value remembered in ``memo`` from one of the last three calls
    with equal array ``keys`` (None allowed); the keys are kept as copies, so a caller may
    change its arrays afterwards."""
    for kept, value in memo:
        if all(_same(a, b) for a, b in zip(kept, keys)):
            return value
    value = compute()
    memo.insert(0, (tuple(None if k is None else np.array(k, copy=True) for k in keys), value))
    del memo[3:]
    return value


#: a tool-axis direction that the rotary axes turn by less than this (rad per rad) is left
#: uncorrected: near a singular orientation (within about 3 deg of it on the DMU 50) the
#: correction would need large rotary motions for a few urad
ORIENTATION_RCOND = 0.05


def _truncated_solve(j: np.ndarray, r: np.ndarray, rcond: float = ORIENTATION_RCOND):
    """Least-squares x of j x = r per row, singular directions (sigma < rcond) dropped; also
    returns per row whether a direction was dropped."""
    u, s, vt = np.linalg.svd(j, full_matrices=False)
    inv = np.where(s > rcond, 1.0 / np.where(s > rcond, s, 1.0), 0.0)
    y = inv * np.einsum("nji,nj->ni", u, r)   # diag(1/s) U^T r
    return np.einsum("nji,nj->ni", vt, y), np.any(s <= rcond, axis=1)     # V y


def solve_linear(j: np.ndarray, r: np.ndarray) -> np.ndarray:
    """x of j x = r per row, j (N, k, k), r (N, k).  For k = 3 (the linear axes of every
    shipped layout) by the adjugate, column arrays at a time: the batched LAPACK solve spends
    most of its time per 3x3 matrix, not per flop (the linear Jacobians are rotations and
    shears of the axes: well conditioned, so the explicit inverse loses nothing)."""
    if j.shape[1:] != (3, 3):
        return np.linalg.solve(j, r[:, :, None])[:, :, 0]
    a, b, c, d, e, f, g, h, i = np.ascontiguousarray(j.reshape(-1, 9).T)
    A, B, C = e * i - f * h, f * g - d * i, d * h - e * g       # cofactors of the first row
    det = a * A + b * B + c * C
    if not np.all(det != 0.0):
        raise np.linalg.LinAlgError("Singular matrix")
    r0, r1, r2 = np.ascontiguousarray(r.T)
    return np.column_stack([(A * r0 + (c * h - b * i) * r1 + (b * f - c * e) * r2),
                            (B * r0 + (a * i - c * g) * r1 + (c * d - a * f) * r2),
                            (C * r0 + (b * g - a * h) * r1 + (a * e - b * d) * r2)]) \
        / det[:, None]


def solve(em: ErrorModel, q_nom: np.ndarray, orientation: bool = False, tol: float = 1e-4,
          max_iter: int = 50, direction=None, out: dict | None = None):
    """Corrected positions (N, n) for programmed ``q_nom``, the iteration count per row, and
    per row whether the orientation correction was limited: stopped because a rotary axis would
    have left its travel or its error table, or partial near a singular orientation.

    Iterates until the change of the correction is below ``tol`` (mm; rotary axes weighted by a
    1 m lever).  ``direction`` (N, n) -1 / 0 / +1: the approach direction of each axis in each
    row (tables with reversal; the corrected positions are approached as the programmed
    ones).  ``out``: a dict that gets ``target`` (N, 3), the nominal tool tip, with the
    orientation also ``tool_axis`` (N, 3), the nominal tool axis, and -- when the first
    iteration evaluates the whole model at the programmed positions (no orientation, no
    restriction to some types) -- ``before`` (N, 3), the error there (mm)."""
    m = em.model
    q_nom = np.atleast_2d(np.asarray(q_nom, dtype=float))
    n = len(q_nom)
    lin_idx = [m.axes.index(a) for a in em.lin]
    rot_idx = [m.axes.index(a) for a in em.rot]
    target_p = em.nominal_position(q_nom)
    if out is not None:
        out["target"] = target_p
    target_k = em.tool_axis(q_nom) if orientation and em.rot else None
    if out is not None and target_k is not None:
        out["tool_axis"] = target_k
    q = q_nom.copy()
    iters = np.zeros(n, dtype=int)
    active = np.ones(n, dtype=bool)
    limited = np.zeros(n, dtype=bool)
    partial = np.zeros(n, dtype=bool)
    turns = orientation and bool(em.rot)       # the rotary positions move
    mj = None
    for it in range(1, max_iter + 1):
        qa = q[active]
        da = None if direction is None else direction[active]
        change = np.zeros(len(qa))
        if turns:
            k_act = em.tool_axis(qa) + em.orientation_error(qa, em.compensated, da)
            j = rotary_jacobian(m, qa)
            d, dropped = _truncated_solve(j, -(k_act - target_k[active]))
            partial[np.flatnonzero(active)] = dropped
            trial = qa.copy()
            trial[:, rot_idx] += np.rad2deg(d)
            ok = em.admissible(trial)
            limited[np.flatnonzero(active)[~ok]] = True
            d[~ok] = 0.0
            qa[ok] = trial[ok]
            change = np.maximum(change, np.abs(d).max(axis=1) * 1000.0)
        # the first iteration without turning starts at the programmed positions, whose
        # nominal tip is the target
        tip = target_p if it == 1 and not turns else em.nominal_position(qa)
        e = tip + em.position_error(qa, em.compensated, da) - target_p[active]
        if it == 1 and out is not None and not orientation and em.compensated is None:
            out["before"] = e.copy()        # nominal(q_nom) - target is exactly 0
        # d(tip)/d(linear axes) depends on the rotary positions only (the nominal chain is
        # affine in the linear axes; tests/fiveaxis/test_compensate.py checks the generated
        # Jacobians): without turning, the first iteration's serves them all
        if mj is None or turns:
            mj = linear_jacobian(m, qa, em.tool)
        d = -solve_linear(mj, e)
        qa[:, lin_idx] += d
        change = np.maximum(change, np.abs(d).max(axis=1))
        q[active] = qa
        idx = np.flatnonzero(active)
        iters[idx] = it
        done = change < tol
        active[idx[done]] = False
        if not active.any():
            break
        mj = mj[~done]
    if active.any():
        raise InputError(f"compensation did not converge in {max_iter} iterations (the errors "
                         "are too large or the position is singular)")
    return q, iters, limited | partial


def solve_thesis(em: ErrorModel, q_nom: np.ndarray, direction=None) -> np.ndarray:
    """Ellingsdalen's strategy (rotary errors first, then linear translational errors and
    squareness; angular errors of the linear axes neglected; no iteration)."""
    m = em.model
    q_nom = np.atleast_2d(np.asarray(q_nom, dtype=float))
    lin_idx = [m.axes.index(a) for a in em.lin]
    paxis = m.parameter_axis
    iso = {p: iso_names.parse(p) for p in m.parameters}
    rotary_params = {p for p in m.parameters
                     if paxis[p] in em.rot or (paxis[p] is None and iso[p].kind == "location"
                                               and iso[p].axis in em.rot)}
    linear_params = {p for p in m.parameters if paxis[p] in em.lin and iso[p].is_length}
    linear_params |= {p for p in m.parameters if paxis[p] is None and p not in rotary_params}
    q1 = q_nom.copy()
    mj = linear_jacobian(m, q_nom, em.tool)
    if em.rot:
        e_rot = em.position_error(q_nom, rotary_params, direction)
        q1[:, lin_idx] -= solve_linear(mj, e_rot)
    e_lin = em.position_error(q1, linear_params, direction)
    q2 = q1.copy()
    q2[:, lin_idx] -= solve_linear(linear_jacobian(m, q1, em.tool), e_lin)
    return q2


def resolve_linear(em: ErrorModel, q_nom, q_out, tol, max_iter, direction=None) -> np.ndarray:
    """Linear axes solved again for the (rounded) rotary values of ``q_out``; each row
    iterates until its own correction changes by less than ``tol`` (mm)."""
    m = em.model
    lin_idx = [m.axes.index(a) for a in em.lin]
    target_p = em.nominal_position(q_nom)
    q = q_out.copy()
    active = np.ones(len(q), dtype=bool)
    mj = None
    for _ in range(max_iter):
        qa = q[active]
        da = None if direction is None else direction[active]
        e = em.nominal_position(qa) + em.position_error(qa, em.compensated, da) \
            - target_p[active]
        if mj is None:      # the rotary positions stay: one Jacobian (see solve)
            mj = linear_jacobian(m, qa, em.tool)
        d = -solve_linear(mj, e)
        qa[:, lin_idx] += d
        q[active] = qa
        idx = np.flatnonzero(active)
        done = np.abs(d).max(axis=1) < tol
        active[idx[done]] = False
        if not active.any():
            break
        mj = mj[~done]
    return q
