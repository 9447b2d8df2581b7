"""The ``interferometer`` instrument: a laser interferometer along one line of a linear axis --
positioning (linear optics: the ISO 230-2 run), straightness optics, angular optics.

A file is a run of one axis in the ISO 230-2 formats (``volerr formats "ISO 230-2 positioning
run"``: long ``target_mm,cycle,direction,deviation_um`` or wide) with the line described in
header lines ``# key: value`` (which ``volerr iso230-2`` ignores):

* ``axis`` (required) the moving linear axis; ``mode`` ``positioning`` (default),
  ``straightness`` or ``angular``;
* ``at`` the positions of the other axes (``Y=250, Z=300``; default the middle of their
  travel, rotary axes 0);
* ``optics`` the position of the moving optic relative to the tool point, in the tool frame
  (``Xp, Yp, Zp`` mm; the Abbe arms; default 0, 0, 0);
* ``beam`` the beam direction in the workpiece frame (default the axis' direction of motion);
* ``sense``: straightness -- the direction of the measured displacement; angular -- the axis
  of the measured rotation (required for those modes);
* ``separation`` the reflectors' separation of the angular optics (mm, default 30);
* ``u_um`` (``u_urad`` angular) the standard uncertainty of one reading (default 0.2 um,
  0.5 urad); ``scale_u_ppm`` the standard uncertainty of the reading's scale (default 0.25).

Readings (derived: :mod:`volerr.derive.observations`), ``t`` the nominal position of the
moving optic (the chain at the commanded positions, offset ``optics``), ``e`` the volumetric
error there, ``r`` the optic's nominal position at the first target (where the interferometer
was zeroed):

* positioning: ``P - P_ref + deviation = (1 + k) b . (t + e - r) + z``: set-up unknowns the
  zero offset ``z`` (um: zeroing, dead-path error) and the scale ``k`` (ppm: cosine error of
  the beam alignment, air compensation), the latter known to be 0 within ``scale_u_ppm``;
* straightness: ``deviation = s . (t + e - r) + z + m b . (t + e - r)``: the offset ``z`` (um)
  and angle ``m`` (urad) of the beam line (straightness is read about a reference line);
* angular: ``deviation = b . (e(t2) - e(t)) / L + z`` (urad) with the second reflector at
  ``t2 = t + L (b x a)``, ``a`` the ``sense``: the relative rotation of the tool about ``a``;
  unknown zero ``z``.

The direction of approach of each reading is a covariate ``dir_<axis>`` (+1 / -1: a reversal
for the loop).  File format: ``volerr formats interferometer``.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import InputError, require, require_file
from ..fileio import refuse_repeated_readings
from ..units import check_reading_spread_um
from ..generated import instruments as generated
from ..machine.model import Model
from . import _fields as f
from .observations import FileInfo, Observations, Setup

KIND = "interferometer"
MODES = ("positioning", "straightness", "angular")
DEFAULT_U = {"positioning": 0.2, "straightness": 0.2, "angular": 0.5}
DEFAULT_SCALE_U_PPM = 0.25
DEFAULT_SEPARATION_MM = 30.0
KEYS = {"positioning": ("zero", "scale"), "straightness": ("zero", "slope"),
        "angular": ("zero",)}
UNITS = {"positioning": ("um", "ppm"), "straightness": ("um", "urad"), "angular": ("urad",)}
META_KEYS = ("axis", "mode", "at", "optics", "beam", "sense", "separation", "u_um", "u_urad",
             "scale_u_ppm")
_TARGET = re.compile(r"^(target(?:[ _]?position)?|position)(?:[ _]?[(\[]?(um|mm)[)\]]?)?$",
                     re.IGNORECASE)


def detect(names) -> bool:
    """An interferometer file has a target column (ISO 230-2 run)."""
    return any(_TARGET.match(n.strip()) for n in names)


def metadata(path) -> dict:
    """``# key: value`` (or ``# key = value``) header lines -> {key: value text} for the keys
    of :data:`META_KEYS` (names case-insensitive; other comment lines ignored)."""
    out = {}
    p = Path(path)
    require_file(p, f"data file not found: {path}")
    try:
        lines = p.read_text(encoding="utf-8-sig").splitlines()
    except UnicodeDecodeError:
        raise InputError(f"{p.name}: not a UTF-8 text file") from None
    for line in lines:
        s = line.strip()
        if not s.startswith("#"):
            continue
        m = re.match(r"#\s*([A-Za-z_]+)\s*[:=]\s*(.*)$", s)
        if m and m.group(1).lower() in META_KEYS:
            key = m.group(1).lower()
            require(key not in out, f"{p.name}: header line {key} given twice")
            out[key] = m.group(2).strip()
    return out


def _vector(text: str, what: str, where: str) -> np.ndarray:
    try:
        v = np.array([float(x) for x in re.split(r"[,;\s]+", text.strip()) if x])
    except ValueError:
        raise InputError(f"{where}: header {what}: {text!r} is not three numbers") from None
    require(v.shape == (3,) and np.all(np.isfinite(v)), f"{where}: header {what}: {text!r} is "
                                                         f"not three numbers")
    return v


def _number(text: str, what: str, where: str, positive=True) -> float:
    try:
        v = float(text)
    except ValueError:
        raise InputError(f"{where}: header {what}: {text!r} is not a number") from None
    require(np.isfinite(v) and (v > 0 or not positive), f"{where}: header {what} must be a "
                                                         f"positive number")
    return v


def _at(text: str, model: Model, axis: str, where: str) -> dict:
    """Positions of the axes other than ``axis``: the header ``at`` over the defaults."""
    out = {a: (0.0 if a in model.rotary_axes and model.travel[a][0] <= 0 <= model.travel[a][1]
               else 0.5 * sum(model.travel[a])) for a in model.axes if a != axis}
    for part in [p for p in re.split(r"[,;]", text or "") if p.strip()]:
        m = re.fullmatch(r"\s*([A-Za-z])\s*=\s*(\S+)\s*", part)
        require(m is not None, f"{where}: header at: {part.strip()!r} is not AXIS=VALUE")
        a = m.group(1).upper()
        require(a in out, f"{where}: header at: {a} is not another axis of layout "
                          f"{model.name} ({' '.join(model.axes)})")
        out[a] = _number(m.group(2), f"at {a}", where, positive=False)
    for a, v in out.items():
        lo, hi = model.travel[a]
        require(lo - 1e-9 <= v <= hi + 1e-9, f"{where}: header at: {a} = {v:g} lies outside "
                                             f"the travel [{lo:g}, {hi:g}] of {model.name}")
    return out


def read(path, model: Model) -> Observations:
    """Read an interferometer run into :class:`Observations` (InputError, one line)."""
    where = Path(path).name
    meta = metadata(path)
    require("axis" in meta, f"{where}: no header line '# axis: X' naming the moving axis of "
                            f"the run (see volerr formats interferometer)")
    axis = meta["axis"].strip().upper()
    lin = [a for a in model.axes if a not in model.rotary_axes]
    require(axis in lin, f"{where}: header axis: {axis!r} is not a linear axis of layout "
                         f"{model.name} ({' '.join(lin)})")
    mode = meta.get("mode", "positioning").strip().lower()
    require(mode in MODES, f"{where}: header mode: {mode!r} is not {', '.join(MODES)}")
    targets, dev, direction, cycle, temp, rows = _readings(path, axis, mode, where)
    sense = _vector(meta["sense"], "sense", where) if "sense" in meta else None
    require(mode == "positioning" or sense is not None,
            f"{where}: a {mode} run needs the header line '# sense: x, y, z' (the "
            f"{'displacement measured' if mode == 'straightness' else 'axis of rotation'})")
    u_key = "u_urad" if mode == "angular" else "u_um"
    u = _number(meta[u_key], u_key, where) if u_key in meta else DEFAULT_U[mode]
    scale_u = (_number(meta["scale_u_ppm"], "scale_u_ppm", where) if "scale_u_ppm" in meta
               else DEFAULT_SCALE_U_PPM)
    line = Line(axis, mode, _at(meta.get("at", ""), model, axis, where),
                _vector(meta["optics"], "optics", where) if "optics" in meta else np.zeros(3),
                _vector(meta["beam"], "beam", where) if "beam" in meta else None, sense,
                _number(meta["separation"], "separation", where) if "separation" in meta
                else DEFAULT_SEPARATION_MM, u, scale_u)
    covs = {} if temp is None else {"T_C": temp}
    obs = observations(model, line, targets, dev, direction, where, cycle=cycle,
                       covariates=covs)
    obs.row = rows
    return obs


def _readings(path, axis, mode, where):
    """(targets mm, readings mm or rad, direction +1 / -1, cycle labels, material temperature
    or None, data row of each reading in the file) of a run.  Long format (a direction
    column): in file order, one reading a row (cycles and directions as given: a run need not
    be a complete ISO 230-2 cycle for a calibration); wide format: read as ``volerr
    iso230-2`` reads it, each reading's row the row of its target."""
    from ..positioning._io import _DIRECTION
    from ._csv import read_columns

    c = read_columns(path)
    names = list(c.numbers) + list(c.text)
    low = [h.lower() for h in names]
    long = any(d in low for d in _DIRECTION)
    if not long:
        require(mode != "angular", f"{where}: an angular run is read in the long format "
                                   f"(target_mm,cycle,direction,deviation_urad)")
        from ..positioning import read_run

        run = read_run(path, axis)
        m, _, n = run.deviation.shape
        tcol = _target_column(c, names, where)[0]
        order = {round(float(t) * 1e6): i for i, t in enumerate(tcol)}
        rows = np.array([order[round(float(t) * 1e6)] for t in run.targets])
        temp = None if run.temperature is None else run.temperature.reshape(-1)
        return (np.repeat(run.targets, 2 * n), run.deviation.reshape(-1),
                np.tile(np.repeat([1.0, -1.0], n), m),
                np.tile(np.asarray(run.cycles, dtype=object), 2 * m), temp,
                np.repeat(rows, 2 * n))
    targets, _ = _target_column(c, names, where)
    n = len(targets)
    unit = {"deviation_urad": 1e-6} if mode == "angular" else {
        "deviation_um": 1e-3, "deviation_mm": 1.0, "deviation": 1e-3, "deviation_µm": 1e-3}
    hits = [h for h in c.numbers if h.lower().replace(" ", "_") in unit]
    require(len(hits) == 1, f"{where}: a {mode} run needs one reading column "
            f"({' or '.join(unit)}; long format target_mm,cycle,direction,"
            f"{next(iter(unit))})")
    f.require_finite(c.numbers[hits[0]], hits[0], where)
    f.require_finite(targets, _target_column(c, names, where)[1], where)
    factor = unit[hits[0].lower().replace(' ', '_')]      # mm per unit of the column
    dev = c.numbers[hits[0]] * factor
    if mode == "positioning":     # straightness optics read millimetres of misalignment
        _refuse_implausible(targets, dev, hits[0], where)
    if factor == 1e-3:                                    # read in um: not mm under it
        check_reading_spread_um({hits[0]: c.numbers[hits[0]]}, where)
    hd = next(h for h in names if h.lower() in _DIRECTION)
    direction = _directions(c, hd, where)
    hc = next((h for h in names if h.lower() in ("cycle", "run")), None)
    cycle = (np.full(n, "1", dtype=object) if hc is None else
             np.asarray(c.labels.get(hc) or [f"{v:g}" for v in c.numbers[hc]], dtype=object))
    hT = next((h for h in c.numbers if h.lower() in ("t_c", "material_t_c", "t_material_c")),
              None)
    temp = None if hT is None else c.numbers[hT]
    if temp is not None:
        from ..positioning._io import check_material_temperature

        check_material_temperature(temp, f"{where}: column {hT}")
    if hc is not None:
        refuse_repeated_readings(targets, direction, cycle, where)
    return targets, dev, direction, cycle, temp, np.arange(n)


