"""Plots of five-axis errors (matplotlib, Agg backend, PNG).

* :func:`plot_tcp_error_map`: a :class:`volerr.fiveaxis.tcpmap.TcpMap` (the tool-tip error
  over the range of the two rotary axes for one point of the workpiece).
* :func:`plot_program_errors`: predicted tool-tip and tool-axis error along an NC program,
  before and after compensation.

Units: µm and µrad in the plots; mm / deg / rad in the arguments.  Style: volerr.plotstyle.
"""

from __future__ import annotations

import numpy as np

from ..plotstyle import figure, label, save, styled


@styled
def plot_tcp_error_map(tmap, path, title: str = ""):
    """PNG of a :class:`volerr.fiveaxis.tcpmap.TcpMap`: length of the tool-tip error (colour,
    µm), its components and the tool-axis error (µrad)."""
    save(draw_tcp_error_map(tmap, title), path)
    return path


@styled
def unsaved(draw, *args):
    """The figure ``draw(*args)`` in the volerr style, not saved (a result's ``figures()``;
    ``draw``: :func:`draw_tcp_error_map` or :func:`draw_program_errors`)."""
    return draw(*args)


def draw_tcp_error_map(tmap, title: str = ""):
    """The figure of :func:`plot_tcp_error_map`."""
    a1, a2, q1, q2, err = tmap.axis1, tmap.axis2, tmap.q1, tmap.q2, tmap.err
    mag = np.linalg.norm(err, axis=2) * 1e3
    fig, grid = figure(2, 3, height=6.6)
    axs = grid.ravel()
    axs[5].remove()
    panels = [(mag, label("|e|", "um")), (err[..., 0] * 1e3, label("dx", "um")),
              (err[..., 1] * 1e3, label("dy", "um")), (err[..., 2] * 1e3, label("dz", "um")),
              (np.linalg.norm(tmap.orientation, axis=2) * 1e6, label("tool-axis error", "urad"))]
    for ax, (z, name) in zip(axs, panels):
        zm = np.ma.masked_invalid(z)
        lim = np.nanmax(np.abs(z)) if np.isfinite(z).any() else 1.0
        positive = name.startswith("|e|") or name.startswith("tool")
        cmap = "viridis" if positive else "RdBu_r"
        vmin = 0 if positive else -lim
        im = ax.pcolormesh(q1, q2, zm, shading="auto", cmap=cmap, vmin=vmin, vmax=lim)
        if np.isfinite(z).sum() > 4:
            ax.contour(q1, q2, zm, levels=6, colors="k", linewidths=0.4)
        ax.set_facecolor("0.85")
        ax.grid(False)
        ax.set_xlabel(label(a1, "deg"))
        ax.set_ylabel(label(a2, "deg"))
        ax.set_title(name)
        fig.colorbar(im, ax=ax, shrink=0.85)
    p = tmap.point
    fig.suptitle(title or f"{tmap.model_name}: tool-tip error at workpiece point "
                          f"({p[0]:g}, {p[1]:g}, {p[2]:g}) mm over {a1}, {a2}\n"
                          f"(grey: outside travel or error tables)")
    return fig


@styled
def plot_program_errors(errors, path, title: str = ""):
    """PNG: predicted tool-tip error (µm, log scale) and tool-axis error (µrad) per motion
    block, before and after compensation.  ``errors``: a
    :class:`volerr.fiveaxis.program.ProgramErrors` (or the line reports of a
    :class:`volerr.fiveaxis.compensate.Result`)."""
    save(draw_program_errors(errors, title), path)
    return path


def draw_program_errors(errors, title: str = ""):
    """The figure of :func:`plot_program_errors`."""
    from .program import ProgramErrors

    if not isinstance(errors, ProgramErrors):
        errors = ProgramErrors.from_reports(errors)
    lines, before, after = errors.line, errors.before_um, errors.after_um
    ob, oa = errors.orientation_before_urad, errors.orientation_after_urad
    done = lines
    fig, (ax1, ax2) = figure(2, 1, height=6.5, sharex=True)
    if len(done):
        floor = 1e-4
        ax1.semilogy(lines, np.maximum(before, floor), "o-", ms=3, label="before (predicted)")
        ax1.semilogy(lines, np.maximum(after, floor), "s-", ms=3, label="after (predicted)")
        ax1.axhline(0.1, color="0.5", ls=":", lw=1, label="0.1 \u00b5m")
        ax2.plot(lines, ob, "o-", ms=3, label="before")
        ax2.plot(lines, oa, "s-", ms=3, label="after")
    ax1.set_ylabel(label("tool-tip error |e|", "um"))
    ax1.legend(loc="best")
    ax1.grid(True, which="both", alpha=0.3)
    ax2.set_ylabel(label("tool-axis error", "urad"))
    ax2.set_xlabel("program line")
    if len(done) and np.allclose(ob, oa, rtol=1e-6, atol=1e-9):
        ax2.set_title("orientation not compensated (use --orientation): before and after "
                      "coincide", color="0.3")
    ax2.legend(loc="best")
    fig.suptitle(title or "predicted error along the program")
    return fig
