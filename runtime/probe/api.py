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

    def write_map(self, path, inputs=()):
        """Write :meth:`map_csv` (``--out MAP.csv``); returns its path."""
        from ..fileio import write_text

        return write_text(path, self.map_csv(), inputs=list(inputs))

    def write_plot(self, path, inputs=()):
        """Both maps in one PNG (``--plot``): the 3-D lobing map (Pahk Fig. 3a, um) above
        the (phi, theta) map (Fig. 3b); returns its path."""
        from ..fileio import check_plot
        from .plots import plot_probe_calibration

        return plot_probe_calibration(self.calibration, check_plot(path, list(inputs)))

    def _write_own(self, outs, options: dict, inputs: list) -> None:
        """``volerr probe-cal``'s ``--out MAP.csv`` and ``--plots DIR``."""
        self.write_map(outs.path("--out"), inputs=inputs)
        if options.get("plots"):
            self.write_plots(outs.path("--plots"))

    def write_plots(self, folder) -> list:
        """``FOLDER/probe_map_3d.png`` (Fig. 3a) and ``FOLDER/probe_map_2d.png`` (Fig. 3b)
        (``--plots DIR``); returns their paths."""
        from pathlib import Path

        from .plots import plot_probe_map_2d, plot_probe_map_3d

        return [plot_probe_map_3d(self.calibration, Path(folder) / "probe_map_3d.png"),
                plot_probe_map_2d(self.calibration, Path(folder) / "probe_map_2d.png")]


def command_form(data=None, plan=None, out=None) -> None:
    """Refuse, one line, a ``volerr probe-cal`` that is neither a calibration (``data`` read,
    the map written to ``out``) nor a plan (written to ``plan``), or both."""
    if plan:
        require(data is None, "give either DATA.csv (calibrate) or --plan (write a plan)")
    else:
        require(data, "name the probing data DATA.csv (or use --plan to write a plan)")
        require(out, "--out MAP.csv is required")


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
    require(ball_radius is None or (math.isfinite(ball_radius) and ball_radius > 0),
            f"--ball-radius must be a positive length in mm, got {ball_radius}")
    require(degree is None or 0 <= degree <= 20,
            f"--degree must be between 0 and 20, got {degree}")
    cal = probe.calibrate_data(probe.read_sphere_csv(data), sphere_radius, tilt_deg=tilt_deg,
                               roll_deg=roll_deg, degree=degree, outlier_k=outlier_k,
                               exclude_outliers=exclude_outliers, ball_radius=ball_radius)
    return ProbeCal(cal.summary(), cal, exclude_outliers)


@dataclass(repr=False)
class ProbePlan(ResultMixin):
    """Result of :func:`probe_plan`: ``plan`` the nominal probing directions (probe frame,
    deg), ``points`` the nominal stylus-ball centres, machine frame, (n, 3) mm."""

    plan: object
    points: object

    def data(self) -> dict:
        """``{"n_points", "phi_deg", "theta_deg", "points_mm"}``."""
        return {"n_points": len(self.plan), "phi_deg": self.plan.phi_deg,
                "theta_deg": self.plan.theta_deg, "points_mm": self.points}

    def summary(self) -> str:
        """What ``volerr probe-cal --plan`` prints (without the file it writes)."""
        return f"plan: {len(self.plan)} points"

    def csv_text(self) -> str:
        """The plan as ``x,y,z,phi_deg,theta_deg`` (``--plan PLAN.csv``)."""
        from .plans import plan_csv_text

        return plan_csv_text(self.plan, self.points)

    def write_csv(self, path, inputs=()):
        """Write :meth:`csv_text`; returns its path."""
        from ..fileio import write_text

        return write_text(path, self.csv_text(), inputs=list(inputs))


def probe_plan(sphere_radius: float, ball_radius: float, *, center=(0.0, 0.0, 0.0),
               tilt_deg: float = 0.0, roll_deg: float = 0.0, step_deg: float = 18.0,
               circles: int = 5, phis=None, per_circle: int | None = None,
               pole: bool = True) -> ProbePlan:
    """A probing plan on a master sphere (``volerr probe-cal --plan``): nominal ball centres.

    Parameters
    ----------
    sphere_radius, ball_radius : float
        Master-sphere radius and nominal stylus-ball radius, mm (both > 0).
    center : (3,) mm
        Sphere centre, machine frame.
    tilt_deg, roll_deg : float
        Orientation of the probe frame (deg).
    step_deg, circles : float, int
        Pahk's plan: latitude and azimuth step (deg) and the number of latitude circles.
    phis, per_circle : list of float (or ``"30,60,90"``), int, optional
        A custom plan instead: circle latitudes phi (deg) and points per circle (both).
    pole : bool
        Include the pole point.

    Returns
    -------
    ProbePlan
        ``csv_text()`` is the plan file ``x,y,z,phi_deg,theta_deg`` (mm, deg).
    """
    from ..units import parse_number
    from . import plans as pp

    require(ball_radius is not None and ball_radius > 0,
            "--plan needs --ball-radius (stylus-ball radius, mm, > 0)")
    require(sphere_radius > 0, "--sphere-radius must be > 0 mm")
    if phis or per_circle:
        require(phis and per_circle, "a custom plan needs both --phis and --per-circle")
        if isinstance(phis, str):
            phis = [parse_number(v, what="--phis") for v in phis.split(",") if v.strip()]
        plan = pp.circles_plan(phis, per_circle, pole)
    else:
        plan = pp.pahk_plan(step_deg, circles, pole)
    return ProbePlan(plan, pp.nominal_points(plan, list(center), sphere_radius, ball_radius,
                                             tilt_deg, roll_deg))
