"""``volerr.error_map(...)``: the Python API of ``volerr map`` (:mod:`volerr.results`)."""

from __future__ import annotations

from dataclasses import dataclass, field

from ..results import ResultMixin


@dataclass(repr=False)
class ErrorMap(ResultMixin):
    """Result of :func:`error_map`: ``data`` the ``--json`` summary (um), ``map`` the
    :class:`volerr.cmm.volmap.VolumetricMap` (positions mm / deg, errors (N, 3) mm, their
    standard uncertainty (k = 1) ``random`` where the tables carry one)."""

    data: dict
    map: object
    magnify: float | None = None    # the plots' error magnification (None: automatic)
    #: the magnifications of the written plots (``magnification``, ``random_magnification``)
    scales: dict = field(default_factory=dict)

    def _document(self) -> dict:
        """``data`` and, after the plots are written, their magnifications."""
        return {**self.data, **{k: self.scales[k] for k in ("magnification",
                                                            "random_magnification")
                                if k in self.scales}}

    @property
    def has_random(self) -> bool:
        """The tables carry standard deviations: the map has a random component."""
        return self.map.random is not None

    def write_plot(self, path, inputs=()):
        """``--plot``: nominal vs actual grid, magnified (Pahk Fig. 5 / 7(a),
        :func:`volerr.cmm.volmap.plot_map`); the magnification used is recorded in
        :meth:`to_dict` (``"magnification"``).  Returns the path."""
        from .volmap import plot_map

        self.scales["magnification"] = plot_map(self.map, path, self.magnify, inputs)
        return path

    def write_random_plot(self, path, inputs=()):
        """``--plot-random``: the random component (k = 1) as bars at every node (Pahk Fig.
        7(b), :func:`volerr.cmm.volmap.plot_random`); its magnification is recorded in
        :meth:`to_dict` (``"random_magnification"``).  Returns the path."""
        from .volmap import plot_random

        self.scales["random_magnification"] = plot_random(self.map, path, self.magnify,
                                                          inputs)
        return path

    def random_plot_path(self, plot_random=None, plot=None):
        """Where ``volerr map`` draws the random component: ``plot_random``, else beside
        ``plot`` (``NAME_random.png``) when the map has one, else ``None``."""
        from .volmap import random_plot_path

        return plot_random or (random_plot_path(plot) if plot and self.has_random else None)

    def _write_own(self, outs, options: dict, inputs: list) -> None:
        """``volerr map``'s ``--out`` CSV and the random plot (before the JSON: it records
        the magnification)."""
        if options.get("out"):
            self.write_csv(outs.path("--out"), inputs)
        if outs.path("--plot-random"):
            self.write_random_plot(outs.path("--plot-random"), inputs)

    def summary(self, written: dict | None = None) -> str:
        """What ``volerr map`` prints; ``written``: ``{label: path}`` of the files written
        (``map``, ``plot``, ``random plot``, ``summary``), one line each at the end."""
        s, vmap = self.data, self.map
        m = s["max_abs_um"]
        out = [f"{s['layout']}: volumetric error on a {'x'.join(map(str, vmap.shape))} grid, "
               f"probe {' '.join(f'{v:g}' for v in vmap.probe)} mm",
               f"  max |dx| {m['x']:.2f} um, |dy| {m['y']:.2f} um, |dz| {m['z']:.2f} um; "
               f"max |d| {s['max_length_um']:.2f} um, RMS |d| {s['rms_length_um']:.2f} um"]
        if vmap.random is not None:
            r = s["random_max_um"]
            out.append(f"  random (1 sigma, k = 1) max rx {r['x']:.2f} um, ry {r['y']:.2f} um, "
                       f"rz {r['z']:.2f} um")
        out += [f"  {label}: {path}" for label, path in (written or {}).items() if path]
        return "\n".join(out)

    def write_csv(self, path, inputs=()):
        """The map CSV of ``volerr map --out``: positions, probe, dx_um dy_um dz_um (and
        their u columns)."""
        from .volmap import write_map_csv

        return write_map_csv(path, self.map, inputs)

    def _rows(self) -> list:
        """The printed figures (um; actual minus nominal probe tip): max |dx|, |dy|, |dz|,
        max and RMS |d| (exact over the grid, no uncertainty: ``std`` None), and where the
        tables carry one the largest standard uncertainty (k = 1) of the random part."""
        from ..results import Row

        s = self.data
        rows = [Row(f"max_abs_d{a}", float(s["max_abs_um"][a]), None, "um", 1.0)
                for a in "xyz"]
        rows += [Row("max_length", float(s["max_length_um"]), None, "um", 1.0),
                 Row("rms_length", float(s["rms_length_um"]), None, "um", 1.0)]
        if self.map.random is not None:
            rows += [Row(f"random_max_{a}", float(s["random_max_um"][a]), None, "um", 1.0)
                     for a in "xyz"]
        return rows


