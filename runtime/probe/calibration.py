"""Probe (lobing) error: master-sphere calibration and the probe error map (Pahk sec. 3).

Conventions (stated once, used everywhere in volerr)
----------------------------------------------------
* Probe frame: tilt ``A`` and roll ``B`` of the probe head (deg at the API) define the probe
  frame (x', y', z') of Pahk eq. (11), z' along the stylus towards the head; the transforms
  are derived in :mod:`volerr.derive.probe` and generated into :mod:`volerr.generated.probe`.
  A vertical probe (A = 0) has the machine frame as its probe frame, whatever the roll B.
* Probing direction ``M`` (unit vector): the outward normal of the probed surface at the
  contact, i.e. from the contact point towards the stylus-ball centre.  On the master sphere it
  is the direction from the sphere centre to the recorded ball centre, so the pole (phi = 0) is
  the point probed straight along the stylus.  ``phi`` = angle from the probe axis z' (eq. 15),
  ``theta`` = azimuth from x' in [0, 360) deg (eq. 16).  The approach motion is ``-M``.
* Eq. (13): ``R_eff - Probe(phi, theta) = R_m - R_s`` with ``R_m`` the distance of the
  recorded ball centre from the fitted sphere centre and ``R_s`` the master-sphere radius.  The
  least-squares sphere fit of the ball centres gives the centre and the radius ``R_fit`` =
  mean(R_m) (the normal equation of the radius), so ``R_eff = R_fit - R_s`` and
  ``Probe_i = R_eff - (R_m,i - R_s)``: positive where the probe triggers late (more
  pretravel, the ball centre recorded nearer the surface).
* What the sphere fit absorbs: the part of the true pretravel pattern that is constant or
  linear in the direction (1, Mx, My, Mz) over the probed points cannot be told from the
  ball radius and the sphere centre; it goes into R_eff and the centre (on Pahk's hemisphere
  plan a pattern growing with phi moves the centre along the probe axis by several um).  That
  is the probe's effective centre and radius -- what a stylus qualification uses -- so the
  along-normal error of a measured point is still -Probe(M); the reported u(centre), u(R_eff)
  are Type A (scatter about the map) and do not include this definitional part.
* Eq. (17): a point measured with probing direction ``M`` is reported ``Probe(M)`` inside the
  surface (reported minus true = ``-Probe(M) M``); in the "actual minus nominal" convention of
  the volumetric error that is ``+Probe(M) M``, which :meth:`volerr.Model.volumetric_error`
  adds (``direction=M, probe_error=probe_map``).  Pahk writes ``- Probe M`` with ``M`` the
  contact (approach) direction, the opposite of ours.
* Units: mm and deg at the API, um in files' ``_um`` columns and in reports.

The smooth map is a least-squares fit of real spherical harmonics of degree <= L (L chosen by
generalised cross-validation within what the number of points supports, or given), with a tiny
smoothness (Laplace-Beltrami) ridge so that directions the data do not constrain stay quiet.
It handles the pole and the theta wrap-around by construction and is evaluated in any
direction; directions beyond the probed range of phi are refused (or clamped) rather than
silently extrapolated.  Outliers are flagged by a robust (MAD) test on the leave-one-out
residuals of the map and kept, unless the caller asks to exclude them.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..units import MM_PER_UM, UM_PER_MM, parse_number
from ..errors import InputError, require, require_file
from ..fileio import sniff_delimiter
from .fits import (MAX_CONDITION, MAX_DEGREE, MIN_POINTS, OUTLIER_K,  # noqa: F401
                               PLANE_RATIO, RIDGE, SCALE_FLOOR_MM, SHFit, SphereFit,
                               check_sphere_points, fit_sh, fit_sphere, max_degree_for,
                               robust_flags, sh_design)

#: largest plausible effective stylus-ball radius, mm (a sphere radius that implies more is
#: wrong): the largest stylus balls of touch probes are about 20 mm in diameter
MAX_BALL_RADIUS_MM = 10.0
#: smallest plausible effective stylus-ball radius, mm
MIN_BALL_RADIUS_MM = 0.005
#: largest difference between the effective and the nominal stylus-ball radius, mm: the mean
#: pretravel and the bending of a stylus stay well below it
TIP_TOLERANCE_MM = 0.1
#: what a declared sphere radius that does not fit the ball centres may really be: text,
#: the radius it then stands for (mm) from the declared one
_RADIUS_MISTAKES = (("the diameter given for the radius", lambda r: r / 2.0),
                    ("the radius in inches", lambda r: r * 25.4),
                    ("the radius in cm", lambda r: r * 10.0),
                    ("the radius in um", lambda r: r * MM_PER_UM))
#: tolerance on the probed phi range when evaluating the map, deg
COVERAGE_TOL_DEG = 2.0


def _gen():
    from volerr.generated import probe as gen  # numpy only

    return gen


def _flat_angles(phi_deg, theta_deg):
    """(phi, theta) broadcast together and flattened, and their common shape."""
    phi = np.asarray(phi_deg, dtype=float)
    theta = np.asarray(theta_deg, dtype=float)
    shape = np.broadcast_shapes(phi.shape, theta.shape)
    return np.broadcast_to(phi, shape).ravel(), np.broadcast_to(theta, shape).ravel(), shape


# ---- frames and directions ---------------------------------------------------------------
def _head_angles_rad(tilt_deg, roll_deg):
    """(tilt, roll) in rad.  A vertical probe (tilt 0) has the machine frame as its probe frame
    whatever the roll: eq. (11)'s cross product vanishes there, and the roll of a vertical
    stylus is not part of the probe frame (it is 0 here, where the closed form of eq. 11 gives
    the machine frame)."""
    t = np.radians(np.asarray(tilt_deg, dtype=float))
    r = np.where(t == 0.0, 0.0, np.radians(np.asarray(roll_deg, dtype=float)))
    return (float(t), float(r)) if t.ndim == 0 and r.ndim == 0 else (t, r)


def machine2probe(tilt_deg: float = 0.0, roll_deg: float = 0.0) -> np.ndarray:
    """Tp of eq. (12) as stated (``v_probe = machine2probe @ v_machine``), (3, 3)."""
    return _gen().machine2probe(*_head_angles_rad(tilt_deg, roll_deg))


def probe2machine(tilt_deg: float = 0.0, roll_deg: float = 0.0) -> np.ndarray:
    """Columns e'_x, e'_y, e'_z of eq. (11) (``v_machine = probe2machine @ v_probe``), (3, 3)."""
    return _gen().probe2machine(*_head_angles_rad(tilt_deg, roll_deg))