def _refuse_implausible(targets, dev_mm, column, where) -> None:
    """Refuse a positioning reading (long format) of 1 mm or more
    (:data:`volerr.positioning._io.MAX_DEVIATION_MM`, the limit ``volerr iso230-2`` holds the
    same files to): a machine axis' deviations are micrometres to tens of micrometres; such a
    value is nm under a ``_um`` header, or um under a ``_mm`` header (one line)."""
    from ..positioning._io import MAX_DEVIATION_MM

    a = np.abs(np.asarray(dev_mm, dtype=float))
    if not a.size or float(a.max()) < MAX_DEVIATION_MM:
        return
    i = int(np.argmax(a))
    cause = ("values in um under a _mm header?" if column.lower().endswith("_mm") else
             f"values in nm under a um header? ({1e3 * a[i]:g} nm = {a[i]:g} um); give um")
    raise InputError(f"{where}: column {column}: reading {1e3 * a[i]:g} um at target "
                     f"{targets[i]:g} mm (row {i + 2}) is {MAX_DEVIATION_MM:g} mm or more: not "
                     f"a deviation of a machine axis ({cause})")


def _target_column(c, names, where):
    """(targets mm in file order, column name) of the target column."""
    hits = [h for h in names if _TARGET.match(h.strip())]
    if len(hits) > 1:      # a target... column wins over a bare position column
        hits = [h for h in hits if h.lower().startswith("target")] or hits
    require(len(hits) == 1, f"{where}: {'no' if not hits else 'more than one'} target "
                            f"column (target_mm)")
    h = hits[0]
    require(h in c.numbers, c.text.get(h) or f"{where}: column {h} is not numeric")
    m = _TARGET.match(h.strip())
    return c.numbers[h] * (1e-3 if (m.group(2) or "mm").lower() == "um" else 1.0), h