def error_map(layout, errors, *, grid=None, probe=(0.0, 0.0, 0.0), at=None,
              volume: str = "travel", approach=None, method: str = "linear",
              degree: int | None = None, extrapolate: bool = False,
              accept_implausible: bool = False, magnify: float | None = None) -> ErrorMap:
    """The volumetric error over the working volume (``volerr map``).

    Parameters
    ----------
    layout : str, path or volerr.Model
        Layout name or file (or a loaded model).
    errors : path or volerr.tables.ErrorFunctions
        Error directory (``X.csv`` ... ``constants.csv``; 'volerr formats tables') or error
        functions already made from one.
    grid : int or sequence of int, optional
        Points per linear axis (default: the command's).
    probe : (3,) mm
        Probe / tool offset.
    at : dict, optional
        Positions of the rotary axes during the test, deg (default 0).
    volume : {"travel", "measured"}
        The layout's travel, or the part of it the tables cover.
    approach : dict or str, optional
        ``{axis: +1 or -1}`` or the option's text (``"X+,Y-"``, ``"+"``, ``"-"``): evaluate
        the tables' reversal for that approach direction.
    method, degree, extrapolate
        How the tables are interpolated (as ``--method``, ``--degree``, ``--extrapolate``).
    accept_implausible : bool
        Use table values beyond what a machine of the layout's travel can have
        (:mod:`volerr.tables.plausible`; by default refused naming the likely unit).
    magnify : float, optional
        Error magnification of the plots (:meth:`ErrorMap.write_plot`; > 0; default
        automatic).

    Returns
    -------
    ErrorMap
        ``to_dict()`` is ``--json``: max ``|dx|``, ``|dy|``, ``|dz|``, max and RMS ``|d|``
        (um; actual minus nominal probe tip), and the random part's maximum (k = 1); after
        :meth:`ErrorMap.write_plot` also the plots' magnifications.
    """
    import math

    from ..errors import require
    from ..machine.model import Model, load
    from ..tables.functions import ErrorFunctions, parse_approach
    from . import volmap

    require(magnify is None or (math.isfinite(magnify) and magnify > 0),
            f"--magnify must be a positive finite number, got {magnify}")
    model = layout if isinstance(layout, Model) else load(layout)
    from ..tables.plausible import DEFAULT_SIZE_MM, machine_size
    from ..units import check_offset_mm

    funcs = errors if isinstance(errors, ErrorFunctions) else ErrorFunctions.from_dir(
        errors, model, method=method, degree=degree, extrapolate=extrapolate,
        accept_implausible=accept_implausible)
    probe = check_offset_mm(probe, "--probe", machine_size(model) or DEFAULT_SIZE_MM, "offset")
    if not isinstance(approach, dict):
        approach = parse_approach(approach, model, funcs)
    grid = [grid] if isinstance(grid, int) else grid
    vmap = volmap.volumetric_map(model, funcs, grid, tuple(probe), dict(at or {}),
                                 box=volmap.volume(model, funcs, volume), approach=approach)
    s = vmap.summary()
    if approach:
        s["approach"] = {a: ("+" if v > 0 else "-") for a, v in approach.items()}
    return ErrorMap(s, vmap, magnify)