def angles_of(directions_machine, tilt_deg=0.0, roll_deg=0.0):
    """Machine-frame directions, shape (n, 3) (any length) -> (phi_deg, theta_deg) in the
    probe frame (eq. 14-16); tilt/roll scalars or (n,) arrays (deg)."""
    d = np.atleast_2d(np.asarray(directions_machine, dtype=float))
    gen = _gen()
    mp = gen.direction_to_probe(*_head_angles_rad(tilt_deg, roll_deg),
                                d[:, 0], d[:, 1], d[:, 2])
    phi, theta = gen.direction_angles(*mp)
    theta = np.degrees(theta)
    return np.degrees(phi), np.where(theta >= 360.0, theta - 360.0, theta)


def directions_of(phi_deg, theta_deg, tilt_deg=0.0, roll_deg=0.0):
    """Probe-frame angles (deg) -> machine-frame unit vectors, shape (n, 3); tilt/roll
    scalars or arrays broadcasting with the angles (deg)."""
    gen = _gen()
    m = gen.direction_to_machine(*_head_angles_rad(tilt_deg, roll_deg),
                                 np.radians(np.asarray(phi_deg, dtype=float)),
                                 np.radians(np.asarray(theta_deg, dtype=float)))
    return np.stack(m, axis=-1)


# ---- input ---------------------------------------------------------------------------------
@dataclass
class SphereData:
    """Master-sphere probing data: ball centres (n, 3) mm and optional nominal directions."""

    points: np.ndarray
    phi_deg: np.ndarray | None = None
    theta_deg: np.ndarray | None = None
    source: str = ""


def _float(text: str, where: str) -> float:
    return parse_number(text, where)


def _csv_rows(path: Path) -> list:
    """The non-blank rows of a CSV file (cells as written), InputError (one line) for a file
    that is missing, not text, malformed or empty."""
    require_file(path, f"{path}: no such file")
    try:
        text = path.read_text(encoding="utf-8-sig")
        rows = [r for r in csv.reader(io.StringIO(text), delimiter=sniff_delimiter(text))
                if any(c.strip() for c in r)]
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a text CSV file") from None
    except csv.Error as exc:
        raise InputError(f"{path}: malformed CSV: {exc}") from None
    require(rows, f"{path}: empty file")
    return rows


#: the reading columns of volerr's other measurement files (docs/formats.md): a file that
#: carries one is that instrument's file, not master-sphere probing data, whatever x, y, z
#: it also has (a deviations or sphere file's X, Y, Z are axis positions, not ball centres)
OTHER_KINDS = {"dx_um": "deviations or sphere (R-test)", "dy_um": "deviations or sphere (R-test)",
               "dz_um": "deviations or sphere (R-test)", "dr_um": "ballbar",
               "d_mm": "distances", "dd_mm": "distances", "deviation_um": "interferometer",
               "x_mm,u_mm": "artifact"}


def _refuse_other_kind(path, header) -> None:
    """One line when ``header`` (lower case) holds the reading columns of another file kind
    (:data:`OTHER_KINDS`): the wrong file given to ``probe-cal``."""
    hit = [c for c in OTHER_KINDS if all(k in header for k in c.split(","))]
    if hit:
        raise InputError(f"{path}: column {hit[0].split(',')[-1]} is a reading of the "
                         f"{OTHER_KINDS[hit[0]]} format, not master-sphere probing data (x,y,z "
                         f"ball centres, mm): the wrong file for probe-cal?")


