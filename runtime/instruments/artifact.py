"""The ``artifact`` instrument: a calibrated artifact measured by the machine -- a ball plate or a
hole plate (the ball-plate method: the plate in several placements, its pose in each unknown)
or a step gauge (the faces along a line).

Each row is one feature (a ball, a hole, a face) of the artifact as the machine measured it:
``x_mm, y_mm, z_mm`` the point the machine reports (its nominal chain: machine coordinates of
a CMM, the workpiece frame of a machine tool), ``u_mm, v_mm, w_mm`` the feature's calibrated
coordinates in the artifact's own frame.  The machine's actual probe point is on the feature
where it reports ``t``: ``t + e = a`` (``e`` the volumetric error, ``a`` the actual feature
point); so the measured value of every reading is 0 and the information is in where the
machine reports the feature.  Model (:func:`volerr.derive.observations.artifact`), in the
artifact frame::

    0 = R^T (t + e - o) - d - (I + [r]x)(p + c)

``R, o`` the nominal orientation and origin of the placement (the rigid least-squares fit of
the calibrated points to the reported ones, per placement), ``d`` (``du dv dw`` um) and ``r``
(``eu ev ew`` urad, about the artifact's origin) the pose's correction, both unknown per
placement, and ``c`` (``cu cv cw`` um) the calibration error of the feature, known to be zero
within ``u_std_um`` (a set-up unknown with that prior, shared by the feature's placements).

Readings per feature: a ``ball`` three (the components along u, v, w), a ``hole`` two (u, v:
a hole's axial position is not measured), a step-gauge ``face`` one (u, along the gauge, whose
faces lie on its u axis).  File format: ``volerr formats artifact``.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, require
from ..generated import instruments as generated
from ..machine.model import Model
from . import _fields as f
from .observations import FileInfo, Observations, Setup

KIND = "artifact"
#: default standard uncertainty of one probed coordinate, um
DEFAULT_U_UM = 0.5
FEATURES = {"ball": 3, "hole": 2, "face": 1}
#: pose-correction keys a placement gets from the features it holds
POSE_KEYS = {"ball": ("du", "dv", "dw", "eu", "ev", "ew"), "hole": ("du", "dv", "ew"),
             "face": ("du",)}
ALL_POSE = ("du", "dv", "dw", "eu", "ev", "ew")
CAL_KEYS = ("cu", "cv", "cw")
#: an axis whose positions spread less than this (mm) within a placement did not move
STILL_MM = 0.05
#: largest distance between a reported point and its calibrated point placed by the fitted
#: pose, mm: beyond it the calibrated coordinates and the measured points disagree
FIT_TOLERANCE_MM = 0.5


def detect(names) -> bool:
    """An artifact file names calibrated coordinates or features."""
    low = {n.lower() for n in names}
    return bool(low & {"u_mm", "v_mm", "w_mm", "ball", "u_std_um"})


def read(path, model: Model) -> Observations:
    """Read an artifact CSV into :class:`Observations` (InputError, one line, on a defect)."""
    return f.read_file(path, model, columns_to_observations, unique_rows=False)


def _labels(find, raw, name, n, where, required=True):
    lab = f.labels(find, name, raw, n)
    require(lab is not None or not required, f"{where}: missing column {name}")
    return lab


def columns_to_observations(cols: dict, text: dict, raw: dict, model: Model,
                            where: str) -> Observations:
    needed = {"u_mm", "v_mm", "w_mm", "x_mm", "y_mm", "z_mm", "Xp", "Yp", "Zp", "u_std_um",
              "probe_u_um"}
    find, warnings = f.open_columns(cols, text, model, where, needed,
                                    labels=("placement", "ball", "feature"))
    require(find.name("u_um") is None, f"{where}: column u_um is ambiguous in an artifact file "
            f"(u_mm is a calibrated coordinate): give the probing uncertainty as probe_u_um "
            f"and the calibration's as u_std_um")
    lin_axes = [a for a in model.axes if a not in model.rotary_axes]
    require(len(lin_axes) == 3, f"{where}: layout {model.name} has not three linear axes")
    given = [a for a in lin_axes if find.name(a) is not None]
    require(not given, f"{where}: axis column {given[0] if given else ''} in an artifact file: "
            f"give the measured point as x_mm, y_mm, z_mm (the axis positions follow)")
    n = find.cols and len(next(iter(find.cols.values()))) or 0
    require(n >= 3, f"{where}: too few rows ({n}); an artifact needs at least 3 features")
    measured = f.vector(find, ("x", "y", "z"), "measured point (machine coordinates)", where,
                        units=("_mm",))
    point = f.vector(find, ("u", "v", "w"), "calibrated coordinates (artifact frame)", where,
                     units=("_mm",))
    probe = f.probe(find, n, where)
    rotary = {}
    for a in model.rotary_axes:
        h = find(a, ("", "_deg"), f"axis {a}")
        require(h is not None, f"{where}: missing axis column {a} (layout {model.name} has "
                f"rotary axis {a}: its position during the measurement)")
        rotary[a] = find.cols[h]
    placement = _labels(find, raw, "placement", n, where)
    ball = _labels(find, raw, "ball", n, where)
    feature = _features(find, raw, n, where)
    u = f.uncertainty_named(find, "probe_u", n, DEFAULT_U_UM, where)
    u_std = _calibration_uncertainty(find, n, where)
    pos = model.linear_positions(measured, rotary, probe)
    _inside_travel(model, pos, lin_axes, where)
    t = model.nominal_position(pos, probe)
    names, gidx = np.unique(placement.astype(str), return_inverse=True)
    gidx = gidx.ravel()
    f.check_groups(placement, "placement", where, 3, "its pose is unknown")
    f.check_groups(ball, "ball", where, 1, "")
    refuse_repeats(where, names[gidx], ball.astype(str), point, measured)
    pos = _hold_still_axes(pos, gidx, lin_axes)
    R0 = np.zeros((n, 3, 3))
    origin = np.zeros((n, 3))
    check_geometry(model, names[gidx], point, t, where)
    for g, name in enumerate(names):
        m = gidx == g
        R0[m], origin[m] = rigid_fit(point[m], t[m])
    lin = generated.artifact(t[:, 0], t[:, 1], t[:, 2], origin[:, 0], origin[:, 1],
                             origin[:, 2], *[R0[:, i, j] for i in range(3) for j in range(3)],
                             point[:, 0], point[:, 1], point[:, 2])      # (3, 13, n)
    lin = np.moveaxis(lin, -1, 0)                                         # (n, 3, 13)
    rows = np.array([FEATURES[k] for k in feature])
    used = (np.arange(3)[None, :] < rows[:, None]).astype(float)          # (n, 3)
    lin = lin * used[:, :, None]
    setup = _setup(where, names, gidx, ball, feature, u_std, lin)
    covs = f.covariates(find, model, where, skip=NOMINAL_COLUMNS)
    info = {"placement": names[gidx].astype(object), "ball": ball, "feature": feature,
            "point": point, "measured": measured, "rotation": R0, "origin": origin,
            "u_std": np.zeros(n) if u_std is None else u_std}
    return Observations(pos, probe, -lin[:, :, 0], covs, warnings, proj=lin[:, :, 1:4],
                        rows=rows, setup=setup, files=(FileInfo(where, KIND, "um", 3),),
                        sigma=u, info=info)


def _inside_travel(model, pos: dict, lin_axes, where) -> None:
    """Refuse a measured point whose axis positions lie outside the travel, naming the likely
    cause (:func:`volerr.instruments.geometry_check.travel_cause`: swapped x_mm / y_mm ...,
    another machine), else "layout mismatch"."""
    import re

    from .geometry_check import travel_cause

    for a in lin_axes:
        lo, hi = model.travel[a]
        margin = 0.05 * (hi - lo)
        bad = np.flatnonzero((pos[a] < lo - margin) | (pos[a] > hi + margin))
        if not len(bad):
            continue
        cause = travel_cause(model, pos)
        m = re.fullmatch(r"columns ([XYZ]) and ([XYZ]) swapped", cause or "")
        if m:
            cause = (f"columns {m.group(1).lower()}_mm and {m.group(2).lower()}_mm swapped "
                     f"(exchanged, every point lies inside the travel)")
        raise InputError(f"{where}: row {bad[0] + 2}: the measured point puts {a} at "
                         f"{pos[a][bad[0]]:g}, outside the travel of layout {model.name}: "
                         + (f"likely {cause}" if cause else "layout mismatch"))


def check_geometry(model, placement, point, measured, where) -> None:
    """The calibrated coordinates fit the measured points of each placement by a rigid pose
    within :data:`FIT_TOLERANCE_MM` (:func:`volerr.instruments.geometry_check.artifact_misfit`);
    a miss is refused naming the likely cause (calibrated coordinates in um or inches, the
    measured points in inches, their columns swapped)."""
    from . import geometry_check as gc

    targets = {"the measured points": measured, "the calibrated coordinates": point}
    extra = [("the calibrated coordinates in um (/ 1000 makes the file consistent)",
              "u_mm, v_mm, w_mm", {"the calibrated coordinates": point * 1e-3})]
    for i, j in ((0, 1), (1, 2), (0, 2)):
        swap = point.copy()
        swap[:, [i, j]] = swap[:, [j, i]]
        extra.append((f"columns {'uvw'[i]}_mm and {'uvw'[j]}_mm swapped (a wrong ball "
                      f"numbering?)", f"{'uvw'[i]}_mm, {'uvw'[j]}_mm",
                      {"the calibrated coordinates": swap}))
    gc.require_consistent(where, model, gc.Geometry(
        {}, np.zeros((len(point), 3)), targets,
        {"the measured points": "x_mm, y_mm, z_mm",
         "the calibrated coordinates": "u_mm, v_mm, w_mm"},
        gc.artifact_misfit(placement, rigid_fit, FIT_TOLERANCE_MM)), extra=extra)


def _hold_still_axes(pos: dict, gidx, axes) -> dict:
    """Axis positions for the model's columns: within a placement, an axis whose positions
    (derived from the reported points) spread less than :data:`STILL_MM` did not move -- the
    spread is the machine's error and the probing noise -- and is held at its mean (else a
    series term of that axis would be fitted to the noise of a plate lying in a plane).  The
    change of the levers is below ``STILL_MM`` times the angular errors: negligible."""
    out = {a: np.array(v, dtype=float) for a, v in pos.items()}
    for g in np.unique(gidx):
        m = gidx == g
        for a in axes:
            if np.ptp(out[a][m]) < STILL_MM:
                out[a][m] = np.mean(out[a][m])
    return out


def rigid_fit(p: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation ``R`` and origin ``o`` minimising ``sum |x - (R p + o)|^2`` (Kabsch: SVD of the
    cross-covariance, a proper rotation); collinear points leave the turn about their line
    free (any one is returned)."""
    pc, xc = p - p.mean(axis=0), x - x.mean(axis=0)
    U, _, Vt = np.linalg.svd(xc.T @ pc)
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt)) or 1.0])
    R = U @ D @ Vt
    return R, x.mean(axis=0) - R @ p.mean(axis=0)