@dataclass(repr=False)
class Diagonals(ResultMixin):
    """Result of :func:`diagonals`: ``data`` the ``--json`` document (per line its length
    deviation dL = actual minus nominal distance of the probe tip, um, with its random part
    u(dL), k = 1, where the tables carry standard deviations, and the profile along it),
    ``lines`` the evaluated lines."""

    data: dict
    lines: list

    def summary(self, written: dict | None = None) -> str:
        """What ``volerr diagonals`` prints; ``written``: ``{label: path}`` of the files
        written (``json``, ``plot``), one line each at the end."""
        from .diagonals import format_table

        probe = " ".join(f"{v:g}" for v in self.data["probe_mm"])
        return "\n".join([f"{self.data['layout']}: length deviation dL = actual - nominal "
                          f"distance of the probe tip (first order), probe {probe} mm",
                          format_table(self.lines)]
                         + [f"{label}: {path}" for label, path in (written or {}).items()
                            if path])

    def write_plot(self, path, inputs=()):
        """``--plot``: the space-diagonal profiles and every line's deviation
        (:func:`volerr.cmm.diagonals.plot_lines`); returns the path."""
        from .diagonals import plot_lines

        title = f"{self.data['layout']}: length deviations ({self.data['errors']})"
        plot_lines(self.lines, path, title, inputs)
        return path

    def _rows(self) -> list:
        """One row per line: its length deviation dL (um, positive: the line measures long)
        with the standard uncertainty (k = 1) of its random part where the tables carry
        one."""
        from ..results import Row

        return [Row(f"dL({ln['name']})", float(ln["deviation_um"]),
                    None if ln.get("random_um") is None else float(ln["random_um"]), "um", 1.0)
                for ln in self.data["lines"]]


def diagonals(layout, errors, *, lines=None, probe=(0.0, 0.0, 0.0), at=None,
              volume: str = "travel", profile_points: int = 21, method: str = "linear",
              degree: int | None = None, extrapolate: bool = False,
              accept_implausible: bool = False) -> Diagonals:
    """Length deviations of the space diagonals (Pahk sec. 4), face diagonals and
    axis-parallel lines of the working volume (``volerr diagonals``).

    Parameters
    ----------
    layout : str, path or volerr.Model
        Layout name or file (or a loaded model).
    errors : path or volerr.tables.ErrorFunctions
        Error directory or error functions made from one.
    lines : sequence of str, optional
        Which lines (:data:`volerr.cmm.diagonals.KINDS`; default all).
    probe : (3,) mm
        Probe / tool offset.
    at : dict, optional
        Positions of the rotary axes, deg.
    volume : {"travel", "measured"}
        The box of the lines.
    profile_points : int
        Points along each line for its profile (2 .. 10000).
    method, degree, extrapolate
        How the tables are interpolated.
    accept_implausible : bool
        Use table values beyond what a machine of the layout's travel can have
        (:mod:`volerr.tables.plausible`; by default refused naming the likely unit).

    Returns
    -------
    Diagonals
        ``to_dict()`` is ``--json``; dL in um (positive: the line measures long).
    """
    from ..errors import require
    from ..machine.model import Model, load
    from ..tables.functions import ErrorFunctions
    from . import diagonals as dg
    from .volmap import linear_axes, volume as box

    require(2 <= profile_points <= 10000, "--profile-points must be between 2 and 10000")
    model = layout if isinstance(layout, Model) else load(layout)
    funcs = errors if isinstance(errors, ErrorFunctions) else ErrorFunctions.from_dir(
        errors, model, method=method, degree=degree, extrapolate=extrapolate,
        accept_implausible=accept_implausible)
    found = dg.box_lines(box(model, funcs, volume), linear_axes(model),
                         tuple(lines or dg.KINDS))
    results = dg.evaluate_lines(model, funcs, found, tuple(probe), dict(at or {}),
                                profile_points)
    doc = {"layout": model.name, "probe_mm": [float(v) for v in probe],
           "errors": (funcs.source or "") if errors is funcs else str(errors), "method": method,
           "lines": [r.as_dict() for r in results], "budgets": dg.budgets(results)}
    return Diagonals(doc, results)


