"""``volerr.error_map(...)``: the Python API of ``volerr map`` (:mod:`volerr.results`)."""

from __future__ import annotations

from dataclasses import dataclass

from ..results import ResultMixin


@dataclass(repr=False)
class ErrorMap(ResultMixin):
    """Result of :func:`error_map`: ``data`` the ``--json`` summary (um), ``map`` the
    :class:`volerr.cmm.volmap.VolumetricMap` (positions mm / deg, errors (N, 3) mm, their
    standard uncertainty (k = 1) ``random`` where the tables carry one)."""

    data: dict
    map: object

    def summary(self) -> str:
        """What ``volerr map`` prints (without the lines naming the written files)."""
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
        return "\n".join(out)

    def write_csv(self, path, inputs=()):
        """The map CSV of ``volerr map --out``: positions, probe, dx_um dy_um dz_um (and
        their u columns)."""
        from .volmap import write_map_csv

        return write_map_csv(path, self.map, inputs)

    def _rows(self) -> list:
        return []


def error_map(layout, errors, *, grid=None, probe=(0.0, 0.0, 0.0), at=None,
              volume: str = "travel", approach=None, method: str = "linear",
              degree: int | None = None, extrapolate: bool = False) -> ErrorMap:
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
    approach : dict, optional
        ``{axis: +1 or -1}``: evaluate the tables' reversal for that approach direction.
    method, degree, extrapolate
        How the tables are interpolated (as ``--method``, ``--degree``, ``--extrapolate``).

    Returns
    -------
    ErrorMap
        ``to_dict()`` is ``--json``: max ``|dx|``, ``|dy|``, ``|dz|``, max and RMS ``|d|`` (um; actual minus
        nominal probe tip), and the random part's maximum (k = 1).
    """
    from ..machine.model import Model, load
    from ..tables.functions import ErrorFunctions
    from . import volmap

    model = layout if isinstance(layout, Model) else load(layout)
    funcs = errors if isinstance(errors, ErrorFunctions) else ErrorFunctions.from_dir(
        errors, model, method=method, degree=degree, extrapolate=extrapolate)
    grid = [grid] if isinstance(grid, int) else grid
    vmap = volmap.volumetric_map(model, funcs, grid, tuple(probe), dict(at or {}),
                                 box=volmap.volume(model, funcs, volume), approach=approach)
    s = vmap.summary()
    if approach:
        s["approach"] = {a: ("+" if v > 0 else "-") for a, v in approach.items()}
    return ErrorMap(s, vmap)