def _features(find, raw, n, where) -> np.ndarray:
    col = next((raw[h] for h in raw if h.lower() == "feature"), None)
    if col is None:
        require(find.name("feature") is None, f"{where}: column feature must be ball, hole or "
                                               f"face")
        return np.full(n, "ball", dtype=object)
    vals = np.asarray([str(v).strip().lower() for v in col], dtype=object)
    bad = [v for v in vals if v not in FEATURES]
    require(not bad, f"{where}: feature {bad[0] if bad else ''!r} is not ball, hole or face")
    return vals


def _calibration_uncertainty(find, n, where) -> np.ndarray | None:
    h = find("u_std", ("_um",), "u_std_um")
    if h is None:
        return None
    v = find.cols[h]
    require(np.all(v >= 0), f"{where}: u_std_um must not be negative")
    return v * 1e-3


#: where a plan (``volerr plan``) puts each feature, machine coordinates mm: informative, not
#: read (the measured point is ``x_mm, y_mm, z_mm``), not a covariate
NOMINAL_COLUMNS = ("x_nom_mm", "y_nom_mm", "z_nom_mm")

#: calibrated coordinates of one ball closer than this are the same, mm
SAME_POINT_MM = 1e-6


def refuse_repeats(where, placement, ball, point, measured) -> None:
    """Data that cannot be right (one line): a row given twice (every cell equal: a file
    pasted twice), a ball given twice in one placement with different calibrated coordinates
    (two balls with one label), a placement that repeats another one's measured points row
    for row (a placement copied under a new label).  A ball probed twice in one placement
    with the same calibrated coordinates (a repeated probing) is accepted."""
    seen: dict = {}
    calibrated: dict = {}
    for i, key in enumerate(zip(placement, ball, map(tuple, point), map(tuple, measured))):
        j = seen.setdefault(key, i)
        require(j == i, f"{where}: rows {j + 2} and {i + 2} are the same (placement "
                        f"{key[0]}, ball {key[1]}, same coordinates): a row given twice")
        first = calibrated.setdefault(key[:2], (i, point[i]))
        require(np.max(np.abs(first[1] - point[i])) <= SAME_POINT_MM,
                f"{where}: placement {key[0]}: ball {key[1]} has different calibrated "
                f"coordinates in rows {first[0] + 2} and {i + 2} (two balls with one label?)")
    _refuse_moving_labels(where, placement, ball, point)
    groups: dict = {}
    for name in dict.fromkeys(placement.tolist()):
        m = placement == name
        key = (tuple(ball[m]), measured[m].round(9).tobytes())
        require(key not in groups, f"{where}: placement {name} repeats placement "
                                   f"{groups.get(key)} row for row (the same balls measured at "
                                   f"the same points): a placement copied under a new label")
        groups[key] = name


