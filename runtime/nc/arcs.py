"""Circular arcs ``G2``/``G3`` in axis space: their geometry, and how an arc is written.

Geometry (:class:`ArcPath`)
---------------------------
An arc block moves the two axes of its plane on a circle and the third linear axis (the
normal of the plane) in proportion to the angle (a helix); rotary axes stand still (a rotary
word in an arc block is refused).  Planes and their axes (first, second, normal; the normal is
first x second, so that ``G3`` turns positively about it and ``G2`` negatively, both seen from
the positive normal):

    G17: X Y (Z)      G18: Z X (Y)      G19: Y Z (X)

The centre is given by ``I J K`` (the words of the plane's axes X -> I, Y -> J, Z -> K, the
centre minus the start point) or by the radius ``R`` (positive: at most half a turn,
negative: more).  With ``I J K`` an end point equal to the start is a full turn.  The end
point must lie on the circle: the radii at the start and at the end may differ by at most
``max(RADIUS_TOLERANCE_MM, RADIUS_TOLERANCE_FACTOR x radius)`` (the defaults of SINUMERIK's
circle end-point monitoring, machine data 21000 ``CIRCLE_ERROR_CONST`` and 21010
``CIRCLE_ERROR_FACTOR``; alarm 14040), else the program is refused naming the line.  Within
that, the radius changes in proportion to the angle from the start radius to the end radius
(a spiral), as controllers interpolate such an arc.

How an arc is written after compensation (:class:`ArcResult`: kept as an arc with its end
point and centre corrected, or linearised into straight moves) is decided by
:mod:`volerr.fiveaxis.arc_compensation`; the writer (:mod:`volerr.nc.writer`) writes either.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

#: plane -> (first axis, second axis, normal axis)
PLANES = {17: ("X", "Y", "Z"), 18: ("Z", "X", "Y"), 19: ("Y", "Z", "X")}
#: the centre word of each linear axis
CENTRE_WORD = {"X": "I", "Y": "J", "Z": "K"}
#: end point on the circle: radii at start and end may differ by this (mm) ...
RADIUS_TOLERANCE_MM = 0.01
#: ... or by this fraction of the radius, whichever is larger
RADIUS_TOLERANCE_FACTOR = 0.001


@dataclass
class ArcPath:
    """A nominal arc in axis space.  ``start`` / ``end`` (n_axes,) mm / deg; ``plane`` the
    indices (first, second, normal) into the axes; ``centre`` (2,) mm in the plane axes;
    ``angle0`` start angle, ``sweep`` signed angle (rad, positive counter-clockwise about the
    normal); ``r0`` / ``r1`` radius at start / end (mm)."""

    start: np.ndarray
    end: np.ndarray
    plane: tuple
    centre: np.ndarray
    angle0: float
    sweep: float
    r0: float
    r1: float

    def points(self, t) -> np.ndarray:
        """Axis positions at the fractions ``t`` (k,) of the arc, (k, n_axes)."""
        t = np.asarray(t, dtype=float)
        a, b, c = self.plane
        out = np.repeat(self.start[None, :], len(t), axis=0)
        ang = self.angle0 + t * self.sweep
        r = self.r0 + t * (self.r1 - self.r0)
        out[:, a] = self.centre[0] + r * np.cos(ang)
        out[:, b] = self.centre[1] + r * np.sin(ang)
        out[:, c] = self.start[c] + t * (self.end[c] - self.start[c])
        return out

    @property
    def radius(self) -> float:
        return max(self.r0, self.r1)

    def distance(self, q: np.ndarray) -> np.ndarray:
        """Distance (mm) of the axis positions ``q`` (k, n_axes) from the arc, in the linear
        axes: to the point of the arc at the same angle (clamped to the arc's sweep)."""
        a, b, c = self.plane
        u, v = q[:, a] - self.centre[0], q[:, b] - self.centre[1]
        rel = np.arctan2(v, u) - self.angle0
        s = self.sweep
        # the angle along the sweep's direction, in [0, 2 pi), then clamped to the arc
        rel = np.mod(rel * np.sign(s), 2 * math.pi) if s else np.zeros_like(rel)
        past = rel > abs(s)
        # beyond the end: the nearer of the two ends
        to_start = 2 * math.pi - rel
        rel = np.where(past, np.where(to_start < rel - abs(s), 0.0, abs(s)), rel)
        t = rel / abs(s) if s else rel
        p = self.points(t)
        lin = list(self.plane)
        return np.linalg.norm(q[:, lin] - p[:, lin], axis=1)


def arc_path(axes, start: dict, end: dict, arc, where: str) -> ArcPath:
    """The :class:`ArcPath` of an arc block (:class:`volerr.nc.gcode.Arc`) from
    ``start`` to ``end`` (axis -> mm / deg); raises :class:`InputError` naming ``where`` for an
    arc that cannot be: an end point off the circle, a radius too short for the chord, a full
    turn given by its radius."""
    names = PLANES[arc.plane]
    for n in names:
        if n not in axes:
            raise InputError(f"{where}: the arc's plane G{arc.plane} needs axis {n}")
    ia, ib, ic = (axes.index(n) for n in names)
    s = np.array([start[a] for a in axes], dtype=float)
    e = np.array([end[a] for a in axes], dtype=float)
    p0 = np.array([s[ia], s[ib]])
    p1 = np.array([e[ia], e[ib]])
    chord = p1 - p0
    d = float(np.hypot(*chord))
    if arc.radius is not None and not arc.centre:
        r = abs(arc.radius)
        if d < 1e-9:
            raise InputError(f"{where}: a full circle cannot be given by its radius R "
                             "(give the centre with I J K)")
        if d > 2 * r + _tolerance(r):
            raise InputError(f"{where}: the end point is not on the arc's circle: the radius "
                             f"R {r:g} mm is shorter than half the chord ({d / 2:.4f} mm)")
        h = math.sqrt(max(r * r - d * d / 4, 0.0))
        left = np.array([-chord[1], chord[0]]) / d       # normal x chord: to the left
        sign = 1.0 if (arc.ccw == (arc.radius > 0)) else -1.0
        centre = (p0 + p1) / 2 + sign * h * left
    else:
        if arc.radius is not None:
            raise InputError(f"{where}: an arc with both R and {' '.join(arc.centre)}")
        words = {CENTRE_WORD[names[0]], CENTRE_WORD[names[1]]}
        other = [w for w in arc.centre if w not in words]
        if other:
            raise InputError(f"{where}: centre word {other[0]} does not belong to the plane "
                             f"G{arc.plane} ({' '.join(sorted(words))})")
        centre = p0 + np.array([arc.centre.get(CENTRE_WORD[names[0]], 0.0),
                                arc.centre.get(CENTRE_WORD[names[1]], 0.0)])
    r0 = float(np.hypot(*(p0 - centre)))
    r1 = float(np.hypot(*(p1 - centre)))
    if r0 < 1e-9:
        raise InputError(f"{where}: the arc's centre is its start point")
    if abs(r1 - r0) > _tolerance(max(r0, r1)):
        raise InputError(f"{where}: the end point is not on the arc's circle: radius "
                         f"{r0:.4f} mm at the start, {r1:.4f} mm at the end (at most "
                         f"{_tolerance(max(r0, r1)) * 1e3:g} um apart)")
    a0 = math.atan2(*(p0 - centre)[::-1])
    a1 = math.atan2(*(p1 - centre)[::-1])
    if arc.ccw:
        sweep = (a1 - a0) % (2 * math.pi)
    else:
        sweep = -((a0 - a1) % (2 * math.pi))
    if abs(sweep) < 1e-12 and d < 1e-9:
        sweep = 2 * math.pi if arc.ccw else -2 * math.pi
    return ArcPath(s, e, (ia, ib, ic), centre, a0, sweep, r0, r1)


def _tolerance(r: float) -> float:
    return max(RADIUS_TOLERANCE_MM, RADIUS_TOLERANCE_FACTOR * r)


def segments_for_chord(path: ArcPath, chord_mm: float) -> int:
    """Segments of equal angle whose chords deviate from the arc by at most ``chord_mm``."""
    r = path.radius
    if r <= chord_mm:
        return max(1, math.ceil(abs(path.sweep) / math.pi))
    step = 2 * math.acos(1 - chord_mm / r)
    return max(1, math.ceil(abs(path.sweep) / step))


# ---------------------------------------------------------------------------------------
# how an arc is written
@dataclass
class ArcResult:
    """How one arc is written: ``kept`` (an arc with corrected end point and ``centre``, axis
    coordinates of the plane's two axes, mm) or linearised into ``points`` (k, n_axes), the
    compensated end of each segment (the last is the block's end point, as solved for the
    block); ``variation_um`` how much the correction varies along the arc; ``deviation_um``
    the largest predicted distance of the tool tip from the nominal arc between the points
    (linearised) or the variation (kept)."""

    kept: bool
    centre: np.ndarray | None
    points: np.ndarray | None
    variation_um: float
    deviation_um: float

    @property
    def status(self) -> str:
        if self.kept:
            return (f"arc kept (correction varies {self.variation_um:.3g} um along it; end "
                    "point and centre corrected)")
        return (f"arc linearised into {len(self.points)} segments (predicted path deviation "
                f"{self.deviation_um:.3g} um)")
