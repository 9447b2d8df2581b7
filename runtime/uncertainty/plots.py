"""Plots of a Monte Carlo result: histogram with the coverage interval, and convergence of the
estimate and the standard uncertainty with the number of samples (matplotlib, Agg)."""

from __future__ import annotations

import io

import numpy as np

from ..units import UM_PER_MM


def _fig_bytes(fig, tight: bool = True, dpi: int = 100) -> bytes:
    import matplotlib.pyplot as plt
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight" if tight else None)
    plt.close(fig)
    return buf.getvalue()


#: histogram figure: inches per panel (width), height, dots per inch -> >= 1200 px wide
HIST_PANEL_IN, HIST_HEIGHT_IN, HIST_DPI = 5.0, 4.6, 120
HIST_MIN_WIDTH_IN = 10.0


def histogram_figure(values, names, summary: dict, title: str):
    """The histogram figure (matplotlib Figure, Agg): one panel per quantity, the samples as
    deviations from the estimate in um (x label in one unit), the estimate in mm in the panel
    title, the probabilistically symmetric 95 % interval (red) and +-U (blue, k = 2)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    k = len(names)
    width = max(HIST_MIN_WIDTH_IN, HIST_PANEL_IN * k)
    fig, axes = plt.subplots(1, k, figsize=(width, HIST_HEIGHT_IN), squeeze=False,
                             layout="constrained")
    for ax, j, name in zip(axes[0], range(k), names):
        s = summary[name]
        est = s["estimate_mm"]
        d = (values[:, j] - est) * UM_PER_MM
        ax.hist(d, bins=60, color="0.65", density=True)
        lo, hi = s["coverage_interval_mm"]
        for i, x in enumerate(((lo - est) * UM_PER_MM, (hi - est) * UM_PER_MM)):
            ax.axvline(x, color="tab:red", lw=1.5, label="95 % interval" if i == 0 else None)
        U = s["expanded_uncertainty_um"]
        for i, x in enumerate((-U, U)):
            ax.axvline(x, color="tab:blue", lw=1.5, ls="--",
                       label="estimate \u00b1 U (k = 2)" if i == 0 else None)
        ax.set_xlabel("deviation from estimate / um", fontsize=12)
        ax.set_title(f"{name}: estimate {est:.6f} mm\n"
                     f"u = {s['standard_uncertainty_um']:.3g} um, U = {U:.3g} um", fontsize=12)
        ax.tick_params(labelsize=11)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("probability density / (1/um)", fontsize=12)
    fig.legend(*axes[0][0].get_legend_handles_labels(), loc="outside lower center", ncol=2,
               fontsize=11, frameon=False)
    fig.suptitle(title, fontsize=14)
    return fig


def histogram_png(values, names, summary: dict, title: str) -> bytes:
    """PNG bytes of :func:`histogram_figure` (at least 1200 px wide)."""
    fig = histogram_figure(values, names, summary, title)
    return _fig_bytes(fig, tight=False, dpi=HIST_DPI)


def convergence_png(values, names, title: str) -> bytes:
    """Running mean (um about the final one) and running standard uncertainty (um)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = values.shape[0]
    idx = np.unique(np.geomspace(10, n, 200).astype(int))
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 3.4))
    for j, name in enumerate(names):
        v = values[:, j]
        c1 = np.cumsum(v - v.mean())
        c2 = np.cumsum((v - v.mean()) ** 2)
        mean = c1[idx - 1] / idx
        var = (c2[idx - 1] - idx * mean ** 2) / (idx - 1)
        a1.plot(idx, mean * 1e3, label=name)
        a2.plot(idx, np.sqrt(np.clip(var, 0, None)) * UM_PER_MM, label=name)
    for a, lab in ((a1, "running mean - final / um"), (a2, "running u / um")):
        a.set_xscale("log")
        a.set_xlabel("samples")
        a.set_ylabel(lab)
        a.grid(alpha=0.3)
    a2.legend(fontsize=7)
    fig.suptitle(title, fontsize=9)
    return _fig_bytes(fig)
