"""The ``distances`` instrument: a tracking interferometer (LaserTRACER type) measuring the
distance from its station to a reflector at the tool -- self-calibrating multilateration.

Each row: the ``station`` (label), the commanded axis positions, the reflector's offset from
the tool point ``Xp, Yp, Zp`` (tool frame, mm) and the reading ``d_mm`` (absolute distance)
or ``dd_mm`` (the change of the distance since the station's first reading: an
interferometer counts length changes).  Model (:func:`volerr.derive.observations.distances`)::

    d = |t + e - (s + ds)| + dd

``t`` the nominal reflector position (the chain at the commanded positions), ``e`` the
volumetric error there, ``s`` the station's nominal position (the centre of its reference
sphere, workpiece frame) and ``ds`` its unknown correction, ``dd`` the station's dead path:
the unknown offset of its length scale (for ``dd_mm`` readings minus the initial length).
Four set-up unknowns per station (``station_dx station_dy station_dz dead_path`` um).  The
nominal station position and dead path come from the readings themselves (multilateration on
the nominal tool points: a linear solution refined by Gauss-Newton) unless ``station_x,
station_y, station_z`` give a start.  File format: ``volerr formats distances``.
"""

from __future__ import annotations

import numpy as np

from ..errors import require
from ..generated import instruments as generated
from ..machine.model import Model
from . import _fields as f
from .observations import FileInfo, Observations, Setup

KIND = "distances"
#: default standard uncertainty of a reading: U0 + K * distance (um, um/m)
DEFAULT_U0_UM, DEFAULT_K_UM_PER_M = 0.3, 0.3
SETUP_KEYS = tuple(generated.SETUP[KIND])
#: largest RMS misfit of the nominal multilateration (mm): beyond it the readings and the
#: positions disagree (wrong unit, wrong station label)
FIT_TOLERANCE_MM = 0.5


#: the fewest stations a distances file may hold: three distances fix a point (trilateration)
MIN_STATIONS = 3


def detect(names) -> bool:
    """A distances file has a station column or a distance reading."""
    low = {n.lower() for n in names}
    return bool(low & {"station", "d_mm", "dd_mm", "station_x", "station_y", "station_z"})


def require_stations(parts) -> None:
    """Refuse (InputError, one line) a campaign whose distances come from fewer than
    :data:`MIN_STATIONS` stations in all: the distances from fewer stations do not fix the
    tool point in space (each station's position and dead path are unknowns too).  Counted over
    the campaign, not per file: a tracking interferometer moved from station to station is
    often saved as one file per station."""
    stations = [(o.files[0].name, str(s)) for o in parts if o.files and o.files[0].kind == KIND
                for s in np.unique(o.info["station"].astype(str))]
    files = ", ".join(dict.fromkeys(f for f, _ in stations))
    require(not stations or len(stations) >= MIN_STATIONS,
            f"{files}: {len(stations)} station{'s' if len(stations) > 1 else ''} in the campaign "
            f"({', '.join(s for _, s in stations)}); multilateration needs at least "
            f"{MIN_STATIONS}: the distances from fewer stations do not fix the tool point in "
            f"space (each station's position and dead path are unknowns too)")


def read(path, model: Model) -> Observations:
    """Read a distances CSV into :class:`Observations` (InputError, one line, on a defect)."""
    return f.read_file(path, model, columns_to_observations)


