"""Fill the empty reading columns of ``volerr plan`` files with readings of the EXACT chain of
``tests/helpers/instrument_sim.py`` (independent of the runtime: it never calls volerr's model,
instruments or plan code), planted errors, set-up offsets and Gaussian noise.

Reading models (the instruments' documented definitions, exact):

* ballbar: ``dr = |t_act - (p + dp)| - L + dL`` per placement (``dp`` (3,), ``dL`` um);
* sphere (frame work): ``d = t_act(probe + tool_dz z_tool) - (c + dc)`` per placement;
* distances: ``d = |t_act - (s + ds)| + dead`` per station (absolute distance, mm).

Planted errors: constants in JSON units (um, urad) and scale slopes ``EXX@slope`` (um/mm, the
error ``slope * (X - middle of the measured X range)``).  Units: positions mm / deg.
"""

from __future__ import annotations

import csv

import numpy as np

from helpers import instrument_sim as S


def read(path) -> tuple[list, dict]:
    """(header comment lines, columns: name -> list of cell texts) of a plan file."""
    with open(path, newline="") as fh:
        lines = fh.read().splitlines()
    comments = [ln for ln in lines if ln.startswith("#")]
    body = list(csv.reader(ln for ln in lines if ln.strip() and not ln.startswith("#")))
    names = body[0]
    return comments, {n: [r[j] for r in body[1:]] for j, n in enumerate(names)}


def write(path, comments, cols) -> None:
    names = list(cols)
    n = len(cols[names[0]])
    with open(path, "w", newline="") as fh:
        for c in comments:
            fh.write(c + "\n")
        w = csv.writer(fh)
        w.writerow(names)
        for i in range(n):
            w.writerow([cols[k][i] for k in names])


def _errors(machine, pos, planted: dict, ranges: dict) -> dict:
    n = len(next(iter(pos.values())))
    out = {}
    for name, v in planted.items():
        if "@slope" in name:
            comp = name.split("@")[0]
            axis = comp[2]
            mid = 0.5 * sum(ranges[axis])
            out[comp] = out.get(comp, 0.0) + v * 1e-3 * (pos[axis] - mid)
        else:
            scale = 1e-6 if S.is_angular(name) else 1e-3
            out[name] = np.full(n, v * scale)
    return out


def fill(path, layout, planted: dict, rng, setup_um: float = 20.0, tool_dz_um: float = 0.0,
         dead_mm: float = 0.2, ranges: dict | None = None) -> dict:
    """Fill the file in place; returns the planted set-up values (um)."""
    machine = S.Machine(layout)
    comments, cols = read(path)
    pos = {a: np.array(cols[a], float) for a in machine.axes}
    probe = np.column_stack([np.array(cols[c], float) for c in ("Xp", "Yp", "Zp")])
    n = len(probe)
    ranges = ranges or {a: (float(v.min()), float(v.max())) for a, v in pos.items()}
    errs = _errors(machine, pos, planted, ranges)
    u = np.array(cols["u_um"], float) if "u_um" in cols else None
    if "dr_um" in cols:
        label = np.array(cols["placement"])
        pivot = np.column_stack([np.array(cols[c], float) for c in ("pivot_x", "pivot_y",
                                                                    "pivot_z")])
        t = machine.tool_point(pos, errs, probe)
        dp, dl = np.zeros((n, 3)), np.zeros(n)
        for p in np.unique(label):
            m = label == p
            dp[m] = rng.normal(0, setup_um * 1e-3, 3)
            dl[m] = rng.normal(0, setup_um * 1e-3)
        L = np.array(cols["length_mm"], float)
        r = 1e3 * (np.linalg.norm(t - pivot - dp, axis=1) - L + dl)
        r += rng.normal(0, 1, n) * (u if u is not None else 0.5)
        cols["dr_um"] = [f"{v:.5f}" for v in r]
    elif "dx_um" in cols:
        label = np.array(cols["placement"])
        axis = machine.tool_axis(pos)
        t = machine.tool_point(pos, errs, probe + tool_dz_um * 1e-3 * np.array([0, 0, 1.0]))
        del axis
        c = np.column_stack([np.array(cols[k], float) for k in ("sphere_x", "sphere_y",
                                                                "sphere_z")])
        dc = np.zeros((n, 3))
        for p in np.unique(label):
            dc[label == p] = rng.normal(0, setup_um * 1e-3, 3)
        d = 1e3 * (t - c - dc) + rng.normal(0, 1, (n, 3)) * (u[:, None] if u is not None
                                                             else 1.0)
        for k, name in enumerate(("dx_um", "dy_um", "dz_um")):
            cols[name] = [f"{v:.5f}" for v in d[:, k]]
    else:
        label = np.array(cols["station"])
        s = np.column_stack([np.array(cols[k], float) for k in ("station_x", "station_y",
                                                                "station_z")])
        t = machine.tool_point(pos, errs, probe)
        ds, dead = np.zeros((n, 3)), np.zeros(n)
        for p in np.unique(label):
            ds[label == p] = rng.normal(0, setup_um * 1e-3, 3)
            dead[label == p] = dead_mm + rng.normal(0, 0.05)
        dist = np.linalg.norm(t - s - ds, axis=1)
        sig = (u if u is not None else 0.3 + 0.3e-3 * dist) * 1e-3
        cols["d_mm"] = [f"{v:.8f}" for v in dist + dead + rng.normal(0, 1, n) * sig]
    write(path, comments, cols)
    return {}