def _refuse_moving_labels(where, placement, ball, point) -> None:
    """Refuse a ball label whose calibrated coordinates differ by more than
    :data:`FIT_TOLERANCE_MM` between placements (one line): a label names the same ball of
    the one artifact in every placement, its coordinates those of the calibration
    certificate -- calibrated coordinates that move with the placement are measured ones (the
    calibrated and measured columns swapped), or labels of different balls."""
    first: dict = {}
    for i, (name, label) in enumerate(zip(placement, ball)):
        j = first.setdefault(label, i)
        if placement[j] == name:
            continue
        gap = float(np.max(np.abs(point[i] - point[j])))
        require(gap <= FIT_TOLERANCE_MM,
                f"{where}: ball {label} has calibrated coordinates {gap:.4g} mm apart in "
                f"placements {placement[j]} (row {j + 2}) and {name} (row {i + 2}); a ball's "
                f"calibrated coordinates are the same in every placement: likely the "
                f"calibrated (u_mm, v_mm, w_mm) and measured (x_mm, y_mm, z_mm) columns "
                f"swapped, or one label for different balls")


def _ordered(keys) -> tuple:
    return tuple(k for k in ALL_POSE + CAL_KEYS if k in keys)


def _setup(where, names, gidx, ball, feature, u_std, lin) -> Setup:
    """Groups: the pose correction of every placement (keys by the features it holds) and,
    with ``u_std_um``, the calibration correction of every feature (its prior)."""
    n = len(gidx)
    column = {k: 4 + j for j, k in enumerate(ALL_POSE + CAL_KEYS)}
    segments, blocks = {}, []

    def segment(keys):
        if keys not in segments:
            segments[keys] = sum(len(k) for k in segments)
            blocks.append(lin[:, :, [column[k] for k in keys]])
        return segments[keys]

    group = np.full((n, 2), -1)
    gnames, gkeys, gsource, gunits, gpriors = [], [], [], [], []
    for g, name in enumerate(names):
        m = gidx == g
        keys = _ordered({k for ft in np.unique(feature[m]) for k in POSE_KEYS[ft]})
        group[m, 0] = len(gnames)
        gnames.append(f"{where}#{name}")
        gkeys.append(keys)
        gsource.append(("local", segment(keys)))
        gunits.append(tuple("urad" if k.startswith("e") else "um" for k in keys))
        gpriors.append((None,) * len(keys))
    if u_std is not None:
        labels = ball.astype(str)
        for b in dict.fromkeys(labels.tolist()):
            m = labels == b
            fts = set(feature[m].tolist())
            require(len(fts) == 1, f"{where}: ball {b} is given as several features "
                                   f"({', '.join(sorted(fts))})")
            keys = CAL_KEYS[:FEATURES[fts.pop()]]
            u = float(np.max(u_std[m]))
            if u <= 0:
                continue
            group[m, 1] = len(gnames)
            gnames.append(f"{where}@{b}")
            gkeys.append(keys)
            gsource.append(("local", segment(keys)))
            gunits.append(("um",) * len(keys))
            gpriors.append((u,) * len(keys))
    local = np.concatenate(blocks, axis=2) if blocks else np.zeros((n, 3, 0))
    if np.all(group[:, 1] < 0):
        group = group[:, :1]
    return Setup(group, local, gnames, gkeys, gsource, gunits, gpriors)


