"""The ``sphere`` instrument: a calibration sphere probed at the tool point (a touch probe's
kinematics cycle) or an R-test (three displacement sensors on the table around a ball in the
spindle), at many positions of the rotary axes.

Reading (three per pose): ``dx, dy, dz`` = measured position of the tool point minus the
sphere's centre, in the workpiece frame (an R-test on the table measures there), um or mm.
A touch probe reports in the machine's linear-axis frame: a column ``frame`` = ``machine``
declares it, and the reading is then the same vector in that frame, ``R (t + e - c - dc)``
with ``R`` the orientation of the workpiece frame (the layout's generated ``work_rotation``).
Model (:func:`volerr.derive.observations.sphere`)::

    d = t + e - (c + dc)

``t`` the nominal tool point (the layout's nominal chain at the commanded positions and the
tool offset ``Xp, Yp, Zp``), ``e`` the volumetric error, ``c`` the nominal sphere centre
(``sphere_x, sphere_y, sphere_z``, approximate) and ``dc`` the unknown offset of its
``placement`` (three set-up unknowns per placement, ``centre_dx centre_dy centre_dz`` um).
Each file has one more set-up unknown, ``tool_dz``: an error of the tool length (the tool point
displaced along the tool's own z axis), which a single sphere height cannot tell from a location
error along the axis.  File format: ``volerr formats sphere``.
"""

from __future__ import annotations

import numpy as np

from ..errors import require
from ..generated import instruments as generated
from ..machine.model import Model
from ..units import MIN_CYCLE_SPREAD_UM
from . import _fields as f
from .observations import FileInfo, Observations, Setup

KIND = "sphere"
#: default standard uncertainty of one reading (per coordinate), um
DEFAULT_U_UM = 1.0
SETUP_KEYS = tuple(generated.SETUP[KIND])
#: twist column of the tool end along the tool's z axis (tool length)
TOOL_DZ = 8
FRAMES = ("work", "machine")


def detect(names) -> bool:
    """A sphere file names the sphere's nominal centre (any of its columns)."""
    return bool({n.lower() for n in names} & {"sphere_x", "sphere_y", "sphere_z"})


def read(path, model: Model) -> Observations:
    """Read a sphere / R-test CSV into :class:`Observations` (InputError, one line)."""
    return f.read_file(path, model, columns_to_observations)


def columns_to_observations(cols: dict, text: dict, raw: dict, model: Model,
                            where: str) -> Observations:
    needed = ({"sphere_x", "sphere_y", "sphere_z", "Xp", "Yp", "Zp", "u_um", "tool_u_um"}
              | {f"{d}_{u}" for d in ("dx", "dy", "dz") for u in ("um", "mm")})
    find, warnings = f.open_columns(cols, text, model, where, needed,
                                    labels=("placement", "frame"))
    pos = f.positions(find, model, where, min_points=3, needs="a sphere file")
    n = len(next(iter(pos.values())))
    probe = f.probe(find, n, where)
    centre = f.vector(find, ("sphere_x", "sphere_y", "sphere_z"), "nominal sphere centre",
                      where)
    reading = f.readings(find, ("dx", "dy", "dz"), n, where, limit_mm=5.0,
                         what="a sphere reading", min_spread_um=MIN_CYCLE_SPREAD_UM)
    u = f.uncertainty(find, n, DEFAULT_U_UM, where)
    placement = f.labels(find, "placement", raw, n)
    require(placement is not None, f"{where}: no placement column: give each reading the "
                                   f"label of its sphere placement (column placement)")
    f.check_groups(placement, "placement", where, 2, "its sphere's true centre is unknown")
    frame = _frames(find, raw, n, where)
    # a tool measured on a presetter or a tool setter: its length error known to within it
    tool_u = f.known_uncertainty(find, "tool_u", where)
    check_geometry(model, pos, probe, centre, reading, placement, frame, where)
    t = model.nominal_position(pos, probe)
    lin = generated.sphere(t[:, 0], t[:, 1], t[:, 2], centre[:, 0], centre[:, 1],
                           centre[:, 2])                   # (3, 7, n)
    lin = np.moveaxis(lin, -1, 0)                          # (n, 3, 7)
    R = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
    machine = frame == "machine"
    if machine.any():
        rot = model.module.work_rotation(**model.positions({a: v[machine]
                                                            for a, v in pos.items()}))
        R[machine] = np.moveaxis(np.broadcast_to(rot, (3, 3, int(machine.sum()))), -1, 0)
    proj = np.einsum("nij,njk->nik", R, lin[:, :, 1:4])
    local = np.einsum("nij,njk->nik", R, lin[:, :, 4:7])
    nominal = np.einsum("nij,nj->ni", R, lin[:, :, 0])
    names, idx = np.unique(placement.astype(str), return_inverse=True)
    groups = np.column_stack([idx.ravel(), np.full(n, len(names))])
    setup = Setup(groups, local, [f"{where}#{m}" for m in names] + [where],
                  [SETUP_KEYS] * len(names) + [("tool_dz",)],
                  [("local", 0)] * len(names) + [("twist", (TOOL_DZ,))],
                  [("um",) * 3] * len(names) + [("um",)],
                  [(None,) * 3] * len(names) + [(tool_u,)])
    covs = f.covariates(find, model, where)
    return Observations(pos, probe, reading - nominal, covs, warnings, proj=proj,
                        setup=setup, files=(FileInfo(where, KIND, "um", 3),), sigma=u,
                        info={"centre": centre, "placement": placement, "frame": frame})


