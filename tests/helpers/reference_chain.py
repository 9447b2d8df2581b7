"""An independent numpy implementation of the chain conventions (no sympy, no generated code).

It rebuilds ``tool2work`` from a parsed layout with exact rotations (``scipy`` rotation
vectors, a different exact parameterisation from the derivation's Rz Ry Rx) so that tests can
check the derived first-order model by finite differences.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.spatial.transform import Rotation

from volerr.machine.layout import SQUARENESS, Layout

_LETTER = {"X": 0, "Y": 1, "Z": 2, "A": 0, "B": 1, "C": 2}


def trans(v) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = v
    return m


def rot(rotvec) -> np.ndarray:
    v = np.asarray(rotvec, dtype=float)
    return _rot(v.tobytes(), v.shape).copy()


@functools.lru_cache(maxsize=256)
def _rot(key: bytes, shape: tuple) -> np.ndarray:
    """:func:`rot` of the rotation vector whose float64 bytes are ``key`` (the frames' and the
    zero error rotations repeat at every point: computed once; keyed by the bytes, so -0.0 and
    0.0 stay apart and every matrix is bitwise the one computed from its own vector)."""
    m = np.eye(4)
    m[:3, :3] = Rotation.from_rotvec(np.frombuffer(key, float).reshape(shape).copy()).as_matrix()
    return m


def error_htm(trans_err, ang_err) -> np.ndarray:
    return trans(trans_err) @ rot(ang_err)


def _axis_errors(name: str, errors: dict) -> tuple[np.ndarray, np.ndarray]:
    d = np.array([errors.get(f"E{t}{name}", 0.0) for t in "XYZ"])
    e = np.array([errors.get(f"E{r}{name}", 0.0) for r in "ABC"])
    return d, e


def stage(layout: Layout, entry: str, q: dict, errors: dict, table: bool = False) -> np.ndarray:
    """Exact HTM of one chain entry in tool-relative form; positions q in mm / rad.

    A rotary table turns the workpiece: in tool-relative form the rotation comes first and the
    error motions act in the frame of the (non-turning) body that carries the table."""
    if entry in layout.frames:
        f = layout.frames[entry]
        t = [float(eval(str(c), {}, dict(layout.parameters))) for c in f.translation]
        ang = np.deg2rad(float(eval(str(f.angle_deg), {}, dict(layout.parameters))))
        return trans(t) @ rot(np.asarray(f.rotation_axis) * ang)
    ax = layout.axes[entry]
    u = np.asarray(ax.direction)
    d, e = _axis_errors(entry, errors)
    if ax.kind == "linear":
        omega = np.zeros(3)
        for name, carrier in layout.squareness.items():
            if carrier == entry:
                about, moving, _ = SQUARENESS[name]
                omega[about] += (1 if carrier == moving else -1) * errors.get(name, 0.0)
        u_actual = Rotation.from_rotvec(omega).apply(u)
        return trans(q[entry] * u_actual) @ error_htm(d, e)
    c = np.array([float(eval(str(v), {}, dict(layout.parameters))) for v in ax.point])
    loc_d = np.zeros(3)
    loc_e = np.zeros(3)
    for n in ax.location_errors:
        (loc_d if n[1] in "XYZ" else loc_e)[_LETTER[n[1]]] = errors.get(n, 0.0)
    errs = error_htm(loc_d, loc_e) @ error_htm(d, e)
    if table:
        return trans(c) @ rot(u * q[entry]) @ errs @ trans(-c)
    return trans(c) @ errs @ rot(u * q[entry]) @ trans(-c)


def tool_point(layout: Layout, q: dict, errors: dict, probe) -> np.ndarray:
    """Actual (exact) probe tip in the workpiece frame, mm; ``errors={}`` gives the nominal."""
    m = np.eye(4)
    for entry in reversed(layout.workpiece_chain):
        m = m @ stage(layout, entry, q, errors, table=True)
    for entry in layout.tool_chain:
        m = m @ stage(layout, entry, q, errors)
    return (m @ np.array([*probe, 1.0]))[:3]


def first_order_by_differences(layout: Layout, q: dict, errors: dict, probe,
                               step: float = 1e-2) -> np.ndarray:
    """Central finite difference of the exact chain along the error vector: the first-order
    volumetric error, independent of the derivation."""
    plus = tool_point(layout, q, {k: step * v for k, v in errors.items()}, probe)
    minus = tool_point(layout, q, {k: -step * v for k, v in errors.items()}, probe)
    return (plus - minus) / (2 * step)
