"""Error functions of position from the error tables of a directory.

:class:`ErrorFunctions` turns the tables of a directory into functions of position:
``method="linear"`` (piecewise linear interpolation), ``"cubic"`` (not-a-knot cubic spline,
exact at the nodes) or ``"poly"`` (least-squares polynomial; the degree is given, or chosen per
parameter by leave-one-out cross-validation with the one-standard-error rule: the lowest degree
whose prediction error is within one standard error of the best).  Positions outside a table's
measured range raise :class:`InputError`; with ``extrapolate=True`` the fitted function itself
is evaluated there (linear: the end segment extended; cubic: the end polynomial of the spline;
poly: the polynomial).  Standard uncertainties are always interpolated linearly (clamped at the
ends); a ``u95`` column without ``std`` gives ``std = u95 / 2``; :meth:`ErrorFunctions.sigmas`
combines a table's ``_std`` (uncertainty of the tabulated value) and ``_s`` (repeatability of
one reading) in quadrature: the standard uncertainty of the error at a position for one
reading.

Units: positions mm (linear axes) / deg (rotary axes); errors and standard deviations mm
(translational) / rad (angular).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, require
from . import legendre
from .table import axis_unit, read_error_dir


# ---------------------------------------------------------------------------------------------
# fitting
def loo_press(x, y, degree: int) -> np.ndarray:
    """Leave-one-out prediction errors of a least-squares polynomial of ``degree`` (hat matrix);
    :func:`volerr.tables.legendre.loo_errors`."""
    return legendre.loo_errors(x, y, degree)


def choose_degree(x, y, max_degree: int | None = None) -> int:
    """Polynomial degree by leave-one-out cross-validation with the one-standard-error rule;
    :func:`volerr.tables.legendre.choose_degree`."""
    return legendre.choose_degree(x, y, max_degree)


class _LinearGroup:
    """Piecewise-linear functions sharing their nodes ``x`` (the parameters of one axis' table),
    evaluated together: one bracket search for all of them, then one gather per value row.
    Inside the range the values are ``numpy.interp``'s (same slope formula, same operation
    order); outside it the end segments are extended, or with ``clamp`` the end values are kept
    (numpy.interp's rule).  ``__call__(q)`` with q (N,) -> (n_functions, N)."""

    def __init__(self, x, ys, clamp: bool = False):
        self.clamp = clamp
        self.x = np.asarray(x, float)
        self.y = np.array([np.asarray(y, float) for y in ys]).reshape(len(ys), -1)
        step = np.diff(self.x)
        self.slope = np.diff(self.y, axis=1) / step
        #: evenly spaced positions: the bracket comes from arithmetic, then is checked
        self.inv_step = 1.0 / step.mean() if np.allclose(step, step.mean(), rtol=1e-9) else None

    def bracket(self, q: np.ndarray) -> np.ndarray:
        """Segment index j per position: x[j] <= q < x[j+1], clipped to the end segments
        (the same j as a binary search)."""
        x, last = self.x, len(self.x) - 2
        if self.inv_step is None:
            return np.clip(np.searchsorted(x, q, side="right") - 1, 0, last)
        return _bracket_even(x, q, x[0], self.inv_step, last)

    def __call__(self, q) -> np.ndarray:
        x, y, slope = self.x, self.y, self.slope
        q = np.asarray(q, float)
        j = self.bracket(q)
        out = np.take(slope, j, axis=1) * (q - x.take(j)) + np.take(y, j, axis=1)
        last = q >= x[-1]
        if last.any():
            out[:, last] = y[:, -1:] if self.clamp else \
                y[:, -1:] + (q[last] - x[-1]) * (y[:, -1:] - y[:, -2:-1]) / (x[-1] - x[-2])
        first = q < x[0]
        if first.any():
            out[:, first] = y[:, :1] if self.clamp else \
                y[:, :1] + (q[first] - x[0]) * (y[:, 1:2] - y[:, :1]) / (x[1] - x[0])
        return out


def _range_tolerance(lo: float, hi: float) -> float:
    """How far beyond a table's measured range ``lo`` .. ``hi`` (mm / deg) a position still
    counts as inside (rounding of positions written to a few decimals)."""
    return 1e-9 * max(1.0, hi - lo)


def _bracket_even(x, q, first, inv_step, last, off=None):
    """Segment index j per position on evenly spaced nodes ``x``: x[j] <= q < x[j+1],
    clipped to the end segments (the same j as a binary search).  ``first``, ``inv_step``,
    ``last`` (the last segment's index) scalars for one axis, or columns (n_axes, 1) with
    ``off`` each axis' first index into the concatenated ``x`` (:class:`_LinearStack`)."""
    j = np.minimum(np.maximum((q - first) * inv_step, 0), last).astype(np.intp)
    lo = 0
    if off is not None:
        j += off
        lo, last = off, off + last
    j -= (x.take(j) > q) & (j > lo)          # rounding may put q one segment off
    j += (x.take(j + 1) <= q) & (j < last)
    return j


#: up to this many positions the linear functions of all axes are evaluated at once
#: (:class:`_LinearStack`: a few numpy calls in all instead of some twenty per axis); beyond
#: it axis by axis (the stacked gathers copy (n_functions, N) arrays: slower on long chunks,
#: 20000 positions 18 -> 22 ms)
STACK_POINTS = 256


class _LinearStack:
    """The :class:`_LinearGroup` s of several axes evaluated at once, for the per-call cost
    of a few positions (a compensation chunk of one line): the brackets of all axes in one
    pass, then one gather of the slopes and values of every function.  Each value is the one
    its group gives (the same operands, the same operations in the same order); an axis with
    a position beyond its nodes, or whose nodes are not evenly spaced, is left to its group.
    ``__call__(Q)`` with Q (n_groups, N) -> list of (n_functions of the group, N)."""

    def __init__(self, groups: list):
        self.groups = groups
        self.even = all(g.inv_step is not None for g in groups)
        if not self.even:
            return
        col = lambda v: np.array(v)[:, None]   # noqa: E731  (one value per axis, a column)
        sizes = [len(g.x) for g in groups]
        self.x = np.concatenate([g.x for g in groups])
        self.off = col(np.cumsum([0] + sizes[:-1]))
        self.first, self.end = col([g.x[0] for g in groups]), col([g.x[-1] for g in groups])
        self.inv_step, self.last = col([g.inv_step for g in groups]), col([m - 2 for m in sizes])
        self.y = np.concatenate([g.y.ravel() for g in groups])
        self.slope = np.concatenate([g.slope.ravel() for g in groups])
        #: per function row: its group, where its values and its slopes start
        rows = [(a, k) for a, g in enumerate(groups) for k in range(len(g.y))]
        y0, s0 = np.cumsum([0] + [g.y.size for g in groups]), \
            np.cumsum([0] + [g.slope.size for g in groups])
        self.row_group = np.array([a for a, _ in rows], dtype=np.intp)
        self.row_y = col([y0[a] + k * sizes[a] for a, k in rows])
        self.row_slope = col([s0[a] + k * (sizes[a] - 1) for a, k in rows])
        ends = np.cumsum([0] + [len(g.y) for g in groups]).tolist()
        self.rows = list(zip(ends[:-1], ends[1:]))     # the rows of each group

    def __call__(self, Q: np.ndarray) -> list:
        if not self.even:
            return [g(q) for g, q in zip(self.groups, Q)]
        j = _bracket_even(self.x, Q, self.first, self.inv_step, self.last, self.off)
        d = (Q - self.x.take(j))[self.row_group]
        j -= self.off
        jr = j[self.row_group]
        out = self.slope.take(self.row_slope + jr) * d + self.y.take(self.row_y + jr)
        parts = [out[i:k] for i, k in self.rows]
        beyond = ((Q >= self.end) | (Q < self.first)).any(axis=1)
        for a in np.flatnonzero(beyond):     # the end segments: the group's own rule
            parts[a] = self.groups[a](Q[a])
        return parts


class _Linear:
    """One piecewise-linear function of position (a :class:`_LinearGroup` of one), for any
    shape of ``q``; ``clamp``: the end values outside the range instead of the end lines."""

    def __init__(self, x, y, clamp: bool = False):
        self.x, self.y = np.asarray(x, float), np.asarray(y, float)
        self._group = _LinearGroup(self.x, [self.y], clamp)

    def __call__(self, q):
        q = np.asarray(q, float)
        return self._group(q.ravel())[0].reshape(q.shape)


def make_function(x, y, method: str = "linear", degree: int | None = None):
    """One error function of position from nodes ``x`` (increasing) and values ``y``.

    Returns a callable; for ``method="poly"`` it has a ``degree`` attribute."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if method == "linear":
        return _Linear(x, y)
    if method == "cubic":
        from scipy.interpolate import CubicSpline
        return CubicSpline(x, y, bc_type="not-a-knot", extrapolate=True)
    if method == "poly":
        if degree is None:
            degree = choose_degree(x, y)
        require(0 <= degree < len(x), f"polynomial degree {degree} needs more than {degree} "
                                      f"positions, the table has {len(x)}")
        return legendre.LegendreFit(x, y, degree)
    raise InputError(f"unknown interpolation method {method!r} (linear, cubic, poly)")


from ..choices import INTERPOLATION as METHODS  # noqa: E402  (stated once, light)


class ErrorFunctions:
    """Error functions of a machine built from its error tables and constants.

    Call with positions (``{axis: array}`` in mm / deg, or an (N, n_axes) array in
    ``model.axes`` order) -> ``{name: (N,) array}`` in mm / rad for every parameter that has
    data (table parameters and constants), ready for ``model.volumetric_error``.
    :meth:`sigmas` gives the standard deviations the same way, for ``model.random_error``.

    Parameters
    ----------
    tables : dict
        Axis -> :class:`volerr.tables.ErrorTable` (positions mm / deg, values mm / rad).
    constants : dict or None
        ISO name (``EC0Y`` ...) -> constant error, mm or rad.
    model : volerr.Model or str
        The model whose parameters the tables must name (a layout name or file is loaded).
    method : {"linear", "cubic", "poly"}
        Interpolation between the table positions (``poly``: Legendre least squares).
    degree : int, optional
        Polynomial degree for ``poly`` (default: by leave-one-out cross-validation).
    extrapolate : bool
        Evaluate beyond a table's measured range (default: refuse with InputError).
    constants_std : dict, optional
        Standard deviations of the constants, mm or rad.
    source : str
        Where the data came from (error messages).
    """

    def __init__(self, tables: dict, constants: dict | None, model, method: str = "linear",
                 degree: int | None = None, extrapolate: bool = False,
                 constants_std: dict | None = None, source: str = ""):
        if isinstance(model, str):
            from ..machine.model import load
            model = load(model)
        require(method in METHODS, f"unknown interpolation method {method!r} (linear, cubic, poly)")
        require(degree is None or method == "poly", "a polynomial degree needs method 'poly'")
        require(degree is None or degree >= 0, f"polynomial degree must be >= 0, got {degree}")
        self.model, self.method, self.extrapolate = model, method, bool(extrapolate)
        self.source = source
        where = f"{source}: " if source else ""
        params, paxis = set(model.parameters), model.parameter_axis
        self.tables = dict(tables or {})
        self.constants = {k: float(v) for k, v in (constants or {}).items()}
        self.constants_std = {k: float(v) for k, v in (constants_std or {}).items()}
        for ax, t in self.tables.items():
            require(ax in model.axes, f"{where}table for axis {ax}, but {model.name} has axes "
                                      f"{' '.join(model.axes)}")
            for name in t.values:
                require(name in params and paxis.get(name) == ax,
                        f"{where}{ax}.csv: {model.name} has no parameter {name}")
        for name in list(self.constants) + list(self.constants_std):
            require(name in params and paxis.get(name) is None,
                    f"{where}constants: {model.name} has no constant parameter {name} "
                    f"(its constants are {' '.join(p for p in model.parameters if paxis[p] is None)})")
        self.functions, self.std_functions, self.degrees = {}, {}, {}
        for ax, t in self.tables.items():
            for name, y in t.values.items():
                try:
                    f = make_function(t.positions, y, method, degree)
                except InputError as exc:
                    raise InputError(f"{where}{ax}.csv {name}: {exc}") from None
                self.functions[name] = (ax, f)
                if method == "poly":
                    self.degrees[name] = f.degree
                s = t.std.get(name)
                if s is None and name in t.u95:
                    s = t.u95[name] / 2.0
                if name in t.s:  # repeatability of one reading, in quadrature
                    s = np.hypot(s if s is not None else 0.0, t.s[name])
                if s is not None:
                    self.std_functions[name] = (ax, _Linear(t.positions, s, clamp=True))
        #: reversal (ISO 230-2 B_i) of the axes whose table has an ``RV_<axis>`` column:
        #: axis -> (its positioning error E<A><A>, B_i as a function of position, mm)
        self.reversal_functions = {}
        for ax, t in self.tables.items():
            if t.reversal is None:
                continue
            name = f"E{ax}{ax}"
            require(ax not in model.rotary_axes and name in params and paxis.get(name) == ax,
                    f"{where}{ax}.csv: a reversal column RV_{ax} needs a linear axis with a "
                    f"positioning error {name} in {model.name}")
            self.reversal_functions[ax] = (name, _Linear(t.positions, t.reversal, clamp=True))

    @property
    def has_reversal(self) -> bool:
        """True when a table carries a reversal column (``RV_<axis>_um``)."""
        return bool(self.reversal_functions)

    def reversal(self, positions, direction) -> dict:
        """The direction-dependent part of the positioning errors: ``+B_i / 2`` approaching
        in the positive direction, ``-B_i / 2`` in the negative one, 0 where the direction is
        0 (unknown: the tabulated error is the bidirectional mean).  ``positions`` (N, n_axes)
        mm / deg and ``direction`` (N, n_axes) -1 / 0 / +1, both in ``model.axes`` order ->
        {E<A><A>: (N,) mm}."""
        q = np.atleast_2d(np.asarray(positions, dtype=float))
        d = np.atleast_2d(np.asarray(direction, dtype=float))
        axes = self.model.axes
        out = {}
        for ax, (name, f) in self.reversal_functions.items():
            i = axes.index(ax)
            out[name] = 0.5 * d[:, i] * f(q[:, i])
        return out

    @classmethod
    def from_dir(cls, directory, model, method: str = "linear", degree: int | None = None,
                 extrapolate: bool = False,
                 accept_implausible: bool = False) -> "ErrorFunctions":
        """Read an error directory (``X.csv`` ... ``constants.csv``) for ``model``; values
        beyond what a machine of the model's travel can have are refused unless
        ``accept_implausible`` (:mod:`volerr.tables.plausible`)."""
        if isinstance(model, str):
            from ..machine.model import load
            model = load(model)
        tables, (consts, cstd, cu95) = read_error_dir(directory, model.axes, machine=model,
                                                      accept_implausible=accept_implausible)
        cstd = {**{k: v / 2.0 for k, v in cu95.items()}, **cstd}
        return cls(tables, consts, model, method, degree, extrapolate, constants_std=cstd,
                   source=str(directory))

    # ---- evaluation ---------------------------------------------------------------------
    @property
    def has_random(self) -> bool:
        """True when any table or constant carries an uncertainty (_std, _s or u95)."""
        return bool(self.std_functions or self.constants_std)

    def ranges(self) -> dict:
        """Axis -> (min, max) measured position of its table."""
        return {ax: (float(t.positions[0]), float(t.positions[-1])) for ax, t in self.tables.items()}

    def _positions(self, positions) -> tuple[dict, int]:
        axes = self.model.axes
        if isinstance(positions, dict):
            unknown = set(positions) - set(axes)
            if unknown:
                raise InputError(f"unknown axis {sorted(unknown)[0]!r}; axes are {' '.join(axes)}")
            missing = [a for a in self.tables if a not in positions]
            require(not missing, f"positions lack axis {missing[0] if missing else ''}")
            cols = {a: np.atleast_1d(np.asarray(v, dtype=float)) for a, v in positions.items()}
        else:
            arr = np.asarray(positions, dtype=float)
            arr = arr[None, :] if arr.ndim == 1 else arr
            if not (arr.ndim == 2 and arr.shape[1] == len(axes)):
                raise InputError(f"positions must have {len(axes)} columns ({' '.join(axes)}), "
                                 f"got {arr.shape}")
            if np.isfinite(arr).all() and self._inside(arr):
                # (the usual case; the columns as below: contiguous, views where they are)
                return {a: arr[:, i].ravel() for i, a in enumerate(axes)}, len(arr)
            cols = {a: arr[:, i] for i, a in enumerate(axes)}
        shape = np.broadcast_shapes(*(v.shape for v in cols.values()))
        cols = {a: np.broadcast_to(v, shape).ravel() for a, v in cols.items()}
        n = int(np.prod(shape)) if shape else 1
        for a, v in cols.items():
            require(np.all(np.isfinite(v)), f"position {a} has NaN or infinite values")
        if not self.extrapolate:
            for ax, (lo, hi) in self.ranges().items():
                v = cols[ax]
                tol = _range_tolerance(lo, hi)
                if not len(v) or (v.min() >= lo - tol and v.max() <= hi + tol):
                    continue        # (finite values, all inside: the usual case)
                bad = (v < lo - tol) | (v > hi + tol)
                if bad.any():
                    u = axis_unit(ax)
                    x = v[bad][np.argmax(np.abs(v[bad] - 0.5 * (lo + hi)))]
                    from .table import range_cause

                    raise InputError(f"{range_cause(ax, lo, hi, float(x), self.source)}"
                                     f"{ax} = {x:g} {u} is outside the measured range "
                                     f"{lo:g} .. {hi:g} {u} of table {ax} (no extrapolation "
                                     f"unless asked for)")
        return cols, n

    def _inside(self, arr: np.ndarray) -> bool:
        """Whether the finite positions ``arr`` (N, n_axes) lie inside every table's measured
        range, with the tolerance of :meth:`_positions` (True with ``extrapolate``): one
        comparison of the table axes' columns with their bounds (built once per ranges)."""
        if self.extrapolate:
            return True
        cache = self.__dict__.setdefault("_bounds", {})
        key = tuple((ax, t.positions[0], t.positions[-1]) for ax, t in self.tables.items())
        if cache.get("key") != key:
            ranges = self.ranges()
            tol = {ax: _range_tolerance(lo, hi) for ax, (lo, hi) in ranges.items()}
            cache.update(key=key, idx=[self.model.axes.index(ax) for ax in ranges],
                         lo=np.array([lo - tol[ax] for ax, (lo, _) in ranges.items()]),
                         hi=np.array([hi + tol[ax] for ax, (_, hi) in ranges.items()]))
        sub = arr[:, cache["idx"]]
        return bool((sub >= cache["lo"]).all() and (sub <= cache["hi"]).all())

    def __call__(self, positions) -> dict:
        """Error values at ``positions`` ({axis: (N,)} or (N, n_axes), mm / deg): name -> (N,)
        array, mm / rad, for every table parameter and constant."""
        out, n = self.table_values(positions)
        out.update({k: np.full(n, v) for k, v in self.constants.items()})
        return out

    def table_values(self, positions) -> tuple[dict, int]:
        """:meth:`__call__` without the constants (for a caller that takes them as scalars:
        :meth:`volerr.fiveaxis.compensate.ErrorModel.errors`) -> (name -> (N,) array, N)."""
        cols, n = self._positions(positions)
        if self.method == "linear":
            return self._grouped(cols, n), n
        return {name: np.asarray(f(cols[ax]), dtype=float).reshape(n)
                for name, (ax, f) in self.functions.items()}, n

    def _grouped(self, cols: dict, n: int, std: bool = False) -> dict:
        """The linear functions (``std``: the standard deviations, clamped at the ends) at the
        positions ``cols``, those of an axis evaluated together (:class:`_LinearGroup`, built
        once): name -> (n,)."""
        functions, clamp = (self.std_functions, True) if std else (self.functions, False)
        cache = self.__dict__.setdefault("_linear_groups", {})
        groups = cache.get(std)
        if groups is None:
            by_axis = {}
            for name, (ax, f) in functions.items():
                by_axis.setdefault(ax, []).append((name, f.y))
            groups = cache[std] = {
                ax: ([name for name, _ in items],
                     _LinearGroup(self.tables[ax].positions, [y for _, y in items], clamp))
                for ax, items in by_axis.items()}
        if not groups:
            return {}
        if n > STACK_POINTS:        # axis by axis
            values = [group(cols[ax].reshape(n)) for ax, (_, group) in groups.items()]
        else:                       # all axes at once
            stack = cache.get(("stack", std))
            if stack is None:
                stack = cache[("stack", std)] = _LinearStack([g for _, g in groups.values()])
            values = stack(np.array([cols[ax].reshape(n) for ax in groups], dtype=float)
                           .reshape(len(groups), n))
        out = {}
        for (names, _), v in zip(groups.values(), values):
            out.update(zip(names, v))
        return {name: out[name] for name in functions}

    def sigmas(self, positions) -> dict:
        """Standard uncertainties (mm / rad, k = 1) of the errors at ``positions`` for one
        reading (as :meth:`__call__`): name -> (N,) array; a table's ``_std`` (or ``u95 / 2``)
        and ``_s`` combined in quadrature, a constant's ``std``."""
        cols, n = self._positions(positions)
        out = self._grouped(cols, n, std=True)
        out.update({k: np.full(n, v) for k, v in self.constants_std.items()})
        return out


def parse_approach(spec, model, funcs=None) -> dict:
    """Approach directions given on a command line -> {axis: +1 | -1}: ``"X+,Y-"`` per axis,
    or ``"+"`` / ``"-"`` for every axis whose table has a reversal (``funcs``); None or ""
    -> {} (the bidirectional mean).  Only linear axes of ``model``."""
    if not spec:
        return {}
    spec = spec.replace(" ", "")
    if spec in ("+", "-"):
        require(funcs is not None and funcs.has_reversal,
                "--approach: no error table has a reversal column (RV_<axis>_um)")
        return {a: (1 if spec == "+" else -1) for a in funcs.reversal_functions}
    out = {}
    lin = [a for a in model.axes if a not in model.rotary_axes]
    for part in filter(None, spec.split(",")):
        require(len(part) == 2 and part[1] in "+-",
                f"--approach: expected AXIS+ or AXIS- (e.g. X+,Y-), got {part!r}")
        a = part[0].upper()
        require(a in lin, f"--approach: {a} is not a linear axis of {model.name} "
                          f"({' '.join(lin)})")
        out[a] = 1 if part[1] == "+" else -1
    return out


def approach_array(approach: dict, axes, n: int) -> np.ndarray:
    """(n, len(axes)) directions from {axis: +1 | -1} (0 elsewhere)."""
    d = np.zeros((n, len(axes)))
    for a, v in approach.items():
        d[:, list(axes).index(a)] = v
    return d

