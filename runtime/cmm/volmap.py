"""Volumetric error map over the working volume (Pahk 1995, sec. 4, Fig. 5 and 7).

The grid spans the travel of the linear axes of the layout (``nx x ny x nz`` positions, ends
included); rotary axes, if any, stay at fixed positions (default 0 deg, or the nearest travel
limit).  At every node the model gives the systematic volumetric error ``d = actual - nominal``
of the probe tip / tool centre point (mm, first order), and, when the error tables carry
standard deviations, its random component ``r`` (standard uncertainty per direction,
first-order propagation, ``Model.random_error``).

Map CSV columns: the axis positions (mm / deg), the probe offset ``Xp,Yp,Zp`` (mm),
``dx_um,dy_um,dz_um`` and, with standard deviations, ``rx_um,ry_um,rz_um``.  The first part is
the input format of ``volerr loop`` (measured deviations).  Numbers have 6 decimals (1 nm,
1e-6 um), trailing zeros dropped; the CSV is written in blocks of rows.

Plots: the nominal grid of the volume's outer faces (dashed) against the actual grid, nominal +
K x error (solid), K the magnification (automatic: the largest error drawn as 15 % of the
smallest box edge); the random component as its own figure (nominal grid with +-K x r bars).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..units import UM_PER_MM
from ..errors import InputError, require
from . import csvformat
from ..fileio import AtomicFile, check_plot, layout_inputs
from ..plotstyle import styled


@dataclass
class VolumetricMap:
    """A computed map.  ``positions``: axis -> (N,) mm/deg; ``nominal``, ``error``, ``random``:
    (N, 3) mm (``random`` None without standard deviations); ``shape`` = grid counts of the
    linear axes in ``grid_axes`` order (C order, last axis fastest); ``ticks``: grid axis ->
    its positions (mm)."""

    layout: str
    axes: tuple
    grid_axes: tuple
    shape: tuple
    positions: dict
    probe: np.ndarray
    nominal: np.ndarray
    error: np.ndarray
    random: np.ndarray | None
    ticks: dict | None = None  # grid axis -> its (count,) positions (mm), C-order grid

    def summary(self) -> dict:
        """Max |component|, max and RMS length of the error vector, in um."""
        e = self.error * UM_PER_MM
        length = np.linalg.norm(e, axis=1)
        out = {"layout": self.layout, "grid": list(self.shape), "n_points": int(len(e)),
               "probe_mm": [float(v) for v in self.probe],
               "max_abs_um": {k: float(np.max(np.abs(e[:, i]))) for i, k in enumerate("xyz")},
               "max_length_um": float(length.max()),
               "rms_length_um": float(np.sqrt(np.mean(length ** 2)))}
        if self.random is not None:
            r = self.random * UM_PER_MM
            out["random_max_um"] = {k: float(r[:, i].max()) for i, k in enumerate("xyz")}
            out["random_max_length_um"] = float(np.linalg.norm(r, axis=1).max())
        return out


def grid_counts(grid) -> tuple:
    """``None`` -> (5, 5, 5); N -> (N, N, N); (nx, ny, nz) as given; each at least 2."""
    if grid is None:
        grid = [5]
    grid = [int(g) for g in np.atleast_1d(grid)]
    require(len(grid) in (1, 3), f"grid must be N or nx ny nz, got {len(grid)} numbers")
    if len(grid) == 1:
        grid = grid * 3
    require(all(2 <= g <= 200 for g in grid), f"grid counts must be between 2 and 200, got {grid}")
    require(int(np.prod(grid)) <= 1_000_000, f"grid of {int(np.prod(grid))} points is too large "
                                             f"(at most 1000000 points: N <= 100 for --grid N)")
    return tuple(grid)


def linear_axes(model) -> tuple:
    lin = tuple(a for a in model.axes if a not in model.rotary_axes)
    require(len(lin) == 3, f"{model.name}: a volumetric map needs three linear axes, has {lin}")
    return lin


def fixed_positions(model, at: dict | None = None) -> dict:
    """Positions of the rotary axes during the map (deg)."""
    at = dict(at or {})
    unknown = set(at) - set(model.rotary_axes)
    require(not unknown, f"--at: {', '.join(sorted(unknown))} is not a rotary axis of {model.name}")
    out = {}
    for a in model.rotary_axes:
        lo, hi = model.travel[a]
        v = float(at.get(a, min(max(0.0, lo), hi)))
        require(lo <= v <= hi, f"--at {a}={v:g} is outside the travel {lo:g} .. {hi:g} deg")
        out[a] = v
    return out


def volume(model, funcs, choice: str = "travel") -> dict:
    """Axis -> (min, max) of the box to test: the layout's travel, or (``"measured"``) the part
    of it that the error tables of ``funcs`` cover."""
    box = dict(model.travel)
    if choice == "measured":
        for a, (lo, hi) in funcs.ranges().items():
            t_lo, t_hi = box[a]
            require(max(lo, t_lo) < min(hi, t_hi),
                    f"table {a} ({lo:g} .. {hi:g}) does not overlap the travel {t_lo:g} .. {t_hi:g}")
            box[a] = (max(lo, t_lo), min(hi, t_hi))
    return box


def volumetric_map(model, funcs, grid=None, probe=(0.0, 0.0, 0.0), at=None,
                   box=None, approach=None) -> VolumetricMap:
    """Evaluate the volumetric error of ``model`` with error functions ``funcs`` on a grid over
    ``box`` (axis -> (min, max); default the layout's travel).  ``approach``: {axis: +1 | -1}
    the approach direction of axes whose tables carry a reversal (ISO 230-2 B_i; default the
    bidirectional mean)."""
    box = model.travel if box is None else box
    counts = grid_counts(grid)
    lin = linear_axes(model)
    probe = np.asarray(probe, dtype=float)
    require(probe.shape == (3,) and np.all(np.isfinite(probe)), "probe offset must be three numbers")
    ticks = [np.linspace(*box[a], n) for a, n in zip(lin, counts)]
    mesh = np.meshgrid(*ticks, indexing="ij")
    pos = {a: m.ravel() for a, m in zip(lin, mesh)}
    n = mesh[0].size
    for a, v in fixed_positions(model, at).items():
        pos[a] = np.full(n, v)
    pos = {a: pos[a] for a in model.axes}
    err, nominal = np.empty((n, 3)), np.empty((n, 3))
    has_random = getattr(funcs, "has_random", False)
    rnd = np.empty((n, 3)) if has_random else None
    # in blocks: the error functions' values (one (N,) array per parameter, and as many for
    # the standard deviations) never exist for the whole grid at once
    for start in range(0, n, BLOCK):
        sl = slice(start, min(start + BLOCK, n))
        p = {a: v[sl] for a, v in pos.items()}
        e = funcs(p)
        if approach and getattr(funcs, "has_reversal", False):
            from ..tables.functions import approach_array

            q = np.column_stack([p[a] for a in model.axes])
            for k, v in funcs.reversal(q, approach_array(approach, model.axes,
                                                           len(q))).items():
                e[k] = e[k] + v if k in e else v
        err[sl] = model.volumetric_error(p, e, probe=probe)
        if has_random:
            rnd[sl] = model.random_error(p, funcs.sigmas(p), probe=probe)
        nominal[sl] = model.nominal_position(p, probe=probe)
    return VolumetricMap(model.name, model.axes, lin, counts, pos, probe, nominal, err, rnd,
                         dict(zip(lin, ticks)))


#: points per block of the map's evaluation and of its CSV text
BLOCK = 65536

#: decimals of the map CSV: positions and probe offsets (mm, deg) and errors (um)
DECIMALS_MM, DECIMALS_UM = 6, 6


def _header(vmap: VolumetricMap) -> str:
    header = list(vmap.axes) + ["Xp", "Yp", "Zp", "dx_um", "dy_um", "dz_um"]
    if vmap.random is not None:
        header += ["rx_um", "ry_um", "rz_um"]
    return ",".join(header) + "\n"


def map_csv_blocks(vmap: VolumetricMap):
    """The CSV text of a map (format in the module docstring) as bytes, in blocks of rows:
    header first.  Numbers have fixed decimals (:data:`DECIMALS_MM` for mm / deg,
    :data:`DECIMALS_UM` for um), trailing zeros dropped (:mod:`volerr.cmm.csvformat`)."""
    yield _header(vmap).encode("ascii")
    n = len(vmap.error)
    ticks = vmap.ticks or {}
    for start in range(0, n, BLOCK):
        stop = min(start + BLOCK, n)
        sl = slice(start, stop)
        index = np.unravel_index(np.arange(start, stop), vmap.shape) if ticks else None
        cols, dec = [], []
        for a in vmap.axes:
            if a in ticks:  # a grid axis: its ticks and each row's tick index
                cols.append((ticks[a], index[vmap.grid_axes.index(a)]))
            else:
                cols.append(vmap.positions[a][sl])
            dec.append(DECIMALS_MM)
        cols += [float(v) for v in vmap.probe]
        dec += [DECIMALS_MM] * 3
        cols += [vmap.error[sl, i] * UM_PER_MM for i in range(3)]
        if vmap.random is not None:
            cols += [vmap.random[sl, i] * UM_PER_MM for i in range(3)]
        dec += [DECIMALS_UM] * (len(cols) - len(dec))
        yield csvformat.rows_text(cols, dec)


def map_csv(vmap: VolumetricMap) -> str:
    """CSV text of a map (format in the module docstring)."""
    return b"".join(map_csv_blocks(vmap)).decode("ascii")


def write_map_csv(path, vmap: VolumetricMap, inputs=()) -> Path:
    """Write the map CSV to ``path`` streamed in blocks (memory does not grow with the text),
    atomically: a temporary file renamed at the end."""
    out = AtomicFile(path, inputs)
    try:
        for block in map_csv_blocks(vmap):
            out.write(block)
    except BaseException:
        out.discard()
        raise
    return out.commit()


# ---------------------------------------------------------------------------------------------
# plots
def save_figure(fig, path, inputs=()) -> Path:
    """Save a matplotlib figure as PNG (:func:`volerr.plotstyle.png`) atomically, never over
    an input file."""
    from ..plotstyle import png

    out = AtomicFile(check_plot(path, inputs), inputs)
    try:
        out.write(png(fig))
    except BaseException:
        out.discard()
        raise
    return out.commit()


def auto_magnification(vmap: VolumetricMap, values: np.ndarray) -> float:
    """K such that the largest vector of ``values`` (mm) is drawn as 15 % of the smallest edge."""
    span = np.ptp(vmap.nominal, axis=0)
    edge = float(np.min(span[span > 0])) if np.any(span > 0) else 1.0
    big = float(np.max(np.linalg.norm(values, axis=1))) if len(values) else 0.0
    if big <= 0:
        return 1.0
    k = 0.15 * edge / big
    e = 10 ** np.floor(np.log10(k))  # round down to 1, 2 or 5 x 10^n
    return float(max(m * e for m in (1, 2, 5) if m * e <= k))


def _face_lines(shape):
    """Index paths of the grid lines on the outer faces: list of (N_line,) flat index arrays."""
    idx = np.arange(int(np.prod(shape))).reshape(shape)
    lines = []
    for axis in range(3):
        others = [d for d in range(3) if d != axis]
        for i in range(shape[others[0]]):
            for j in range(shape[others[1]]):
                on_face = i in (0, shape[others[0]] - 1) or j in (0, shape[others[1]] - 1)
                if not on_face:
                    continue
                sl = [slice(None)] * 3
                sl[others[0]], sl[others[1]] = i, j
                lines.append(idx[tuple(sl)])
    return lines


def _axes3d(fig, pos=111):
    """A 3-D panel with its axis labels and no autoscaling: the caller sets the limits
    (:func:`_equal_box`), so the hundreds of lines drawn on it do not each rescale it (an
    ``autoscale_view`` of three axes at every ``plot``, then overwritten)."""
    from ..plotstyle import label

    ax = fig.add_subplot(pos, projection="3d")
    ax.set_autoscale_on(False)
    ax.set_xlabel(label("x", "mm"))
    ax.set_ylabel(label("y", "mm"))
    ax.set_zlabel(label("z", "mm"))
    return ax


def _equal_box(ax, pts, zoom: float = 0.85):
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = np.where(hi - lo > 0, hi - lo, 1.0)
    ax.set_box_aspect(tuple(span), zoom=zoom)  # < 1: the axis labels stay inside the panel
    pad = 0.08 * span
    ax.set_xlim(lo[0] - pad[0], hi[0] + pad[0])
    ax.set_ylim(lo[1] - pad[1], hi[1] + pad[1])
    ax.set_zlim(lo[2] - pad[2], hi[2] + pad[2])


def _face_grid(shape, axis: int, side: int):
    """Flat indices of the nodes on one face of the grid (axis fixed at 0 or max), 2-D array."""
    idx = np.arange(int(np.prod(shape))).reshape(shape)
    sl = [slice(None)] * 3
    sl[axis] = 0 if side == 0 else shape[axis] - 1
    return idx[tuple(sl)]


@styled
def plot_map(vmap: VolumetricMap, path, magnify: float | None = None, inputs=()) -> float:
    """Nominal grid (dashed) vs actual grid magnified (solid), like Pahk Fig. 5 / 7(a): the
    outer faces in 3-D, and three faces in their own planes (top z = max, front y = min, side
    x = max) with the in-plane error components.  Returns the magnification used."""
    from ..plotstyle import PAGE_WIDTH_IN, label, pyplot

    k = float(magnify) if magnify else auto_magnification(vmap, vmap.error)
    require(k > 0, f"magnification must be positive, got {k:g}")
    nom, act = vmap.nominal, vmap.nominal + k * vmap.error
    fig = pyplot().figure(figsize=(PAGE_WIDTH_IN, 7.5), layout="constrained")
    gs = fig.add_gridspec(3, 3, width_ratios=[1.5, 0.12, 1])  # a gap for the 3-D z label
    ax = _axes3d(fig, gs[:, 0])
    for line in _face_lines(vmap.shape):
        ax.plot(*nom[line].T, ls="--", lw=0.7, color="0.55")
        ax.plot(*act[line].T, ls="-", lw=1.1, color="C3")
    _equal_box(ax, np.vstack([nom, act]))
    s = vmap.summary()
    ax.set_title(f"{vmap.layout} volumetric error map, errors magnified \u00d7{k:g}\n"
                 f"dashed: nominal grid, solid: actual\nmax |d| {s['max_length_um']:.1f} "
                 f"\u00b5m, RMS {s['rms_length_um']:.1f} \u00b5m")
    faces = [(2, 1, (0, 1), "top face z = max"), (1, 0, (0, 2), "front face y = min"),
             (0, 1, (1, 2), "side face x = max")]
    for row, (axis, side, (i, j), face) in enumerate(faces):
        a2 = fig.add_subplot(gs[row, 2])
        g = _face_grid(vmap.shape, axis, side)
        for lines in (g, g.T):
            for line in lines:
                a2.plot(nom[line, i], nom[line, j], ls="--", lw=0.7, color="0.55")
                a2.plot(act[line, i], act[line, j], ls="-", lw=1.1, color="C3")
        a2.set_aspect("equal", adjustable="datalim")
        a2.set_xlabel(label("xyz"[i], "mm"))
        a2.set_ylabel(label("xyz"[j], "mm"))
        a2.set_title(f"{face} (in-plane errors \u00d7{k:g})")
    save_figure(fig, path, inputs)
    return k


@styled
def plot_random(vmap: VolumetricMap, path, magnify: float | None = None, inputs=()) -> float:
    """Random component: nominal grid with +-K x (rx, ry, rz) bars at every node (Fig. 7(b)):
    the standard uncertainty (k = 1) of the volumetric error for one reading, from the
    tables' ``_std`` and ``_s`` columns (:meth:`volerr.tables.ErrorFunctions.sigmas`)."""
    require(vmap.random is not None, "no random component: the error tables have no _std, "
                                     "_s or _u95 columns")
    import matplotlib
    from matplotlib import cm

    from ..plotstyle import label, pyplot

    r = vmap.random
    k = float(magnify) if magnify else auto_magnification(vmap, r)
    nom = vmap.nominal
    fig = pyplot().figure(figsize=(8.0, 6.5), layout="constrained")
    ax = _axes3d(fig)
    for line in _face_lines(vmap.shape):
        ax.plot(*nom[line].T, ls="--", lw=0.6, color="0.6")
    mag = np.linalg.norm(r, axis=1) * UM_PER_MM
    norm = matplotlib.colors.Normalize(vmin=0.0, vmax=max(mag.max(), 1e-12))
    cmap = matplotlib.colormaps["viridis"]
    for p, rv, m in zip(nom, r, mag):
        c = cmap(norm(m))
        for i in range(3):
            d = np.zeros(3)
            d[i] = k * rv[i]
            ax.plot(*np.stack([p - d, p + d]).T, color=c, lw=1.4)
    _equal_box(ax, np.vstack([nom - k * r, nom + k * r]))
    sm = cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=ax, shrink=0.6, pad=0.14,  # clear of the z label
                 label=label("|r| = \u221a(rx\u00b2 + ry\u00b2 + rz\u00b2)", "um"))
    ax.set_title(f"{vmap.layout} random component (k = 1), bars \u00b1{k:g} \u00d7 "
                 f"(rx, ry, rz)\nmax |r| {mag.max():.2f} \u00b5m")
    save_figure(fig, path, inputs)
    return k


def random_plot_path(path) -> Path:
    p = Path(path)
    return p.with_name(p.stem + "_random" + p.suffix)


def error_dir_inputs(directory) -> list:
    """The files of an error directory (never to be overwritten)."""
    d = Path(directory)
    if not d.is_dir():
        return []
    return [f for f in d.iterdir() if f.is_file()]


def map_inputs(layout, errors) -> list:
    """The inputs of a run on an error model, never overwritten: the files of the error
    directory ``errors`` and the layout file (not a shipped layout's name)."""
    return error_dir_inputs(errors) + layout_inputs(layout)


def check_distinct(*paths) -> None:
    seen = {}
    for label, p in paths:
        if p is None:
            continue
        key = Path(p).resolve()
        if key in seen:
            raise InputError(f"{label} and {seen[key]} name the same file {p}")
        seen[key] = label