# ---- results, plans, simulated readings --------------------------------------------------
def results(obs: Observations, setup: dict) -> dict:
    """The pose of every placement (artifact frame in the workpiece frame) with the identified
    correction applied: ``{"poses": {"<file>#<placement>": {"origin_mm": [x, y, z],
    "origin_std_um": [..], "rotation": 3x3 (columns: the artifact's u, v, w axes),
    "rotation_vector_deg": [..], "rotation_std_urad": [..]}}}``; ``setup`` the calibration
    report's set-up estimates (um, urad)."""
    from scipy.spatial.transform import Rotation

    where = obs.files[0].name if obs.files else "artifact"
    out = {}
    names = obs.info["placement"]
    for name in dict.fromkeys(names.tolist()):
        m = np.flatnonzero(names == name)[0]
        R0, o0 = obs.info["rotation"][m], obs.info["origin"][m]
        est = setup.get(f"{where}#{name}", {})
        val = {k: est[k]["value"] if k in est else 0.0 for k in ALL_POSE}
        std = {k: est[k]["std"] if k in est else 0.0 for k in ALL_POSE}
        d = 1e-3 * np.array([val[k] for k in ("du", "dv", "dw")])
        r = 1e-6 * np.array([val[k] for k in ("eu", "ev", "ew")])
        R = R0 @ Rotation.from_rotvec(r).as_matrix()
        origin = o0 + R0 @ d
        sd = np.array([std[k] for k in ("du", "dv", "dw")])
        out[f"{where}#{name}"] = {
            "origin_mm": [round(float(v), 7) for v in origin],
            "origin_std_um": [round(float(v), 5) for v in np.sqrt((R0 ** 2) @ sd ** 2)],
            "rotation": [[round(float(v), 10) for v in row] for row in R],
            "rotation_vector_deg": [round(float(v), 7) for v in
                                    np.rad2deg(Rotation.from_matrix(R).as_rotvec())],
            "rotation_std_urad": [round(std[k], 5) for k in ("eu", "ev", "ew")]}
    return {"poses": out}


