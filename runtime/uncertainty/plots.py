"""Plots of a Monte Carlo result: histogram with the coverage interval, and convergence of the
estimate and the standard uncertainty with the number of samples (matplotlib, Agg)."""

from __future__ import annotations

import io

import numpy as np


def _fig_bytes(fig) -> bytes:
    import matplotlib.pyplot as plt
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def histogram_png(values, names, summary: dict, title: str) -> bytes:
    """One panel per quantity: histogram (um about the estimate), interval, +-U lines."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    k = len(names)
    fig, axes = plt.subplots(1, k, figsize=(4.2 * k, 3.4), squeeze=False)
    for ax, j, name in zip(axes[0], range(k), names):
        s = summary[name]
        est = s["estimate_mm"]
        d = (values[:, j] - est) * 1e3
        ax.hist(d, bins=60, color="0.6", density=True)
        lo, hi = s["coverage_interval_mm"]
        for x in ((lo - est) * 1e3, (hi - est) * 1e3):
            ax.axvline(x, color="r", lw=1)
        for x in (-s["expanded_uncertainty_um"], s["expanded_uncertainty_um"]):
            ax.axvline(x, color="b", lw=1, ls="--")
        ax.set_xlabel(f"{name} - {est:.6f} mm / um")
        ax.set_title(f"u = {s['standard_uncertainty_um']:.3g} um", fontsize=9)
    axes[0][0].set_ylabel("density")
    fig.suptitle(title + "  (red: 95 % interval, blue: +-U, k = 2)", fontsize=9)
    return _fig_bytes(fig)


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
        a2.plot(idx, np.sqrt(np.clip(var, 0, None)) * 1e3, label=name)
    for a, lab in ((a1, "running mean - final / um"), (a2, "running u / um")):
        a.set_xscale("log")
        a.set_xlabel("samples")
        a.set_ylabel(lab)
        a.grid(alpha=0.3)
    a2.legend(fontsize=7)
    fig.suptitle(title, fontsize=9)
    return _fig_bytes(fig)
