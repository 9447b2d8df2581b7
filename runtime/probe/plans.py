"""Probing plans on a master sphere and simulated probing (Pahk sec. 3.2).

A plan is a list of nominal probing directions in the probe frame, ``(phi_deg, theta_deg)``
(phi from the probe axis, theta azimuth; the direction is the outward normal at the contact,
see :mod:`volerr.probe.calibration`).  Pahk's plan: the pole plus 5 latitude circles phi = 18, 36, 54, 72,
90 deg of 20 points each at theta = 0, 18, ..., 342 deg: 101 points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..units import MM_PER_UM
from ..errors import require
from .calibration import directions_of


@dataclass
class Plan:
    """Nominal probing directions, probe frame, deg (arrays of equal length)."""

    phi_deg: np.ndarray
    theta_deg: np.ndarray

    def __len__(self) -> int:
        return len(self.phi_deg)

    def directions(self, tilt_deg: float = 0.0, roll_deg: float = 0.0) -> np.ndarray:
        """Machine-frame unit directions, shape (n, 3)."""
        return directions_of(self.phi_deg, self.theta_deg, tilt_deg, roll_deg)


def circles_plan(phis_deg, n_per_circle: int, pole: bool = True,
                 theta0_deg: float = 0.0, stagger_deg: float = 0.0) -> Plan:
    """Latitude circles: ``n_per_circle`` equally spaced azimuths on each phi of ``phis_deg``
    (each circle turned by ``stagger_deg`` more than the previous one), plus the pole."""
    phis = [float(p) for p in phis_deg]
    require(n_per_circle >= 1, "points per circle must be >= 1")
    require(all(0 < p <= 180 for p in phis), "circle latitudes phi must lie in (0, 180] deg")
    phi, theta = ([0.0], [0.0]) if pole else ([], [])
    for k, p in enumerate(phis):
        for j in range(n_per_circle):
            phi.append(p)
            theta.append((theta0_deg + k * stagger_deg + 360.0 * j / n_per_circle) % 360.0)
    require(phi, "empty plan")
    return Plan(np.asarray(phi), np.asarray(theta))


def pahk_plan(step_deg: float = 18.0, n_circles: int = 5, pole: bool = True) -> Plan:
    """Pahk's plan: the pole and ``n_circles`` circles at phi = step, 2 step, ... with
    azimuth step ``step_deg`` (defaults: 5 x 20 + 1 = 101 points, 18 deg steps)."""
    require(step_deg > 0 and 360.0 / step_deg == round(360.0 / step_deg),
            f"the azimuth step must divide 360 deg, got {step_deg}")
    require(n_circles >= 1 and n_circles * step_deg <= 180.0,
            "circles must stay within phi <= 180 deg")
    return circles_plan([step_deg * (k + 1) for k in range(n_circles)],
                        int(round(360.0 / step_deg)), pole)


def nominal_points(plan: Plan, center, sphere_radius: float, ball_radius: float,
                   tilt_deg: float = 0.0, roll_deg: float = 0.0) -> np.ndarray:
    """Nominal stylus-ball centres of a plan, machine frame, shape (n, 3), mm."""
    c = np.asarray(center, dtype=float)
    return c + (sphere_radius + ball_radius) * plan.directions(tilt_deg, roll_deg)


def pahk_like_pretravel(phi, theta, scale: float = 1.0, mean_um: float = 18.0,
                        orientation_deg: float = 20.0) -> np.ndarray:
    """Pretravel (mm) of a kinematic (three-lobe) trigger probe at probe-frame angles (rad):
    three lobes sideways growing as sin^3(phi), a six-fold harmonic sharpening them, and a
    stiffer stylus axis (more pretravel along it than sideways).  ``scale`` multiplies the
    variation.  With a 1.006 mm ball on Pahk's 25.006 mm sphere and plan the calibration gives
    figures close to Pahk's (R_eff 0.997 mm, Probe about +6.8 / -9.2 um, RMS 3.8 um)."""
    s = np.sin(phi)
    t = theta - math.radians(orientation_deg)
    var = 7.9 * s ** 3 * np.cos(3 * t) - 2.15 * s ** 6 * np.cos(6 * t) - 8.2 * s ** 2
    return (mean_um + scale * var) * MM_PER_UM


def simulate_probing(plan: Plan, center, sphere_radius: float, ball_radius: float,
                     pretravel=pahk_like_pretravel, noise_mm: float = 0.0,
                     tilt_deg: float = 0.0, roll_deg: float = 0.0, rng=None) -> np.ndarray:
    """Recorded ball centres (n, 3) mm of a trigger probe on a perfect master sphere: the
    machine moves on ``pretravel(phi, theta)`` (mm, probe-frame angles in rad) after the
    contact, so the recorded centre lies that much nearer the sphere centre; plus isotropic
    Gaussian noise of ``noise_mm`` per axis."""
    rng = np.random.default_rng(rng)
    u = plan.directions(tilt_deg, roll_deg)
    pt = np.broadcast_to(pretravel(np.radians(plan.phi_deg), np.radians(plan.theta_deg)),
                         (len(plan),))
    r = sphere_radius + ball_radius - pt
    pts = np.asarray(center, dtype=float) + r[:, None] * u
    return pts + noise_mm * rng.standard_normal(pts.shape)


def plan_csv_text(plan: Plan, points: np.ndarray) -> str:
    """A plan as the sphere CSV (``x,y,z,phi_deg,theta_deg``), nominal ball centres in mm."""
    lines = ["x,y,z,phi_deg,theta_deg"]
    for (x, y, z), p, t in zip(points, plan.phi_deg, plan.theta_deg):
        lines.append(f"{x:.6f},{y:.6f},{z:.6f},{p:.6f},{t:.6f}")
    return "\n".join(lines) + "\n"


def simulate_demo_sphere(path, seed: int = 1995, center=(250.0, 180.0, -120.0),
                         noise_mm: float = 0.3e-3) -> dict:
    """Write a simulated Pahk-like master-sphere run (``x,y,z`` ball centres, mm) to ``path``:
    25.006 mm sphere, 1.006 mm ball, vertical probe, Pahk's 101-point plan, the
    :func:`pahk_like_pretravel` kinematic probe and ``noise_mm`` Gaussian noise per axis.
    Returns ``{"path", "sphere_radius_mm", "ball_radius_mm", "center_mm", "n_points"}``."""
    from ..fileio import write_text

    plan = pahk_plan()
    pts = simulate_probing(plan, center, 25.006, 1.006, noise_mm=noise_mm, rng=seed)
    lines = ["x,y,z"] + [f"{x:.6f},{y:.6f},{z:.6f}" for x, y, z in pts]
    out = write_text(path, "\n".join(lines) + "\n")
    return {"path": str(out), "sphere_radius_mm": 25.006, "ball_radius_mm": 1.006,
            "center_mm": [float(v) for v in center], "n_points": len(plan)}
