"""Axis compensation tables of a controller, built from error functions, and the correction
they command (what compensating with them leaves: :mod:`volerr.fiveaxis.tables_left`).

A controller's axis compensation table (SINUMERIK LEC / CEC, Heidenhain ``.COM``, Fanuc pitch
error compensation; the formats in :mod:`volerr.tables.sinumerik`,
:mod:`volerr.tables.heidenhain_tables`, :mod:`volerr.tables.fanuc`) holds values of one error
at equally spaced positions of one axis (the *input* axis) and moves one axis (the *output*
axis) against it: the controller interpolates linearly between the points, holds the end
values beyond them (or wraps a modulo table of a rotary axis over the turn) and commands the
output axis at ``position - value``.  A table carries one ISO 230-1 component error, as volerr
defines it (tool relative to workpiece): ``E<A><A>`` (positioning of A, input and output A)
or ``E<B><A>`` (straightness of linear axis A in the direction of linear axis B: input A,
output B).  Values are errors (mm; deg for a rotary axis' positioning); a format that stores
compensation amounts writes them negated.

What compensating leaves (:func:`volerr.fiveaxis.tables_left.left`): at every node of a grid over the working volume (the
linear axes over the part of their travel the error tables cover, rotary axes at fixed
positions), the model's volumetric error ``e(q)`` (first order, all error functions) minus the
tool-tip motion of the corrections, ``J(q) v(q)`` (``J`` the nominal Jacobian of the tool tip
with respect to the axes, ``v`` the table values the controller interpolates, with the
format's increments and spacing).  What no table of the format carries (angular errors times
their Abbe offsets, squareness, the errors of the rotary axes beyond their positioning, and
for a format of positioning only, straightness) is left whole.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, require


@dataclass
class CompTable:
    """One compensation table: ``parameter`` (ISO name of the error it carries), ``input`` /
    ``output`` axis, ``start`` position (mm / deg) and ``step`` (> 0), ``values`` (n,) errors
    at ``start + k step`` (mm; deg when the output is a rotary axis), ``modulo`` (a rotary
    table over one turn, first and last point the same position mod 360), ``direction`` 0
    (both directions), +1 / -1 (approaching in that direction only)."""

    parameter: str
    input: str
    output: str
    start: float
    step: float
    values: np.ndarray
    modulo: bool = False
    direction: int = 0
    #: a multiple of the format's increment the values come in (Fanuc's magnification)
    scale: int = 1

    @property
    def positions(self) -> np.ndarray:
        return self.start + self.step * np.arange(len(self.values))

    @property
    def end(self) -> float:
        return self.start + self.step * (len(self.values) - 1)

    def value(self, pos) -> np.ndarray:
        """The controller's value at input positions ``pos``: linear interpolation, end
        values held beyond the table (a modulo table wraps)."""
        pos = np.asarray(pos, dtype=float)
        if self.modulo:
            pos = self.start + np.mod(pos - self.start, 360.0)
        return np.interp(pos, self.positions, self.values)


def rotary(axis: str) -> bool:
    return axis in ("A", "B", "C")


def direction(model, axis: str) -> np.ndarray:
    """Unit direction of a rotary axis (layout)."""
    u = np.asarray(model.layout.axes[axis].direction, dtype=float)
    return u / np.linalg.norm(u)


def error_values(funcs, parameter: str, axis: str, positions: np.ndarray) -> np.ndarray:
    """Values of one error function at positions of its axis, in table units (mm).  The
    positioning ``E<R><R>`` of a rotary axis R is its angular error about its own direction
    ``u``: ``u . (EAR, EBR, ECR)``, in deg (for an axis along x, y or z the one of them)."""
    t = funcs.tables[axis]
    q = np.zeros((len(positions), len(funcs.model.axes)))
    q[:, funcs.model.axes.index(axis)] = np.clip(positions, t.positions[0], t.positions[-1])
    e = funcs(q)
    if rotary(axis) and parameter == f"E{axis}{axis}":
        u = direction(funcs.model, axis)
        ang = sum(u[k] * e.get(f"E{r}{axis}", 0.0) for k, r in enumerate("ABC"))
        return np.rad2deg(np.broadcast_to(ang, (len(positions),)))
    return e[parameter]


def has_positioning(funcs, axis: str) -> bool:
    """The error functions hold the positioning error of ``axis`` (a rotary axis: an angular
    error about a direction its own direction has a component along)."""
    if not rotary(axis):
        return f"E{axis}{axis}" in funcs.functions
    u = direction(funcs.model, axis)
    return any(abs(u[k]) > 1e-12 and f"E{r}{axis}" in funcs.functions
               for k, r in enumerate("ABC"))


#: spacing of table points in multiples of this (mm / deg): exact decimals for MIN + k STEP
STEP_RESOLUTION = 1e-3


def grid_for(funcs, axis: str, max_points: int, modulo: bool, step=None) -> tuple:
    """(start, step, n) of equally spaced points over the range of axis' table: as many as
    the table's finest spacing needs, at most ``max_points``; the step a multiple of
    :data:`STEP_RESOLUTION` (the last point may lie a little beyond the table, where the end
    value holds).  A modulo table spans 0..360 deg with a step that divides the turn."""
    t = funcs.tables[axis]
    lo, hi = float(t.positions[0]), float(t.positions[-1])
    if modulo:
        lo, hi = 0.0, 360.0
    finest = float(np.min(np.diff(t.positions))) if len(t.positions) > 1 else hi - lo
    if step is None:
        n = int(math.ceil((hi - lo) / finest - 1e-9)) + 1
        n = max(2, min(n, max_points))
    else:
        n = int(math.ceil((hi - lo) / step - 1e-9)) + 1
    units = int(round(1.0 / STEP_RESOLUTION))
    if modulo:
        k = n - 1
        while k > 1 and (360 * units) % k:
            k -= 1                     # fewer, wider steps that still divide the turn
        return 0.0, 360.0 / k, k + 1
    step = math.ceil((hi - lo) / (n - 1) * units - 1e-6) / units
    n = int(math.ceil((hi - lo) / step - 1e-9)) + 1
    require(n <= max_points, f"table {axis}: {n} points exceed the format's {max_points}")
    return lo, step, n


def quantize(values: np.ndarray, increment: float) -> np.ndarray:
    """Values rounded to the format's increment."""
    return np.round(np.asarray(values, dtype=float) / increment) * increment


