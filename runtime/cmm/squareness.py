"""Squareness of linear axes from the reference straight lines of straightness (ISO 230-1).

The straightness ``E{T}{A}`` of axis ``A`` in direction ``T`` is fitted with its least-squares
reference straight line; its slope ``a_{T}{A} = d E{T}{A} / d A`` is the inclination of the
line of motion of ``A`` towards ``T``.  A squareness is the angle between the two lines of
motion of a pair of axes (thesis 2.3.1 and 3.3; ISO 230-1 3.4.9), and the slopes are then
removed from the straightness tables (the reference position stays zero).

Sign convention (the one of ``volerr.machine.layout``): ``E{R}0{B}`` is the small right-hand rotation
about axis ``R`` of the line of motion of ``B`` relative to the reference axis (X for EC0Y and
EB0Z, Y for EA0Z).  A line of motion inclined by slope ``a`` is a rotation by

* about z: X line ``+a_YX``, Y line ``-a_XY``   ->  ``EC0Y = -(a_XY + a_YX)``
* about y: X line ``-a_ZX``, Z line ``+a_XZ``   ->  ``EB0Z = a_XZ + a_ZX``
* about x: Y line ``+a_ZY``, Z line ``-a_YZ``   ->  ``EA0Z = -(a_YZ + a_ZY)``

The slopes are those of the *tool relative to the workpiece*.  ``volerr identify`` writes the
motion of the component that carries the points; for an axis in the layout's workpiece chain
(a table axis) that motion is minus the tool-relative one, so its slopes change sign
(``tables_are="carrier"``, the default); pass ``tables_are="component"`` for tables that
already hold ISO component errors.

Note: thesis eq. 3.16 puts ``+y E_C(0X)Y`` into the x row of the Y-axis HTM, i.e. its
``E_C(0X)Y`` is the clockwise angle, opposite to the convention above (the audit reports it).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import require
from ..tables.table import ErrorTable

#: squareness -> ((straightness, axis, sign), (straightness, axis, sign)): value = sum sign*slope
PAIRS = {
    "EC0Y": (("EYX", "X", -1.0), ("EXY", "Y", -1.0)),
    "EB0Z": (("EZX", "X", +1.0), ("EXZ", "Z", +1.0)),
    "EA0Z": (("EZY", "Y", -1.0), ("EYZ", "Z", -1.0)),
}


def reference_line(positions, values) -> tuple[float, float, float]:
    """Least-squares reference straight line: (slope, intercept, standard error of the slope).

    The standard error comes from the residuals about the line (``n - 2`` degrees of
    freedom); zero with two points."""
    x = np.asarray(positions, dtype=float)
    y = np.asarray(values, dtype=float)
    require(x.size >= 2, "a reference straight line needs at least two positions")
    xm = x.mean()
    sxx = float(np.sum((x - xm) ** 2))
    require(sxx > 0, "a reference straight line needs distinct positions")
    slope = float(np.sum((x - xm) * (y - y.mean())) / sxx)
    intercept = float(y.mean() - slope * xm)
    if x.size > 2:
        res = y - (intercept + slope * x)
        u = math.sqrt(float(np.sum(res ** 2)) / (x.size - 2) / sxx)
    else:
        u = 0.0
    return slope, intercept, u


def squareness(tables: dict, layout=None, tables_are: str = "carrier"):
    """Squareness errors from straightness tables and the tables with the slopes removed.

    Parameters
    ----------
    tables : dict axis -> :class:`volerr.tables.table.ErrorTable` (X, Y and/or Z)
    layout : Layout, optional
        Gives the table axes (workpiece chain) for ``tables_are="carrier"``.
    tables_are : "carrier" (as written by ``volerr identify``) or "component" (ISO, tool
        relative to workpiece).

    Returns
    -------
    values, std : dict name -> rad (squareness and its standard uncertainty from the fits)
    corrected : dict axis -> ErrorTable, straightness with the reference-line slope removed
    slopes : dict straightness name -> slope (rad, as in the tables)
    """
    require(tables_are in ("carrier", "component"),
            f"tables_are must be 'carrier' or 'component', got {tables_are!r}")
    table_axes = set()
    if layout is not None and tables_are == "carrier":
        table_axes = {a for a in layout.workpiece_chain if a in layout.axes}
    slopes, u_slopes = {}, {}
    for ax, t in tables.items():
        for name in (f"E{c}{ax}" for c in "XYZ" if c != ax):
            if name in t.values:
                a, _, u = reference_line(t.positions, t.values[name])
                slopes[name], u_slopes[name] = a, u
    values, std = {}, {}
    for sq, legs in PAIRS.items():
        if all(name in slopes for name, _, _ in legs):
            v, var = 0.0, 0.0
            for name, ax, sign in legs:
                flip = -1.0 if ax in table_axes else 1.0
                v += sign * flip * slopes[name]
                var += u_slopes[name] ** 2
            values[sq], std[sq] = v, math.sqrt(var)
    corrected = {}
    used = {name for sq in values for name, _, _ in PAIRS[sq]}
    for ax, t in tables.items():
        vals = dict(t.values)
        for name in list(vals):
            if name in used:
                # keep the value at the reference (first) position: remove slope * (s - s_ref)
                s_ref = _reference_position(t)
                vals[name] = vals[name] - slopes[name] * (t.positions - s_ref)
        corrected[ax] = ErrorTable(t.axis, t.positions, vals, t.std, t.u95, t.reversal, t.s)
    return values, std, corrected, slopes


def _reference_position(t: ErrorTable) -> float:
    """The reference position of a table: where all its errors are zero (identify's reference),
    else the first position."""
    zero = np.all(np.stack([np.abs(v) for v in t.values.values()]) == 0, axis=0)
    return float(t.positions[int(np.argmax(zero))]) if zero.any() else float(t.positions[0])


def budgets(tables: dict, values: dict) -> dict:
    """The GUM budget (:mod:`volerr.report.budget`, urad) of every squareness in
    ``values`` (:func:`squareness`): its two legs' reference-line slopes, each with the
    standard error of its least-squares slope (:func:`reference_line`), sensitivity 1 (a
    sign does not change a contribution)."""
    from ..report.budget import budget, source
    from ..units import URAD_PER_RAD

    out = {}
    for sq in values:
        srcs = []
        for name, ax, _ in PAIRS[sq]:
            t = tables[ax]
            _, _, u = reference_line(t.positions, t.values[name])
            srcs.append(source(f"slope of the reference line of {name} (its least-squares "
                               f"standard error)", u * URAD_PER_RAD, "urad"))
        out[sq] = budget(sq, "urad", srcs, 2.0)
    return out
