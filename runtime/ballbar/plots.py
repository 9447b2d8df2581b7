"""The ballbar polar plot (ISO 230-4 style): the radial deviation of each trace about its
least-squares circle (centring removed, as G is evaluated), magnified, counter-clockwise and
clockwise overlaid, with G and H in the legend; a rotary sweep (ISO 10791-6) is drawn as its
reading against the swept axis' angle (its first harmonic is the axis' location error: not
removed).  Angles as in :mod:`volerr.ballbar.iso230_4`."""

from __future__ import annotations

import numpy as np


def polar_plot(traces: list, results: list, path, title: str = "") -> None:
    """Write the polar plot of ``traces`` (their ISO 230-4 ``results``) to ``path`` (PNG).
    The scale ring is the nominal circle; radial deviations are drawn at a magnification
    (um per ring division) chosen from the largest deviation."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .iso230_4 import least_squares_circle

    def about_lsc(t):
        if t.plane.endswith("sweep"):       # ISO 10791-6: the reading itself against the angle
            return t.theta, 1e3 * t.dr
        r = t.radius_mm + t.dr
        x, y = r * np.cos(t.theta), r * np.sin(t.theta)
        a, b, rho = least_squares_circle(x, y)
        return np.arctan2(y - b, x - a), 1e3 * (np.hypot(x - a, y - b) - rho)

    dev = [about_lsc(t) for t in traces]
    planes = list(dict.fromkeys(t.plane for t in traces))
    fig, axes = plt.subplots(1, len(planes), subplot_kw={"projection": "polar"},
                             figsize=(4.4 * len(planes), 5.6), squeeze=False)
    span = max(max(np.max(np.abs(d)) for _, d in dev), 0.5)
    div = float(10 ** np.ceil(np.log10(span / 4)))           # um per division
    if span / div < 2:
        div /= 2
    for ax, plane in zip(axes[0], planes):
        ring = 4 * div
        th = np.linspace(0, 2 * np.pi, 361)
        ax.plot(th, np.full_like(th, ring), color="0.6", lw=0.8, label="least-squares circle")
        for t, r, (phi, d) in zip(traces, results, dev):
            if t.plane != plane:
                continue
            order = np.argsort(np.mod(phi, 2 * np.pi))
            theta = np.mod(phi[order], 2 * np.pi)
            rad = ring + d[order]
            theta, rad = np.append(theta, theta[0]), np.append(rad, rad[0])
            ccw = t.direction > 0
            label = (f"{'CCW' if ccw else 'CW'} {t.placement}: G = {r['G_um']:.2f} µm"
                     + (f", H = {r['H_um']:.2f} µm" if "H_um" in r and ccw else ""))
            ax.plot(theta, rad, lw=1.2, color="C0" if ccw else "C3", label=label)
        ax.set_ylim(0, ring + 4 * div)
        ax.set_yticks([ring - 2 * div, ring, ring + 2 * div])
        ax.set_yticklabels([f"{-2 * div:g}", "0", f"+{2 * div:g} µm"], fontsize=9)
        ax.set_xticks(np.deg2rad([0, 90, 180, 270]))
        if plane.endswith("sweep"):
            ax.set_xticklabels([f"{plane[0]} = {v}°" for v in (0, 90, 180, 270)])
        else:
            a, b = plane[0], plane[1]
            ax.set_xticklabels([f"+{a}", f"+{b}", f"-{a}", f"-{b}"])
        radius = next(t.radius_mm for t in traces if t.plane == plane)
        what = plane if plane.endswith("sweep") else f"{plane} plane"
        ax.set_title(f"{what}, radius {radius:g} mm\n{div:g} µm / division", fontsize=10)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), fontsize=9, frameon=False)
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout(rect=(0, 0.02, 1, 0.97))
    fig.savefig(path, dpi=110)
    plt.close(fig)