def _directions(c, h, where) -> np.ndarray:
    from ..positioning._io import _DIR_WORDS

    raw = (c.labels[h] if h in c.labels
           else [f"{v:+g}" if v < 0 else f"{v:g}" for v in c.numbers[h]])
    bad = [r for r in raw if str(r).strip().lower() not in _DIR_WORDS]
    require(not bad, f"{where}: direction = {bad[0] if bad else ''!r}: use +1 (forward) or "
                     f"-1 (backward)")
    return np.array([float(_DIR_WORDS[str(r).strip().lower()]) for r in raw])


class Line:
    """The geometry of a run: ``axis`` moving, ``mode``, ``at`` the other axes' positions
    (mm / deg), ``optics`` (3,) the moving optic's offset from the tool point (tool frame, mm),
    ``beam`` (3,) or None (the direction of motion), ``sense`` (3,) or None, ``separation``
    mm, ``u`` standard uncertainty of a reading (um or urad), ``scale_u`` ppm."""

    def __init__(self, axis, mode, at, optics, beam=None, sense=None,
                 separation=DEFAULT_SEPARATION_MM, u=None, scale_u=DEFAULT_SCALE_U_PPM):
        self.axis, self.mode, self.at = axis, mode, dict(at)
        self.optics = np.asarray(optics, float)
        self.beam = None if beam is None else np.asarray(beam, float)
        self.sense = None if sense is None else np.asarray(sense, float)
        self.separation = float(separation)
        self.u = DEFAULT_U[mode] if u is None else float(u)
        self.scale_u = float(scale_u)

    def describe(self) -> str:
        at = ", ".join(f"{a}={v:g}" for a, v in self.at.items())
        return (f"{self.mode} run of {self.axis} at {at}, optics "
                f"({', '.join(f'{v:g}' for v in self.optics)}) mm")


