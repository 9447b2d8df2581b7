"""Plots of five-axis errors (matplotlib, Agg backend, PNG).

* :func:`tcp_error_map` / :func:`plot_tcp_error_map`: the tool-tip error over the range of the
  two rotary axes for one point of the workpiece: for every pair of rotary positions the
  linear axes are those of the nominal inverse that bring the tool tip to the point, so the
  map shows what a five-axis move around that point would see.
* :func:`plot_program_errors`: predicted tool-tip and tool-axis error along an NC program,
  before and after compensation.

Units: um and urad in the plots; mm / deg / rad in the arguments.
"""

from __future__ import annotations

import numpy as np

from volerr.errors import require


def tcp_error_map(model, funcs, point, tool=(0.0, 0.0, 0.0), n1: int = 73, n2: int = 73,
                  range1=None, range2=None):
    """Tool-tip error over the rotary range for the workpiece point ``point`` (mm).

    Returns ``(axis1, axis2, q1 (n1,), q2 (n2,), err (n2, n1, 3) mm, valid (n2, n1))``; ``valid``
    is False where the linear axes leave their travel or a position leaves an error table's
    measured range (there ``err`` is NaN).  :func:`tool_axis_error_map` gives the matching
    tool-axis error."""
    a1, a2, q1, q2, q, valid, em = _grid(model, funcs, point, tool, n1, n2, range1, range2)
    err = np.full((len(q), 3), np.nan)
    if valid.any():
        err[valid] = em.position_error(q[valid])
    return a1, a2, q1, q2, err.reshape(len(q2), len(q1), 3), valid.reshape(len(q2), len(q1))


def tool_axis_error_map(model, funcs, point, tool=(0.0, 0.0, 0.0), n1: int = 73, n2: int = 73,
                        range1=None, range2=None) -> np.ndarray:
    """First-order tool-axis error (rad) on the grid of :func:`tcp_error_map`, (n2, n1, 3)."""
    a1, a2, q1, q2, q, valid, em = _grid(model, funcs, point, tool, n1, n2, range1, range2)
    err = np.full((len(q), 3), np.nan)
    if valid.any():
        err[valid] = em.orientation_error(q[valid])
    return err.reshape(len(q2), len(q1), 3)


def _grid(model, funcs, point, tool, n1, n2, range1, range2):
    """Axis positions of the (rotary 1, rotary 2) grid that keep the tool tip on ``point``."""
    from volerr.fiveaxis.compensate import ErrorModel
    from volerr.fiveaxis.kinematics import is_five_axis

    require(is_five_axis(model), f"{model.name}: not a five-axis layout")
    a1, a2 = model.rotary_axes
    ranges = funcs.ranges() if funcs is not None else {}

    def default(a):
        lo, hi = model.travel[a]
        if a in ranges:  # the measured range, inside the travel
            lo, hi = max(lo, ranges[a][0]), min(hi, ranges[a][1])
        return (max(lo, -180.0), min(hi, 180.0)) if hi - lo > 360 else (lo, hi)

    r1 = range1 or default(a1)
    r2 = range2 or default(a2)
    q1 = np.linspace(*r1, n1)
    q2 = np.linspace(*r2, n2)
    g1, g2 = np.meshgrid(q1, q2)
    rot = {a1: np.deg2rad(g1.ravel()), a2: np.deg2rad(g2.ravel())}
    p = np.asarray(point, dtype=float)
    t = np.asarray(tool, dtype=float)
    lin = model.module.inverse_linear(*(rot[a] for a in model.rotary_axes),
                                      p[0], p[1], p[2], t[0], t[1], t[2])
    n = g1.size
    q = np.empty((n, len(model.axes)))
    for i, a in enumerate(model.axes):
        if a in rot:
            q[:, i] = np.rad2deg(rot[a])
        else:
            q[:, i] = np.broadcast_to(lin[("X", "Y", "Z").index(a)], (n,))
    em = ErrorModel(model, funcs, tool)
    valid = np.ones(n, dtype=bool)
    for i, a in enumerate(model.axes):
        lo, hi = model.travel[a]
        valid &= (q[:, i] >= lo) & (q[:, i] <= hi)
    if funcs is not None and not funcs.extrapolate:
        ql = em.lookup(q)
        for a, (lo, hi) in em.ranges.items():
            i = model.axes.index(a)
            valid &= (ql[:, i] >= lo) & (ql[:, i] <= hi)
    return a1, a2, q1, q2, q, valid, em


def plot_tcp_error_map(model, funcs, point, path, tool=(0.0, 0.0, 0.0), title: str = "",
                       **kw):
    """PNG of :func:`tcp_error_map`: length of the error (colour, um) and its components."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    a1, a2, q1, q2, err, valid = tcp_error_map(model, funcs, point, tool, **kw)
    ori = tool_axis_error_map(model, funcs, point, tool, **kw)
    mag = np.linalg.norm(err, axis=2) * 1e3
    fig, axs = plt.subplots(1, 5, figsize=(21, 4.2), constrained_layout=True)
    panels = [(mag, "|e| / um"), (err[..., 0] * 1e3, "dx / um"), (err[..., 1] * 1e3, "dy / um"),
              (err[..., 2] * 1e3, "dz / um"),
              (np.linalg.norm(ori, axis=2) * 1e6, "tool-axis error / urad")]
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
        ax.set_xlabel(f"{a1} / deg")
        ax.set_ylabel(f"{a2} / deg")
        ax.set_title(name)
        fig.colorbar(im, ax=ax, shrink=0.85)
    p = np.asarray(point, dtype=float)
    fig.suptitle(title or f"{model.name}: tool-tip error at workpiece point "
                          f"({p[0]:g}, {p[1]:g}, {p[2]:g}) mm over {a1}, {a2} "
                          f"(grey: outside travel or error tables)")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_program_errors(errors, path, title: str = ""):
    """PNG: predicted tool-tip error (um, log scale) and tool-axis error (urad) per motion
    block, before and after compensation.  ``errors``: a
    :class:`volerr.fiveaxis.program.ProgramErrors` (or the line reports of a
    :class:`volerr.fiveaxis.compensate.Result`)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from volerr.fiveaxis.program import ProgramErrors

    if not isinstance(errors, ProgramErrors):
        errors = ProgramErrors.from_reports(errors)
    lines, before, after = errors.line, errors.before_um, errors.after_um
    ob, oa = errors.orientation_before_urad, errors.orientation_after_urad
    done = lines
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(10, 6.5), sharex=True, constrained_layout=True)
    if len(done):
        floor = 1e-4
        ax1.semilogy(lines, np.maximum(before, floor), "o-", ms=3, label="before (predicted)")
        ax1.semilogy(lines, np.maximum(after, floor), "s-", ms=3, label="after (predicted)")
        ax1.axhline(0.1, color="0.5", ls=":", lw=1, label="0.1 um")
        ax2.plot(lines, ob, "o-", ms=3, label="before")
        ax2.plot(lines, oa, "s-", ms=3, label="after")
    ax1.set_ylabel("tool-tip error |e| / um")
    ax1.legend(loc="best", fontsize=8)
    ax1.grid(True, which="both", alpha=0.3)
    ax2.set_ylabel("tool-axis error / urad")
    ax2.set_xlabel("program line")
    if len(done) and np.allclose(ob, oa, rtol=1e-6, atol=1e-9):
        ax2.set_title("orientation not compensated (use --orientation): before and after "
                      "coincide", fontsize=9, color="0.3")
    ax2.legend(loc="best", fontsize=8)
    ax2.grid(True, alpha=0.3)
    fig.suptitle(title or "predicted error along the program")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