def columns_to_observations(cols: dict, text: dict, raw: dict, model: Model,
                            where: str) -> Observations:
    needed = {"d_mm", "dd_mm", "Xp", "Yp", "Zp", "u_um", "station_x", "station_y", "station_z"}
    find, warnings = f.open_columns(cols, text, model, where, needed, labels=("station",))
    pos = f.positions(find, model, where, min_points=8, needs="multilateration")
    n = len(next(iter(pos.values())))
    probe = f.probe(find, n, where)
    station = f.labels(find, "station", raw, n)
    require(station is not None, f"{where}: missing column station (the label of the "
                                 f"tracking interferometer's position)")
    h_abs, h_rel = find("d", ("_mm",), "d_mm"), find("dd", ("_mm",), "dd_mm")
    require(bool(h_abs) != bool(h_rel), f"{where}: give one reading column: d_mm (absolute "
                                        f"distance) or dd_mm (change since the first reading)")
    d = find.cols[h_abs or h_rel]
    relative = h_rel is not None
    start = None
    if any(find.name(c) for c in ("station_x", "station_y", "station_z")):
        start = f.vector(find, ("station_x", "station_y", "station_z"),
                         "nominal station position", where)
    check_geometry(model, pos, probe, station, d, h_abs or h_rel, start, where)
    t = model.nominal_position(pos, probe)
    names, gidx = np.unique(station.astype(str), return_inverse=True)
    gidx = gidx.ravel()
    s0 = np.zeros((n, 3))
    dead0 = np.zeros(n)
    for g, name in enumerate(names):
        m = gidx == g
        require(m.sum() >= 8, f"{where}: station {name} has {int(m.sum())} readings; "
                              f"multilateration needs at least 8 per station")
        guess = None if start is None else start[m][0]
        s, dd, rms = locate(t[m], d[m], guess, f"{where}: station {name}")
        require(rms <= FIT_TOLERANCE_MM, f"{where}: station {name}: the distances do not fit "
                f"the positions (RMS {rms:.3f} mm after locating the station): wrong unit, "
                f"wrong station labels or layout")
        s0[m], dead0[m] = s, dd
    lin = generated.distances(t[:, 0], t[:, 1], t[:, 2], s0[:, 0], s0[:, 1], s0[:, 2])[0]
    nominal = lin[0] + dead0
    dist = lin[0]
    u = _uncertainty(find, dist, where)
    proj = np.zeros((n, 3, 3))
    proj[:, 0, :] = lin[1:4].T
    local = np.zeros((n, 3, len(SETUP_KEYS)))
    local[:, 0, :] = lin[4:8].T
    dev = np.zeros((n, 3))
    dev[:, 0] = d - nominal
    setup = Setup(gidx[:, None], local, [f"{where}#{m}" for m in names],
                  [SETUP_KEYS] * len(names), [("local", 0)] * len(names),
                  [("um",) * 4] * len(names), [(None,) * 4] * len(names))
    covs = f.covariates(find, model, where)
    info = {"station": names[gidx].astype(object), "station_nominal": s0,
            "dead_path_nominal": dead0, "relative": np.full(n, relative)}
    return Observations(pos, probe, dev, covs, warnings, proj=proj, rows=np.ones(n, int),
                        setup=setup, files=(FileInfo(where, KIND, "um", 1),), sigma=u,
                        info=info)


def check_geometry(model, pos, probe, station, d, column, start, where) -> None:
    """The distances fit the commanded tool points from one station each, within
    :data:`FIT_TOLERANCE_MM` RMS (:func:`volerr.instruments.geometry_check.distances_misfit`;
    with ``station_x ...`` given the station's own refit below still applies); a miss is
    refused naming the likely cause (radians, inches, the offset's sign, swapped columns,
    another layout, distances in m or um, the distances' sign)."""
    from . import geometry_check as gc

    names = np.asarray(station).astype(str)
    for name in np.unique(names):
        require((names == name).sum() >= 8, f"{where}: station {name} has "
                f"{int((names == name).sum())} readings; multilateration needs at least 8 per "
                f"station")
    if start is not None:
        return
    gc.require_consistent(where, model, gc.Geometry(
        pos, probe, {"the distances": d}, {"the distances": column},
        gc.distances_misfit(names, locate, FIT_TOLERANCE_MM)),
        extra=[("distances in m (x 1000 makes the file consistent)", column,
                {"the distances": d * 1000.0}),
               ("distances in um, not mm (/ 1000 makes the file consistent)", column,
                {"the distances": d * 1e-3}),
               ("distances with the wrong sign (negated, the file is consistent: a length "
                "change is the later reading minus the first, positive away from the station)",
                column, {"the distances": -d})])


