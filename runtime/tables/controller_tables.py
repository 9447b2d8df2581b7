"""Axis compensation tables of SINUMERIK, Heidenhain and Fanuc controllers: export from an
error directory, import back into one, and what compensating with them leaves.

The formats (each module documents its file, limits and sources):

=================  ===========================================  ==============================
``sinumerik-lec``  :mod:`volerr.tables.sinumerik` (LEC)          positioning ``E<A><A>``
``sinumerik-cec``  :mod:`volerr.tables.sinumerik` (CEC)          straightness ``E<B><A>``
                                                                 (+ positioning by direction
                                                                 with a reversal)
``heidenhain``     :mod:`volerr.tables.heidenhain_tables`        positioning and straightness
                                                                 (BACKLASH: reversal)
``fanuc``          :mod:`volerr.tables.fanuc`                    positioning, relative to the
                                                                 reference position
``linuxcnc``       :mod:`volerr.tables.linuxcnc`                 positioning per joint, forward
                                                                 and reverse (a folder of
                                                                 ``COMP_FILE`` s + ini lines)
=================  ===========================================  ==============================

What compensating leaves: :func:`volerr.fiveaxis.tables_left.left`; whether that is worse
than no compensation: :func:`worse_than_none`; the API of the capability:
:mod:`volerr.fiveaxis.controller_api` (``volerr.controller_export`` / ``controller_import``).
"""

from __future__ import annotations

from pathlib import Path

from ..errors import require, require_file
from . import comp_tables as ct

FORMATS = ("sinumerik-lec", "sinumerik-cec", "heidenhain", "fanuc", "linuxcnc")


def build(funcs, fmt: str, points: int | None = None) -> list:
    """The :class:`~volerr.tables.comp_tables.CompTable` list of format ``fmt`` from error
    functions (``points``: at most this many per table, within the format's limit)."""
    from . import fanuc, heidenhain_tables, linuxcnc, sinumerik

    builders = {"linuxcnc": (linuxcnc.build, linuxcnc.MAX_POINTS),
                "sinumerik-lec": (sinumerik.build_lec, sinumerik.MAX_POINTS),
                "sinumerik-cec": (sinumerik.build_cec, sinumerik.MAX_POINTS),
                "heidenhain": (heidenhain_tables.build, heidenhain_tables.MAX_POINTS),
                "fanuc": (fanuc.build, fanuc.MAX_POINTS)}
    require(fmt in builders, f"unknown format {fmt!r} ({' '.join(FORMATS)})")
    fn, limit = builders[fmt]
    require(points is None or 2 <= points <= limit,
            f"--points must be 2 .. {limit} for {fmt}")
    tables = fn(funcs, points or limit)
    kind = "straightness" if fmt in ("sinumerik-cec", "heidenhain") else "positioning"
    require(tables, f"{fmt}: the error tables hold nothing this format carries ({kind} "
                    "errors of the axes)")
    return tables


def write(model, tables: list, fmt: str, out: Path, comp_type: int = 0) -> dict:
    """{path: text} of the files of ``tables`` in format ``fmt``, the main file (at ``out``)
    first (Heidenhain: the ``.CMA`` there and its ``.COM`` tables next to it; LinuxCNC: the
    files in the folder ``out``, ``comp_type`` its ``COMP_FILE_TYPE``)."""
    from . import fanuc, heidenhain_tables, linuxcnc, sinumerik

    out = Path(out)
    if fmt == "linuxcnc":
        return {out / name: text for name, text in
                linuxcnc.write(model.name, tables, model.axes, comp_type).items()}
    if fmt == "sinumerik-lec":
        return {out: sinumerik.write_lec(model.name, tables)}
    if fmt == "sinumerik-cec":
        return {out: sinumerik.write_cec(model.name, tables, model.axes)}
    if fmt == "fanuc":
        return {out: fanuc.write(model.name, tables, model.axes)}
    files = heidenhain_tables.write(out.stem, model.name, tables)
    cma = next(name for name in files if name.endswith(".cma"))
    return {out: files[cma], **{out.parent / name: text for name, text in files.items()
                                if name != cma}}