def read_sphere_csv(path) -> SphereData:
    """Read ``x,y,z[,phi_deg,theta_deg]`` (mm, deg); other columns are ignored, except the
    reading columns of another instrument's file (:data:`OTHER_KINDS`: refused)."""
    path = Path(path)
    rows = _csv_rows(path)
    header = [h.strip().lower() for h in rows[0]]
    _refuse_other_kind(path, header)
    alias = {"x_mm": "x", "y_mm": "y", "z_mm": "z"}
    header = [alias.get(h, h) for h in header]
    dup = [c for c in ("x", "y", "z", "phi_deg", "theta_deg") if header.count(c) > 1]
    require(not dup, f"{path}: column {dup[0]!r} appears twice" if dup else "")
    missing = [c for c in ("x", "y", "z") if c not in header]
    if missing:
        raise InputError(f"{path}: missing column {missing[0]!r} (need x,y,z in mm, "
                         f"optional phi_deg,theta_deg)")
    for bad, good in (("phi", "phi_deg"), ("theta", "theta_deg"), ("phi_rad", "phi_deg"),
                      ("theta_rad", "theta_deg")):
        require(bad not in header, f"{path}: column {bad!r}: give the angles as {good} (deg)")
    has_phi, has_theta = "phi_deg" in header, "theta_deg" in header
    require(has_phi == has_theta, f"{path}: give both phi_deg and theta_deg or neither")
    cols = ["x", "y", "z"] + (["phi_deg", "theta_deg"] if has_phi else [])
    idx = [header.index(c) for c in cols]
    data = []
    for k, r in enumerate(rows[1:], start=2):
        require(len(r) >= len(header) or len(r) > max(idx),
                f"{path}: line {k}: {len(r)} fields, header has {len(header)}")
        data.append([_float(r[i].strip(), f"{path}: line {k}, column {c}")
                     for i, c in zip(idx, cols)])
    require(data, f"{path}: no data rows")
    arr = np.asarray(data, dtype=float)
    bad = ~np.isfinite(arr)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise InputError(f"{path}: line {i + 2}, column {cols[j]}: NaN or infinite value")
    if has_phi:
        require(np.all((arr[:, 3] >= 0) & (arr[:, 3] <= 180)),
                f"{path}: phi_deg must lie in [0, 180] (angle from the probe axis)")
        return SphereData(arr[:, :3], arr[:, 3], np.mod(arr[:, 4], 360.0), str(path))
    return SphereData(arr[:, :3], source=str(path))


# ---- the probe error map ------------------------------------------------------------------
def unit_vectors(phi_deg, theta_deg) -> np.ndarray:
    """Probe-frame unit vectors of the angles (phi, theta) in deg, shape (..., 3) of the
    broadcast angles: generated :func:`volerr.generated.probe.unit_direction`."""
    m = _gen().unit_direction(np.radians(phi_deg), np.radians(theta_deg))
    return np.stack(m, axis=-1)


def coverage_of(phi_deg, theta_deg) -> float:
    """Coverage radius of probed directions, deg: 1.5 x the largest nearest-neighbour angle
    (at least 5 deg)."""
    u = unit_vectors(phi_deg, theta_deg)
    if len(u) < 2:
        return 5.0
    dots = u @ u.T
    np.fill_diagonal(dots, -2.0)
    nn = np.degrees(np.arccos(np.clip(dots.max(axis=1), -1.0, 1.0)))
    return float(max(1.5 * nn.max(), 5.0))



