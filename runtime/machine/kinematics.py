"""Five-axis kinematics at run time: nominal inverse, branch choice, Jacobians.

The closed-form inverse is generated per layout (``inverse_rotary``, ``inverse_linear`` in the
generated module, derived by :mod:`volerr.derive.inverse`).  This module picks among its
solutions: the two branches of the rotary solution, the turn (multiples of 360 deg) of each
rotary axis, and the value of an undetermined rotary axis on a singular orientation (tool axis
along the first rotary axis, e.g. B = 0 on the DMU 50, where C does not change the tool axis).

Units: mm and deg at this interface (rad only inside the generated code).  Frames: target tool
tip (x, y, z) and unit tool axis (i, j, k) in the workpiece frame, as returned by
:meth:`volerr.machine.model.Model.forward`.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, require

#: a rotary axis whose motion turns the tool axis by less than this (rad per rad) is singular
SINGULAR = 1e-9


def is_five_axis(model) -> bool:
    """True when the model's generated module carries the five-axis inverse."""
    return hasattr(model.module, "inverse_rotary") and hasattr(model.module, "inverse_linear")


def linear_axes(model) -> tuple[str, ...]:
    return tuple(a for a in model.axes if a not in model.rotary_axes)


def _wrap_near(angle_deg: np.ndarray, ref_deg: np.ndarray) -> np.ndarray:
    """The representative of ``angle`` (mod 360) nearest to ``ref``."""
    return ref_deg + (angle_deg - ref_deg + 180.0) % 360.0 - 180.0


def inverse(model, target, tool=(0.0, 0.0, 0.0), near=None) -> np.ndarray:
    """Axis positions (N, n_axes) in ``model.axes`` order (mm / deg) that put the tool tip at
    ``target[:, :3]`` (mm) with tool axis ``target[:, 3:6]`` (normalised here).

    ``near``: (n_axes,) or (N, n_axes) positions to stay close to (e.g. the previous block);
    it chooses the branch and the turn of every rotary axis, and fills a rotary axis that is
    undetermined on a singular orientation.  Without it the solution inside the travel
    closest to the middle of the rotary travel is taken, and an undetermined axis gets 0.
    Raises :class:`InputError` for an unreachable orientation."""
    require(is_five_axis(model), f"{model.name}: no five-axis inverse kinematics "
                                 "(needs three linear and two rotary axes)")
    t = np.atleast_2d(np.asarray(target, dtype=float))
    require(t.ndim == 2 and t.shape[1] == 6, f"target must be (N, 6) x y z i j k, got {t.shape}")
    require(np.all(np.isfinite(t)), "target has NaN or infinite values")
    n = len(t)
    k = t[:, 3:6]
    norm = np.linalg.norm(k, axis=1, keepdims=True)
    require(np.all(norm > 1e-12), "tool axis (i, j, k) must not be the zero vector")
    k = k / norm
    rot = model.rotary_axes
    travel = model.travel
    if near is not None:
        near = np.broadcast_to(np.asarray(near, dtype=float), (n, len(model.axes)))
        near_rot = {a: near[:, model.axes.index(a)] for a in rot}
    else:
        near_rot = {a: np.full(n, 0.5 * sum(travel[a])) for a in rot}

    candidates = []
    for branch in (1.0, -1.0):
        sol = model.module.inverse_rotary(k[:, 0], k[:, 1], k[:, 2], branch)
        cand = {}
        for a, v in zip(rot, sol):
            v = np.rad2deg(np.broadcast_to(np.asarray(v, dtype=float), (n,)))
            cand[a] = _wrap_near(v, near_rot[a])
        candidates.append(cand)
    # an axis that does not turn the tool axis at the solution is undetermined: keep near
    for cand in candidates:
        sens_all = _sensitivities(model, cand)
        for a in rot:
            sens = sens_all[a]
            undetermined = sens < SINGULAR
            if undetermined.any():
                cand[a] = np.where(undetermined, near_rot[a], cand[a])
    ok = [np.all([np.isfinite(c[a]) for a in rot], axis=0) for c in candidates]
    require(np.all(ok[0] | ok[1]),
            f"{model.name}: tool orientation unreachable (row {int(np.argmin(ok[0] | ok[1]))})")

    def score(c, good):
        inside = np.all([(c[a] >= travel[a][0] - 1e-9) & (c[a] <= travel[a][1] + 1e-9)
                         for a in rot], axis=0)
        dist = sum(np.abs(np.nan_to_num(c[a], nan=1e9) - near_rot[a]) for a in rot)
        return np.where(good, np.where(inside, 0.0, 1e6) + dist, np.inf)

    s0, s1 = score(candidates[0], ok[0]), score(candidates[1], ok[1])
    pick = s1 < s0
    rot_deg = _polish_rotary(model, {a: np.where(pick, candidates[1][a], candidates[0][a])
                                     for a in rot}, k)
    tool = np.broadcast_to(np.asarray(tool, dtype=float), (n, 3))
    lin = model.module.inverse_linear(*(np.deg2rad(rot_deg[a]) for a in rot),
                                      t[:, 0], t[:, 1], t[:, 2], tool[:, 0], tool[:, 1], tool[:, 2])
    lin = {a: np.broadcast_to(np.asarray(v, dtype=float), (n,)) for a, v in
           zip(("X", "Y", "Z"), lin)}
    out = np.empty((n, len(model.axes)))
    for i, a in enumerate(model.axes):
        out[:, i] = rot_deg[a] if a in rot else lin[a]
    return out


