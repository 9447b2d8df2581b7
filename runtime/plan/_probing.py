"""Where a touch probe touches a ball of a ball plate, and the path round it (workpiece frame,
mm): shared by the NC programs (:mod:`volerr.plan._nc`) and the candidates (a placement whose
probing path leaves the travel is not one, :mod:`volerr.plan._candidates`).

A plate's balls stand on its free side, +w (w = u x v, the plate's normal); the stylus is
along the tool axis.  A ball is probed at the points a centre needs: a plate lying flat (its
normal along the tool axis) at the four equator points along the plate's axes and the pole; a
standing plate at the pole on its free side, both equator points normal to the tool axis and
the top (a stylus along the tool axis cannot reach under a ball).  Each probing move starts
:data:`PROBE_START_MM` from the centre along the point's direction and is programmed to
:data:`PROBE_PAST_MM` past the expected contact (ball radius + stylus tip radius); the stylus
goes from point to point over the corners of a box :data:`PROBE_START_MM` round the ball on its
free side, so it never comes nearer the ball than :data:`PROBE_START_MM` but along a probing
move and back out along it.
"""

from __future__ import annotations

import numpy as np

#: ball and stylus tip diameters (mm), the start of a probing move from the ball centre, how
#: far past the expected contact a probing move is programmed (mm)
BALL_D_MM, STYLUS_D_MM, PROBE_START_MM, PROBE_PAST_MM = 25.0, 3.0, 22.0, 2.0
#: plate plane -> (workpiece axis of u, of v) at 0 deg (as :mod:`volerr.plan._candidates`)
PLATE_AXES = {"XY": (0, 1), "YZ": (1, 2), "ZX": (2, 0)}


def directions(model, plane: str, tool, rot: dict) -> tuple:
    """(free-side normal (3,), [unit directions (3,) from a ball's centre to the points
    probed]) of a plate in ``plane`` with the rotary axes at ``rot`` {axis: deg} (module
    docstring)."""
    axis = model.forward({**{a: np.zeros(1) for a in model.axes},
                          **{a: np.array([v]) for a, v in rot.items()}}, probe=tool)[0, 3:]
    n = np.eye(3)[3 - sum(PLATE_AXES[plane])]
    inplane = [e for e in np.eye(3) if abs(e @ n) < 0.5]
    if abs(n @ axis) > 0.99:
        return n, [e * s for e in inplane for s in (1.0, -1.0)] + [n]
    up = axis - (axis @ n) * n
    up = up / np.linalg.norm(up)
    side = np.cross(n, up)
    return n, [n, side, -side, up]


def ball_path(c, n, dirs) -> np.ndarray:
    """(2 + 5 len(dirs), 3) the points round the ball at ``c``: first and last the point
    :data:`PROBE_START_MM` out along ``n``; for each direction its box corner, the probing
    move's start, its programmed end, the start and the corner again."""
    r = PROBE_START_MM
    past = 0.5 * (BALL_D_MM + STYLUS_D_MM) - PROBE_PAST_MM
    pts = [c + r * n]
    for d in dirs:
        corner = c + r * n + (r * d if abs(d @ n) < 0.5 else 0.0)
        pts += [corner, c + r * d, c + past * d, c + r * d, corner]
    pts.append(c + r * n)
    return np.array(pts)
