"""What compensating with a controller's axis tables leaves of the model's volumetric error
over the working volume (:mod:`volerr.tables.comp_tables` for the tables and the correction
they command): at every node of a grid, the first-order volumetric error minus the tool-tip
motion of the corrections ``J(q) v(q)``.  Here, above the tables, because it needs the
volume of the error tables (:mod:`volerr.cmm.volmap`) and the nominal Jacobian of the chain
(:mod:`volerr.machine.kinematics`).  Units: mm inside, um in the summary."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import require
from ..tables.comp_tables import correction


@dataclass
class Left:
    """The model's volumetric error on a grid over the working volume before and after the
    tables' correction: ``positions`` (N, n_axes) mm / deg in the order of ``axes``,
    ``before`` / ``after`` (N, 3) mm, ``shape`` the grid counts of the linear axes (C
    order), ``linear`` their names."""

    positions: np.ndarray
    before: np.ndarray
    after: np.ndarray
    shape: tuple
    linear: tuple
    axes: tuple = ()

    def summary(self) -> dict:
        b = np.linalg.norm(self.before, axis=1) * 1e3
        a = np.linalg.norm(self.after, axis=1) * 1e3
        return {"before_um": {"max": float(b.max()), "rms": float(np.sqrt(np.mean(b ** 2)))},
                "left_um": {"max": float(a.max()), "rms": float(np.sqrt(np.mean(a ** 2)))},
                "points": int(len(a))}



def _grid(model, funcs, grid: int, at) -> tuple:
    """(q (N, n_axes), ticks of the linear axes): ``grid`` points per linear axis over the
    part of the travel the error tables cover, rotary axes at ``at``."""
    from ..cmm.volmap import fixed_positions, volume

    require(2 <= grid <= 60, "--grid must be 2..60 points per axis")
    box = volume(model, funcs, "measured")
    lin = tuple(a for a in model.axes if a not in model.rotary_axes)
    ticks = [np.linspace(*box[a], grid) for a in lin]
    mesh = np.meshgrid(*ticks, indexing="ij")
    n = mesh[0].size
    q = np.zeros((n, len(model.axes)))
    for a, m in zip(lin, mesh):
        q[:, model.axes.index(a)] = m.ravel()
    for a, v in fixed_positions(model, at).items():
        q[:, model.axes.index(a)] = v
    return q, ticks


def left(model, funcs, tables: list, grid: int = 9, at=None, probe=(0.0, 0.0, 0.0)) -> Left:
    """What compensating with ``tables`` leaves (module docstring) on a grid of ``grid``
    points per linear axis over the part of the travel the error tables cover; rotary axes at
    ``at`` (axis -> deg, default 0 or the nearest travel limit)."""
    from ..machine.kinematics import nominal_jacobian

    q, ticks = _grid(model, funcs, grid, at)
    lin = tuple(a for a in model.axes if a not in model.rotary_axes)
    probe = np.asarray(probe, dtype=float)
    e = model.volumetric_error(q, funcs(q), probe=probe)
    v = correction(model, tables, q)
    rot = [model.axes.index(a) for a in model.rotary_axes]
    v[:, rot] = np.deg2rad(v[:, rot])           # deg -> rad: the Jacobian is per rad
    jac = nominal_jacobian(model, q, probe)[:, 0:3, :]
    after = e - np.einsum("nij,nj->ni", jac, v)
    return Left(q, e, after, tuple(len(t) for t in ticks), lin, tuple(model.axes))


def volumetric_left(model, funcs, grid: int = 9, at=None) -> Left:
    """What a controller's volumetric compensation with every parameter of the error
    functions (ISG, Etalon) leaves when it corrects by the first-order model: the exact error
    of the chain (:meth:`volerr.machine.model.Model.exact_error`) minus the first-order one,
    on the grid of :func:`left`."""
    q, ticks = _grid(model, funcs, grid, at)
    lin = tuple(a for a in model.axes if a not in model.rotary_axes)
    errs = funcs(q)
    e = model.volumetric_error(q, errs)
    return Left(q, e, model.exact_error(q, errs) - e, tuple(len(t) for t in ticks), lin,
                tuple(model.axes))
