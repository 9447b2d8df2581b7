"""Built-in instrument campaigns of known truth for ``volerr demo``: ballbar circles of Pahk's
CMM A example tables, and a sphere / R-test plan on a five-axis layout with planted location
errors of its rotary axes.  Simulated with the layout's first-order model (what the demo shows
is the calibration, not the simulator)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

#: the planted location errors of the five-axis example, um and urad
SPHERE_TRUTH = {"EX0B": 12.0, "EY0B": -8.0, "EA0B": 35.0, "EB0B": -20.0,
                "EX0C": 15.0, "EY0C": -10.0, "EA0C": 25.0, "EB0C": -40.0}


#: the planted errors of the ballbar example: squareness (urad) and scale errors (um/m)
BALLBAR_TRUTH = {"EC0Y": 20.0, "EB0Z": -12.0, "EA0Z": 8.0, "EXX": 15.0, "EYY": -5.0,
                 "EZZ": 10.0}


def write_ballbar_example(folder, layout: str = "MB1", noise_um: float = 0.3) -> dict:
    """Three ISO 230-4 circles (XY, YZ, ZX; radius 150 mm; both directions) of ``layout`` with
    the squareness and scale errors :data:`BALLBAR_TRUTH`, written as ballbar files in
    ``folder`` (and the error directory they come from).  Returns ``{"errors": DIR, "files":
    [...], "truth": {...}}``."""
    from ..ballbar.simulate import simulate, write_csv
    from ..machine.model import load
    from ..tables.functions import ErrorFunctions
    from ..tables.table import ErrorTable, write_error_dir

    folder = Path(folder)
    model = load(layout)
    tables = {}
    for a in ("X", "Y", "Z"):
        q = np.linspace(*model.travel[a], 11)
        tables[a] = ErrorTable(a, q, {f"E{a}{a}": BALLBAR_TRUTH[f"E{a}{a}"] * 1e-6 * q})
    constants = {k: v * 1e-6 for k, v in BALLBAR_TRUTH.items() if k[2] == "0"}
    errors = write_error_dir(folder / f"errors_{layout}", tables, constants)
    funcs = ErrorFunctions(tables, constants, model)
    mid = [0.5 * sum(model.travel[a]) for a in ("X", "Y", "Z")]
    files = []
    for k, plane in enumerate(("XY", "YZ", "ZX")):
        cols = simulate(model, funcs, plane, 150.0, mid, (0.0, 0.0, 0.0), None, 180,
                        noise_um, "both", seed=10 + k)
        path = folder / f"ballbar_{plane}.csv"
        write_csv(path, cols)
        files.append(path)
    return {"errors": errors, "files": files, "truth": dict(BALLBAR_TRUTH)}


def write_sphere_example(path, layout: str = "DMU50", noise_um: float = 0.5,
                         seed: int = 3) -> dict:
    """A touch-probe kinematics plan on ``layout``: two sphere placements, the rotary axes over
    their travel, a 120 mm probe; planted location errors :data:`SPHERE_TRUTH` (those the
    layout has), unknown true sphere centres (a few um off), noise.  Returns ``{"path",
    "truth": {name: um or urad}, "n"}``."""
    from ..instruments import sphere
    from ..machine.model import load

    model = load(layout)
    truth = {k: v for k, v in SPHERE_TRUTH.items() if k in model.parameters}
    errors = {k: v * (1e-6 if k[1] in "ABC" else 1e-3) for k, v in truth.items()}
    rotary = {a: np.linspace(*_range(model.travel[a]), 9) for a in model.rotary_axes}
    tool = (0.0, 0.0, 120.0)
    poses = sphere.plan(model, [(80.0, 40.0, 20.0), (-60.0, 70.0, 90.0)], rotary, tool)
    cols = sphere.simulate(model, errors, poses, tool,
                           {"1": (0.004, -0.006, 0.003), "2": (-0.005, 0.002, 0.007)},
                           noise_um, seed)
    sphere.write_csv(path, cols)
    return {"path": Path(path), "truth": truth, "n": len(cols["X"])}


def _range(travel) -> tuple[float, float]:
    lo, hi = travel
    return lo, min(hi, lo + 320.0)
