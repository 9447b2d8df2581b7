"""An independent NC controller for the tests (numpy and re only, no volerr code).

It reads the ISO subset the tests write and the compensated programs volerr writes back --
``G0 G1 G2 G3`` (modal), ``G17 G18 G19``, ``G90 G91``, arc centres ``I J K`` (relative to the
start) or radius ``R``, comments ``( )`` and ``;`` -- and samples the axis path of every block
the way a controller interpolates it: straight lines in axis space, circles (and helices) in
the plane of the arc with the radius going linearly from the start to the end radius.  Under
``G43.4`` (TCPM, rotary angles) the linear words are the tool tip in the workpiece frame: the
axis positions come from the caller's nominal inverse ``tcpm_inverse(tip, rot) -> linear``.
"""

from __future__ import annotations

import math
import re

import numpy as np

_WORD = re.compile(r"([A-Za-z])[ \t]*([+-]?(?:\d+\.?\d*|\.\d+))")
_PLANES = {17: ("X", "Y", "Z"), 18: ("Z", "X", "Y"), 19: ("Y", "Z", "X")}
_CENTRE = {"X": "I", "Y": "J", "Z": "K"}


def _strip(line: str) -> str:
    line = re.sub(r"\([^)]*\)", " ", line)
    return line.split(";", 1)[0]


class Move:
    """One block: ``line`` number, ``start`` / ``end`` axis dicts, and for arcs the plane axes,
    the centre (two numbers in the plane), the signed sweep (rad) and the radii."""

    def __init__(self, line, start, end, arc=None, tcpm=False):
        self.line, self.start, self.end, self.arc, self.tcpm = line, start, end, arc, tcpm

    def sample(self, axes, t) -> np.ndarray:
        """Axis positions (len(t), len(axes)) at the fractions ``t`` of the block."""
        t = np.asarray(t, float)
        s = np.array([self.start[a] for a in axes])
        e = np.array([self.end[a] for a in axes])
        out = s[None, :] + t[:, None] * (e - s)[None, :]
        if self.arc is not None:
            (a, b, _), centre, a0, sweep, r0, r1 = self.arc
            ia, ib = axes.index(a), axes.index(b)
            ang = a0 + t * sweep
            r = r0 + t * (r1 - r0)
            out[:, ia] = centre[0] + r * np.cos(ang)
            out[:, ib] = centre[1] + r * np.sin(ang)
        return out


def moves(text: str, axes, initial=None, tcpm_inverse=None) -> list:
    """The moves of a program (blocks whose start and end are known)."""
    pos = {a: None for a in axes}
    pos.update(initial or {})
    mode, plane, inc, tcpm = 0, 17, False, False
    tip = {a: None for a in "XYZ"}
    out = []
    for n, raw in enumerate(text.splitlines(), start=1):
        body = _strip(raw)
        words = [(m.group(1).upper(), float(m.group(2))) for m in _WORD.finditer(body)]
        if not words:
            continue
        g = [v for k, v in words if k == "G"]
        for v in g:
            v = round(v, 1)
            if v in (0, 1, 2, 3):
                mode = int(v)
            elif v in (17, 18, 19):
                plane = int(v)
            elif v == 90:
                inc = False
            elif v == 91:
                inc = True
            elif v == 43.4:
                tcpm = True
                tip = {a: None for a in "XYZ"}
            elif v == 49:
                tcpm = False
        ax = {k: v for k, v in words if k in axes}
        if not ax:
            continue
        start = dict(pos)
        if tcpm:
            for k, v in ax.items():
                if k in tip:
                    tip[k] = v
                else:
                    pos[k] = v
            if any(v is None for v in tip.values()):
                continue
            rot = [pos[a] for a in axes if a not in "XYZ"]
            lin = tcpm_inverse(np.array([tip[a] for a in "XYZ"]), np.array(rot))
            for a, v in zip("XYZ", lin):
                pos[a] = float(v)
            if all(v is not None for v in start.values()):
                out.append(Move(n, start, dict(pos), tcpm=True))
            continue
        for k, v in ax.items():
            pos[k] = (pos[k] + v if pos[k] is not None else None) if inc else v
        if any(v is None for v in start.values()) or any(v is None for v in pos.values()):
            continue
        arc = None
        if mode in (2, 3):
            names = _PLANES[plane]
            a, b = names[0], names[1]
            p0 = np.array([start[a], start[b]])
            p1 = np.array([pos[a], pos[b]])
            wd = dict(words)
            if "R" in wd:
                r = wd["R"]
                d = p1 - p0
                L = math.hypot(*d)
                h = math.sqrt(max(r * r - L * L / 4, 0.0))
                # centre to the left of the chord for a counter-clockwise arc of at most
                # half a turn (R > 0), to the right for clockwise
                left = np.array([-d[1], d[0]]) / L
                sign = 1.0 if ((mode == 3) == (r > 0)) else -1.0
                centre = (p0 + p1) / 2 + sign * h * left
            else:
                centre = p0 + np.array([wd.get(_CENTRE[a], 0.0), wd.get(_CENTRE[b], 0.0)])
            a0 = math.atan2(p0[1] - centre[1], p0[0] - centre[0])
            a1 = math.atan2(p1[1] - centre[1], p1[0] - centre[0])
            if mode == 3:
                sweep = (a1 - a0) % (2 * math.pi) or 2 * math.pi
            else:
                sweep = -((a0 - a1) % (2 * math.pi) or 2 * math.pi)
            arc = (names, centre, a0, sweep, math.dist(p0, centre), math.dist(p1, centre))
        out.append(Move(n, start, dict(pos), arc))
    return out
