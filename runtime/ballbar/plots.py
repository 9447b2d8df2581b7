"""The ballbar polar plot (ISO 230-4 style): the radial deviation of each trace about its
least-squares circle (centring removed, as G is evaluated), magnified, counter-clockwise and
clockwise overlaid, with G and H in the legend; a rotary sweep (ISO 10791-6) is drawn as its
reading against the swept axis' angle (its first harmonic is the axis' location error: not
removed).  Angles as in :mod:`volerr.ballbar.iso230_4`.  The figure style is volerr's
(:mod:`volerr.plotstyle`)."""

from __future__ import annotations

import numpy as np

from ..plotstyle import PAGE_WIDTH_IN, figure, png, save, styled


def _deviation(t):
    """(angle rad, deviation um) drawn for one trace."""
    from .iso230_4 import least_squares_circle

    if t.plane.endswith("sweep"):       # ISO 10791-6: the reading itself against the angle
        return t.theta, 1e3 * t.dr
    r = t.radius_mm + t.dr
    x, y = r * np.cos(t.theta), r * np.sin(t.theta)
    a, b, rho = least_squares_circle(x, y)
    return np.arctan2(y - b, x - a), 1e3 * (np.hypot(x - a, y - b) - rho)


@styled
def polar_figure(traces: list, results: list):
    """The figure: one polar panel per plane (or sweep), the scale ring at the least-squares
    circle, radial deviations magnified (um per ring division chosen from the largest)."""
    dev = [_deviation(t) for t in traces]
    planes = list(dict.fromkeys(t.plane for t in traces))
    fig, axes = figure(1, len(planes), width=min(PAGE_WIDTH_IN, 3.6 * len(planes) + 0.4),
                       height=5.2, subplot_kw={"projection": "polar"}, squeeze=False)
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
            text = (f"{'CCW' if ccw else 'CW'} {t.placement}: G {r['G_um']:.2f} µm"
                    + (f", H {r['H_um']:.2f} µm" if "H_um" in r and ccw else ""))
            ax.plot(theta, rad, lw=1.2, color="C0" if ccw else "C3", label=text)
        ax.set_ylim(0, ring + 4 * div)
        ax.set_yticks([ring - 2 * div, ring, ring + 2 * div])
        ax.set_yticklabels([f"{-2 * div:g}", "0", f"+{2 * div:g} µm"])
        ax.set_xticks(np.deg2rad([0, 90, 180, 270]))
        if plane.endswith("sweep"):
            ax.set_xticklabels([f"{plane[0]} {v}°" for v in (0, 90, 180, 270)])
        else:
            a, b = plane[0], plane[1]
            ax.set_xticklabels([f"+{a}", f"+{b}", f"-{a}", f"-{b}"])
        radius = next(t.radius_mm for t in traces if t.plane == plane)
        what = plane if plane.endswith("sweep") else f"{plane} plane"
        ax.set_title(f"{what}, radius {radius:g} mm\n{div:g} µm / division")
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), frameon=False)
    return fig


def polar_plot(traces: list, results: list, path, inputs=()) -> None:
    """Write the polar plot of ``traces`` (their ISO 230-4 ``results``) to ``path`` (PNG)."""
    save(polar_figure(traces, results), path, inputs)


def polar_png(traces: list, results: list) -> bytes:
    """The polar plot as PNG bytes (embedded in the report page)."""
    return png(polar_figure(traces, results))
