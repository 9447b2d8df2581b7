"""The ``deviations`` instrument: 3-D deviations of the tool point (a CMM against a reference, a
laser tracker, any instrument that gives the actual minus the nominal position).

Reading: ``dx, dy, dz`` = actual minus nominal position of the probe tip / tool point in the
workpiece frame (the instrument's frame), um or mm; the projection is the identity and the
set-up is the instrument's rigid placement (three translations, three small rotations of the
workpiece end of the chain, through the layout's generated ``setup_sensitivity``).
File format: ``volerr formats deviations``.
"""

from __future__ import annotations

import re

import numpy as np

from ..errors import require
from ..machine.model import Model
from ._csv import read_columns
from .observations import FileInfo, Observations

AXIS_NAMES = "XYZUVWABC"
KIND = "deviations"


def read_deviations(path, model: Model) -> Observations:
    """Read a measured-deviation CSV and check it against ``model`` (InputError on defects)."""
    c = read_columns(path)
    obs = columns_to_data(c.numbers, model, c.name, c.text)
    obs.files = (FileInfo(c.name, KIND, "um", 3),)
    return obs


def columns_to_data(cols: dict, model: Model, where: str = "data", text=None) -> Observations:
    """Column dict (CSV names) -> :class:`Observations`, checking axes, units and ranges.

    ``text``: columns that are not all numbers (name -> the first bad cell's message, None for a
    label column): an error when the column is needed, else a warning and left out.  A
    covariate with NaN is left out with a warning; positions, offsets and deviations must be
    finite."""
    cols, text = dict(cols), dict(text or {})
    for h in list(cols):
        v = np.asarray(cols[h], dtype=float)
        if not np.all(np.isfinite(v)):
            k = int(np.flatnonzero(~np.isfinite(v))[0])
            text[h] = f"{where}: column {h} row {k + 2} is NaN or infinite"
            del cols[h]
    warnings = _text_columns(text, model, where)
    find = _Finder(cols, where)
    positions = _positions(find, model, where)
    n = len(next(iter(positions.values())))
    probe = _probe(find, n, where)
    dev = _deviations(find, cols, n, where)
    covs = {c: v for c, v in cols.items() if c not in find.used
            and not c.startswith(("dx", "dy", "dz"))}
    missing = [c for c in model.covariates if c not in covs]
    require(not missing, f"{where}: layout {model.name} needs covariate column "
            f"{missing[0] if missing else ''}")
    return Observations(positions, probe, dev, covs, warnings)


def _text_columns(text: dict, model: Model, where: str) -> list:
    """Refuse a needed column that is not numeric; one warning for each other such column."""
    needed = {a + u for a in model.axes for u in ("", "_mm", "_deg")}
    needed |= {c + u for c in ("Xp", "Yp", "Zp") for u in ("", "_mm")}
    needed |= {f"{d}_{u}" for d in ("dx", "dy", "dz") for u in ("um", "mm")}
    needed |= set(model.covariates)
    warnings = []
    for h, msg in text.items():
        require(h not in needed, msg or f"{where}: column {h} is not numeric")
        warnings.append(f"column {h} is not numeric: left out of the candidates" if msg is None
                        else f"column {h} has a value that is not a finite number: left out "
                             f"of the candidates")
    return warnings


class _Finder:
    """Finds a column under one of its unit spellings; remembers the columns used."""

    def __init__(self, cols: dict, where: str):
        self.cols, self.where, self.used = cols, where, set()

    def __call__(self, name, units, what):
        hits = [f"{name}{u}" for u in units if f"{name}{u}" in self.cols]
        require(len(hits) <= 1, f"{self.where}: both {' and '.join(hits)} given for {what}")
        if hits:
            self.used.add(hits[0])
            return hits[0]
        return None


def _positions(find: _Finder, model: Model, where: str) -> dict:
    """Axis columns (mm | deg): every axis of the layout, no other, inside the travel."""
    cols, positions = find.cols, {}
    for a in model.axes:
        unit = ("", "_deg") if a in model.rotary_axes else ("", "_mm")
        c = find(a, unit, f"axis {a}")
        require(c is not None, f"{where}: missing axis column {a} (layout {model.name} has "
                f"axes {' '.join(model.axes)})")
        positions[a] = cols[c]
    extra_axes = [h for h in cols if re.fullmatch(rf"[{AXIS_NAMES}](_mm|_deg)?", h)
                  and h[0] not in model.axes]
    require(not extra_axes, f"{where}: axis column {extra_axes[0] if extra_axes else ''} is "
            f"not an axis of layout {model.name} ({' '.join(model.axes)}): layout mismatch")
    n = len(next(iter(positions.values())))
    require(n >= 20, f"{where}: too few points ({n}); the loop needs at least 20")
    for a, v in positions.items():
        lo, hi = model.travel[a]
        margin = 0.05 * (hi - lo)
        out = np.flatnonzero((v < lo - margin) | (v > hi + margin))
        require(len(out) == 0, f"{where}: {a} = {v[out[0]] if len(out) else 0:g} lies outside "
                f"the travel [{lo:g}, {hi:g}] of layout {model.name}: layout mismatch")
    return positions


def _probe(find: _Finder, n: int, where: str) -> np.ndarray:
    """Probe / tool offsets (n, 3) mm: all of Xp, Yp, Zp or none (zero)."""
    pc = [find(c, ("", "_mm"), f"probe offset {c}") for c in ("Xp", "Yp", "Zp")]
    require(all(c is None for c in pc) or all(c is not None for c in pc),
            f"{where}: give all of Xp, Yp, Zp or none")
    if pc[0] is None:
        return np.zeros((n, 3))
    return np.column_stack([find.cols[c] for c in pc])


def _deviations(find: _Finder, cols: dict, n: int, where: str) -> np.ndarray:
    """Deviations (n, 3) mm from dx/dy/dz columns in um or mm, plausibility-checked."""
    dev = np.zeros((n, 3))
    for i, d in enumerate(("dx", "dy", "dz")):
        require(d not in cols, f"{where}: deviation column {d} has no unit suffix "
                f"(use {d}_um or {d}_mm)")
        c_um, c_mm = find(d, ("_um",), d), find(d, ("_mm",), d)
        require(not (c_um and c_mm), f"{where}: both {d}_um and {d}_mm given")
        for bad in (f"{d}_nm", f"{d}_m", f"{d}_in", f"{d}_urad", f"{d}_rad"):
            require(bad not in cols, f"{where}: deviation column {bad}: unit not supported "
                    f"(use {d}_um or {d}_mm)")
        require(c_um or c_mm, f"{where}: missing deviation column {d}_um (or {d}_mm)")
        dev[:, i] = cols[c_um] * 1e-3 if c_um else cols[c_mm]
    big = float(np.max(np.abs(dev)))
    require(big < 5.0, f"{where}: deviations up to {big:g} mm are implausible for an error "
            f"map: wrong unit (um given as mm?) or nominal instead of deviation values")
    return dev


