"""Plots of identified error motions (thesis Fig. 4.x style): value vs position with
+-2 sigma bars (Type A over rounds, else the propagated uncertainty), every round as faint
markers, the fitted error function when given; rotary axes also as polar plots."""

from __future__ import annotations

import numpy as np

from ..plotstyle import figure, label, save, styled
from ..units import UM_PER_MM, URAD_PER_RAD

SCALE = (UM_PER_MM,) * 3 + (URAD_PER_RAD,) * 3


def _sigma(result):
    """(standard deviation of ONE round, label of the +-2 sigma bars): the scatter over the
    rounds (Type A, the table's ``_s``), else the propagated tracker uncertainty."""
    if result.std is not None:
        return result.std, "\u00b1 2 s (s of one round)"
    return result.u_tracker, "\u00b1 2 u (propagated, k = 2)"


@styled
def plot_identification(result, path, fits: dict | None = None) -> None:
    """Write a PNG of :func:`identification_figure` (the six error motions of ``result``)."""
    save(identification_figure(result, fits), path)


@styled
def identification_figure(result, fits: dict | None = None):
    """The six error motions of ``result`` (:class:`volerr.identify.solve.Identification`,
    um and urad against the axis position): a matplotlib figure; ``fits``: name -> callable
    of position (mm or rad), optional.  Bars: +-2 s, s the standard deviation of one round
    (the scatter the table's ``_s`` holds)."""
    rotary = result.kind == "rotary"
    sig, sig_label = _sigma(result)
    unit_pos = "deg" if rotary else "mm"
    nrows = 4 if rotary else 3
    fig, grid = figure(nrows, 2, height=2.6 * nrows)
    for ax in grid[3:].ravel() if rotary else ():
        ax.remove()
    x = result.positions
    for j, name in enumerate(result.names):
        col, row = (0, j) if j < 3 else (1, j - 3)
        ax = grid[row, col]
        for r in result.rounds:
            order = np.argsort(r.positions)
            ax.plot(r.positions[order], r.values[order, j] * SCALE[j], ".", color="0.7", ms=3)
        ax.errorbar(x, result.values[:, j] * SCALE[j], yerr=2 * sig[:, j] * SCALE[j],
                    fmt="o", ms=4, color="C0", ecolor="k", capsize=3,
                    label=f"mean, bars {sig_label}")
        if fits and name in fits:
            q = np.linspace(x[0], x[-1], 400)
            ax.plot(q, np.asarray(fits[name](q)) * SCALE[j], "-", color="C3", lw=1,
                    label="fitted function")
        ax.axhline(0, color="0.5", lw=0.5)
        ax.set_xlabel(label(result.axis, unit_pos))
        ax.set_ylabel(label(name, "um" if j < 3 else "urad"))
        if j == 0:
            ax.legend(loc="best")
    if rotary:
        th = np.radians(x)
        for k, (lo, hi, unit) in enumerate(((0, 3, "µm"), (3, 6, "µrad"))):
            ax = fig.add_subplot(nrows, 2, 7 + k, projection="polar")
            vals = result.values[:, lo:hi] * np.array(SCALE[lo:hi])
            span = float(np.max(np.abs(vals))) or 1.0
            base = 2.0 * span
            for i in range(3):
                ax.plot(th, base + vals[:, i], "-o", ms=3, label=result.names[lo + i])
            ax.plot(np.linspace(0, 2 * np.pi, 200), np.full(200, base), color="0.6", lw=0.5)
            ax.set_rmin(0)
            ax.set_rmax(base + 1.2 * span)
            ax.set_yticklabels([])
            ax.set_title(f"polar, {unit}: radius = {base:.3g} + value (grey circle = 0)")
            ax.legend(loc="lower right", bbox_to_anchor=(1.3, -0.1))
    fig.suptitle(f"Error motions of axis {result.axis} ({len(result.rounds)} round(s), "
                 f"{result.method}, {len(result.rounds[0].labels)} points)")
    return fig