def _unit(v, what, where) -> np.ndarray:
    n = float(np.linalg.norm(v))
    require(n > 0, f"{where}: {what} must not be the zero vector")
    return np.asarray(v, float) / n


#: the largest angle (deg) between a declared beam and the axis' nominal motion: a laser aligned
#: to the axis is within a fraction of a degree of it
MAX_BEAM_ANGLE_DEG = 5.0


def _travel_cause(model: Model, axis: str, targets) -> str:
    """The likely cause of targets outside the axis' travel: um for mm, the run of another
    linear axis (the axis header), else a layout mismatch."""
    def inside(a, v):
        lo, hi = model.travel[a]
        return bool(np.all((v >= lo - 1e-9) & (v <= hi + 1e-9)))

    lo, hi = model.travel[axis]
    if inside(axis, targets * 1e-3) and np.ptp(targets) * 1e-3 >= 0.1 * (hi - lo):
        return "likely targets in um, not mm"
    others = [a for a in model.axes if a not in model.rotary_axes and a != axis
              and inside(a, targets)]
    if others:
        return f"likely the run of axis {others[0]} (the header '# axis:' wrong)"
    return "layout mismatch"


def observations(model: Model, line: Line, targets, deviation, direction, where: str,
                 cycle=None, covariates=None) -> Observations:
    """Readings of a run as :class:`Observations`: ``targets`` (n,) positions of the moving
    axis (mm), ``deviation`` (n,) the readings as the file gives them (mm; rad for angular),
    ``direction`` (n,) +1 / -1."""
    targets = np.asarray(targets, float)
    n = len(targets)
    lo, hi = model.travel[line.axis]
    margin = 0.05 * (hi - lo)
    bad = np.flatnonzero((targets < lo - margin) | (targets > hi + margin))
    require(len(bad) == 0, f"{where}: target {targets[bad[0]] if len(bad) else 0:g} lies "
            f"outside the travel [{lo:g}, {hi:g}] of {line.axis} on {model.name}: "
            f"{_travel_cause(model, line.axis, targets)}")
    require(np.ptp(targets) > 0, f"{where}: all targets are equal: not a run along a line")
    pos = {a: (targets.copy() if a == line.axis else np.full(n, float(line.at[a])))
           for a in model.axes}
    probe = np.tile(line.optics, (n, 1))
    t = model.nominal_position(pos, probe)
    ends = {a: np.array([lo, hi]) if a == line.axis else np.full(2, float(line.at[a]))
            for a in model.axes}
    te = model.nominal_position(ends, line.optics)
    motion = _unit(te[1] - te[0], "the direction of motion", where)
    beam = motion if line.beam is None else _unit(line.beam, "beam", where)
    angle = float(np.degrees(np.arccos(min(1.0, abs(float(beam @ motion))))))
    require(angle <= MAX_BEAM_ANGLE_DEG, f"{where}: header beam: the beam is {angle:.3g} deg "
            f"from the motion of {line.axis} (at most {MAX_BEAM_ANGLE_DEG:g}): likely the beam "
            f"of another axis (swapped components) or the wrong axis header")
    ref = t[int(np.argmin(targets))]
    first = float(np.min(targets))
    rows = np.ones(n, int)
    proj = np.zeros((n, 3, 3))
    local = np.zeros((n, 3, len(KEYS[line.mode])))
    dev = np.zeros((n, 3))
    probe2 = proj2 = None
    args = (beam[0], beam[1], beam[2], ref[0], ref[1], ref[2])
    if line.mode == "positioning":
        lin = generated.interferometer_positioning(t[:, 0], t[:, 1], t[:, 2], *args)[0]
        dev[:, 0] = (targets - first) + np.asarray(deviation, float) - lin[0]
    elif line.mode == "straightness":
        s = _unit(line.sense, "sense", where)
        require(abs(s @ beam) < 0.02, f"{where}: header sense must be normal to the beam")
        lin = generated.interferometer_straightness(t[:, 0], t[:, 1], t[:, 2], *s, *args)[0]
        dev[:, 0] = np.asarray(deviation, float) - lin[0]
    else:
        a = _unit(line.sense, "sense", where)
        require(abs(a @ beam) < 0.02, f"{where}: header sense (the axis of the measured "
                                      f"rotation) must be normal to the beam")
        m_work = np.cross(beam, a)
        tool_rot = _tool_rotation(model, pos, line.optics)           # (n, 3, 3)
        probe2 = probe + line.separation * np.einsum("nji,j->ni", tool_rot, m_work)
        t2 = model.nominal_position(pos, probe2)
        lin = generated.interferometer_angular(t[:, 0], t[:, 1], t[:, 2], t2[:, 0], t2[:, 1],
                                               t2[:, 2], *beam, line.separation)[0]
        dev[:, 0] = np.asarray(deviation, float) - lin[0]
        proj2 = np.zeros((n, 3, 3))
        proj2[:, 0, :] = lin[4:7].T
        lin = np.concatenate([lin[:4], lin[7:]])
    proj[:, 0, :] = lin[1:4].T
    local[:, 0, :] = lin[4:].T
    keys = KEYS[line.mode]
    setup = Setup(np.zeros((n, 1), int), local, [where], [keys], [("local", 0)],
                  [UNITS[line.mode]],
                  [(None, line.scale_u * 1e-6) if line.mode == "positioning"
                   else (None,) * len(keys)])
    unit = "urad" if line.mode == "angular" else "um"
    sigma = np.full(n, line.u * 1e-6 if line.mode == "angular" else line.u * 1e-3)
    covs = {f"dir_{line.axis}": np.asarray(direction, float), **(covariates or {})}
    missing = [c for c in model.covariates if c not in covs]
    require(not missing, f"{where}: layout {model.name} needs covariate column "
                         f"{missing[0] if missing else ''}")
    info = {"target": targets, "cycle": np.asarray(cycle if cycle is not None
                                                   else np.full(n, "1"), dtype=object)}
    return Observations(pos, probe, dev, covs, [], proj=proj, rows=rows, setup=setup,
                        files=(FileInfo(where, KIND, unit, 1),), sigma=sigma, info=info,
                        probe2=probe2, proj2=proj2)


