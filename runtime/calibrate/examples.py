"""Built-in instrument campaigns of known truth for ``volerr demo``: ballbar circles of Pahk's
CMM A example tables, a sphere / R-test plan on a five-axis layout with planted location
errors of its rotary axes, a ball plate in four placements on a CMM, and multilateration from
four stations of a tracking interferometer on a five-axis layout.  Simulated with the
layout's first-order model (what the demo shows is the calibration, not the simulator)."""

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
    from ..instruments.ballbar import simulate, write_csv
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
    their travel, the tool offset (0, 0, +120) mm (the tool point 120 mm from the reference
    point towards the spindle, docs/conventions.md); planted location errors
    :data:`SPHERE_TRUTH` (those the layout has), unknown true sphere centres (a few um off),
    noise.  Returns ``{"path", "truth": {name: um or urad}, "n"}``."""
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


#: the planted errors of the ball-plate example: scale errors (um/mm) and squareness (urad),
#: in the report's names
PLATE_TRUTH = {"EXX@slope": 0.012, "EYY@slope": -0.008, "EZZ@slope": 0.010, "EC0Y": 15.0,
               "EB0Z": -12.0, "EA0Z": 10.0}


def _planted(truth: dict, mids: dict) -> dict:
    """Report names -> the model's error values: constants (mm / rad) and, for ``@slope``
    terms, callables of the positions about the middle ``mids[axis]`` of the measured range
    (a translational error has no offset by the calibration's convention: an offset on a
    five-axis machine would reappear in the rotary axes' location errors)."""
    out = {}
    for name, v in truth.items():
        if name.endswith("@slope"):
            p = name.split("@")[0]
            out[p] = (lambda pos, p=p, v=v: v * 1e-3 * (np.asarray(pos[p[2]]) - mids[p[2]]))
        else:
            out[name] = v * (1e-6 if name[1] in "ABC" else 1e-3)
    return out


def _mids(pos: dict) -> dict:
    return {a: 0.5 * (float(np.min(v)) + float(np.max(v))) for a, v in pos.items()}


def write_ballplate_example(path, layout: str = "MB1", noise_um: float = 0.5,
                            seed: int = 3) -> dict:
    """A 5 x 5 ball plate (pitch 80 mm) in four placements on ``layout`` -- XY at two heights,
    XZ, YZ, each turned a little -- with the scale and squareness errors :data:`PLATE_TRUTH`.
    Returns ``{"path", "truth", "poses": {label: (R, origin)}}``."""
    from scipy.spatial.transform import Rotation

    from ..instruments import artifact
    from ..machine.model import load

    model = load(layout)
    rng = np.random.default_rng(seed)
    pts = artifact.plate_points(5, 5, 80.0)
    lo = model.nominal_position({a: model.travel[a][0] for a in model.axes})[0]
    hi = model.nominal_position({a: model.travel[a][1] for a in model.axes})[0]
    mid = 0.5 * (lo + hi)
    poses = {}
    for label, plane, dz in (("XYlow", "XY", -0.25), ("XYhigh", "XY", 0.25),
                             ("XZ", "XZ", 0.0), ("YZ", "YZ", 0.0)):
        centre = mid + np.array([0.0, 0.0, dz * (hi[2] - lo[2])])
        R, _ = artifact.placed(model, pts, plane, centre)
        R = R @ Rotation.from_rotvec(rng.normal(0.0, 2e-3, 3)).as_matrix()
        poses[label] = (R, centre - R @ pts.mean(axis=0))
    nominal = np.concatenate([pts @ R.T + o for R, o in poses.values()])
    errors = _planted(PLATE_TRUTH, _mids(model.linear_positions(nominal, {})))
    cols = None
    for k, (label, pose) in enumerate(poses.items()):
        c = artifact.columns(model, pts, pose, label, errors=errors, noise_um=noise_um,
                             seed=seed + k)
        cols = c if cols is None else {key: list(cols[key]) + list(c[key]) for key in c}
    artifact.write_csv(path, cols)
    return {"path": Path(path), "truth": dict(PLATE_TRUTH), "poses": poses}


#: the planted errors of the multilateration example (um/mm, um, urad)
TRACER_TRUTH = {"EXX@slope": 0.012, "EYY@slope": -0.010, "EZZ@slope": 0.015, "EC0Y": 20.0,
                "EB0Z": -15.0, "EA0Z": 12.0, "EX0B": 12.0, "EY0B": -8.0, "EA0B": 35.0,
                "EB0B": -20.0, "EX0C": 15.0, "EY0C": -10.0, "EA0C": 25.0, "EB0C": -30.0}
#: stations of the multilateration example, workpiece frame, mm
TRACER_STATIONS = {"S1": (-180.0, -170.0, 10.0), "S2": (190.0, -160.0, 40.0),
                   "S3": (170.0, 185.0, 5.0), "S4": (-160.0, 175.0, 60.0)}


def write_multilateration_example(path, layout: str = "DMU50", n: int = 200,
                                  seed: int = 2) -> dict:
    """A tracking interferometer at four stations on the table of ``layout`` measuring ``n``
    poses of the five axes (reflector 100 mm out along the tool, inside a box on the table),
    relative readings, noise 0.3 um + 0.3 um/m; planted :data:`TRACER_TRUTH` (those the
    layout has).  Returns ``{"path", "truth", "stations", "parameters"}``."""
    from ..instruments import distances
    from ..machine.model import load

    model = load(layout)
    rng = np.random.default_rng(seed)
    truth = {k: v for k, v in TRACER_TRUTH.items() if k.split("@")[0] in model.parameters}
    probe = (0.0, 0.0, 100.0)
    pos = {a: np.zeros(0) for a in model.axes}
    while len(pos[model.axes[0]]) < n:
        t = rng.uniform([-150, -150, 20], [150, 150, 250], (4 * n, 3))
        rot = {a: (rng.choice([0.0, 20.0, 45.0, 70.0, 90.0], 4 * n) if k == 0
                   else rng.uniform(0.0, 360.0, 4 * n))
               for k, a in enumerate(model.rotary_axes)}
        q = model.linear_positions(t, rot, probe)
        ok = np.ones(4 * n, bool)
        for a in model.axes:
            lo, hi = model.travel[a]
            ok &= (q[a] >= lo) & (q[a] <= hi)
        pos = {a: np.concatenate([pos[a], q[a][ok]]) for a in model.axes}
    pos = {a: v[:n] for a, v in pos.items()}
    errors = {k: (v(pos) if callable(v) else v) for k, v in _planted(truth, _mids(pos)).items()}
    cols = distances.simulate(model, pos, TRACER_STATIONS, probe, errors,
                              {"S1": 0.012, "S2": -0.02, "S3": 0.03}, relative=True,
                              seed=seed)
    distances.write_csv(path, cols)
    names = sorted({k.split("@")[0] for k in truth}, key=list(model.parameters).index)
    return {"path": Path(path), "truth": truth, "stations": dict(TRACER_STATIONS),
            "parameters": ",".join(names)}