def check_geometry(model, pos, probe, centre, reading, placement, frame, where) -> None:
    """The commanded tool point meets each placement's sphere centre
    (:func:`volerr.instruments.geometry_check.sphere_misfit`); a miss is refused naming the
    likely cause (radians, inches, the offset's sign, swapped columns, another layout)."""
    from . import geometry_check as gc

    misfit = gc.sphere_misfit(placement, reading, np.asarray(frame) == "machine")
    gc.require_consistent(where, model, gc.Geometry(
        pos, probe, {"the sphere centre": centre},
        {"the sphere centre": "sphere_x, sphere_y, sphere_z"}, misfit))


def _frames(find, raw: dict, n: int, where: str) -> np.ndarray:
    """``frame`` of each reading: ``work`` (default) or ``machine``."""
    col = next((raw[h] for h in raw if h.lower() == "frame"), None)
    if col is None:
        require(find.name("frame") is None, f"{where}: column frame must be work or machine")
        return np.full(n, "work", dtype=object)
    vals = np.asarray([str(v).strip().lower() for v in col], dtype=object)
    bad = [v for v in vals if v not in FRAMES]
    require(not bad, f"{where}: frame {bad[0] if bad else ''!r} is not work or machine")
    return vals


# ---- plans and simulated readings ---------------------------------------------------------
def plan(model, centres, rotary: dict, tool=(0.0, 0.0, 0.0)) -> dict:
    """Commanded poses of a sphere test: for each nominal sphere centre (workpiece frame, mm)
    and each combination of the rotary positions ``rotary`` {axis: [deg, ...]}, the linear
    positions that put the tool point on the centre (poses outside the travel left out).
    Returns ``{"positions": {axis: (N,)}, "centre": (N, 3), "placement": (N,) labels}``."""
    import itertools

    tool = np.asarray(tool, float)
    axes = [a for a in model.rotary_axes]
    grid = list(itertools.product(*[np.atleast_1d(rotary[a]) for a in axes])) or [()]
    pos_parts, cen, place = [], [], []
    for k, c in enumerate(np.atleast_2d(centres)):
        rot = {a: np.array([g[i] for g in grid], float) for i, a in enumerate(axes)}
        pos = model.linear_positions(np.tile(c, (len(grid), 1)), rot, tool)
        inside = np.ones(len(grid), bool)
        for a in model.axes:
            lo, hi = model.travel[a]
            inside &= (pos[a] >= lo) & (pos[a] <= hi)
        pos_parts.append({a: v[inside] for a, v in pos.items()})
        cen.append(np.tile(c, (int(inside.sum()), 1)))
        place += [str(k + 1)] * int(inside.sum())
    positions = {a: np.concatenate([p[a] for p in pos_parts]) for a in model.axes}
    require(len(place) > 0, "no pose of the sphere plan lies inside the travel")
    return {"positions": positions, "centre": np.concatenate(cen),
            "placement": np.asarray(place, dtype=object)}