@dataclass
class ProbeMap:
    """Smooth probe error Probe(phi, theta) (mm) of a probe, in its own frame.

    ``probe_map(directions)`` takes machine-frame probing directions, shape (n, 3) (outward
    surface normals, see the module docstring), converts them to the probe frame of tilt
    ``tilt_deg`` and roll ``roll_deg`` (eq. 14-16) and returns Probe in mm, shape (n,).  It is
    the ``probe_error`` argument of :meth:`volerr.Model.volumetric_error` (eq. 17).

    Coverage: a direction is *outside* when its phi lies beyond the probed range
    ``phi_range_deg`` (+- 2 deg), or when it is farther than ``coverage_deg`` from every probed
    direction ``support_deg`` (a hole in the plan, e.g. azimuths never probed).
    ``outside``: ``"raise"`` (InputError), ``"clamp"`` (phi clamped into the probed range, then
    a direction still in a hole takes the value of the nearest probed direction) or
    ``"extrapolate"`` (evaluate the harmonics as they are)."""

    degree: int
    coefficients: np.ndarray  # mm
    phi_range_deg: tuple = (0.0, 180.0)
    tilt_deg: float = 0.0
    roll_deg: float = 0.0
    outside: str = "raise"
    support_deg: np.ndarray | None = None   # (n, 2) probed (phi, theta), deg
    coverage_deg: float = 180.0

    def __post_init__(self):
        require(self.outside in ("raise", "clamp", "extrapolate"),
                f"outside must be raise, clamp or extrapolate, not {self.outside!r}")
        self.coefficients = np.asarray(self.coefficients, dtype=float)
        require(len(self.coefficients) == (self.degree + 1) ** 2,
                "coefficient count does not match the degree")
        if self.support_deg is not None:
            self.support_deg = np.asarray(self.support_deg, dtype=float).reshape(-1, 2)
            self._support_u = unit_vectors(self.support_deg[:, 0], self.support_deg[:, 1])

    def covered(self, phi_deg, theta_deg) -> np.ndarray:
        """Boolean mask: probe-frame angles (deg) inside the calibrated coverage."""
        phi, theta, shape = _flat_angles(phi_deg, theta_deg)
        lo, hi = self.phi_range_deg
        ok = (phi >= lo - COVERAGE_TOL_DEG) & (phi <= hi + COVERAGE_TOL_DEG)
        if self.support_deg is not None and len(phi):
            ok &= self._nearest(np.clip(phi, lo, hi), theta)[0] <= self.coverage_deg
        return ok.reshape(shape)

    def _nearest(self, phi, theta):
        """(angle to the nearest probed direction in deg, its index) for each query."""
        u = unit_vectors(phi, theta)
        best = np.empty(len(u))
        idx = np.empty(len(u), dtype=int)
        for s in range(0, len(u), 20000):
            dots = u[s:s + 20000] @ self._support_u.T
            idx[s:s + 20000] = np.argmax(dots, axis=1)
            best[s:s + 20000] = np.max(dots, axis=1)
        return np.degrees(np.arccos(np.clip(best, -1.0, 1.0))), idx

    def oriented(self, tilt_deg, roll_deg) -> "ProbeMap":
        """The same probe used with the head at tilt/roll (deg): scalars, or (n,) arrays of
        per-point head angles (e.g. a probe on a five-axis head) matching the directions."""
        t = np.asarray(tilt_deg, dtype=float)
        r = np.asarray(roll_deg, dtype=float)
        require(np.all(np.isfinite(t)) and np.all(np.isfinite(r)), "tilt/roll must be finite")
        return replace(self, tilt_deg=float(t) if t.ndim == 0 else t,
                       roll_deg=float(r) if r.ndim == 0 else r)

    def with_outside(self, outside: str) -> "ProbeMap":
        return replace(self, outside=outside)

    def at(self, phi_deg, theta_deg) -> np.ndarray:
        """Probe (mm) at probe-frame angles (deg); same shape as the broadcast inputs."""
        phi, theta, shape = _flat_angles(phi_deg, theta_deg)
        require(np.all(np.isfinite(phi)) and np.all(np.isfinite(theta)),
                "probe directions contain NaN")
        lo, hi = self.phi_range_deg
        if self.outside != "extrapolate":
            out = (phi < lo - COVERAGE_TOL_DEG) | (phi > hi + COVERAGE_TOL_DEG)
            if out.any() and self.outside == "raise":
                k = int(np.argmax(out))
                raise InputError(
                    f"probing direction phi = {phi[k]:.1f} deg (theta {theta[k]:.1f}) lies "
                    f"outside the calibrated range phi {lo:.0f}..{hi:.0f} deg; calibrate "
                    f"there or use outside='clamp'")
            phi = np.clip(phi, lo, hi)
            if self.support_deg is not None and len(phi):
                gap, idx = self._nearest(phi, theta)
                hole = gap > self.coverage_deg
                if hole.any() and self.outside == "raise":
                    k = int(np.argmax(hole))
                    raise InputError(
                        f"probing direction phi = {phi[k]:.1f} deg, theta {theta[k]:.1f} deg "
                        f"is {gap[k]:.0f} deg from the nearest probed direction (coverage "
                        f"{self.coverage_deg:.0f} deg): not calibrated there; use "
                        f"outside='clamp'")
                phi = np.where(hole, self.support_deg[idx, 0], phi)
                theta = np.where(hole, self.support_deg[idx, 1], theta)
        return (sh_design(self.degree, np.radians(phi), np.radians(theta))
                @ self.coefficients).reshape(shape)

    def __call__(self, directions) -> np.ndarray:
        d = np.asarray(directions, dtype=float)
        d = np.atleast_2d(d)
        require(d.ndim == 2 and d.shape[1] == 3, f"directions must be (n, 3), got {d.shape}")
        require(np.all(np.isfinite(d)), "probing directions contain NaN")
        norm = np.linalg.norm(d, axis=1)
        require(np.all(norm > 0), "a probing direction is the zero vector")
        for v in (self.tilt_deg, self.roll_deg):
            require(np.ndim(v) == 0 or np.shape(v) == (len(d),),
                    f"per-point tilt/roll need one value per direction ({len(d)})")
        phi, theta = angles_of(d / norm[:, None], self.tilt_deg, self.roll_deg)
        return self.at(phi, theta)


