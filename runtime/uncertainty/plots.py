"""Plots of a Monte Carlo result: histogram with the coverage interval, and convergence of the
estimate and the standard uncertainty with the number of samples (matplotlib, Agg)."""

from __future__ import annotations

import numpy as np

from ..plotstyle import figure, label, png, styled
from ..units import UM_PER_MM, num


#: histogram figure: height, inches (the width is the page width)
HIST_HEIGHT_IN = 4.6


@styled
def histogram_figure(values, names, summary: dict, title: str):
    """The histogram figure (matplotlib Figure, Agg): one panel per quantity, the samples as
    deviations from the estimate in µm (x label in one unit), the estimate in mm in the panel
    title, the probabilistically symmetric 95 % interval (red) and +-U (blue, k = 2)."""
    k = len(names)
    ncols = min(k, 3)
    nrows = -(-k // ncols)
    fig, axes = figure(nrows, ncols, height=HIST_HEIGHT_IN * (0.75 if nrows > 1 else 1) * nrows,
                       squeeze=False)
    flat = axes.ravel()
    for ax in flat[k:]:
        ax.remove()
    for ax, j, name in zip(flat, range(k), names):
        s = summary[name]
        est = s["estimate_mm"]
        d = (values[:, j] - est) * UM_PER_MM
        ax.hist(d, bins=60, color="0.65", density=True)
        lo, hi = s["coverage_interval_mm"]
        for i, x in enumerate(((lo - est) * UM_PER_MM, (hi - est) * UM_PER_MM)):
            ax.axvline(x, color="tab:red", lw=1.5,
                       label="95 % coverage interval" if i == 0 else None)
        U = s["expanded_uncertainty_um"]
        for i, x in enumerate((-U, U)):
            ax.axvline(x, color="tab:blue", lw=1.5, ls="--",
                       label="estimate \u00b1 U (k = 2)" if i == 0 else None)
        ax.set_xlabel(label("deviation from the estimate", "um"))
        nominal = (f", nominal {s['nominal_mm']:.6f} mm" if "nominal_mm" in s else "")
        bias = (f"bias {num(s['bias_um'], '+.3g')} \u00b5m, " if "bias_um" in s else "")
        ax.set_title(f"{name}: estimate {est:.6f} mm{nominal}\n"
                     f"{bias}u = {s['standard_uncertainty_um']:.3g} \u00b5m, U = {U:.3g} \u00b5m "
                     f"(k = 2)")
    for row in axes:
        row[0].set_ylabel(label("probability density", "1/\u00b5m"))
    fig.legend(*flat[0].get_legend_handles_labels(), loc="outside lower center", ncol=2,
               frameon=False)
    fig.suptitle(title)
    return fig


def histogram_png(values, names, summary: dict, title: str) -> bytes:
    """PNG bytes of :func:`histogram_figure` (the page width, 1000 px)."""
    return png(histogram_figure(values, names, summary, title))


@styled
def convergence_png(values, names, title: str) -> bytes:
    """Running mean (µm about the final one) and running standard uncertainty (µm)."""
    n = values.shape[0]
    idx = np.unique(np.geomspace(10, n, 200).astype(int))
    fig, (a1, a2) = figure(1, 2, height=3.6)
    for j, name in enumerate(names):
        v = values[:, j]
        c1 = np.cumsum(v - v.mean())
        c2 = np.cumsum((v - v.mean()) ** 2)
        mean = c1[idx - 1] / idx
        var = (c2[idx - 1] - idx * mean ** 2) / (idx - 1)
        a1.plot(idx, mean * 1e3, label=name)
        a2.plot(idx, np.sqrt(np.clip(var, 0, None)) * UM_PER_MM, label=name)
    for a, lab in ((a1, label("running mean \u2212 final mean", "um")),
                   (a2, label("running u", "um"))):
        a.set_xscale("log")
        a.set_xlabel("samples")
        a.set_ylabel(lab)
    a2.legend()
    fig.suptitle(title)
    return png(fig)