def _tool_rotation(model: Model, pos: dict, optics) -> np.ndarray:
    """(n, 3, 3) orientation of the tool frame in the workpiece frame (nominal): columns the
    images of the tool frame's unit vectors."""
    base = model.nominal_position(pos, optics)
    cols = [model.nominal_position(pos, np.asarray(optics, float) + e) - base
            for e in np.eye(3)]
    return np.stack(cols, axis=-1)


# ---- simulated runs and plans ------------------------------------------------------------
def simulate(model: Model, line: Line, targets, cycles: int = 2, errors=None,
             noise: float = 0.0, seed: int = 0, zero: float = 0.0) -> dict:
    """Readings of a bidirectional run (``cycles`` per direction) of the layout's first-order
    model with ``errors`` {name: value} (mm / rad): ``{"target", "cycle", "direction",
    "deviation"}`` (mm; rad for angular), ``noise`` its standard deviation (same unit)."""
    targets = np.asarray(targets, float)
    rng = np.random.default_rng(seed)
    rows = []
    for c in range(1, cycles + 1):
        for d in (1.0, -1.0):
            for p in (targets if d > 0 else targets[::-1]):
                rows.append((p, str(c), d))
    tg = np.array([r[0] for r in rows])
    obs = observations(model, line, tg, np.zeros(len(tg)), np.array([r[2] for r in rows]),
                       "simulated")
    e = model.volumetric_error(obs.positions, errors, probe=obs.probe)
    reading = np.einsum("nj,nj->n", obs.proj[:, 0, :], e)
    if obs.proj2 is not None:
        e2 = model.volumetric_error(obs.positions, errors, probe=obs.probe2)
        reading = reading + np.einsum("nj,nj->n", obs.proj2[:, 0, :], e2)
    dev = reading + zero + (rng.normal(0.0, noise, len(tg)) if noise else 0.0)
    return {"target": tg, "cycle": [r[1] for r in rows], "direction": [r[2] for r in rows],
            "deviation": dev}


