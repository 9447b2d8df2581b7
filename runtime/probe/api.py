"""``volerr.probe_cal(...)``: the Python API of ``volerr probe-cal`` (:mod:`volerr.results`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import require
from ..results import ResultMixin


@dataclass(repr=False)
class ProbeCal(ResultMixin):
    """Result of :func:`probe_cal`: ``data`` the ``--json`` summary (``r_eff_mm``,
    ``center_mm``, ``probe_error_um`` max / min / rms with the sign of Pahk's eq. (13):
    Probe = R_eff - (R_m - R_s)), ``calibration`` the full
    :class:`volerr.probe.ProbeCalibration`."""

    data: dict
    calibration: object
    excluded: bool = False

    def summary(self) -> str:
        """What ``volerr probe-cal`` prints (without the line naming the map file)."""
        from .report import summary_lines

        return "\n".join(summary_lines(self.calibration, self.excluded))

    def map_csv(self) -> str:
        """The probe error map ``phi_deg,theta_deg,probe_um`` (``--out MAP.csv``)."""
        from .calibration import map_csv_text

        return map_csv_text(self.calibration)

    def _rows(self) -> list:
        from ..results import Row

        u = self.data.get("uncertainty", {})
        return [Row("r_eff", self.data["r_eff_mm"], u.get("u_r_eff_um", 0.0) / 1e3, "mm", 1.0)]


def probe_cal(data, sphere_radius: float, *, tilt_deg: float = 0.0, roll_deg: float = 0.0,
              degree: int | None = None, outlier_k: float = 5.0,
              exclude_outliers: bool = False, ball_radius: float | None = None) -> ProbeCal:
    """Probe (lobing) calibration on a master sphere (``volerr probe-cal``; Pahk's probe frame).

    Parameters
    ----------
    data : str or path
        Master-sphere probing data ``x,y,z[,phi_deg,theta_deg]``: the probe-ball centre at
        each trigger (mm) and the nominal probing direction in the probe frame.
    sphere_radius : float
        Calibrated radius R_s of the master sphere, mm.
    tilt_deg, roll_deg : float
        Orientation of the probe frame (deg).
    degree : int, optional
        Degree of the spherical-harmonic probe map (0 .. 20; default: chosen).
    outlier_k : float
        Flag points whose residual exceeds k times the noise.
    exclude_outliers : bool
        Refit without the flagged points.
    ball_radius : float, optional
        Nominal stylus-ball radius, mm: a sphere radius that implies an effective ball radius
        farther from it than the pretravel could explain is refused (with the likely mistake).

    Returns
    -------
    ProbeCal
        ``to_dict()`` is ``--json``; standard uncertainties (k = 1) of the centre and R_eff.
    """
    from . import calibration as probe

    require(math.isfinite(sphere_radius) and sphere_radius > 0,
            f"--sphere-radius must be a positive length in mm, got {sphere_radius}")
    require(degree is None or 0 <= degree <= 20,
            f"--degree must be between 0 and 20, got {degree}")
    cal = probe.calibrate_data(probe.read_sphere_csv(data), sphere_radius, tilt_deg=tilt_deg,
                               roll_deg=roll_deg, degree=degree, outlier_k=outlier_k,
                               exclude_outliers=exclude_outliers, ball_radius=ball_radius)
    return ProbeCal(cal.summary(), cal, exclude_outliers)