def _uncertainty(find, dist, where) -> np.ndarray:
    h = find("u", ("_um",), "u_um")
    if h is None:
        return 1e-3 * (DEFAULT_U0_UM + DEFAULT_K_UM_PER_M * 1e-3 * dist)
    u = find.cols[h]
    require(np.all(u > 0), f"{where}: column {h}: uncertainties must be positive")
    return u * 1e-3


def locate(t: np.ndarray, d: np.ndarray, guess=None, where: str = "station",
           iterations: int = 30) -> tuple[np.ndarray, float, float]:
    """Station position ``s`` (3,), dead path ``dd`` and the RMS misfit (mm) minimising
    ``sum (|t_i - s| + dd - d_i)^2`` over the points ``t`` (n, 3) with readings ``d`` (n,):
    from ``guess`` or the linear solution of ``(d - dd)^2 = |t - s|^2`` (unknowns ``s``,
    ``dd`` and ``|s|^2 - dd^2``), refined by Gauss-Newton."""
    t = np.asarray(t, float)
    d = np.asarray(d, float)
    if guess is None:
        A = np.column_stack([-2.0 * t, 2.0 * d, np.ones(len(d))])
        rhs = d ** 2 - np.sum(t ** 2, axis=1)
        sv = np.linalg.svd(A / np.linalg.norm(A, axis=0), compute_uv=False)
        require(sv[-1] > 1e-6 * sv[0], f"{where}: the targets do not fix the station (all in "
                f"one plane or on one line?): give station_x, station_y, station_z")
        sol, *_ = np.linalg.lstsq(A, rhs, rcond=None)
        s, dd = sol[:3], sol[3]
    else:
        s = np.asarray(guess, float)
        dd = float(np.median(d - np.linalg.norm(t - s, axis=1)))
    for _ in range(iterations):
        v = t - s
        r = np.linalg.norm(v, axis=1)
        res = r + dd - d
        J = np.column_stack([-v / r[:, None], np.ones(len(d))])
        step, *_ = np.linalg.lstsq(J, -res, rcond=None)
        s, dd = s + step[:3], dd + step[3]
        if np.max(np.abs(step)) < 1e-12 * (1.0 + np.max(np.abs(s))):
            break
    res = np.linalg.norm(t - s, axis=1) + dd - d
    require(np.all(np.isfinite(s)), f"{where}: the station could not be located")
    return s, float(dd), float(np.sqrt(np.mean(res ** 2)))


# ---- results, plans, simulated readings --------------------------------------------------
def results(obs: Observations, setup: dict) -> dict:
    """Every station's identified position (nominal + correction, workpiece frame) and dead
    path: ``{"stations": {"<file>#<station>": {"position_mm": [..], "position_std_um": [..],
    "dead_path_mm", "dead_path_std_um"}}}``; ``setup`` the report's set-up estimates (um)."""
    where = obs.files[0].name if obs.files else "distances"
    out = {}
    names = obs.info["station"]
    for name in dict.fromkeys(names.tolist()):
        i = np.flatnonzero(names == name)[0]
        est = setup.get(f"{where}#{name}", {})
        corr = [est.get(k, {}).get("value", 0.0) for k in SETUP_KEYS]
        std = [est.get(k, {}).get("std", 0.0) for k in SETUP_KEYS]
        pos = obs.info["station_nominal"][i] + 1e-3 * np.array(corr[:3])
        out[f"{where}#{name}"] = {
            "position_mm": [round(float(v), 7) for v in pos],
            "position_std_um": [round(float(v), 5) for v in std[:3]],
            "dead_path_mm": round(float(obs.info["dead_path_nominal"][i] + 1e-3 * corr[3]), 7),
            "dead_path_std_um": round(float(std[3]), 5)}
    return {"stations": out}