# ---- calibration --------------------------------------------------------------------------
@dataclass
class ProbeCalibration:
    """Result of a master-sphere calibration (eq. 13).  Lengths mm, angles deg."""

    center: np.ndarray
    fit_radius: float
    sphere_radius: float
    r_eff: float
    phi_deg: np.ndarray
    theta_deg: np.ndarray
    r_m: np.ndarray
    probe: np.ndarray              # Probe(phi_i, theta_j), mm, eq. (13)
    map: ProbeMap
    map_fitted: np.ndarray         # smooth map at the points, mm
    outlier: np.ndarray            # bool flags
    robust_sigma: float            # robust sigma of the map residuals (bisquare fit), mm
    used: np.ndarray               # bool: point used in the fit
    direction_source: str
    direction_mismatch_deg: np.ndarray | None = None
    condition: float = 0.0
    noise: float = 0.0             # scatter about the smooth map (Type A), mm
    u_center: np.ndarray | None = None  # standard uncertainty of the centre from it, mm
    u_r_eff: float = 0.0           # standard uncertainty of R_eff from it (without u(R_s)), mm
    notes: list = field(default_factory=list)

    @property
    def n_points(self) -> int:
        return len(self.probe)

    def stats_um(self, which: np.ndarray | None = None) -> dict:
        """max / min / rms of Probe (um) over the used points (as Pahk reports them)."""
        v = self.probe[self.used if which is None else which] * UM_PER_MM
        return {"max": float(v.max()), "min": float(v.min()),
                "rms": float(math.sqrt(np.mean(v ** 2)))}

    def budget(self) -> dict:
        """The GUM budget of R_eff (um, :mod:`volerr.report.budget`): the scatter of the
        probed points about the sphere fit (Type A, ``noise``, um) with the sensitivity
        sqrt((J^T J)^-1_rr) of the fitted radius to it (the fit's covariance per unit
        residual variance), the u the report states.  The master sphere's radius
        uncertainty u(R_s) is not given to volerr and is not in it (a note)."""
        from ..report.budget import budget, source

        n, u = self.noise * UM_PER_MM, self.u_r_eff * UM_PER_MM
        return budget("r_eff", "um", [source(
            "scatter of the points about the probe map (Type A)", n, "um",
            u / n if n > 0 else 0.0)], 2.0, notes=[
            "The master sphere's radius uncertainty u(R_s) is not included: add it in "
            "quadrature (sensitivity 1)."])

    def summary(self) -> dict:
        """The ``--json`` report (INTERFACE.md keys first, then details)."""
        out = {
            "r_eff_mm": float(self.r_eff),
            "center_mm": [float(v) for v in self.center],
            "probe_error_um": self.stats_um(),
            "n_points": int(self.n_points),
            "n_used": int(self.used.sum()),
            "sphere_radius_mm": float(self.sphere_radius),
            "fit_radius_mm": float(self.fit_radius),
            "tilt_deg": float(self.map.tilt_deg),
            "roll_deg": float(self.map.roll_deg),
            "direction_source": self.direction_source,
            "phi_range_deg": [float(v) for v in self.map.phi_range_deg],
            "map": {
                "kind": "real spherical harmonics, orthonormal, l <= degree, m = -l..l",
                "degree": int(self.map.degree),
                "coefficients_um": [float(v) * UM_PER_MM for v in self.map.coefficients],
                "coverage_deg": float(self.map.coverage_deg),
                "support_deg": [[round(float(p), 6), round(float(t), 6)]
                                for p, t in self.map.support_deg],
                "residual_rms_um": float(math.sqrt(np.mean(
                    (self.probe[self.used] - self.map_fitted[self.used]) ** 2)) * UM_PER_MM),
            },
            "outliers": {
                "threshold": "studentised residual of a bisquare map fit > k x robust sigma",
                "robust_sigma_um": float(self.robust_sigma * UM_PER_MM),
                "index": [int(i) for i in np.flatnonzero(self.outlier)],
                "excluded": bool((~self.used).any()),
            },
            "uncertainty": {
                "note": "standard uncertainties (Type A) from the scatter about the smooth map; "
                        "u(R_eff) excludes the master-sphere radius uncertainty u(R_s)",
                "noise_um": float(self.noise * UM_PER_MM),
                "u_center_um": [float(v) * UM_PER_MM for v in (self.u_center if self.u_center
                                                         is not None else np.zeros(3))],
                "u_r_eff_um": float(self.u_r_eff * UM_PER_MM),
            },
            "sphere_fit_condition": float(self.condition),
            "budgets": {"r_eff": self.budget()},
        }
        if self.direction_mismatch_deg is not None:
            out["direction_mismatch_deg"] = {
                "median": float(np.median(self.direction_mismatch_deg)),
                "max": float(np.max(self.direction_mismatch_deg))}
        if self.notes:
            out["notes"] = list(self.notes)
        return out


