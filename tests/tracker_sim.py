"""Exact rigid-body simulation of laser-tracker three-point data (test helper).

Independent of ``volerr.identify``: full rotation matrices (no small-angle approximation).
A body carrying points ``r`` (reference coordinates, mm, measurement frame) is moved
nominally (translation ``sense * (s - s0) * d`` or rotation by ``sense * (s - s0)`` deg about
``d`` through ``origin``) and then by its error motions: the exact rotation
``Rz(ec) Ry(eb) Rx(ea)`` about the frame origin of the pose (after the nominal motion)
and the translation ``t`` of the body point at the frame origin.
"""

import numpy as np


def rot(axis, a):
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K


def error_rotation(ea, eb, ec):
    return rot((0, 0, 1), ec) @ rot((0, 1, 0), eb) @ rot((1, 0, 0), ea)


def simulate(kind, ref_points, positions, errors, direction=(1, 0, 0), origin=(0, 0, 0),
             sense=1, noise_mm=0.0, rng=None):
    """Measured points (n_pos, n_pts, 3). ``errors``: (n_pos, 6) = EX EY EZ (mm) EA EB EC (rad)
    of the body, zero at the first position by the caller's choice."""
    ref = np.asarray(ref_points, float)
    o = np.asarray(origin, float)
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    out = np.empty((len(positions), len(ref), 3))
    for k, s in enumerate(positions):
        e = errors[k]
        R = error_rotation(*e[3:])
        if kind == "linear":
            lever = ref - o  # moving-frame coordinates, origin translated with the body
            out[k] = o + sense * (s - positions[0]) * d + e[:3] + lever @ R.T
        else:
            Rn = rot(d, sense * np.radians(s - positions[0]))
            lever = (ref - o) @ Rn.T
            out[k] = o + e[:3] + lever @ R.T
    if noise_mm:
        rng = rng or np.random.default_rng(0)
        out = out + rng.normal(0, noise_mm, out.shape)
    return out


def smooth_errors(positions, scale_mm=0.02, scale_rad=50e-6, seed=1):
    """Smooth error motions, zero at the first position."""
    rng = np.random.default_rng(seed)
    s = np.asarray(positions, float)
    u = (s - s[0]) / max(np.ptp(s), 1e-9)
    cols = []
    for j in range(6):
        a, b, c = rng.normal(size=3)
        f = a * u + b * np.sin(np.pi * u) + c * u ** 2
        cols.append(f * (scale_mm if j < 3 else scale_rad))
    e = np.stack(cols, axis=1)
    return e - e[0]


def to_csv(rounds_points, positions, labels):
    lines = ["round,point,position,x,y,z"]
    for r, pts in enumerate(rounds_points, start=1):
        for i, lab in enumerate(labels):
            for k, s in enumerate(positions):
                x, y, z = pts[k, i]
                lines.append(f"{r},{lab},{s:.10g},{x:.9f},{y:.9f},{z:.9f}")
    return "\n".join(lines) + "\n"