@dataclass(repr=False)
class Squareness(ResultMixin):
    """Result of :func:`squareness`: ``data`` the ``--json`` document (squareness, its standard
    uncertainty (k = 1) and the straightness slopes, urad; sign convention
    :mod:`volerr.cmm.squareness`), ``values`` / ``std`` the squareness in rad, ``texts`` the
    slope-free tables as CSV text by file name, ``constants`` / ``constants_std`` (rad, mm) the
    constants to write: those of the input directory with the squareness replaced."""

    data: dict
    values: dict
    std: dict
    texts: dict
    constants: dict
    constants_std: dict
    layout: object = None               # the layout the tables are of (their size limits)
    accept_implausible: bool = False    # --accept-implausible: the limits waived

    def summary(self) -> str:
        """What ``volerr squareness`` prints (without the line naming the written folder)."""
        from ..units import URAD_PER_RAD

        return "\n".join(f"{sq} = {v * URAD_PER_RAD:.3f} urad (u = "
                         f"{self.std[sq] * URAD_PER_RAD:.3f} urad)"
                         for sq, v in self.values.items())

    def write_dir(self, folder, inputs=()) -> None:
        """The slope-free tables and ``constants.csv`` into ``folder`` (``--errors-out``)."""
        from pathlib import Path

        from ..fileio import write_text
        from ..tables.table import write_constants

        folder = Path(folder)
        for name, text in self.texts.items():
            write_text(folder / name, text, inputs=list(inputs))
        write_constants(folder / "constants.csv", self.constants, inputs=list(inputs),
                        std=self.constants_std, machine=self.layout,
                        accept_implausible=self.accept_implausible)

    def _rows(self) -> list:
        from ..results import Row

        return [Row(k, v, self.data["u_urad"][k], "urad", 1)
                for k, v in self.data["squareness_urad"].items()]


def squareness(layout, directory, *, tables_are: str = "carrier",
               accept_implausible: bool = False) -> Squareness:
    """Squareness of the linear axes from the reference straight lines of the straightness
    tables of ``directory`` (``volerr squareness``).

    Parameters
    ----------
    layout : str or path
        Layout name or file.
    directory : path
        Error directory with the straightness tables (``X.csv`` ..., e.g. written by
        ``volerr identify``).
    tables_are : {"carrier", "component"}
        carrier: motions of the component carrying the points (as ``volerr identify``
        writes them); component: ISO component errors (tool relative to workpiece).
    accept_implausible : bool
        Accept tables beyond what a machine of the layout's travel can have
        (:mod:`volerr.tables.plausible`); by default refused with the likely unit.

    Returns
    -------
    Squareness
        ``EC0Y EB0Z EA0Z`` (those whose two straightness tables exist), rad, with the tables
        with the slopes removed.
    """
    from pathlib import Path

    from ..errors import require
    from ..machine.layout import read_layout
    from ..tables.table import read_error_dir, table_to_csv
    from ..units import URAD_PER_RAD
    from .squareness import budgets as leg_budgets, squareness as fit

    lay = read_layout(layout)
    src = Path(directory)
    require(src.exists(), f"error directory {src} does not exist")
    require(src.is_dir(), f"{src} is a file: give the error directory (X.csv, Y.csv ...)")
    tables, (consts, cstd, _) = read_error_dir(src, axes=lay.axis_names, machine=lay,
                                               accept_implausible=accept_implausible)
    require(tables, f"{src}: no error tables")
    values, std, corrected, slopes = fit(tables, lay, tables_are)
    require(values, f"{src}: no pair of straightness tables for a squareness (EC0Y needs EYX "
                    f"in X.csv and EXY in Y.csv, EB0Z EZX and EXZ, EA0Z EZY and EYZ)")
    merged = {k: v for k, v in consts.items() if k not in values}
    merged_std = {k: v for k, v in cstd.items() if k in merged}
    merged.update(values)
    merged_std.update(std)
    doc = {"squareness_urad": {k: v * URAD_PER_RAD for k, v in values.items()},
           "u_urad": {k: v * URAD_PER_RAD for k, v in std.items()},
           "slopes_urad": {k: v * URAD_PER_RAD for k, v in slopes.items()},
           "tables_are": tables_are, "budgets": leg_budgets(tables, values)}
    texts = {f"{ax}.csv": table_to_csv(t) for ax, t in corrected.items()}
    return Squareness(doc, values, std, texts, merged, merged_std, lay, accept_implausible)