def _polish_rotary(model, rot_deg: dict, k: np.ndarray, steps: int = 2) -> dict:
    """Newton steps on the rotary positions towards the unit tool axis ``k`` (N, 3).

    The closed form goes through a square root whose argument vanishes at the singular
    orientation: there it keeps only half the digits (an orientation 1e-6 deg from the
    singular one comes back 1.2e-8 rad off).  A step ``pinv(J) (k - k(q))`` with the exact
    Jacobian restores full precision; a direction the rotary axes hardly turn (singular
    values below 1e-6 per rad: the undetermined axis) is left alone."""
    rot = model.rotary_axes
    idx = [model.axes.index(a) for a in rot]
    q = np.zeros((len(k), len(model.axes)))
    for a, i in zip(rot, idx):
        q[:, i] = rot_deg[a]
    for _ in range(steps):
        k_now = model.forward(q)[:, 3:6]
        j = nominal_jacobian(model, q)[:, 3:6, idx]
        d = pinv_apply_3x2(j, k - k_now, rcond=1e-6)
        q[:, idx] += np.rad2deg(np.nan_to_num(d))
    return {a: q[:, i] for a, i in zip(rot, idx)}


def pinv_apply_3x2(j: np.ndarray, r: np.ndarray, rcond: float = 1e-6) -> np.ndarray:
    """``pinv(j, rcond) @ r`` row by row for ``j`` (N, 3, 2) and ``r`` (N, 3), in closed form:
    the 2x2 Gram matrix ``j^T j`` diagonalised by one Jacobi rotation (stable for nearly
    orthogonal columns, as the tool-axis derivatives of two rotary axes are), a singular value
    ``sqrt(eigenvalue)`` at or below ``rcond`` times the largest dropped as numpy's ``pinv``
    drops it.  Batched; replaces one SVD per row.  The Newton step of :func:`_polish_rotary`
    adds a correction of a few ulps, so its result is the SVD's to the last bit, except within
    ~1e-5 deg of a singular orientation (measured: 34 of 200000 rows, by <= 1e-21 deg)."""
    c0, c1 = j[:, :, 0], j[:, :, 1]
    a = np.einsum("ni,ni->n", c0, c0)
    b = np.einsum("ni,ni->n", c0, c1)
    c = np.einsum("ni,ni->n", c1, c1)
    g0 = np.einsum("ni,ni->n", c0, r)
    g1 = np.einsum("ni,ni->n", c1, r)
    theta = 0.5 * np.arctan2(2.0 * b, a - c)
    cs, sn = np.cos(theta), np.sin(theta)
    l0 = np.maximum(a * cs * cs + 2.0 * b * cs * sn + c * sn * sn, 0.0)
    l1 = np.maximum(a * sn * sn - 2.0 * b * cs * sn + c * cs * cs, 0.0)
    s0, s1 = np.sqrt(l0), np.sqrt(l1)
    cutoff = rcond * np.maximum(s0, s1)
    with np.errstate(divide="ignore", invalid="ignore"):
        y0 = np.where(s0 > cutoff, (cs * g0 + sn * g1) / l0, 0.0)
        y1 = np.where(s1 > cutoff, (cs * g1 - sn * g0) / l1, 0.0)
    return np.column_stack([cs * y0 - sn * y1, sn * y0 + cs * y1])


def nominal_jacobian(model, positions, tool=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Exact derivatives of the nominal tool tip (rows 0-2) and tool axis (rows 3-5) with
    respect to the axis positions (columns in ``model.axes`` order), (N, 6, n_axes): mm/mm and
    mm/rad for the tip, 0 and 1/rad for the axis.  ``positions`` (N, n_axes) mm / deg; from the
    generated ``nominal_jacobian`` (derived by :func:`volerr.derive.volumetric.nominal_jacobian`).
    """
    pos, n = model._points(positions)
    j = model.module.nominal_jacobian(**pos, **model._probe(tool, n))
    return np.moveaxis(np.broadcast_to(j, (6, len(model.axes), n)), -1, 0)


def _axis_sensitivity(model, rot_deg: dict, axis: str) -> np.ndarray:
    """|d(tool axis)/d(axis)| (per rad) at the rotary positions ``rot_deg`` (exact)."""
    return _sensitivities(model, rot_deg)[axis]


def _sensitivities(model, rot_deg: dict) -> dict:
    """Rotary axis -> |d(tool axis)/d(axis)| (per rad) at the rotary positions ``rot_deg``
    (exact; one Jacobian for all axes)."""
    n = len(next(iter(rot_deg.values())))
    q = np.zeros((n, len(model.axes)))
    for a in model.rotary_axes:
        if a in rot_deg:
            q[:, model.axes.index(a)] = np.nan_to_num(rot_deg[a])
    j = nominal_jacobian(model, q)
    return {a: np.linalg.norm(j[:, 3:6, model.axes.index(a)], axis=1)
            for a in model.rotary_axes}


def linear_jacobian(model, positions: np.ndarray, tool=(0.0, 0.0, 0.0)) -> np.ndarray:
    """d(tool tip)/d(X, Y, Z), (N, 3, 3), exact (the generated Jacobian)."""
    idx = [model.axes.index(a) for a in linear_axes(model)]
    return nominal_jacobian(model, positions, tool)[:, 0:3, idx]


def rotary_jacobian(model, positions: np.ndarray) -> np.ndarray:
    """d(tool axis)/d(rotary axes in ``model.rotary_axes`` order), (N, 3, n_rot), per rad,
    exact (the generated Jacobian)."""
    idx = [model.axes.index(a) for a in model.rotary_axes]
    return nominal_jacobian(model, positions)[:, 3:6, idx]


def check_axes(model, axes) -> None:
    for a in axes:
        if a not in model.axes:
            raise InputError(f"{model.name}: unknown axis {a!r}; axes are {' '.join(model.axes)}")