def calibrate(points, sphere_radius: float, phi_deg=None, theta_deg=None,
              tilt_deg: float = 0.0, roll_deg: float = 0.0, degree: int | None = None,
              outlier_k: float = OUTLIER_K, exclude_outliers: bool = False,
              ball_radius: float | None = None) -> ProbeCalibration:
    """Master-sphere calibration (Pahk eq. 13).

    Parameters
    ----------
    points : array, shape (n, 3)
        Recorded stylus-ball centres, mm, machine frame.
    sphere_radius : float
        Master-sphere radius R_s, mm (calibrated value).
    phi_deg, theta_deg : array, shape (n,), optional
        Nominal probing directions in the probe frame (deg); default: from the fitted centre.
    tilt_deg, roll_deg : float
        Probe-head tilt A and roll B during the calibration (deg).
    degree : int, optional
        Degree of the spherical-harmonic map; default chosen by cross-validation.
    exclude_outliers : bool
        Refit the sphere and the map without the flagged points (they stay in the result,
        flagged, with their Probe relative to the refit).
    outlier_k : float
        Flag points whose studentised map residual exceeds ``outlier_k`` x the robust sigma.
    ball_radius : float, optional
        Nominal stylus-ball radius, mm: the effective radius R_fit - R_s must lie within
        ``TIP_TOLERANCE_MM`` of it (:func:`check_stylus`).

    Returns
    -------
    ProbeCalibration
        Fitted centre (3,) mm, effective ball radius ``r_eff`` mm, ``probe`` (n,) mm
        (Probe = R_eff - (R_m - R_s) at every point), the smooth :class:`ProbeMap` ``map``,
        outlier flags (n,) and standard uncertainties of centre and R_eff (mm).
    """
    p = check_sphere_points(points)
    require(math.isfinite(sphere_radius) and sphere_radius > 0,
            f"sphere radius must be a positive length in mm, got {sphere_radius}")
    require(math.isfinite(tilt_deg) and math.isfinite(roll_deg), "tilt/roll must be finite")
    require((phi_deg is None) == (theta_deg is None), "give both phi and theta or neither")
    require(outlier_k > 0, "outlier threshold must be positive")
    require(ball_radius is None or (math.isfinite(ball_radius) and ball_radius > 0),
            f"the stylus-ball radius must be a positive length in mm, got {ball_radius}")
    used = np.ones(len(p), dtype=bool)
    result = _calibrate_once(p, used, sphere_radius, phi_deg, theta_deg, tilt_deg, roll_deg,
                             degree, outlier_k, ball_radius=ball_radius)
    if exclude_outliers and result.outlier.any():
        used = ~result.outlier
        require(used.sum() >= MIN_POINTS, "too few points left after excluding the outliers")
        result = _calibrate_once(p, used, sphere_radius, phi_deg, theta_deg, tilt_deg,
                                 roll_deg, degree, outlier_k, flags=result.outlier,
                                 ball_radius=ball_radius)
    return result


def _radius_hint(fit_radius: float, sphere_radius: float, ball_radius=None) -> str:
    """What a sphere radius that does not fit the ball centres (``fit_radius``, mm) likely is:
    a clause for the refusal ("" when no known mistake explains it)."""
    def fits(radius):
        r = fit_radius - radius
        if ball_radius is not None:
            return abs(r - ball_radius) <= TIP_TOLERANCE_MM
        return MIN_BALL_RADIUS_MM <= r <= MAX_BALL_RADIUS_MM

    if abs(fit_radius - sphere_radius) <= TIP_TOLERANCE_MM and \
            (ball_radius is None or ball_radius > TIP_TOLERANCE_MM):
        return ("; the points lie on a sphere of the given radius: contact points "
                "(probe-corrected) instead of stylus-ball centres, or the sphere radius plus "
                "the ball radius given?")
    found = [f"{text} ({radius(sphere_radius):.6g} mm would fit)"
             for text, radius in _RADIUS_MISTAKES if fits(radius(sphere_radius))]
    if ball_radius is not None and abs((fit_radius - sphere_radius) * 2.0 - ball_radius) \
            <= 2 * TIP_TOLERANCE_MM:
        found.append("the ball's diameter given as --ball-radius")
    if not found and ball_radius is not None:
        found.append(f"another sphere's radius (with this ball the centres fit a "
                     f"{fit_radius - ball_radius:.6g} mm sphere)")
    return f"; likely {', or '.join(found)}?" if found else ""


