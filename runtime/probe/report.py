"""The text report of a probe calibration: the lines ``volerr probe-cal`` prints (lengths in
mm, probe errors and uncertainties in um)."""

from __future__ import annotations


def summary_lines(cal, excluded: bool) -> list[str]:
    """Points, centre, R_eff with their standard uncertainties, probe-error statistics, map
    degree and outliers of ``cal`` (:class:`volerr.probe.ProbeCalibration`); ``excluded`` says
    whether the flagged points were left out of the fit (``--exclude-outliers``)."""
    summary = cal.summary()
    e = summary["probe_error_um"]
    c = summary["center_mm"]
    u = summary["uncertainty"]
    n_out = len(summary["outliers"]["index"])
    return [
        f"{cal.n_points} points, sphere radius {cal.sphere_radius:.4f} mm, "
        f"directions from {cal.direction_source}",
        f"centre {c[0]:.4f} {c[1]:.4f} {c[2]:.4f} mm, R_eff {cal.r_eff:.4f} mm "
        f"(u, k = 1: centre {max(u['u_center_um']):.2f} um, R_eff {u['u_r_eff_um']:.2f} um; "
        f"noise {u['noise_um']:.2f} um)",
        f"probe error max {e['max']:.1f} um, min {e['min']:.1f} um, rms {e['rms']:.1f} um; "
        f"map degree {cal.map.degree}, residual rms {summary['map']['residual_rms_um']:.2f} um;"
        f" {n_out} outlier{'s' if n_out != 1 else ''} flagged"
        + (" and excluded" if excluded and n_out else "")
        + (" (kept in the fit: --exclude-outliers refits without them)"
           if n_out and not excluded else ""),
    ]
