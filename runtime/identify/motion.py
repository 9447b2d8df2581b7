"""The nominal motion of the tracked points and what a file that does not follow it likely is.

The points fixed on the moving component follow the axis' nominal motion up to its error
motions (um, urad): a translation ``sense * (q - q0) * d`` (linear axis) or a rotation by
``sense * (q - q0)`` deg about the direction ``d`` through ``o`` (rotary axis).  A round whose
points deviate from it by more than a limit (5 % of the travel, at least 0.5 mm; rotary: 0.5
deg of arc at the largest lever, at least 0.5 mm) is no measurement of that axis; the
hypotheses below, each held against the same limit, name what it likely is: points that do
not move (points on the fixed part), coordinates in inches, m, cm or um, two coordinate
columns swapped, the file of another axis of the layout, rotary positions in rad.
"""

from __future__ import annotations

import numpy as np

from ..units import MM_PER_M, MM_PER_UM


def _gen():
    from volerr.generated import three_point as gen  # numpy only

    return gen


def rotation_matrix(axis, angle_rad) -> np.ndarray:
    """Right-hand rotation about ``axis`` (normalised here) by ``angle_rad`` (array, rad) ->
    (..., 3, 3); generated from :func:`volerr.derive.three_point.axis_rotation`."""
    k = np.asarray(axis, dtype=float)
    k = k / np.linalg.norm(k)
    a = np.asarray(angle_rad, dtype=float)
    return np.moveaxis(_gen().axis_rotation(k[0], k[1], k[2], a), (0, 1), (-2, -1))


def nominal(kind, ref, steps, d, o, sense):
    """Nominal positions (K, n, 3) and lever arms (K, n, 3) for reference points ref (n, 3)
    mm, after the steps (K,) mm or deg from the reference position."""
    lever0 = ref - o
    if kind == "linear":
        nom = ref[None] + sense * steps[:, None, None] * d
        lever = np.broadcast_to(lever0, nom.shape)
    else:
        R = rotation_matrix(d, sense * np.radians(steps))
        lever = np.einsum("kab,nb->kna", R, lever0)
        nom = lever + o
    return nom, lever


def limit_mm(kind, pts, steps, d, o) -> float:
    """The largest deviation (mm) of measured points from the nominal motion (module
    docstring)."""
    if kind == "linear":
        return max(0.05 * float(np.max(np.abs(steps))), 0.5)
    lever = np.linalg.norm(np.cross(pts[0] - o, d), axis=-1).max()
    return max(np.radians(0.5) * lever, 0.5)


def motion_fit(kind, pts, steps, d, o, senses=(1, -1)) -> tuple:
    """(sense, largest deviation mm, limit mm) of the sense that fits the points (K, n, 3)
    best."""
    best = None
    for s in senses:
        nom, _ = nominal(kind, pts[0], steps, d, o, s)
        dev = float(np.max(np.linalg.norm(pts - nom, axis=-1)))
        if best is None or dev < best[1]:
            best = (s, dev)
    return best[0], best[1], limit_mm(kind, pts, steps, d, o)


#: coordinates in another unit: name -> factor to mm
_UNITS = (("inches", 25.4), ("m", MM_PER_M), ("cm", 10.0), ("um", MM_PER_UM))


def likely_cause(kind, pts, steps, d, o, senses, others) -> str:
    """What a round whose points do not follow the nominal motion likely is (module
    docstring); ``others``: {axis: (kind, unit direction)} of the layout's other axes.
    Returns a clause for the refusal; the general advice when no hypothesis fits."""

    def fits(p=pts, st=steps, dd=d):
        _, dev, lim = motion_fit(kind, p, st, dd, o, senses)
        return dev <= lim

    found = [f"coordinates in {u}, not mm" for u, f in _UNITS if fits(p=pts * f)]
    moved = float(np.max(np.linalg.norm(pts - pts[0], axis=-1)))
    if not found and moved <= limit_mm(kind, pts, steps, d, o):
        return (f"the points hardly move ({moved:.3g} mm) as the axis moves: points on the "
                f"fixed part, or a file of another axis?")
    for i, j in ((0, 1), (0, 2), (1, 2)):
        perm = [0, 1, 2]
        perm[i], perm[j] = j, i
        if fits(p=pts[..., perm]):
            found.append(f"the {'xyz'[i]} and {'xyz'[j]} columns swapped")
    for name, (k2, d2) in others.items():
        if k2 == kind and fits(dd=np.asarray(d2, dtype=float)):
            found.append(f"a file of axis {name} (the points move as {name} does)")
    if kind == "linear":
        found += [f"the position column in {u}, not mm" for u, f in _UNITS
                  if fits(st=steps * f)]
    if kind == "rotary" and fits(st=np.degrees(steps)):
        found.append("positions in rad, not deg")
    if found:
        return "likely " + ", or ".join(found) + "?"
    stray = _one_stray_reading(kind, pts, steps, d, o, senses)
    if stray:
        return stray
    return ("check --axis, the axis direction, the units (mm, deg)"
            f"{', the origin on the axis' if kind == 'rotary' else ''} and the point order")


def _one_stray_reading(kind, pts, steps, d, o, senses) -> str | None:
    """The clause naming the one reading (point at a position) that alone leaves the nominal
    motion by more than its limit, when there is exactly one: a mistyped coordinate or a stray
    measurement (every other reading of the round follows the axis); else None."""
    lim = limit_mm(kind, pts, steps, d, o)
    best = None
    for s in senses:
        nom, _ = nominal(kind, pts[0], steps, d, o, s)
        dev = np.linalg.norm(pts - nom, axis=-1)                     # (K, n)
        off = np.argwhere(dev > lim)
        if best is None or len(off) < len(best[0]):
            best = (off, dev)
    off, dev = best
    if len(off) != 1 or off[0][0] == 0:
        return None
    k, j = (int(v) for v in off[0])
    unit = "mm" if kind == "linear" else "deg"
    return (f"one reading alone is {dev[k, j]:.3g} mm off the motion (point {j + 1} in file "
            f"order at {steps[k]:+g} {unit} from the round's first position): likely a mistyped "
            f"coordinate or a stray measurement of that point")