def write_run(path, line: Line, run: dict, inputs=()):
    """Write a run in the ISO 230-2 long format with the line's header lines."""
    from ..fileio import write_text

    unit = "urad" if line.mode == "angular" else "um"
    factor = 1e6 if line.mode == "angular" else 1e3
    head = [f"# axis: {line.axis}", f"# mode: {line.mode}",
            "# at: " + ", ".join(f"{a}={v:g}" for a, v in line.at.items()),
            "# optics: " + ", ".join(f"{v:g}" for v in line.optics)]
    if line.beam is not None:
        head.append("# beam: " + ", ".join(f"{v:g}" for v in line.beam))
    if line.sense is not None:
        head.append("# sense: " + ", ".join(f"{v:g}" for v in line.sense))
    if line.mode == "angular":
        head.append(f"# separation: {line.separation:g}")
    head.append(f"# u_{unit}: {line.u:g}")
    lines = head + [f"target_mm,cycle,direction,deviation_{unit}"]
    for t, c, d, v in zip(run["target"], run["cycle"], run["direction"], run["deviation"]):
        lines.append(f"{t:.6f},{c},{int(d):+d},{factor * v:.5f}")
    return write_text(path, "\n".join(lines) + "\n", inputs=list(inputs))


def extensions(model, obs) -> list:
    """Plan extensions: the same run with the optics 100 mm further out along each tool-frame
    direction normal to the motion (a second Abbe arm), and angular runs of the same axis
    about the two directions normal to the beam."""
    if "target" not in obs.info or obs.setup is None:
        return []
    where = obs.files[0].name if obs.files else "interferometer"
    moving = [a for a in model.axes if np.ptp(obs.positions[a]) > 0]
    if len(moving) != 1:
        return []
    axis = moving[0]
    at = {a: float(obs.positions[a][0]) for a in model.axes if a != axis}
    optics = obs.probe[0]
    targets = np.unique(obs.info["target"])
    mode = "angular" if obs.proj2 is not None else (
        "positioning" if obs.setup.keys[0] == KEYS["positioning"] else "straightness")
    ends = {a: (np.array([targets[0], targets[-1]]) if a == axis else np.full(2, at[a]))
            for a in model.axes}
    te = model.nominal_position(ends, optics)
    b = _unit(te[1] - te[0], "motion", where)
    normals = [v for v in np.eye(3) if abs(v @ b) < 0.5]
    trials = []
    if mode == "positioning":
        for v in normals:
            name = "XYZ"[int(np.argmax(np.abs(v)))]
            trials.append((f"the same {axis} run with the optics 100 mm further along "
                           f"{name}p", Line(axis, "positioning", at, optics + 100.0 * v)))
    for v in normals:
        name = "XYZ"[int(np.argmax(np.abs(v)))]
        trials.append((f"an angular run of {axis} about {name}",
                       Line(axis, "angular", at, optics, sense=v)))
    out = []
    for text, line in trials:
        try:
            grid = np.linspace(targets[0], targets[-1], max(len(targets), 5))
            run = simulate(model, line, grid, 1)
            ext = observations(model, line, run["target"], run["deviation"],
                               np.asarray(run["direction"]), f"{where} + {text}")
        except InputError:
            continue
        out.append((text, ext))
    return out
