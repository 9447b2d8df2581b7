"""The identified model as a volumetric error map with its uncertainty, propagated from the
calibration's covariance.

At any commanded pose ``q`` (tool offset ``p``) the identified volumetric error is ``e(q) =
A(q) theta`` -- ``A`` the parameter columns of the calibration's design for a 3-D reading of
the tool point (the layout's sensitivity times the series basis of each component error),
``theta`` the identified coefficients -- and its covariance ``A C A^T`` with ``C`` the
covariance of ``theta`` (a-posteriori, :mod:`volerr.calibrate.run`), correlations included.
Parameters the campaign does not determine are not in ``theta`` (their value 0, no
uncertainty): the map is the map of what was determined, and says so (``undetermined``).
The same propagation gives the standard uncertainty of an identified error function
(:func:`function_std`, the error tables' ``_std`` columns).

Units: positions mm / deg, errors and uncertainties mm inside, um in reports.  The map's grid
spans the measured range of the linear axes (where the series are defined), rotary axes fixed
(0 deg when inside their measured range, else its middle).
"""

from __future__ import annotations

import numpy as np

#: grid of the map in the report (points per linear axis)
GRID = 9


def covariance(cal, cols) -> np.ndarray:
    """Covariance (mm, rad) of the design columns ``cols`` (indices into ``cal.labels``); zero
    rows and columns for columns not in the solution or not written (not determined:
    :attr:`volerr.calibrate.run.Calibration.written`)."""
    sol = cal.solution
    written = cal.written
    where = {int(j): i for i, j in enumerate(sol.kept) if written[int(j)]}
    idx = [where.get(int(j), -1) for j in cols]
    C = np.zeros((len(cols), len(cols)))
    ok = np.array([i >= 0 for i in idx])
    if ok.any():
        sel = np.array([i for i in idx if i >= 0])
        C[np.ix_(ok, ok)] = sol.cov[np.ix_(sel, sel)]
    return C


def function_std(cal, P: np.ndarray, js) -> np.ndarray:
    """Standard uncertainty (n,) of an error function ``sum_k P[:, k] c_k`` over its series
    terms ``js`` = [(k, column index)], from the full covariance of the terms."""
    if not js:
        return np.zeros(len(P))
    B = P[:, [k for k, _ in js]]
    C = covariance(cal, [j for _, j in js])
    return np.sqrt(np.maximum(np.einsum("ni,ij,nj->n", B, C, B), 0.0))


def rows_at(cal, positions: dict, probe) -> tuple[np.ndarray, list]:
    """(A (k, 3, n), cols): the parameter columns of a 3-D reading of the tool point at the
    poses ``positions`` {axis: (n,)} mm / deg with tool offsets ``probe`` (n, 3) mm;
    ``cols`` their indices into ``cal.labels``."""
    from ..estimate import blocks
    from ..estimate.design import parameter_labels
    from ..instruments.observations import Observations

    model = cal.model
    n = len(next(iter(positions.values())))
    covs = {}
    for c in model.covariates:
        vals = [np.median(p.covariates[c]) for p in cal.parts if c in p.covariates]
        covs[c] = np.full(n, float(np.median(vals)) if vals else 0.0)
    obs = Observations({a: np.asarray(positions[a], float) for a in model.axes},
                       np.broadcast_to(np.asarray(probe, float), (n, 3)).copy(),
                       np.zeros((n, 3)), covs)
    have = set(cal.labels)
    keep = [False] * len(obs.setup_labels) + [lab in have
                                               for lab in parameter_labels(model, cal.degree)]
    design = blocks.Design(model, obs, cal.degree, cal.ranges, keep)
    cols = [cal.labels.index(lab) for lab in design.labels]
    A = design.block(np.arange(n)).reshape(len(cols), 3, n)
    return A, cols


def predict(cal, positions: dict, probe) -> tuple[np.ndarray, np.ndarray, np.ndarray, list]:
    """Identified volumetric error (n, 3) mm at the poses, its standard uncertainty (n, 3) mm,
    and the parameter rows (k, 3, n) with their column indices (for derived quantities)."""
    A, cols = rows_at(cal, positions, probe)
    theta = cal.coef_written[cols]
    C = covariance(cal, cols)
    e = np.einsum("k,kin->ni", theta, A)
    var = np.einsum("kin,kl,lin->ni", A, C, A)
    return e, np.sqrt(np.maximum(var, 0.0)), A, cols


def grid_counts(n: int) -> tuple:
    """``(n, n, n)``: the points per linear axis of a map (``--map-grid``), 2 .. 60."""
    from ..errors import require

    require(2 <= n <= 60, "--map-grid must be between 2 and 60")
    return (n,) * 3