def simulate(model, errors: dict, poses: dict, tool=(0.0, 0.0, 0.0), centre_offsets=None,
             noise_um: float = 0.0, seed: int = 0) -> dict:
    """Columns of a sphere file (frame work) for ``poses`` (:func:`plan`) of the layout's
    first-order model with ``errors`` {name: value or callable(positions) -> (N,)} (mm / rad);
    ``centre_offsets`` {placement: (3,) mm}: the spheres' true offsets from their nominal
    centres."""
    pos = poses["positions"]
    n = len(poses["placement"])
    vals = {k: (v(pos) if callable(v) else v) for k, v in (errors or {}).items()}
    e = model.volumetric_error(pos, vals, probe=tool)
    t = model.nominal_position(pos, tool)
    dc = np.zeros((n, 3))
    for k, v in (centre_offsets or {}).items():
        dc[poses["placement"] == str(k)] = v
    d = t + e - poses["centre"] - dc
    if noise_um:
        d = d + np.random.default_rng(seed).normal(0.0, noise_um * 1e-3, d.shape)
    tool = np.asarray(tool, float)
    return {**pos, "Xp": np.full(n, tool[0]), "Yp": np.full(n, tool[1]),
            "Zp": np.full(n, tool[2]), "sphere_x": poses["centre"][:, 0],
            "sphere_y": poses["centre"][:, 1], "sphere_z": poses["centre"][:, 2],
            "dx_um": 1e3 * d[:, 0], "dy_um": 1e3 * d[:, 1], "dz_um": 1e3 * d[:, 2],
            "placement": poses["placement"]}


def write_csv(path, cols: dict, inputs=()):
    """Write sphere columns (6 decimals mm/deg, 5 um; placement as text; no negative zero)."""
    from ..fileio import write_text
    from ..units import num

    names = list(cols)
    n = len(cols[names[0]])
    lines = [",".join(names)]
    for i in range(n):
        lines.append(",".join(str(cols[k][i]) if k == "placement" else
                              num(cols[k][i], ".5f" if k.endswith("_um") else ".6f")
                              for k in names))
    return write_text(path, "\n".join(lines) + "\n", inputs=list(inputs))


def _sweep(travel) -> tuple[float, float]:
    """The range of a rotary axis a plan sweeps: its travel, at most one turn."""
    lo, hi = travel
    return (lo, min(hi, lo + 330.0))


def extensions(model, obs) -> list:
    """Plan extensions a calibration can try when the file leaves parameters undetermined:
    ``[(text, hypothetical Observations)]`` -- the same rotary positions with a second tool
    length, and with the sphere placed 100 mm higher or 100 mm further out."""
    if "centre" not in obs.info:
        return []
    where = obs.files[0].name if obs.files else "sphere"
    rotary = {a: np.unique(np.round(obs.positions[a], 6)) for a in model.rotary_axes}
    centres = np.unique(np.round(obs.info["centre"], 6), axis=0)
    tool = obs.probe[0]
    wide = {a: np.linspace(*_sweep(model.travel[a]), 13) for a in model.rotary_axes}
    trials = [("rotary positions over the whole travel", centres, tool, wide),
              ("a second tool length (+100 mm)", centres, tool + (0.0, 0.0, 100.0)),
              ("a sphere placement 100 mm higher", centres[:1] + (0.0, 0.0, 100.0), tool),
              ("a sphere placement 100 mm further out in X", centres[:1] + (100.0, 0.0, 0.0),
               tool)]
    out = []
    for text, c, t, *grid in trials:
        try:
            poses = plan(model, c, grid[0] if grid else rotary, t)
        except Exception:      # the trial plan leaves the travel: not a suggestion
            continue
        cols = simulate(model, {}, poses, t)
        labels = {"placement": list(cols.pop("placement"))}
        numbers = {k: np.asarray(v, float) for k, v in cols.items()}
        out.append((text, columns_to_observations(numbers, {"placement": None}, labels, model,
                                                  f"{where} + {text}")))
    if obs.setup is not None:
        known = obs.subset(np.arange(obs.n))
        known.setup.priors = [p if k != ("tool_dz",) else (1e-3,)
                              for p, k in zip(known.setup.priors, known.setup.keys)]
        out.append(("the tool length calibrated to 1 um (the same plan)", known))
    return out
