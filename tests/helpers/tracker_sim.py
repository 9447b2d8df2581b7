"""Exact rigid-body simulation of laser-tracker three-point data (test helper).

Independent of ``volerr.identify.solve``: full rotation matrices (no small-angle approximation).
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


def example_set(seed=2021):
    """Thesis-like example: X, Y, Z axes of a machine whose spindle carries P, Q, K; 11 steps,
    4 rounds, 2 um tracker noise, straightness lines inclined so that the squareness is
    EC0Y = 20 urad, EB0Z = -15 urad, EA0Z = 10 urad (layout sign convention).
    Returns {axis: (positions, rounds (4, 11, 3, 3), errors (11, 6))}, squareness dict."""
    rng = np.random.default_rng(seed)
    ref = np.array([[80.0, 0.0, -120.0], [-40.0, 69.3, -160.0], [-40.0, -69.3, -200.0]])
    sq = {"EC0Y": 20e-6, "EB0Z": -15e-6, "EA0Z": 10e-6}
    # lines of motion (tool side): X along x; Y rotated by EC0Y about z -> EXY slope -EC0Y;
    # Z rotated by EB0Z about y -> EXZ slope +EB0Z, by EA0Z about x -> EYZ slope -EA0Z
    slopes = {"X": {}, "Y": {0: -sq["EC0Y"]}, "Z": {0: sq["EB0Z"], 1: -sq["EA0Z"]}}
    out = {}
    for i, (axis, travel) in enumerate((("X", 500.0), ("Y", 450.0), ("Z", 400.0))):
        pos = np.linspace(0.0, travel, 11)
        e = smooth_errors(pos, scale_mm=0.01, scale_rad=40e-6, seed=seed + i)
        for j in range(3):
            if j != i:  # straightness: no inclination of its own (least-squares slope 0)
                e[:, j] -= np.polyfit(pos, e[:, j], 1)[0] * (pos - pos[0])
        for j, a in slopes[axis].items():
            e[:, j] += a * (pos - pos[0])
        d = np.eye(3)[i]
        rounds = np.array([simulate("linear", ref, pos, e, direction=d, noise_mm=0.002,
                                    rng=rng) for _ in range(4)])
        out[axis] = (pos, rounds, e)
    return out, sq
