"""The geometry check of an instrument's file against the layout: one place for every kind.

Each instrument's reader states what its file claims about the geometry -- the commanded tool
point (the layout's nominal forward kinematics at the file's axis positions with its tool
offset ``Xp, Yp, Zp``) meets a declared target: the sphere centre (sphere / R-test), the pivot
at the bar length (ballbar), the station's distances (tracking interferometer), the artifact's
calibrated balls (ball plate) -- as a *misfit*: a function of (model, positions, offsets,
targets) giving the worst miss in mm, the tolerance it is held against and one phrase saying
where it happens.  :func:`require_consistent` refuses a file whose misfit exceeds its
tolerance, and names the likely cause by trying the usual technician's mistakes one at a time
and keeping the one that makes the file consistent:

* rotary axes in radians (their columns times 180/pi),
* axis positions and tool offset in inches (times 25.4), or the target's columns in inches,
* the tool offset with the wrong sign (``Xp, Yp, Zp`` negated), in the wrong column (two of
  them exchanged), in m, um or inches (x 1000, / 1000, x 25.4),
* a rotary axis counting the other way (its column negated),
* two axis columns swapped (``X`` <-> ``Y`` ...),
* the file of another machine (every shipped layout with the same axes),
* an instrument's own alternatives (a bar length that is a diameter, distances in m ...).

The sign convention of the offset is the chain's (``volerr.generated.*.nominal_position``):
``Xp, Yp, Zp`` is the vector from the point the axis positions refer to (the spindle / ram
reference point) to the tool point, in the tool (ram) frame, whose ``+z`` is the tool axis
pointing from the tool point towards the spindle; a tool of length L hanging below the
reference point is ``(0, 0, -L)``.  ``docs/conventions.md`` ("Tool and probe offsets") draws it.

A miss no alternative explains is still refused, naming the file, the columns and saying that
none of the usual mistakes explains it -- or, when a rotary axis column holds one value in
every row, naming that column (the export lost the axis).  Nothing is written: the readers run before outputs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import InputError

#: millimetres per inch
INCH_MM = 25.4


@dataclass
class Miss:
    """The worst miss of a file's geometry: ``worst`` mm against ``tolerance`` mm, ``text``
    where (``"placement 1 row 5: the tool point misses the sphere centre by 224 mm"``)."""

    worst: float
    tolerance: float
    text: str

    @property
    def ratio(self) -> float:
        return self.worst / self.tolerance if np.isfinite(self.worst) else np.inf


@dataclass
class Geometry:
    """What an instrument's file claims: axis positions ``pos`` {axis: (n,)} (mm / deg), the
    tool offsets ``probe`` (n, 3) mm, the targets {name: array} (mm) and the column names of
    each target (for the message); ``misfit(model, pos, probe, targets) -> Miss``."""

    pos: dict
    probe: np.ndarray
    targets: dict
    target_columns: dict
    misfit: Callable


def _alternatives(model, g: Geometry, extra=()):
    """(cause, columns, model, pos, probe, targets) of every usual mistake, in the order they
    are reported when several explain the file equally well."""
    rot = [a for a in model.rotary_axes if a in g.pos]
    lin = [a for a in model.axes if a not in model.rotary_axes and a in g.pos]
    small = [a for a in rot if float(np.max(np.abs(g.pos[a]))) <= 2 * np.pi + 1e-6]
    for group in ([small] if len(small) > 1 else []) + [[a] for a in small]:
        yield (f"rotary {'axes' if len(group) > 1 else 'axis'} in radians, not degrees (with "
               f"{', '.join(group)} x 180/pi the file is consistent)", ", ".join(group), model,
               {**g.pos, **{a: np.degrees(g.pos[a]) for a in group}}, g.probe, g.targets)
    off = [j for j in range(3) if np.any(g.probe[:, j] != 0)]
    for group in ([off] if off else []) + ([[j] for j in off] if len(off) > 1 else []):
        names = ", ".join("XYZ"[j] + "p" for j in group)
        flipped = g.probe.copy()
        flipped[:, group] *= -1.0
        yield (f"the tool offset with the wrong sign ({names} negated makes the file "
               f"consistent; the offset is the vector from the reference point to the tool "
               f"point in the tool frame, +z towards the spindle)", names, model, g.pos,
               flipped, g.targets)
    yield from _offset_alternatives(model, g, off)
    for a in rot:
        yield (f"rotary axis {a} counting the other way (sense reversed: with {a} negated the "
               f"file is consistent; the controller's sign of {a} differs from the layout's)",
               a, model, {**g.pos, a: -g.pos[a]}, g.probe, g.targets)
    for name, cols in g.target_columns.items():
        yield (f"{name} in inches (x 25.4 makes the file consistent)", cols, model, g.pos,
               g.probe, {**g.targets, name: g.targets[name] * INCH_MM})
    if lin:
        yield (f"axis positions and tool offset in inches (x 25.4 makes the file consistent)",
               ", ".join(lin + ["Xp", "Yp", "Zp"]), model,
               {**g.pos, **{a: g.pos[a] * INCH_MM for a in lin}}, g.probe * INCH_MM, g.targets)
        scaled = {k: v * INCH_MM for k, v in g.targets.items()}
        yield ("every length in inches (x 25.4 makes the file consistent)", "every length column",
               model, {**g.pos, **{a: g.pos[a] * INCH_MM for a in lin}}, g.probe * INCH_MM,
               scaled)
    for group in (lin, rot):
        for i, a in enumerate(group):
            for b in group[i + 1:]:
                yield (f"columns {a} and {b} swapped (exchanged, the file is consistent)",
                       f"{a}, {b}", model, {**g.pos, a: g.pos[b], b: g.pos[a]}, g.probe,
                       g.targets)
    for cause, cols, targets in extra:
        yield cause, cols, model, g.pos, g.probe, {**g.targets, **targets}
    yield from _other_layouts(model, g)


def _offset_alternatives(model, g: Geometry, off):
    """The tool offset typed into the wrong column (two of Xp Yp Zp exchanged) or in m / um /
    inches (x 1000, / 1000, x 25.4): only for a file with a non-zero offset ``off`` (its
    columns)."""
    if not off:
        return
    for i, j in ((0, 2), (1, 2), (0, 1)):
        if i in off or j in off:
            p = g.probe.copy()
            p[:, [i, j]] = p[:, [j, i]]
            names = f"{'XYZ'[i]}p, {'XYZ'[j]}p"
            yield (f"the tool offset in the wrong column ({names} swapped makes the file "
                   f"consistent)", names, model, g.pos, p, g.targets)
    names = ", ".join("XYZ"[j] + "p" for j in off)
    for unit, factor in (("m", 1000.0), ("um", 1e-3), ("inches", INCH_MM)):
        yield (f"the tool offset in {unit}, not mm (x {factor:g} makes the file consistent)",
               names, model, g.pos, g.probe * factor, g.targets)


def _stuck_rotary(model, g: Geometry) -> str | None:
    """A rotary axis column holding one value in every row of a file that needs it moving
    (the export lost the axis): the clause for the refusal, or None."""
    for a in model.rotary_axes:
        v = np.asarray(g.pos.get(a, ()), dtype=float)
        if v.size > 1 and float(np.ptp(v)) == 0.0:
            return (f"column {a}: constant ({v[0]:g} deg in every row): the rotary axis is "
                    f"stuck in the export (a lost column?)")
    return None


def _other_layouts(model, g: Geometry):
    """Every shipped layout with exactly the file's axes (the file of another machine)."""
    from ..machine.layout import layout_names
    from ..machine.model import load

    for name in layout_names():
        if name == model.name:
            continue
        try:
            other = load(name)
        except Exception:       # a layout that cannot load is not a candidate  # noqa: BLE001
            continue
        if set(other.axes) != set(g.pos):
            continue
        yield (f"the file of another machine: it fits layout {name}", "the axis columns",
               other, g.pos, g.probe, g.targets)