def check_stylus(fit_radius: float, sphere_radius: float, ball_radius=None) -> None:
    """Refuse a sphere radius R_s (mm) that the ball centres' fitted radius R_fit (mm) cannot
    explain: R_fit - R_s is the effective stylus-ball radius, which must be a plausible
    stylus (MIN_BALL_RADIUS_MM .. MAX_BALL_RADIUS_MM) and, with the nominal ``ball_radius``,
    within TIP_TOLERANCE_MM of it.  The refusal names the likely mistake (the diameter for
    the radius, inches, contact points instead of ball centres)."""
    r_eff = fit_radius - sphere_radius
    hint = _radius_hint(fit_radius, sphere_radius, ball_radius)
    require(r_eff > 0,
            f"fitted radius of the ball centres {fit_radius:.6g} mm minus the sphere radius "
            f"{sphere_radius:.6g} mm gives a stylus-ball radius {r_eff:.4g} mm <= 0: check "
            f"--sphere-radius (a radius in mm, not a diameter){hint}")
    shown = f"{r_eff * UM_PER_MM:.3g} um" if r_eff < 1.0 else f"{r_eff:.4g} mm"
    require(MIN_BALL_RADIUS_MM <= r_eff <= MAX_BALL_RADIUS_MM,
            f"the sphere radius {sphere_radius:.6g} mm implies a stylus-ball radius {shown} "
            f"(fitted radius {fit_radius:.6g} mm): not a plausible stylus; check "
            f"--sphere-radius (mm){hint}")
    require(ball_radius is None or abs(r_eff - ball_radius) <= TIP_TOLERANCE_MM,
            f"the sphere radius {sphere_radius:.6g} mm implies a stylus-ball radius {shown} "
            f"(fitted radius {fit_radius:.6g} mm), the stylus ball has {ball_radius} mm: more "
            f"than the probe's pretravel could explain (at most {TIP_TOLERANCE_MM:g} mm); "
            f"check --sphere-radius and --ball-radius (mm){hint}")


def _calibrate_once(p, used, sphere_radius, phi_deg, theta_deg, tilt_deg, roll_deg, degree,
                    outlier_k, flags=None, ball_radius=None) -> ProbeCalibration:
    fit = fit_sphere(p[used])
    c = fit.center
    r_eff = fit.radius - sphere_radius
    check_stylus(fit.radius, sphere_radius, ball_radius)
    d = p - c
    r_m = np.linalg.norm(d, axis=1)
    probe = r_eff - (r_m - sphere_radius)            # eq. (13)
    u = d / r_m[:, None]
    phi_m, theta_m = angles_of(u, tilt_deg, roll_deg)
    mismatch = None
    notes = []
    if phi_deg is not None:
        phi = np.asarray(phi_deg, dtype=float)
        theta = np.mod(np.asarray(theta_deg, dtype=float), 360.0)
        require(phi.shape == (len(p),) and theta.shape == (len(p),),
                "phi/theta must have one value per point")
        require(np.all(np.isfinite(phi)) and np.all(np.isfinite(theta)), "phi/theta have NaN")
        nominal = directions_of(phi, theta, tilt_deg, roll_deg)
        cosang = np.clip(np.sum(nominal * u, axis=1), -1.0, 1.0)
        mismatch = np.degrees(np.arccos(cosang))
        if np.median(mismatch) > 5.0:
            notes.append(f"given directions differ from the measured ones by "
                         f"{np.median(mismatch):.1f} deg (median): check phi/theta convention "
                         f"(outward normal, phi from the probe axis) and the tilt/roll")
        source = "columns"
    else:
        phi, theta = phi_m, theta_m
        source = "fitted centre"
    sh = fit_sh(np.radians(phi[used]), np.radians(theta[used]), probe[used], degree)
    support = np.column_stack([phi[used], theta[used]])
    pmap = ProbeMap(sh.degree, sh.coefficients,
                    (float(phi[used].min()), float(phi[used].max())),
                    float(tilt_deg), float(roll_deg), support_deg=support,
                    coverage_deg=coverage_of(phi[used], theta[used]))
    fitted = sh(np.radians(phi), np.radians(theta))
    flag_used, sigma = robust_flags(sh.degree, np.radians(phi[used]), np.radians(theta[used]),
                                    probe[used], outlier_k)
    res = probe[used] - sh.fitted
    noise = math.sqrt(float(res @ res) / max(used.sum() - sh.dof, 1.0))
    u_par = noise * np.sqrt(np.diag(fit.cov_unit))
    outlier = np.zeros(len(p), dtype=bool)
    outlier[used] = flag_used
    if flags is not None:
        outlier |= flags
        outlier[~used] = True
    return ProbeCalibration(
        center=c, fit_radius=fit.radius, sphere_radius=float(sphere_radius), r_eff=r_eff,
        phi_deg=phi, theta_deg=theta, r_m=r_m, probe=probe, map=pmap, map_fitted=fitted,
        outlier=outlier, robust_sigma=sigma, used=used.copy(),
        direction_source=source, direction_mismatch_deg=mismatch, condition=fit.condition,
        noise=noise, u_center=u_par[:3], u_r_eff=float(u_par[3]), notes=notes)