def columns(model, points, pose, placement="1", ball=None, feature="ball", probe=(0, 0, 0),
            rotary=None, errors=None, noise_um=0.0, seed=0) -> dict:
    """Columns of an artifact file for ``points`` (n, 3) calibrated coordinates placed by
    ``pose`` = (R (3, 3), origin (3,)) in the workpiece frame: the points the machine of the
    layout's first-order model with ``errors`` {name: value or callable(positions) -> (n,)}
    (mm / rad; None: a perfect machine) reports, found by fixed-point iteration of
    ``t + e(t) = a``; ``noise_um``: Gaussian noise on the reported coordinates."""
    R, o = (np.asarray(v, float) for v in pose)
    p = np.atleast_2d(np.asarray(points, float))
    n = len(p)
    a = p @ R.T + o
    rot = {k: np.full(n, float(v)) for k, v in (rotary or {}).items()}
    t = a.copy()
    for _ in range(4 if errors else 0):
        pos = model.linear_positions(t, rot, probe)
        vals = {k: (v(pos) if callable(v) else v) for k, v in errors.items()}
        t = a - model.volumetric_error(pos, vals, probe=probe)
    if noise_um:
        t = t + np.random.default_rng(seed).normal(0.0, noise_um * 1e-3, t.shape)
    labels = ball if ball is not None else [f"B{i + 1:02d}" for i in range(n)]
    probe = np.asarray(probe, float)
    return {"placement": [str(placement)] * n, "ball": list(labels),
            "feature": [feature] * n, "u_mm": p[:, 0], "v_mm": p[:, 1], "w_mm": p[:, 2],
            "x_mm": t[:, 0], "y_mm": t[:, 1], "z_mm": t[:, 2], **{k: v for k, v in rot.items()},
            "Xp": np.full(n, probe[0]), "Yp": np.full(n, probe[1]), "Zp": np.full(n, probe[2])}