def endless(model, axis: str) -> bool:
    """A rotary axis that turns endlessly (travel of at least a turn each way)."""
    lo, hi = model.travel[axis]
    return rotary(axis) and hi - lo >= 720.0 - 1e-9


def positioning_tables(funcs, max_points: int, increment: float, axes=None) -> list:
    """One table per axis with a positioning error ``E<A><A>`` in the error functions
    (rotary axes too: deg, modulo for an endless axis)."""
    model = funcs.model
    out = []
    for a in model.axes:
        name = f"E{a}{a}"
        if not has_positioning(funcs, a) or (axes is not None and a not in axes):
            continue
        mod = endless(model, a)
        start, step, n = grid_for(funcs, a, max_points, mod)
        pos = start + step * np.arange(n)
        vals = error_values(funcs, name, a, np.mod(pos, 360.0) if mod else pos)
        out.append(CompTable(name, a, a, start, step,
                             quantize(vals, increment), mod))
    return out


def straightness_tables(funcs, max_points: int, increment: float) -> list:
    """One table per straightness error ``E<B><A>`` of a linear axis A in the direction of
    another linear axis B (input A, output B)."""
    model = funcs.model
    lin = [a for a in model.axes if not rotary(a)]
    out = []
    for a in lin:
        for b in lin:
            name = f"E{b}{a}"
            if b == a or name not in funcs.functions:
                continue
            start, step, n = grid_for(funcs, a, max_points, False)
            pos = start + step * np.arange(n)
            out.append(CompTable(name, a, b, start, step,
                                 quantize(error_values(funcs, name, a, pos), increment)))
    return out


def reversal_tables(funcs, tables: list, increment: float) -> list:
    """Positioning tables split by approach direction where the error tables carry a reversal
    ``RV_<axis>`` (ISO 230-2 B_i): +1 the positive-direction values ``E + B_i / 2``, -1 the
    negative-direction ones ``E - B_i / 2``; others unchanged."""
    out = []
    for t in tables:
        rf = funcs.reversal_functions.get(t.input)
        if rf is None or t.parameter != f"E{t.input}{t.input}" or rotary(t.input):
            out.append(t)
            continue
        half = 0.5 * rf[1](t.positions)
        for d in (1, -1):
            out.append(CompTable(t.parameter, t.input, t.output, t.start, t.step,
                                 quantize(t.values + d * half, increment), t.modulo, d))
    return out


# ---------------------------------------------------------------------------------------
# back to error tables
def to_error_tables(tables: list, model) -> dict:
    """{axis: :class:`volerr.tables.table.ErrorTable`} of imported compensation tables of
    ``model``: the tables of one input axis on one grid (they must share it); direction
    tables become the bidirectional mean and the reversal ``B_i`` (+ minus -); a rotary
    axis' positioning (deg) the rotation about its direction (rad, in its components)."""
    from .table import ErrorTable

    by_axis: dict = {}
    for t in tables:
        by_axis.setdefault(t.input, []).append(t)
    out = {}
    for a, ts in by_axis.items():
        ref = ts[0]
        pos = ref.positions
        values, rev = {}, None
        pairs: dict = {}
        for t in ts:
            require(len(t.values) == len(ref.values) and abs(t.start - ref.start) < 1e-9
                    and abs(t.step - ref.step) < 1e-9,
                    f"tables of axis {a} on different grids ({t.parameter} and "
                    f"{ref.parameter})")
            v = t.values
            if rotary(a) and t.parameter == f"E{a}{a}":
                # a rotation about the axis' own direction: its components about x, y, z
                u = direction(model, a)
                for k, r in enumerate("ABC"):
                    if abs(u[k]) > 1e-12:
                        require(f"E{r}{a}" not in values, f"two tables for E{r}{a}")
                        values[f"E{r}{a}"] = u[k] * np.deg2rad(v)
                continue
            if t.direction:
                pairs.setdefault(t.parameter, {})[t.direction] = v
            else:
                require(t.parameter not in values, f"two tables for {t.parameter}")
                values[t.parameter] = v
        for p, d in pairs.items():
            require(set(d) == {1, -1}, f"{p}: a direction table without its opposite")
            values[p] = 0.5 * (d[1] + d[-1])
            rev = d[1] - d[-1]
        try:
            out[a] = ErrorTable(a, pos, values, reversal=rev)
        except InputError as exc:
            raise InputError(f"table of axis {a}: {exc}") from None
    return out


def correction(model, tables: list, q: np.ndarray, direction=None) -> np.ndarray:
    """The per-axis values (N, n_axes) the controller subtracts at axis positions ``q``
    (mm; deg for rotary outputs): the sum of the tables of each output axis; a direction
    table counts where ``direction`` (N, n_axes) of its input axis is its direction (None:
    the mean of the two)."""
    v = np.zeros((len(q), len(model.axes)))
    for t in tables:
        i, o = model.axes.index(t.input), model.axes.index(t.output)
        val = t.value(q[:, i])
        if t.direction:
            w = 0.5 if direction is None else (direction[:, i] == t.direction).astype(float)
            val = w * val
        v[:, o] += val
    return v