def _check_point_unit(data: SphereData, sphere_radius: float, ball_radius=None) -> None:
    """Refuse ball centres in inches: their fitted sphere does not fit the declared radius
    (:func:`check_stylus`) but the points x 25.4 do -- one line naming the file and the
    columns x, y, z (the radius is then right, the points are not)."""
    if len(data.points) < MIN_POINTS:
        return
    try:
        r = fit_sphere(data.points).radius
    except (InputError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return

    def fits(fit_radius):
        r_eff = fit_radius - sphere_radius
        if ball_radius is not None:
            return abs(r_eff - ball_radius) <= TIP_TOLERANCE_MM
        return MIN_BALL_RADIUS_MM <= r_eff <= MAX_BALL_RADIUS_MM

    if not fits(r) and fits(r * 25.4):
        raise InputError(f"{data.source or 'probe file'}: columns x, y, z: the ball centres "
                         f"lie on a {r:.6g} mm sphere, less than --sphere-radius "
                         f"{sphere_radius:g} mm; x 25.4 they fit it: likely the points in "
                         f"inches, not mm (give mm)")


def calibrate_data(data: SphereData, sphere_radius: float, **kw) -> ProbeCalibration:
    """:func:`calibrate` on :class:`SphereData` (nominal directions taken when present);
    points in inches refused first (:func:`_check_point_unit`)."""
    _check_point_unit(data, sphere_radius, kw.get("ball_radius"))
    return calibrate(data.points, sphere_radius, data.phi_deg, data.theta_deg, **kw)


# ---- output -------------------------------------------------------------------------------
MAP_COLUMNS = ("phi_deg", "theta_deg", "probe_um", "map_um", "residual_um", "r_m_mm",
               "outlier")


def map_csv_text(cal: ProbeCalibration) -> str:
    """MAP.csv: one row per probed point, in input order.  ``probe_um`` = Probe of eq. (13);
    ``map_um`` = the smooth map there; ``residual_um`` = probe_um - map_um; ``r_m_mm`` =
    distance of the ball centre from the fitted sphere centre; ``outlier`` = 1 when flagged."""
    lines = [",".join(MAP_COLUMNS)]
    res = cal.probe - cal.map_fitted
    for i in range(cal.n_points):
        lines.append(f"{cal.phi_deg[i]:.6f},{cal.theta_deg[i]:.6f},{cal.probe[i] * UM_PER_MM:.4f},"
                     f"{cal.map_fitted[i] * UM_PER_MM:.4f},{res[i] * UM_PER_MM:.4f},"
                     f"{cal.r_m[i]:.7f},{int(cal.outlier[i])}")
    return "\n".join(lines) + "\n"


def probe_map_from_json(source, tilt_deg: float | None = None, roll_deg: float | None = None,
                        outside: str = "raise") -> ProbeMap:
    """The exact :class:`ProbeMap` of a ``probe-cal --json`` report (a path or the parsed
    dict); tilt/roll default to those of the calibration."""
    import json

    if not isinstance(source, dict):
        path = Path(source)
        require_file(path, f"{path}: no such file")
        try:
            source = json.loads(path.read_text(encoding="utf-8"))
        except ValueError as exc:
            raise InputError(f"{path}: not JSON: {exc}") from None
    try:
        m = source["map"]
        return ProbeMap(int(m["degree"]), np.asarray(m["coefficients_um"], dtype=float) * MM_PER_UM,
                        tuple(float(v) for v in source["phi_range_deg"]),
                        float(source.get("tilt_deg", 0.0) if tilt_deg is None else tilt_deg),
                        float(source.get("roll_deg", 0.0) if roll_deg is None else roll_deg),
                        outside, m.get("support_deg"), float(m.get("coverage_deg", 180.0)))
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(f"not a probe-cal report: missing or bad {exc}") from None


def read_probe_map(path, tilt_deg: float = 0.0, roll_deg: float = 0.0,
                   degree: int | None = None, outside: str = "raise") -> ProbeMap:
    """A :class:`ProbeMap` from a MAP.csv (``phi_deg,theta_deg,probe_um``; rows flagged
    ``outlier`` = 1 are left out), refitted as by the calibration."""
    path = Path(path)
    rows = _csv_rows(path)
    header = [h.strip().lower() for h in rows[0]]
    for c in ("phi_deg", "theta_deg", "probe_um"):
        require(c in header, f"{path}: missing column {c!r}")
    idx = [header.index(c) for c in ("phi_deg", "theta_deg", "probe_um")]
    i_out = header.index("outlier") if "outlier" in header else None
    vals = []
    for k, r in enumerate(rows[1:], start=2):
        require(len(r) > max(idx), f"{path}: line {k}: too few fields")
        if i_out is not None and len(r) > i_out and r[i_out].strip() not in ("", "0"):
            continue
        vals.append([_float(r[i].strip(), f"{path}: line {k}") for i in idx])
    arr = np.asarray(vals, dtype=float)
    require(len(arr) >= MIN_POINTS, f"{path}: needs at least {MIN_POINTS} map points")
    require(np.all(np.isfinite(arr)), f"{path}: NaN values")
    sh = fit_sh(np.radians(arr[:, 0]), np.radians(arr[:, 1]), arr[:, 2] * MM_PER_UM, degree)
    return ProbeMap(sh.degree, sh.coefficients,
                    (float(arr[:, 0].min()), float(arr[:, 0].max())),
                    float(tilt_deg), float(roll_deg), outside, arr[:, :2],
                    coverage_of(arr[:, 0], arr[:, 1]))
