"""The HTML page of the loop on drift runs: per channel a time-series figure (measured, the
declared model's prediction "before", the augmented model's "after", the static regression,
the residual; below it the spindle programme and the sensors the effects chose), held-out
readings shaded; the tables of :class:`volerr.loop.drift_report.DriftReport`."""

from __future__ import annotations

from html import escape

import numpy as np

from ..plotstyle import embedded_img, figure, png, styled
from . import drift_basis as basis

MAX_DRAWN = 4000      # readings drawn per line (every n-th: the figure stays light)


@styled
def fig_channel(report, label: str) -> str:
    s = report.series
    p = report.pred[label]
    y = s.channels[label]
    step = max(1, len(y) // MAX_DRAWN)
    i = np.arange(0, len(y), step)
    t_h = (s.t_s + _run_offsets(s)[s.run]) / 3600.0
    fig, ax = figure(3, 1, height=7.0, sharex=True)
    ax[0].plot(t_h[i], y[i], lw=0.8, label="measured")
    ax[0].plot(t_h[i], p["before"][i], lw=0.8, label="before (declared: the run's zero)")
    ax[0].plot(t_h[i], p["static"][i], lw=0.8, label="static regression, all T")
    ax[0].plot(t_h[i], p["after"][i], lw=0.8, label="after (augmented)")
    ax[0].set_ylabel(f"{label} / um")
    ax[0].legend(fontsize="small", ncol=2)
    ax[1].plot(t_h[i], (y - p["after"])[i], lw=0.6, label="residual after")
    ax[1].plot(t_h[i], (y - p["static"])[i], lw=0.6, alpha=0.6, label="residual static")
    ax[1].set_ylabel("residual / um")
    ax[1].legend(fontsize="small")
    chosen = sorted({t["source"] for t in p["terms"] if t["source"] != "heat"}
                    | {t["minus"] for t in p["terms"] if t.get("minus")})
    for k in chosen:
        v = s.inputs[k]
        ax[2].plot(t_h[i], v[i], lw=0.7, label=k)
    ax[2].set_ylabel("temperature / degC")
    if basis.SPEED in s.inputs:
        tw = ax[2].twinx()
        tw.plot(t_h[i], s.inputs[basis.SPEED][i], color="0.5", lw=0.7, label="S_rpm")
        tw.set_ylabel("spindle / rpm")
    if chosen:
        ax[2].legend(fontsize="small", loc="upper left")
    ax[2].set_xlabel("time / h (runs one after the other)")
    for a in ax:
        _shade(a, t_h, s.test)
    return embedded_img(png(fig), f"channel {label} against time")


def _run_offsets(s) -> np.ndarray:
    """Start of every run on a common axis (runs drawn one after the other)."""
    off, at = [], 0.0
    for r in range(len(s.runs)):
        t = s.t_s[s.run == r]
        off.append(at - t[0])
        at += t[-1] - t[0] + 600.0
    return np.array(off)


def _shade(ax, t_h, test) -> None:
    edges = np.flatnonzero(np.diff(np.concatenate([[0], test.astype(int), [0]])))
    for a, b in zip(edges[::2], edges[1::2]):
        ax.axvspan(t_h[a], t_h[b - 1], color="0.9", zorder=0)


def render_html(report) -> str:
    d = report.data
    rows = "".join(
        f"<tr><td>{escape(k)}</td><td>{c['n_test']}</td><td>{c['mae_before_um']:.3f}</td>"
        f"<td>{c['mae_static_um']:.3f}</td><td>{c['mae_after_um']:.3f}</td>"
        f"<td>{c['rms_before_um']:.3f}</td><td>{c['rms_after_um']:.3f}</td>"
        f"<td>{c['max_abs_before_um']:.3f}</td><td>{c['max_abs_after_um']:.3f}</td></tr>"
        for k, c in d["channels"].items())
    eff = "".join(f"<li>{escape(line.strip())}</li>" for line in report.summary_lines()[1:])
    figs = "".join(f"<h2>Channel {escape(k)}</h2>{fig_channel(report, k)}" for k in d["channels"])
    return (f"<!doctype html><html><head><meta charset='utf-8'><title>volerr loop: drift "
            f"runs</title></head><body><h1>Loop on drift runs: {escape(d['layout'])}</h1>"
            f"<p>{escape(report.summary_lines()[0])}</p>"
            f"<table border='1'><tr><th>channel</th><th>held out</th><th>MAE before</th>"
            f"<th>MAE static</th><th>MAE after</th><th>RMS before</th><th>RMS after</th>"
            f"<th>max before</th><th>max after</th></tr>{rows}</table>"
            f"<p>um; held-out readings only; uncertainties with k = 2.</p><ul>{eff}</ul>"
            f"{figs}</body></html>")
