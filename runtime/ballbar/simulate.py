"""Ballbar traces of a layout's model: the commanded positions of a circle test and the bar
readings the model predicts (``volerr ballbar simulate``).

Circle test (ISO 230-4): the pivot ball at ``centre`` (workpiece frame, mm), the tool ball on a
circle of ``radius`` about it in the plane XY, YZ or ZX of the workpiece frame, the rotary axes
held at ``rotary`` (deg); angles counted from the plane's first axis towards its second (XY: from
+X to +Y; YZ: +Y to +Z; ZX: +Z to +X), counter-clockwise seen from the plane's positive normal.
Rotary test (ISO 10791-6:2014, kinematic tests with rotary and linear axes moving
together): one rotary axis sweeps its range (``rotary={"C": (0, 360)}``)
while the linear axes keep the tool ball at ``centre + radius * first axis of the plane`` in
the workpiece frame, i.e. on the table; counter-clockwise = the rotary position increasing.

The linear positions come from the layout's nominal chain (affine in the linear axes at fixed
rotary positions: solved exactly); the readings are the first-order model, ``u . e`` (bar
direction ``u``, volumetric error ``e`` of the error functions at the commanded positions),
plus Gaussian noise.  Units: mm, deg; readings um in the file.
"""

from __future__ import annotations

import numpy as np

from ..errors import require

PLANES = {"XY": (0, 1, 2), "YZ": (1, 2, 0), "ZX": (2, 0, 1)}


def plane_axes(plane: str) -> tuple[np.ndarray, np.ndarray]:
    """The plane's first and second unit axes in the workpiece frame."""
    require(plane in PLANES, f"plane must be one of {' '.join(PLANES)}, got {plane!r}")
    i, j, _ = PLANES[plane]
    e = np.eye(3)
    return e[i], e[j]


def trace(model, plane: str, radius: float, centre, tool=(0.0, 0.0, 0.0), rotary=None,
          points: int = 360, direction: int = 1) -> dict:
    """Commanded positions and geometry of one trace: ``{"positions", "pivot", "angle_deg",
    "direction"}``; ``rotary``: {axis: deg} fixed or {axis: (start, stop)} swept."""
    require(radius > 0, "radius must be positive")
    require(points >= 8, "a trace needs at least 8 points")
    e1, e2 = plane_axes(plane)
    centre = np.asarray(centre, float)
    rotary = dict(rotary or {})
    swept = [a for a, v in rotary.items() if np.ndim(v) == 1 and len(v) == 2]
    require(len(swept) <= 1, "at most one rotary axis can sweep")
    for a in rotary:
        require(a in model.rotary_axes, f"{a} is not a rotary axis of {model.name}")
    frac = np.arange(points) / points
    if swept:
        a = swept[0]
        lo, hi = map(float, rotary[a])
        q = lo + (hi - lo) * (frac if (hi - lo) % 360 == 0 else np.linspace(0, 1, points))
        if direction < 0:
            q = q[::-1]
        rot = {**{k: v for k, v in rotary.items() if k != a}, a: q}
        targets = np.tile(centre + radius * e1, (points, 1))
        angle = q
    else:
        theta = 2 * np.pi * frac * (1 if direction > 0 else -1)
        targets = centre + radius * (np.cos(theta)[:, None] * e1 + np.sin(theta)[:, None] * e2)
        rot = rotary
        angle = np.rad2deg(np.mod(theta, 2 * np.pi))
    pos = model.linear_positions(targets, rot, tool)
    for a in model.axes:
        lo, hi = model.travel[a]
        bad = np.flatnonzero((pos[a] < lo - 1e-9) | (pos[a] > hi + 1e-9))
        require(len(bad) == 0, f"the trace needs {a} = {pos[a][bad[0]] if len(bad) else 0:g}, "
                               f"outside the travel [{lo:g}, {hi:g}] of {model.name}: move "
                               f"the centre or shorten the radius")
    return {"positions": pos, "pivot": centre, "angle_deg": angle, "direction": direction}


def readings(model, functions, positions: dict, pivot, tool, noise_um: float = 0.0,
             seed: int = 0) -> np.ndarray:
    """Bar length minus nominal length (N,) mm of the first-order model: ``u . e``."""
    t = model.nominal_position(positions, tool)
    errors = functions(positions) if functions is not None else {}
    e = model.volumetric_error(positions, errors, probe=tool)
    u = (t - pivot) / np.linalg.norm(t - pivot, axis=1)[:, None]
    dr = np.sum(u * e, axis=1)
    if noise_um:
        dr = dr + np.random.default_rng(seed).normal(0.0, noise_um * 1e-3, len(dr))
    return dr


def simulate(model, functions, plane: str, radius: float, centre, tool=(0.0, 0.0, 0.0),
             rotary=None, points: int = 360, noise_um: float = 0.0, direction: str = "both",
             seed: int = 0) -> dict:
    """Columns of a ballbar file (``volerr formats ballbar``) for one circle (both directions
    by default: counter-clockwise first)."""
    require(direction in ("both", "ccw", "cw"), "direction must be both, ccw or cw")
    dirs = {"both": (1, -1), "ccw": (1,), "cw": (-1,)}[direction]
    tool = np.asarray(tool, float)
    cols: dict = {}
    for k, d in enumerate(dirs):
        tr = trace(model, plane, radius, centre, tool, rotary, points, d)
        dr = readings(model, functions, tr["positions"], tr["pivot"], tool, noise_um, seed + k)
        n = len(dr)
        part = {**{a: tr["positions"][a] for a in model.axes},
                "Xp": np.full(n, tool[0]), "Yp": np.full(n, tool[1]), "Zp": np.full(n, tool[2]),
                "pivot_x": np.full(n, tr["pivot"][0]), "pivot_y": np.full(n, tr["pivot"][1]),
                "pivot_z": np.full(n, tr["pivot"][2]), "length_mm": np.full(n, float(radius)),
                "dr_um": dr * 1e3, "direction": np.full(n, float(d))}
        for key, v in part.items():
            cols[key] = np.concatenate([cols[key], v]) if key in cols else np.asarray(v, float)
    return cols


def write_csv(path, cols: dict, inputs=()):
    """Write ballbar columns (6 decimals for mm/deg, 5 for um; no negative zero)."""
    from ..fileio import write_text

    from ..units import num

    names = list(cols)
    n = len(cols[names[0]])
    fmt = [".5f" if k.endswith("_um") else ".0f" if k == "direction" else ".6f" for k in names]
    lines = [",".join(names)]
    for i in range(n):
        lines.append(",".join(num(cols[k][i], f) for f, k in zip(fmt, names)))
    return write_text(path, "\n".join(lines) + "\n", inputs=list(inputs))