def grid_positions(cal, counts=(GRID, GRID, GRID), at=None) -> tuple[dict, tuple, dict]:
    """Positions of a grid over the measured range of the linear axes (C order, last axis
    fastest), rotary axes at ``at`` {axis: deg} or their default (module docstring).  Returns
    (positions, grid axes, rotary positions)."""
    model = cal.model
    lin = tuple(a for a in model.axes if a not in model.rotary_axes)
    ticks = [np.linspace(*cal.ranges[a], c) for a, c in zip(lin, counts)]
    mesh = np.meshgrid(*ticks, indexing="ij")
    n = mesh[0].size
    rot = {}
    for a in model.rotary_axes:
        lo, hi = cal.ranges[a]
        rot[a] = float((at or {}).get(a, 0.0 if lo <= 0.0 <= hi else 0.5 * (lo + hi)))
    pos = {a: m.ravel() for a, m in zip(lin, mesh)}
    pos.update({a: np.full(n, v) for a, v in rot.items()})
    return {a: pos[a] for a in model.axes}, lin, rot


def summary(cal, counts=(GRID, GRID, GRID), probe=(0.0, 0.0, 0.0)) -> dict | None:
    """The report's ``volumetric_map`` entry: size of the identified error and of its
    standard uncertainty over the grid (um), or None for a layout without three linear axes."""
    model = cal.model
    lin = [a for a in model.axes if a not in model.rotary_axes]
    if len(lin) != 3:
        return None
    pos, grid_axes, rot = grid_positions(cal, counts)
    e, u, _, _ = predict(cal, pos, np.asarray(probe, float))
    length = 1e3 * np.linalg.norm(e, axis=1)
    u_um = 1e3 * u
    return {"grid": list(counts), "box_mm": {a: [round(v, 4) for v in cal.ranges[a]]
                                             for a in grid_axes},
            "rotary_deg": rot, "probe_mm": [float(v) for v in probe],
            "max_length_um": round(float(length.max()), 4),
            "rms_length_um": round(float(np.sqrt(np.mean(length ** 2))), 4),
            "u_max_um": round(float(u_um.max()), 5),
            "u_rms_um": round(float(np.sqrt(np.mean(u_um ** 2))), 5),
            **what_enters(cal),
            "note": "identified volumetric error (actual minus nominal tool point, workpiece "
                    "frame) over the measured range and its standard uncertainty from the "
                    "calibration's covariance (k = 1); parameters not determined by the "
                    "campaign are 0 in it (undetermined), a determined combination enters "
                    "under its written_as name (combinations); --map-out writes every node"}


def what_enters(cal) -> dict:
    """``{"undetermined": [names written as 0], "combinations": [expressions written under
    one of their names]}``: what a map or an ISO 10360 number built from ``cal`` holds."""
    combos = cal.data.get("combinations", [])
    written = {c["written_as"] for c in combos}
    return {"undetermined": [n for n in cal.data.get("unidentifiable", []) if n not in written],
            "combinations": [c["expression"] for c in combos]}


def write_csv(path, cal, counts=(GRID, GRID, GRID), probe=(0.0, 0.0, 0.0), inputs=()):
    """The map as CSV: axis positions (mm / deg), ``Xp,Yp,Zp``, ``dx_um,dy_um,dz_um`` (the
    identified error) and ``u_dx_um,u_dy_um,u_dz_um`` (its standard uncertainty); ``#`` lines
    above the header name what it holds as 0 and the combinations in it."""
    from ..cmm import csvformat
    from ..fileio import AtomicFile

    from ..errors import require

    from ..fit_quality import require_writable

    require_writable(getattr(cal, "quality", None), False, f"--map-out {path}")
    model = cal.model
    require(len(model.axes) - len(model.rotary_axes) == 3,
            f"--map-out: {model.name} has not three linear axes")
    pos, _, _ = grid_positions(cal, counts)
    e, u, _, _ = predict(cal, pos, np.asarray(probe, float))
    header = list(model.axes) + ["Xp", "Yp", "Zp", "dx_um", "dy_um", "dz_um", "u_dx_um",
                                 "u_dy_um", "u_dz_um"]
    cols = [pos[a] for a in model.axes] + [float(v) for v in probe]
    cols += [1e3 * e[:, i] for i in range(3)] + [1e3 * u[:, i] for i in range(3)]
    out = AtomicFile(path, list(inputs))
    held = what_enters(cal)
    notes = ([f"# not determined, 0 in this map: {', '.join(held['undetermined'])}\n"]
             if held["undetermined"] else [])
    notes += [f"# in this map under one of its names: {c}\n" for c in held["combinations"]]
    if cal.data.get("forced"):
        notes.insert(0, f"# {cal.data['forced']}\n")
    try:
        out.write(("".join(notes) + ",".join(header) + "\n").encode("utf-8"))
        out.write(csvformat.rows_text(cols, [6] * len(cols)))
    except BaseException:
        out.discard()
        raise
    return out.commit()