def read(model, path, fmt: str) -> list:
    """The tables of a controller file (Heidenhain: the ``.CMA``; LinuxCNC: the ini)."""
    from . import fanuc, heidenhain_tables, linuxcnc, sinumerik

    p = Path(path)
    if fmt == "linuxcnc":
        return linuxcnc.read_tables(p, model)
    require_file(p, f"controller file not found: {path}")
    if fmt == "heidenhain":
        return heidenhain_tables.read(p, model.axes)
    text = p.read_text(encoding="latin-1")
    reader = {"sinumerik-lec": sinumerik.read_lec, "sinumerik-cec": sinumerik.read_cec,
              "fanuc": fanuc.read}[fmt]
    return reader(text, model.axes, str(p))


def import_tables(model, path, fmt: str) -> dict:
    """{axis: ErrorTable} of a controller file (values back in volerr's units and signs;
    LinuxCNC: the ini naming the ``COMP_FILE`` s)."""
    from . import linuxcnc
    from .controller import check_against_model

    if fmt == "linuxcnc":
        tables = linuxcnc.read(path, model)
    else:
        tables = ct.to_error_tables(read(model, path, fmt), model)
    check_against_model(model, tables, {}, str(path))
    return tables


def worse_than_none(summary: dict) -> bool:
    """Whether a compensation leaves a larger max or rms of the volumetric error than no
    compensation: ``summary["left_um"]`` against ``summary["before_um"]`` (``{"max", "rms"}``,
    um), compared at 1 nm, below which a difference is the rounding of the tables' values."""
    b, a = summary["before_um"], summary["left_um"]
    return a["max"] > b["max"] + 1e-3 or a["rms"] > b["rms"] + 1e-3


def plot_left(result, path, title: str = "") -> None:
    """:func:`left_figure` saved as a PNG at ``path`` (90 dpi)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = left_figure(result, title)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def left_figure(result, title: str = ""):
    """The volumetric error |e| before and after the tables' correction on three levels of
    the last linear axis (lowest, middle, highest), um: a matplotlib figure."""
    import matplotlib.pyplot as plt
    import numpy as np

    shape = result.shape
    lin = result.linear
    q = result.positions
    b = (np.linalg.norm(result.before, axis=1) * 1e3).reshape(shape)
    a = (np.linalg.norm(result.after, axis=1) * 1e3).reshape(shape)
    levels = sorted({0, shape[2] // 2, shape[2] - 1})
    fig, ax = plt.subplots(2, len(levels), figsize=(4 * len(levels), 7), squeeze=False)
    vmax_b, vmax_a = float(b.max()), float(max(a.max(), 1e-9))
    i0, i1, i2 = (result.axes.index(x) for x in lin)
    xs = np.unique(q[:, i0])
    ys = np.unique(q[:, i1])
    zs = np.unique(q[:, i2])
    for col, k in enumerate(levels):
        for row, (v, vmax, label) in enumerate(((b, vmax_b, "before"),
                                                (a, vmax_a, "left after the tables"))):
            im = ax[row][col].imshow(v[:, :, k].T, origin="lower", cmap="viridis",
                                     vmin=0, vmax=vmax, aspect="auto",
                                     extent=(xs[0], xs[-1], ys[0], ys[-1]))
            ax[row][col].set_title(f"{label}, {lin[2]} = {zs[k]:g} mm", fontsize=9)
            ax[row][col].set_xlabel(f"{lin[0]} (mm)")
            ax[row][col].set_ylabel(f"{lin[1]} (mm)")
            fig.colorbar(im, ax=ax[row][col], label="|e| (um)")
    fig.suptitle(title)
    fig.tight_layout()
    return fig
