"""Plots of a probe calibration: the 3-D lobing map (Pahk Fig. 3a) and the 2-D (phi, theta)
map (Fig. 3b).  Errors in µm; directions in the probe frame (x', y', z').  Style:
volerr.plotstyle."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotstyle import PAGE_WIDTH_IN, label, pyplot, save, styled
from ..units import UM_PER_MM
from .calibration import unit_vectors


def _grid(cal, n_phi: int = 61, n_theta: int = 121):
    lo, hi = cal.map.phi_range_deg
    phi = np.linspace(lo, hi, n_phi)
    theta = np.linspace(0.0, 360.0, n_theta)
    pp, tt = np.meshgrid(phi, theta, indexing="ij")
    val = cal.map.with_outside("extrapolate").at(pp, tt) * UM_PER_MM
    return pp, tt, np.ma.masked_where(~cal.map.covered(pp, tt), val)


def _norm(values):
    from matplotlib.colors import TwoSlopeNorm

    lim = max(float(np.nanmax(np.abs(values))), 1e-6)
    return TwoSlopeNorm(vcenter=0.0, vmin=-lim, vmax=lim)


def _save(fig, path) -> Path:
    save(fig, path)
    return Path(path)


def _figure(size):
    return pyplot().figure(figsize=size, layout="constrained")


@styled
def plot_probe_map_3d(cal, path, gain: float | None = None) -> Path:
    """Fig. 3a alone: see :func:`draw_3d`."""
    fig = _figure((8, 7))
    draw_3d(fig, fig.add_subplot(projection="3d"), cal, gain)
    return _save(fig, path)


@styled
def plot_probe_map_2d(cal, path) -> Path:
    """Fig. 3b alone: see :func:`draw_2d`."""
    fig = _figure((PAGE_WIDTH_IN, 5.0))
    draw_2d(fig, fig.add_subplot(), cal)
    return _save(fig, path)


@styled
def plot_probe_calibration(cal, path) -> Path:
    """Both maps in one PNG: 3-D lobing map (top) and the (theta, phi) map (below)."""
    fig = _figure((PAGE_WIDTH_IN, 12.0))
    sub = fig.subfigures(2, 1, height_ratios=(1.25, 1))
    draw_3d(sub[0], sub[0].add_subplot(projection="3d"), cal)
    draw_2d(sub[1], sub[1].add_subplot(), cal)
    return _save(fig, path)


def draw_3d(fig, ax, cal, gain: float | None = None) -> None:
    """Fig. 3a: the probed part of a unit sphere deformed radially by the smooth map
    (1 + gain * Probe), coloured in um, with the measured Probe at each point as a radial
    stem from the reference sphere."""
    import matplotlib.pyplot as plt

    pp, tt, masked = _grid(cal, 37, 73)
    val = masked.filled(0.0)          # uncalibrated directions: reference sphere, grey
    pts_um = cal.probe * UM_PER_MM
    vmax = max(float(np.max(np.abs(val))), float(np.max(np.abs(pts_um))), 1e-6)
    gain = gain if gain is not None else 0.2 / vmax
    r = 1.0 + gain * val
    x, y, z = np.moveaxis(unit_vectors(pp, tt) * np.asarray(r)[..., None], -1, 0)
    norm = _norm(np.concatenate([val.ravel(), pts_um]))
    cmap = plt.get_cmap("RdBu_r")
    colors = cmap(norm(val))
    colors[np.ma.getmaskarray(masked)] = (0.85, 0.85, 0.85, 0.4)
    ax.plot_surface(x, y, z, facecolors=colors, rstride=1, cstride=1,
                    linewidth=0.2, edgecolor=(0, 0, 0, 0.15), antialiased=True, shade=False)
    u = unit_vectors(cal.phi_deg, cal.theta_deg)
    tip = u * (1.0 + gain * pts_um)[:, None]
    for a, b in zip(u, tip):
        ax.plot(*zip(a, b), color="k", linewidth=0.8)
    ax.scatter(*tip.T, c=pts_um, cmap=cmap, norm=norm, s=14, edgecolors="k", linewidths=0.4,
               depthshade=False)
    if cal.outlier.any():
        ax.scatter(*tip[cal.outlier].T, marker="x", color="k", s=60, label="flagged outlier")
        fig.legend(loc="lower left")  # outside the axes: covers no point
    sm = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=ax, shrink=0.6, pad=0.12,
                 label=label("probe error Probe(phi, theta)", "um"))
    ax.set_xlabel("x' (unit direction)")
    ax.set_ylabel("y' (unit direction)")
    ax.set_zlabel("z' (probe axis)")
    ax.set_box_aspect((1, 1, 0.6 if cal.map.phi_range_deg[1] <= 95 else 1))
    stats = cal.stats_um()
    ax.set_title(f"Probe error map (3-D): R_eff {cal.r_eff:.4f} mm, max {stats['max']:.1f} / "
                 f"min {stats['min']:.1f} / rms {stats['rms']:.1f} \u00b5m\n"
                 f"sphere deformed radially by the map (1 \u00b5m = {gain:.3f} of the "
                 f"radius); stems: measured")
    ax.view_init(elev=28, azim=-60)


def draw_2d(fig, ax, cal) -> None:
    """Fig. 3b: the smooth map on the (theta, phi) grid with contours, the measured Probe at
    each point as coloured markers (flagged outliers crossed)."""
    pp, tt, val = _grid(cal)
    pts_um = cal.probe * UM_PER_MM
    norm = _norm(np.concatenate([val.compressed(), pts_um]))
    holes = bool(np.ma.getmaskarray(val).any())
    mesh = ax.pcolormesh(tt, pp, val, cmap="RdBu_r", norm=norm,
                         shading="nearest" if holes else "gouraud")
    cs = ax.contour(tt, pp, val, levels=11, colors="k", linewidths=0.5)
    ax.clabel(cs, fmt="%.1f", fontsize=9)
    ax.scatter(cal.theta_deg, cal.phi_deg, c=pts_um, cmap="RdBu_r", norm=norm, s=28,
               edgecolors="k", linewidths=0.5, label="measured Probe (eq. 13)")
    if cal.outlier.any():
        ax.scatter(cal.theta_deg[cal.outlier], cal.phi_deg[cal.outlier], marker="x",
                   color="k", s=80, label="flagged outlier")
    fig.colorbar(mesh, ax=ax, label=label("probe error", "um"))
    ax.set_xlim(0, 360)
    ax.grid(False)
    ax.set_xticks(np.arange(0, 361, 45))
    lo, hi = cal.map.phi_range_deg
    ax.set_ylim(hi + 2, lo - 2)
    ax.set_xlabel(label("theta (azimuth in the probe frame)", "deg"))
    ax.set_ylabel(label("phi (from the probe axis)", "deg"))
    stats = cal.stats_um()
    ax.set_title(f"Probe error map on (theta, phi): tilt A {cal.map.tilt_deg:g} deg, roll B "
                 f"{cal.map.roll_deg:g} deg\nspherical harmonics of degree {cal.map.degree}; "
                 f"max {stats['max']:.1f} / min {stats['min']:.1f} / rms {stats['rms']:.1f} "
                 f"\u00b5m")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=3)