def _trial(misfit, model, pos, probe, targets) -> Miss:
    """The misfit of one interpretation (an interpretation that cannot be evaluated misses)."""
    try:
        with np.errstate(all="ignore"):
            return misfit(model, pos, probe, targets)
    except (InputError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return Miss(np.inf, 1.0, "")


def diagnose(model, g: Geometry, extra=()) -> tuple[str, str] | None:
    """(cause, columns) of the usual mistake that makes the file consistent (the smallest
    remaining misfit; ties: the order of :func:`_alternatives`), or None."""
    best = None
    for cause, cols, m, pos, probe, targets in _alternatives(model, g, extra):
        miss = _trial(g.misfit, m, pos, probe, targets)
        if miss.ratio <= 1.0 and (best is None or miss.ratio < best[0]):
            best = (miss.ratio, cause, cols)
    return None if best is None else (best[1], best[2])


def require_consistent(where: str, model, g: Geometry, extra=()) -> None:
    """Refuse (InputError, one line: file, columns, likely cause) a file whose geometry misses
    by more than its tolerance.  ``extra``: the instrument's own alternatives ``(cause,
    columns, {target: value})``."""
    with np.errstate(all="ignore"):
        miss = g.misfit(model, g.pos, g.probe, g.targets)   # the file's own defects raise
    if miss.ratio <= 1.0:
        return
    found = diagnose(model, g, extra)
    tail = (f"{miss.text}: the file and layout {model.name} disagree beyond "
            f"{miss.tolerance:g} mm")
    stuck = _stuck_rotary(model, g) if found is None else None
    if stuck is not None:
        raise InputError(f"{where}: {stuck}; {tail}")
    if found is None:
        raise InputError(f"{where}: {tail}; no usual mistake (radians, inches, the tool "
                         f"offset's sign, swapped axis columns, another layout) explains it")
    cause, cols = found
    word = "columns" if "," in cols else "column"
    raise InputError(f"{where}: {word} {cols}: likely {cause}; {tail}")


def inside_travel(model, pos: dict, margin: float = 0.05) -> bool:
    """Every position inside the layout's travel widened by ``margin`` of its span."""
    for a, v in pos.items():
        lo, hi = model.travel[a]
        m = margin * (hi - lo)
        if np.any((np.asarray(v) < lo - m) | (np.asarray(v) > hi + m)):
            return False
    return True


def travel_cause(model, pos: dict) -> str | None:
    """The usual mistake that brings positions outside the travel back inside it: two axis
    columns swapped, linear positions in um, the file of another machine (a shipped layout
    with the same axes whose travel holds the positions); None when none does."""
    from ..machine.layout import layout_names
    from ..machine.model import load

    lin = [a for a in model.axes if a not in model.rotary_axes and a in pos]
    rot = [a for a in model.rotary_axes if a in pos]
    for group in (lin, rot):
        for i, a in enumerate(group):
            for b in group[i + 1:]:
                if inside_travel(model, {**pos, a: pos[b], b: pos[a]}):
                    return f"columns {a} and {b} swapped"
    spans = [np.ptp(pos[a]) * 1e-3 >= 0.1 * (model.travel[a][1] - model.travel[a][0])
             for a in lin]
    if lin and any(spans) and inside_travel(model, {**pos, **{a: pos[a] * 1e-3 for a in lin}}):
        return "linear axis positions in um, not mm"
    fits = []
    for name in layout_names():
        other = load(name) if name != model.name else None
        if other is not None and set(other.axes) == set(pos) and inside_travel(other, pos, 0.0):
            fits.append(name)
    if fits:
        return (f"the file of another machine (its positions lie inside the travel of "
                f"{', '.join(fits[:4])}{' ...' if len(fits) > 4 else ''})")
    return None


# ---- the misfits of each instrument ------------------------------------------------------
def _worst(values: np.ndarray) -> int:
    """Index of the largest value (NaN counts as largest; the first of equal ones)."""
    v = np.where(np.isfinite(values), values, np.inf)
    return int(np.argmax(v))


#: sphere / R-test: the largest spread (mm) of (tool point - centre - reading) within one
#: placement (the machine's errors and the probing; beyond it the positions do not put the
#: tool point on one sphere)
SPHERE_SPREAD_MM = 1.0
#: sphere / R-test: the largest offset (mm) of a placement's sphere from its nominal centre
#: (the readings themselves are limited to 5 mm)
SPHERE_PLACEMENT_MM = 5.0


def sphere_misfit(labels: np.ndarray, reading: np.ndarray, machine_rows: np.ndarray):
    """The misfit of a sphere file: per placement, ``r = t - c - d`` (the reading ``d`` in the
    workpiece frame: rows read in the machine frame turned back) holds the placement's unknown
    centre offset; its spread must stay within :data:`SPHERE_SPREAD_MM` and its median within
    :data:`SPHERE_PLACEMENT_MM`."""
    labels = np.asarray(labels).astype(str)

    def misfit(model, pos, probe, targets) -> Miss:
        t = model.nominal_position(pos, probe)
        d = reading.copy()
        if machine_rows.any():
            rot = model.module.work_rotation(**model.positions(
                {a: v[machine_rows] for a, v in pos.items()}))
            R = np.moveaxis(np.broadcast_to(rot, (3, 3, int(machine_rows.sum()))), -1, 0)
            d[machine_rows] = np.einsum("nji,nj->ni", R, d[machine_rows])
        r = t - targets["the sphere centre"] - d
        best = Miss(0.0, SPHERE_SPREAD_MM, "")
        for name in dict.fromkeys(labels):
            rows = np.flatnonzero(labels == name)
            med = np.median(r[rows], axis=0)
            spread = np.linalg.norm(r[rows] - med, axis=1)
            k = _worst(spread)
            for m in (Miss(float(spread[k]), SPHERE_SPREAD_MM,
                           f"placement {name} row {rows[k] + 2}: the commanded tool point "
                           f"strays {spread[k]:.3g} mm from the placement's sphere centre"),
                      Miss(float(np.linalg.norm(med)), SPHERE_PLACEMENT_MM,
                           f"placement {name}: the commanded tool point misses the sphere "
                           f"centre by {np.linalg.norm(med):.3g} mm")):
                best = m if m.ratio > best.ratio else best
        return best
    return misfit


def ballbar_misfit(reading: np.ndarray, tolerance: float):
    """The misfit of a ballbar file: ``|t - p| - length - dr`` at every row (mm), within
    ``tolerance`` (the pivot's and the bar's unknown offsets and the machine's errors)."""

    def misfit(model, pos, probe, targets) -> Miss:
        t = model.nominal_position(pos, probe)
        dist = np.linalg.norm(t - targets["the pivot"], axis=1)
        off = np.abs(dist - targets["the bar length"] - reading)
        k = _worst(off)
        return Miss(float(off[k]), tolerance,
                    f"row {k + 2}: the tool ball is {dist[k]:.4f} mm from the pivot, "
                    f"length_mm is {float(targets['the bar length'][k]):g}")
    return misfit


def distances_misfit(labels: np.ndarray, locate, tolerance: float):
    """The misfit of a tracking-interferometer file: per station, the RMS (mm) of the
    distances after locating the station and its dead path on the nominal tool points."""
    labels = np.asarray(labels).astype(str)

    def misfit(model, pos, probe, targets) -> Miss:
        t = model.nominal_position(pos, probe)
        d = targets["the distances"]
        best = Miss(0.0, tolerance, "")
        for name in dict.fromkeys(labels):
            m = labels == name
            _, _, rms = locate(t[m], d[m], None, f"station {name}")
            if not rms <= best.worst:
                best = Miss(float(rms) if np.isfinite(rms) else np.inf, tolerance,
                            f"station {name}: the distances do not fit the commanded tool "
                            f"points (RMS {rms:.3g} mm after locating the station)")
        return best
    return misfit


def artifact_misfit(labels: np.ndarray, rigid_fit, tolerance: float):
    """The misfit of an artifact file: per placement, the largest distance (mm) between a
    measured point and its calibrated point placed by the best-fitting rigid pose."""
    labels = np.asarray(labels).astype(str)

    def misfit(model, pos, probe, targets) -> Miss:
        measured, point = targets["the measured points"], targets["the calibrated coordinates"]
        best = Miss(0.0, tolerance, "")
        for name in dict.fromkeys(labels):
            m = labels == name
            R, o = rigid_fit(point[m], measured[m])
            dist = np.linalg.norm(measured[m] - (point[m] @ R.T + o), axis=1)
            k = _worst(dist)
            if not dist[k] <= best.worst:
                best = Miss(float(dist[k]), tolerance,
                            f"placement {name} row {np.flatnonzero(m)[k] + 2}: a measured point "
                            f"lies {dist[k]:.3f} mm from its calibrated point in the "
                            f"best-fitting pose")
        return best
    return misfit
