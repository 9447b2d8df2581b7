"""The HTML page of the loop on drift runs: per channel a time-series figure (measured, the
declared model's prediction "before", the augmented model's "after", the static regression,
the residual; below it the spindle programme and the sensors the effects chose), held-out
readings shaded; the tables of :class:`volerr.loop.drift.report.DriftReport`.  The page is
``templates/drift.html.j2`` of :mod:`volerr.loop`, in the style of the loop's other page
(``templates/style.html.j2``, :func:`render_template`)."""

from __future__ import annotations

import numpy as np

from ...plotstyle import embedded_img, figure, png, styled
from ...plotstyle import label as axis_label
from ...selection.rules import SIG_K
from . import basis

MAX_DRAWN = 4000      # readings drawn per line (every n-th: the figure stays light)


def _draw(report, label: str):
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
    c = report.data["channels"].get(label, {})
    fam = c.get("family", "lag")
    ax[0].plot(t_h[i], p["after"][i], lw=0.8, label=f"after (model: {fam})")
    iv = c.get("interval")
    if iv and np.isfinite(iv["half_width_um"]):
        hw = p.get("half_width")                    # per reading (interval.py)
        hw = (np.full(len(y), iv["half_width_um"]) if hw is None else hw)[i]
        cov = "" if iv["coverage_test"] is None else \
            f", held-out coverage {100 * iv['coverage_test']:.0f} %"
        ax[0].fill_between(t_h[i], p["after"][i] - hw, p["after"][i] + hw, color="C3",
                           alpha=0.15, lw=0,
                           label=f"{100 * iv['level']:.0f} % prediction interval{cov}")
    if c.get("verdict"):
        ax[0].set_title(c["verdict"], fontsize="small")
    ax[0].set_ylabel(axis_label(label, "um"))
    # beside the panels: inside, the legend lay over the measured curve (seen on the page)
    ax[0].legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax[1].plot(t_h[i], (y - p["after"])[i], lw=0.6, label="residual after")
    ax[1].plot(t_h[i], (y - p["static"])[i], lw=0.6, alpha=0.6, label="residual static")
    ax[1].set_ylabel(axis_label("residual", "um"))
    ax[1].legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    chosen = sorted({t["source"] for t in p["terms"] if t["source"] != "heat"}
                    | {t["minus"] for t in p["terms"] if t.get("minus")})
    for k in chosen:
        v = s.inputs[k]
        ax[2].plot(t_h[i], v[i], lw=0.7, label=k)
    ax[2].set_ylabel(axis_label("temperature", "degC"))
    if basis.SPEED in s.inputs:
        tw = ax[2].twinx()
        tw.plot(t_h[i], s.inputs[basis.SPEED][i], color="0.5", lw=0.7, label="S_rpm")
        tw.set_ylabel("spindle / rpm")
    if chosen:
        ax[2].legend(fontsize="small", loc="upper left")
    ax[2].set_xlabel("time / h (runs one after the other)")
    for a in ax:
        _shade(a, t_h, s.test)
    return fig


@styled
def channel_figure(report, label: str):
    """The time-series figure of channel ``label`` (a matplotlib Figure)."""
    return _draw(report, label)


@styled
def _channel_img(report, label: str) -> str:
    return embedded_img(png(_draw(report, label)), f"channel {label} against time")


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


def render_template(name: str, **context) -> str:
    """The loop's template ``name`` (``volerr/loop/templates``) rendered with ``context``
    (autoescaped, undefined names refused), in the one page style of every report
    (:mod:`volerr.report.page`: ``page_style`` in the head, JSON keys in words through the
    filter ``words``, units as µm and µrad, words left and numbers right in every table)."""
    from importlib import resources

    import jinja2

    from ...report.fmt import unit, words
    from ...report.page import STYLE, finish

    folder = resources.files("volerr.loop") / "templates"
    env = jinja2.Environment(
        loader=jinja2.FunctionLoader(lambda n: (folder / n).read_text(encoding="utf-8")),
        autoescape=True, undefined=jinja2.StrictUndefined)
    env.globals["page_style"] = STYLE
    env.filters["words"] = words
    env.filters["unit"] = unit
    return finish(env.get_template(name).render(**context))


def render_html(report) -> str:
    """The complete HTML text of a :class:`volerr.loop.drift.report.DriftReport`."""
    from .series import left_out_line
    from .split import extrapolation_line, room_undecided_line

    d = report.data
    lines = report.summary_lines()
    figs = {k: _channel_img(report, k) for k in d["channels"]}
    return render_template("drift.html.j2", r=d,
                           headline=next(x for x in lines if not x.startswith(" ")).strip(),
                           extrapolation=extrapolation_line(d.get("extrapolation") or []),
                           left_out=left_out_line(d.get("inputs_left_out") or []),
                           room_undecided=room_undecided_line(d.get("room_undecided")),
                           figures=figs, k=report.K_PRINT, sig_k=f"{SIG_K:g}")
