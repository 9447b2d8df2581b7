"""HTML report of ``volerr loop``: a jinja2 template with embedded matplotlib PNG figures.

Figures (residuals of fits to all points, um): residual components against every axis and
covariate before (declared model) and after (augmented model); each effect's evidence (partial
residual -- the after-residual plus the effect's own contribution -- against the effect's
natural variable, with the fitted contribution); error maps (residual length over the first
two axes) before and after; the fitted component errors of every axis before and after (an
unmodelled effect leaks into them).  The headline numbers are the held-out ones of the json report.
Every figure is an ``<img>`` tag with its PNG embedded (style and widths: volerr.plotstyle).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..estimate.design import rotary_rad
from ..plotstyle import embedded_img, figure, label, png, styled


def _png(fig, alt: str = "figure") -> str:
    """The ``<img>`` tag of ``fig`` (PNG embedded, shown at its own pixel width)."""
    return embedded_img(png(fig), alt)


def _thin(n: int, limit: int = 4000, seed: int = 0) -> np.ndarray:
    """At most ``limit`` point indices (plots stay light)."""
    if n <= limit:
        return np.arange(n)
    return np.sort(np.random.default_rng(seed).choice(n, limit, replace=False))


def _unit_label(v: str, model) -> str:
    """Unit of a plotted variable (axis or covariate column)."""
    if v in model.axes:
        return "deg" if v in model.rotary_axes else "mm"
    if v.startswith(("T", "temp")):
        return "°C"
    if v in ("t_s", "time_s"):
        return "s"
    if v in ("t_min", "time_min"):
        return "min"
    if v in ("t_h", "time_h", "time"):
        return "h"
    return "1"


@styled
def fig_residuals(fg) -> str:
    """The ``<img>`` tag of :func:`figure_residuals`."""
    return _png(figure_residuals(fg), "residuals against every axis and covariate")


@styled
def figure_residuals(fg):
    dat = fg.data
    variables = {**dat.positions, **dat.covariates}
    names = [v for v, x in variables.items() if np.ptp(x) > 0][:14]
    idx = _thin(dat.n)
    rb = fg.res_before.reshape(-1, 3)[idx] * 1e3
    ra = fg.res_after.reshape(-1, 3)[idx] * 1e3
    lim = max(np.max(np.abs(rb)), np.max(np.abs(ra)), 1e-6) * 1.05   # nothing clipped
    fig, axes = figure(len(names), 2, height=2.1 * len(names) + 0.8, squeeze=False,
                       sharey=True)
    colors = ("tab:red", "tab:green", "tab:blue")
    for i, v in enumerate(names):
        x = np.asarray(variables[v])[idx]
        for j, (res, title) in enumerate(((rb, "before (declared model)"),
                                          (ra, "after (augmented model)"))):
            ax = axes[i, j]
            for k in range(3):
                ax.plot(x, res[:, k], ".", ms=2, alpha=0.5, color=colors[k],
                        label="xyz"[k] if i == 0 and j == 0 else None)
            ax.set_ylim(-lim, lim)
            ax.axhline(0, color="k", lw=0.5)
            ax.set_xlabel(label(v, _unit_label(v, fg.model)), labelpad=0)
            if i == 0:
                ax.set_title(title)
            if j == 0:
                ax.set_ylabel(label("residual", "um"))
    axes[0, 0].legend(loc="upper right", markerscale=4)
    return fig


def _natural(kind: str, info: dict, model, dat, values) -> tuple[np.ndarray, str]:
    """The variable against which an effect is best seen (its covariate C)."""
    from ..machine.expressions import evaluate

    c = info.get("covariate")
    if kind == "periodic" and {"axis", "period"} <= set(info):
        a, p = info["axis"], info["period"]
        return np.mod(dat.positions[a], p), label(f"{a} modulo {p:.3f}", "mm")
    if kind == "coupling" and {"axis", "depends_on"} <= set(info):
        a, b = info["axis"], info["depends_on"]
        u = {q: (2 * dat.positions[q] - dat.positions[q].min() - dat.positions[q].max())
             / max(np.ptp(dat.positions[q]), 1e-300) for q in (a, b)}
        return u[a] * u[b], f"{a} \u00b7 {b} (normalised to [\u22121, 1])"
    if c in dat.positions:
        return np.asarray(dat.positions[c], dtype=float), label(c, _unit_label(c, model))
    if c in dat.covariates:
        return np.asarray(dat.covariates[c], dtype=float), label(c, _unit_label(c, model))
    if c and kind != "probe_direction":
        try:
            return (np.asarray(evaluate(c, values), dtype=float),
                    label(c, _unit_label(c, model)))
        except Exception:   # noqa: BLE001  (a label that is not an expression)
            pass
    return np.arange(dat.n, dtype=float), "point"


@styled
def fig_effect(fg, eff: dict) -> str:
    """The ``<img>`` tag of :func:`figure_effect`."""
    return _png(figure_effect(fg, eff), f"evidence of {eff['name']}")


@styled
def figure_effect(fg, eff: dict):
    model, dat = fg.model, fg.data
    c3 = fg.contrib[eff["name"]].reshape(-1, 3) * 1e3
    partial = (fg.res_after.reshape(-1, 3) * 1e3) + c3
    values = {**rotary_rad(model, dat.positions), **dat.covariates}
    x, xlabel = _natural(eff["kind"], eff["info"], model, dat, values)
    if eff["kind"] == "probe_direction":
        # along the probing direction: the component of the partial residual along n
        names = eff["info"].get("covariates", ("nx", "ny", "nz"))
        n = np.column_stack([dat.covariates[c] for c in names])
        n = n / np.linalg.norm(n, axis=1, keepdims=True)
        y, fit = np.sum(partial * n, axis=1), np.sum(c3 * n, axis=1)
        x = np.arange(dat.n, dtype=float)
        xlabel, ylabel = "point", label("partial residual along the probing direction", "um")
    else:
        k = int(np.argmax(np.var(c3, axis=0)))
        y, fit = partial[:, k], c3[:, k]
        ylabel = label(f"partial residual d{'xyz'[k]}", "um")
    idx = _thin(dat.n)
    fig, ax = figure(width=8.0, height=3.8)
    jitter = 0.0
    if eff["kind"] in ("reversal", "setup"):
        jitter = np.random.default_rng(0).normal(0, 0.03 * max(np.ptp(x), 1.0), len(x))
    ax.plot((x + jitter)[idx], y[idx], ".", ms=2, alpha=0.5, color="tab:gray",
            label="partial residual")
    order = np.argsort(x[idx])
    ax.plot((x + jitter)[idx][order], fit[idx][order], ".", ms=2, color="tab:red",
            label="fitted effect")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(f"{eff['kind']}: {eff['name']}")
    ax.legend(markerscale=4)
    return fig


def _span(x) -> tuple:
    """Axis limits that show every value of ``x`` with a 3 % margin."""
    lo, hi = float(np.min(x)), float(np.max(x))
    pad = 0.03 * (hi - lo) if hi > lo else 1.0
    return lo - pad, hi + pad


@styled
def fig_maps(fg) -> str:
    """The ``<img>`` tag of :func:`figure_maps`."""
    return _png(figure_maps(fg), "error maps before and after")


@styled
def figure_maps(fg):
    """Residual length before and after over the first two axes: every panel spans the data
    of both axes (equal scales when both are lengths; the panel's box adapts, never the
    limits)."""
    model, dat = fg.model, fg.data
    a, b = model.axes[0], model.axes[1]
    idx = _thin(dat.n)
    nb = np.linalg.norm(fg.res_before.reshape(-1, 3), axis=1)[idx] * 1e3
    na = np.linalg.norm(fg.res_after.reshape(-1, 3), axis=1)[idx] * 1e3
    vmax = max(np.percentile(nb, 99), 1e-6)
    xa, xb = np.asarray(dat.positions[a], float), np.asarray(dat.positions[b], float)
    fig, axes = figure(1, 2, height=4.6)
    for ax, v, title in ((axes[0], nb, "before"), (axes[1], na, "after")):
        sc = ax.scatter(xa[idx], xb[idx], c=v, s=8, cmap="viridis", vmin=0, vmax=vmax)
        ax.set_title(f"residual length {title}")
        ax.set_xlabel(label(a, _unit_label(a, model)))
        ax.set_ylabel(label(b, _unit_label(b, model)))
        ax.set_xlim(*_span(xa))
        ax.set_ylim(*_span(xb))
        if _unit_label(a, model) == _unit_label(b, model):
            ax.set_aspect("equal", adjustable="box")
    fig.colorbar(sc, ax=axes, shrink=0.8, label=label("residual length", "um"))
    return fig


@styled
def fig_functions(report) -> str:
    """The ``<img>`` tag of :func:`figure_functions`."""
    return _png(figure_functions(report), "fitted component errors")


@styled
def figure_functions(report):
    """The fitted component errors of every axis, declared fit (before) and augmented
    fit (after, +-2 standard deviations)."""
    after, _ = report.error_tables()
    before, _ = report.error_tables(which="before")
    axes_names = list(after)
    fig, axes = figure(2, len(axes_names), height=6.0, squeeze=False)
    for i, a in enumerate(axes_names):
        for row, (kind, f, unit) in enumerate((("XYZ", 1e3, "µm"), ("ABC", 1e6, "µrad"))):
            ax = axes[row, i]
            for k, (name, v) in enumerate(after[a].values.items()):
                if name[1] not in kind:
                    continue
                color = f"C{k}"
                q = after[a].positions
                sd = after[a].std.get(name, np.zeros_like(v))
                ax.plot(q, v * f, color=color, label=name)
                ax.fill_between(q, (v - 2 * sd) * f, (v + 2 * sd) * f, color=color, alpha=0.2)
                ax.plot(before[a].positions, before[a].values[name] * f, "--", color=color,
                        lw=0.8)
            ax.set_xlabel(label(a, "deg" if a in report.plot_data.model.rotary_axes else "mm"))
            ax.set_ylabel(label("error", unit))
            # above the panel: inside, it lay over the curves (seen on the page and the PDF)
            ax.legend(fontsize=9, ncol=3, loc="lower center", bbox_to_anchor=(0.5, 1.0),
                      frameon=False, borderaxespad=0.2)
    fig.suptitle("solid: augmented model (band \u00b12 standard deviations, k = 2), dashed: "
                 "declared model")
    return fig


@styled
def fig_interactions(fg, sources) -> str | None:
    """The ``<img>`` tag of :func:`figure_interactions`."""
    fig = figure_interactions(fg, sources)
    return None if fig is None else _png(fig, "residual against covariates")


@styled
def figure_interactions(fg, sources):
    """Residual (after) against the covariates of the top residual sources, coloured by each
    axis position: an interaction shows as a colour gradient across the cloud."""
    dat, model = fg.data, fg.model
    values = {**rotary_rad(model, dat.positions), **dat.covariates}
    covs = []
    for src in sources:
        x, xlab = _natural(src.get("kind", ""), {"covariate": src["covariate"]}, model, dat,
                           values)
        if xlab != "point" and xlab not in [c[1] for c in covs]:
            covs.append((x, xlab))
        if len(covs) == 3:
            break
    if not covs:
        return None
    idx = _thin(dat.n)
    res = fg.res_after.reshape(-1, 3)[idx] * 1e3
    k = int(np.argmax(np.var(res, axis=0)))
    axes_names = list(model.axes)[:3]
    fig, axes = figure(len(covs), len(axes_names), height=2.8 * len(covs) + 0.6,
                       squeeze=False, sharey=True)
    lim = max(np.max(np.abs(res[:, k])), 1e-6) * 1.05
    for i, (x, xlab) in enumerate(covs):
        for j, a in enumerate(axes_names):
            ax = axes[i, j]
            sc = ax.scatter(x[idx], res[:, k], c=dat.positions[a][idx], s=3, cmap="viridis")
            ax.set_ylim(-lim, lim)
            ax.set_xlabel(xlab)
            if j == 0:
                ax.set_ylabel(label(f"residual d{'xyz'[k]} after", "um"))
            fig.colorbar(sc, ax=ax, label=label(a, _unit_label(a, model)))
    return fig


def render_html(report) -> str:
    """The complete HTML text of a :class:`volerr.loop.run.Report`."""
    from .drift.figure import render_template

    fg = report.plot_data
    figures = {"residuals": fig_residuals(fg), "maps": fig_maps(fg),
               "functions": fig_functions(report),
               "interactions": fig_interactions(fg, report.data["residual_sources"])}
    effects = [{"e": e, "png": fig_effect(fg, e),
                "params": [(p, v, e["std"][p], e["units"][p]) for p, v in e["parameters"].items()]}
               for e in report.data["effects"]]
    paths = {k: (Path(v).name if v else v) for k, v in (
        ("augmented_layout", report.data.get("augmented_layout")),
        ("generated_module", report.data.get("generated_module")))}
    return render_template("report.html.j2", r=report.data, figures=figures, effects=effects,
                           paths=paths)
