"""The conventional plan of each instrument at the same number of readings, predicted on the
same path as the plan, so that the user sees what the design gains:

* ballbar: ISO 230-4 -- three circles in XY, YZ and ZX about one pivot at the centre of the
  working volume, the middle of the bar lengths given (the longest that fits when it does
  not), the readings split equally;
* sphere / R-test: one placement off the table's centre (a third of the half width along x,
  as a kinematics cycle places its sphere so that a turning axis moves it; the lowest
  candidate height),
  the rotary axes in equal steps over their travel (a turning axis over one turn), as
  many poses as readings;
* tracking interferometer: four stations at the bottom corners of the working volume, the
  readings split equally.
"""

from __future__ import annotations

import math

from dataclasses import replace

import numpy as np

from . import _candidates, _files
from ..errors import InputError
from ._predict import Prediction, predict

NAMES = {"ballbar": "ISO 230-4: three orthogonal circles about the centre",
         "sphere": "one sphere placement, rotary axes in equal steps",
         "distances": "four stations at the bottom corners",
         "interferometer": "ISO 230-2: one linear-optics line along each linear axis through "
                           "the middle of the travel",
         "artifact": "ball plate in XY at the bottom and the top, YZ and ZX in the middle"}


def baseline(model, insts, spec, files, tool) -> dict:
    """``{"name", "readings", "prediction", "files"}`` of the conventional plan with the
    plan's readings per instrument."""
    picks, names = [], []
    for i, inst in enumerate(insts):
        n = sum(f.n for f in files if f.inst == i)
        if not n:
            continue
        picks += [(i, s, m) for s, m in MAKERS[inst.kind](model, inst, n)]
        names.append(NAMES[inst.kind])
    name = "; ".join(names)
    try:
        bfiles = _files.group(insts, picks)
        parts = [_files.observations(model, f) for f in bfiles]
        pred = predict(model, parts, spec, tool)
    except InputError as exc:      # too few readings for the conventional set-ups
        return {"name": name, "readings": 0, "files": [], "why": str(exc),
                "prediction": Prediction({}, [], map_u_um={"max": None, "rms": None})}
    return {"name": name, "readings": int(sum(f.n for f in bfiles)), "prediction": pred,
            "files": bfiles}


def _ballbar(model, inst, n: int) -> list:
    lo, hi = _candidates.volume(model, inst.tool)
    centre = np.round(0.5 * (lo + hi), 1)
    lengths = sorted(inst.lengths)
    order = [lengths[len(lengths) // 2]] + sorted(lengths, reverse=True)
    for length in order:
        circles = [_candidates._circle(model, inst, p, length, centre, k + 1)
                   for k, p in enumerate(("XY", "YZ", "ZX"))]
        if all(c is not None for c in circles):
            per = [n // 3 + (1 if k < n % 3 else 0) for k in range(3)]
            return list(zip(circles, per))
    return []


def _sphere(model, inst, n: int) -> list:
    lo, hi = _candidates.volume(model, inst.tool)
    half = 0.5 * min(hi[0] - lo[0], hi[1] - lo[1])
    centre = np.array([round(half / 3.0, 1), 0.0, round(float(lo[2] + 0.1 * (hi[2] - lo[2])), 1)])
    axes = model.rotary_axes
    steps = max(2, math.ceil(n ** (1.0 / max(len(axes), 1))))
    s = None
    for _ in range(12):
        grid = _candidates.rotary_grid(model, steps, steps)
        s = _candidates.sphere_placement(model, inst, centre, grid, "S1") or s
        if s is not None and s.template >= n:
            break
        steps += 1
    return [(s, n)] if s is not None else []        # beyond the poses: whole cycles repeated


def _distances(model, inst, n: int) -> list:
    found = _candidates.distances_setups(model, inst)
    corners = [s for s in found if s.geometry["station"][2] < min(
        t.geometry["station"][2] for t in found) + 1e-9][:4]
    per = [n // 4 + (1 if k < n % 4 else 0) for k in range(len(corners))]
    return list(zip(corners, per))


def _interferometer(model, inst, n: int) -> list:
    found = _candidates.interferometer_setups(model, replace(inst, optics=("linear",)))
    mid = [s for s in found if all(abs(v - 0.5 * sum(model.travel[a])) < 0.051 *
                                   (model.travel[a][1] - model.travel[a][0])
                                   for a, v in s.line.at.items() if a not in model.rotary_axes)]
    per = [n // len(mid) + (1 if k < n % len(mid) else 0) for k in range(len(mid))]
    return list(zip(mid, per))


def _artifact(model, inst, n: int) -> list:
    """The ball-plate method's usual placements (XY at the bottom and the top, YZ, ZX in the
    middle, not turned), as many of them as the readings allow."""
    levels = _candidates.PLATE_LEVELS
    found = {(s.geometry["plane"], s.geometry["turn"], s.geometry["level"]): s
             for s in _candidates.artifact_setups(model, inst)}
    order = [found.get(key) for key in (("XY", 0, levels[0]), ("XY", 0, levels[-1]),
                                        ("YZ", 0, levels[1]), ("ZX", 0, levels[1]))]
    order = [s for s in order if s is not None]
    count = min(len(order), max(1, n // order[0].template)) if order else 0
    return [(s, s.template) for s in order[:count]]


MAKERS = {"ballbar": _ballbar, "sphere": _sphere, "distances": _distances,
          "interferometer": _interferometer, "artifact": _artifact}