def simulate(model: Model, positions: dict, stations: dict, probe=(0.0, 0.0, 0.0),
             errors=None, dead_paths=None, relative: bool = False, noise=True,
             seed: int = 0) -> dict:
    """Columns of a distances file: every station (label -> position, workpiece frame, mm)
    measures the tool point at every pose of ``positions`` {axis: (n,)} (mm / deg) of the
    layout's first-order model with ``errors`` (mm / rad); ``dead_paths`` {label: mm};
    ``noise``: Gaussian with the default uncertainty (0.3 um + 0.3 um/m)."""
    rng = np.random.default_rng(seed)
    n = len(next(iter(positions.values())))
    t = model.nominal_position(positions, probe)
    if errors:
        t = t + model.volumetric_error(positions, errors, probe=probe)
    cols = {a: [] for a in model.axes}
    cols.update({"station": [], "d": []})
    for label, s in stations.items():
        dist = np.linalg.norm(t - np.asarray(s, float), axis=1)
        u = 1e-3 * (DEFAULT_U0_UM + DEFAULT_K_UM_PER_M * 1e-3 * dist)
        reading = dist + (dead_paths or {}).get(label, 0.0)
        if noise:
            reading = reading + rng.normal(0.0, 1.0, n) * u
        if relative:
            reading = reading - reading[0]
        for a in model.axes:
            cols[a] += list(positions[a])
        cols["station"] += [str(label)] * n
        cols["d"] += list(reading)
    p = np.asarray(probe, float)
    m = len(cols["station"])
    out = {a: np.asarray(cols[a]) for a in model.axes}
    out.update({"Xp": np.full(m, p[0]), "Yp": np.full(m, p[1]), "Zp": np.full(m, p[2]),
                "station": cols["station"],
                ("dd_mm" if relative else "d_mm"): np.asarray(cols["d"])})
    return out


def write_csv(path, cols: dict, inputs=()):
    from ..fileio import write_text

    names = list(cols)
    n = len(cols[names[0]])
    lines = [",".join(names)]
    for i in range(n):
        lines.append(",".join(str(cols[k][i]) if k == "station" else
                              (f"{cols[k][i]:.7f}" if k.endswith("d_mm") else
                               f"{cols[k][i]:.6f}") for k in names))
    return write_text(path, "\n".join(lines) + "\n", inputs=list(inputs))


def extensions(model, obs) -> list:
    """Plan extensions: the same targets with the reflector 100 mm further out along the tool
    (a second tool length: the angular errors' Abbe arms), and from a fifth station above the
    middle of the stations."""
    if "station_nominal" not in obs.info:
        return []
    where = obs.files[0].name if obs.files else "distances"
    names = obs.info["station"]
    first = names == names[0]
    pos = {a: v[first] for a, v in obs.positions.items()}
    stations = {str(k): obs.info["station_nominal"][np.flatnonzero(names == k)[0]]
                for k in dict.fromkeys(names.tolist())}
    probe = obs.probe[first][0]
    t = model.nominal_position(pos, probe)
    above = np.mean(list(stations.values()), axis=0)
    above[2] = float(np.max(t[:, 2])) + 0.5 * float(np.ptp(t[:, 2]) + 100.0)
    trials = [("the same targets with the reflector 100 mm further out along the tool",
               stations, probe + np.array([0.0, 0.0, 100.0])),
              ("a fifth station above the middle of the others", {"trial": above}, probe)]
    out = []
    for text, st, p in trials:
        try:
            cols = simulate(model, pos, st, p, noise=False)
            labels = {"station": [str(v) for v in cols.pop("station")]}
            numbers = {k: np.asarray(v, float) for k, v in cols.items()}
            first_n = len(next(iter(pos.values())))
            sx = np.concatenate([np.tile(np.asarray(s, float), (first_n, 1))
                                 for s in st.values()])
            numbers["station_x"], numbers["station_y"], numbers["station_z"] = sx.T
            ext = columns_to_observations(numbers, {"station": None}, labels, model,
                                          f"{where} + {text}")
        except Exception:      # the trial leaves the travel: not a suggestion
            continue
        out.append((text, ext))
    return out
