"""Text reports of an identification: the residual CSV and the lines ``volerr identify``
prints (summary on stdout, outlier warnings on stderr).  Residuals in um."""

from __future__ import annotations

from ..units import UM_PER_MM


def residual_csv(result) -> str:
    """Per-position, per-point residuals of every round (um) with the outlier flag.

    Parameters
    ----------
    result : Identification
        The result of :func:`volerr.identify.identify`; ``residuals`` of each round have shape
        (n_positions, n_points, 3), mm.

    Returns
    -------
    str
        CSV ``round,point,position,rx_um,ry_um,rz_um,norm_um,outlier``.
    """
    flagged = {(o[0], o[1], o[2]) for o in result.outliers()}
    lines = ["round,point,position,rx_um,ry_um,rz_um,norm_um,outlier"]
    for r in result.rounds:
        for k, pos in enumerate(r.positions):
            for i, lab in enumerate(r.labels):
                v = r.residuals[k, i] * UM_PER_MM
                n = float((v ** 2).sum()) ** 0.5
                flag = int((r.name, float(pos), lab) in flagged)
                lines.append(f"{r.name},{lab},{pos:.10g},{v[0]:.6g},{v[1]:.6g},{v[2]:.6g},"
                             f"{n:.6g},{flag}")
    return "\n".join(lines) + "\n"


def summary_lines(axis: str, summary: dict, out) -> list[str]:
    """The lines printed after an identification of ``axis`` written to ``out``.

    ``summary`` is :meth:`Identification.report` (with an optional ``"fit"`` list of
    :meth:`volerr.tables.errorfit.ErrorFit.report` dicts)."""
    s = summary
    lines = [f"{axis}: {s['n_positions']} positions x {len(s['points'])} points x "
             f"{s['n_rounds']} round(s), method {s['method']}, condition {s['condition']:.3g}, "
             f"residual RMS {s['residual_rms_um']:.3g} um -> {out}"]
    if "closed_form" in s:
        cf = s["closed_form"]
        d = list(cf["vs_lsq_max"].values())
        g = [v for v in cf["noise_gain_vs_lsq"].values() if v is not None and v == v]
        roles = "; ".join(f"P={r['P']} Q={r['Q']} K={r['K']}" for r in cf["roles"])
        lines.append(f"closed form (Zhang & Hu selection {cf['selection']}, {roles}): equals "
                     f"least squares on consistent data to {cf['consistency_max']:.1g}; on these "
                     f"data it differs by up to {max(d[:3]):.3g} um / {max(d[3:]):.3g} urad"
                     + (f", noise gain {min(g):.2g}-{max(g):.2g} x least squares" if g else ""))
    for f in s.get("fit", []):
        deg = f" degree {f['degree']}" if f["degree"] is not None else ""
        loo = f", leave-one-out {f['loo_rms']:.3g}" if f["loo_rms"] is not None else ""
        lines.append(f"fit {f['name']}: {f['method']}{deg}, residual RMS "
                     f"{f['rms_residual']:.3g} max {f['max_residual']:.3g}{loo} {f['unit']}")
    return lines


def outlier_warnings(summary: dict) -> list[str]:
    """One warning line per flagged point (round, position, point, residual in um)."""
    return [f"warning: round {o['round']} position {o['position']:g} point {o['point']}: "
            f"residual {o['residual_um']:.3g} um = {o['ratio']:.1f} x noise"
            for o in summary["outliers"]]