def plate_points(n_u: int = 5, n_v: int = 5, pitch: float = 100.0) -> np.ndarray:
    """Calibrated centres (n_u * n_v, 3) of a ball plate: a square grid in its u, v plane."""
    uu, vv = np.meshgrid(np.arange(n_u) * pitch, np.arange(n_v) * pitch, indexing="ij")
    return np.column_stack([uu.ravel(), vv.ravel(), np.zeros(uu.size)])


#: orientation of the artifact frame for a placement in a plane (columns u, v, w)
PLANES = {"XY": np.eye(3),
          "XZ": np.column_stack([(1.0, 0, 0), (0, 0, 1.0), (0, -1.0, 0)]),
          "YZ": np.column_stack([(0, 1.0, 0), (0, 0, 1.0), (1.0, 0, 0)])}


def placed(model, points, plane: str, centre=None, turn_deg: float = 0.0):
    """Pose (R, origin) of an artifact laid in ``plane`` with its points' centroid at
    ``centre`` (workpiece frame; default the middle of the travel), turned by ``turn_deg``
    about its w axis."""
    from scipy.spatial.transform import Rotation

    R = PLANES[plane] @ Rotation.from_rotvec([0, 0, np.deg2rad(turn_deg)]).as_matrix()
    if centre is None:
        mid = {a: 0.5 * sum(model.travel[a]) for a in model.axes}
        centre = model.nominal_position(mid)[0]
    p = np.atleast_2d(np.asarray(points, float))
    return R, np.asarray(centre, float) - R @ p.mean(axis=0)


def write_csv(path, cols: dict, inputs=()):
    """Write artifact columns (labels as text, mm with 6 decimals)."""
    from ..fileio import write_text

    names = list(cols)
    n = len(cols[names[0]])
    text = ("placement", "ball", "feature")
    lines = [",".join(names)]
    for i in range(n):
        lines.append(",".join(str(cols[k][i]) if k in text else f"{float(cols[k][i]):.6f}"
                              for k in names))
    return write_text(path, "\n".join(lines) + "\n", inputs=list(inputs))


def extensions(model, obs) -> list:
    """Plan extensions a calibration can try when the file leaves parameters undetermined:
    ``[(text, hypothetical Observations)]`` -- the artifact in the planes (XY, XZ, YZ) and at
    the heights its placements lack, and turned by 90 deg in its plane."""
    if "point" not in obs.info:
        return []
    where = obs.files[0].name if obs.files else "artifact"
    first = obs.info["placement"][0]
    m = obs.info["placement"] == first
    pts = obs.info["point"][m]
    feature = obs.info["feature"][m]
    ball = obs.info["ball"][m]
    probe = obs.probe[0]
    rotary = {a: float(np.median(obs.positions[a])) for a in model.rotary_axes}
    have = set()
    for name in dict.fromkeys(obs.info["placement"].tolist()):
        R = obs.info["rotation"][np.flatnonzero(obs.info["placement"] == name)[0]]
        w = np.argmax(np.abs(R[:, 2]))
        have.add({0: "YZ", 1: "XZ", 2: "XY"}[int(w)])
    lo = model.nominal_position({a: model.travel[a][0] for a in model.axes})[0]
    hi = model.nominal_position({a: model.travel[a][1] for a in model.axes})[0]
    mid = 0.5 * (lo + hi)
    trials = [(f"a placement in the {p} plane", p, mid, 0.0) for p in ("XY", "XZ", "YZ")
              if p not in have]
    trials.append(("a placement turned by 90 deg in its plane", next(iter(have)), mid, 90.0))
    high = mid.copy()
    high[2] = mid[2] + 0.3 * abs(hi[2] - lo[2])
    trials.append(("an XY placement 30 % of the Z travel higher", "XY", high, 0.0))
    out = []
    for text, plane, centre, turn in trials:
        try:
            pose = placed(model, pts, plane, centre, turn)
            cols = columns(model, pts, pose, "trial", ball, "ball", probe, rotary)
            cols["feature"] = list(feature)
            labels = {k: [str(v) for v in cols.pop(k)] for k in ("placement", "ball",
                                                                  "feature")}
            numbers = {k: np.asarray(v, float) for k, v in cols.items()}
            ext = columns_to_observations(numbers, {k: None for k in labels}, labels, model,
                                          f"{where} + {text}")
        except Exception:      # the trial leaves the travel: not a suggestion
            continue
        out.append((text, ext))
    return out
