"""Observations: the readings of any instrument as rows of the layout's linear model.

A reading of any instrument is, to first order, a linear functional of the volumetric error at
its commanded positions plus a few set-up unknowns of the instrument
(:mod:`volerr.derive.observations`)::

    reading - nominal reading = P (S(q, probe) theta) + C s + noise

``S`` is the layout's generated sensitivity (3 x parameters, mm/mm or mm/rad), ``theta`` the
error parameters, ``P`` the instrument's projection of the 3-D error on its readings (identity
for a 3-D deviation, the bar direction for a ballbar, a rotation for a reading in the machine
frame), ``C`` its set-up columns and ``s`` the set-up unknowns (a pivot offset, a bar-length
offset, a sphere centre, an instrument placement ...).

A differential reading (angular interferometer optics: the optical path difference of two
reflectors) combines two points of the same pose: ``P S(q, probe) + P2 S(q, probe2)``, the
second point's tool offset ``probe2`` and projection ``P2``.

Storage: a *point* is one commanded pose with up to three readings (rows).  Arrays are (N, 3)
with unused rows zero (a ballbar point has one reading: rows 2 and 3 are zero in the reading,
the projection and the set-up columns, so they add nothing to any least-squares sum).  The
estimator (:mod:`volerr.estimate`) and the loop work on these rows whatever the instrument.

Units: positions mm / deg, probe offsets mm, readings mm (files carry um), set-up columns
mm/mm or mm/rad.  Sign: every reading is "actual minus nominal" as the instrument defines it
(stated once in each instrument's module).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: keys of the default set-up: the rigid placement of the measuring instrument (workpiece end)
PLACEMENT = ("dx", "dy", "dz", "ex", "ey", "ez")


@dataclass(frozen=True)
class FileInfo:
    """One measurement file of a campaign: its ``name`` (as reported), instrument ``kind``,
    reading unit (``um``), the number of readings per point (1 or 3) and the parameters its
    header declares (``# parameters: SPEC``, written by ``volerr plan``)."""

    name: str
    kind: str
    unit: str = "um"
    rows: int = 3
    #: the parameters the file declares it was planned for (``# parameters: SPEC``), or None
    parameters: str | None = None


@dataclass
class Setup:
    """Set-up unknowns of the instruments, in groups (a group: the unknowns of one placement of
    one instrument, or of one file, such as its tool-length error).

    ``group`` (N, L): the groups each point belongs to, one per layer (-1: none; a sphere
    reading belongs to its placement's group and to its file's tool group).  Group ``g`` has
    the name ``names[g]``, the unknowns ``keys[g]`` and its columns from ``source[g]``:
    ``("local", j)`` -- columns ``local[:, :, j:j + len(keys[g])]`` given by the reader
    (N, 3, K), or ``("twist", (c, ...))`` -- those columns of the projected twist sensitivity
    (the layout's generated ``setup_sensitivity``: a placement or a tool offset acting through
    the chain).  Global column order: group by group, key by key.  ``units[g]``: per key the
    report unit, ``um`` (mm columns) or ``urad`` (rad columns).  ``priors[g]``: per key None
    (unknown) or the standard uncertainty (mm / rad) of a known value zero, e.g. the length of a
    calibrated ballbar."""

    group: np.ndarray
    local: np.ndarray
    names: list
    keys: list
    source: list
    units: list
    priors: list = None

    def __post_init__(self):
        if self.priors is None:
            self.priors = [(None,) * len(k) for k in self.keys]

    @property
    def offsets(self) -> np.ndarray:
        return np.concatenate([[0], np.cumsum([len(k) for k in self.keys])]).astype(int)

    @property
    def n_columns(self) -> int:
        return int(sum(len(k) for k in self.keys))

    @property
    def labels(self) -> list:
        return [f"{n}.{k}" for n, ks in zip(self.names, self.keys) for k in ks]

    def subset(self, idx) -> "Setup":
        return Setup(self.group[idx], self.local[idx], self.names, self.keys, self.source,
                     self.units, self.priors)

    def block(self, twist: np.ndarray | None) -> np.ndarray:
        """(n, 3, m) set-up columns of these points (``twist``: their projected twist
        sensitivity (n, 3, 12), for groups whose source is the twist)."""
        n = len(self.group)
        out = np.zeros((n, 3, self.n_columns))
        off = self.offsets
        for layer in range(self.group.shape[1]):
            g_of = self.group[:, layer]
            for g in np.unique(g_of[g_of >= 0]):
                m = g_of == g
                k = len(self.keys[g])
                kind, where = self.source[g]
                src = (twist[m][:, :, list(where)] if kind == "twist"
                       else self.local[m][:, :, where:where + k])
                out[m, :, off[g]:off[g] + k] = src
        return out


def placement_setup(n: int, name: str) -> Setup:
    """The default set-up of a file of 3-D deviations: the instrument's rigid placement
    (:data:`PLACEMENT`), one group for all its points."""
    return Setup(np.zeros((n, 1), int), np.zeros((n, 3, 0)), [name], [PLACEMENT],
                 [("twist", tuple(range(6)))], [("um",) * 3 + ("urad",) * 3])


def stack_setups(parts: list) -> Setup:
    """One :class:`Setup` of consecutive blocks of points."""
    width = sum(p.local.shape[2] for p in parts)
    layers = max(p.group.shape[1] for p in parts)
    ns = [len(p.group) for p in parts]
    local = np.zeros((sum(ns), 3, width))
    group = np.full((sum(ns), layers), -1)
    names, keys, source, units, priors = [], [], [], [], []
    start = col = 0
    for p, n in zip(parts, ns):
        k = p.local.shape[2]
        local[start:start + n, :, col:col + k] = p.local
        g = p.group.copy()
        g[g >= 0] += len(names)
        group[start:start + n, :g.shape[1]] = g
        names += p.names
        keys += p.keys
        units += p.units
        priors += p.priors
        source += [(kind, w + col) if kind == "local" else (kind, w) for kind, w in p.source]
        start += n
        col += k
    return Setup(group, local, names, keys, source, units, priors)


@dataclass
class Observations:
    """Readings of one or several instruments at commanded poses (see the module docstring).

    ``positions`` axis -> (N,) mm | deg; ``probe`` (N, 3) mm: probe / tool (or tool-side ball)
    offset; ``deviation`` (N, 3) mm: reading minus nominal reading, unused rows zero;
    ``covariates`` name -> (N,); ``proj`` (N, 3, 3) or None (identity: 3-D deviations);
    ``rows`` (N,) readings per point or None (all 3); ``weight`` (N,) relative weight of each
    point's readings (1 / u^2, normalised) or None (equal); ``setup`` or None (one rigid
    placement of the instrument, :data:`PLACEMENT`); ``file`` (N,) index into ``files`` and
    ``row`` (N,) the point's data row in its file (0-based), or None (one file)."""

    positions: dict
    probe: np.ndarray
    deviation: np.ndarray
    covariates: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)   # columns left out, one line each
    proj: np.ndarray | None = None
    rows: np.ndarray | None = None
    weight: np.ndarray | None = None
    setup: Setup | None = None
    file: np.ndarray | None = None
    row: np.ndarray | None = None
    files: tuple = ()
    sigma: np.ndarray | None = None      # (N,) standard uncertainty of a reading, mm
    #: the instrument's own per-point columns (e.g. a ballbar's pivot, length, raw reading and
    #: placement): name -> (N, ...) array, for evaluations beyond the model's rows
    info: dict = field(default_factory=dict)
    #: a second point of the chain in the same reading (differential readings): its tool
    #: offset (N, 3) mm and projection (N, 3, 3), or None
    probe2: np.ndarray | None = None
    proj2: np.ndarray | None = None
    #: (the observations this is a subset of, the indices there) or None: a lag of a
    #: covariate (:mod:`volerr.machine.lags`) is filtered over the whole series
    lag_source: tuple | None = field(default=None, repr=False, compare=False)

    @property
    def n(self) -> int:
        return len(self.deviation)

    @property
    def n_readings(self) -> int:
        """Number of readings (rows that carry a reading)."""
        return 3 * self.n if self.rows is None else int(np.sum(self.rows))

    def readings_per_point(self) -> np.ndarray:
        return np.full(self.n, 3) if self.rows is None else self.rows

    def subset(self, idx) -> "Observations":
        def take(a):
            return None if a is None else a[idx]

        return Observations({a: v[idx] for a, v in self.positions.items()}, self.probe[idx],
                            self.deviation[idx], {c: v[idx] for c, v in self.covariates.items()},
                            self.warnings, take(self.proj), take(self.rows), take(self.weight),
                            None if self.setup is None else self.setup.subset(idx),
                            take(self.file), take(self.row), self.files, take(self.sigma),
                            {k: v[idx] for k, v in self.info.items()}, take(self.probe2),
                            take(self.proj2), self._lag_subset(idx))

    def _lag_subset(self, idx) -> tuple:
        if self.lag_source is None:
            return (self, np.arange(self.n)[idx])
        return (self.lag_source[0], self.lag_source[1][idx])

    def lag_values(self, model) -> dict:
        """The lags of ``model``'s effects ({canonical text: (N,) values}) at these points,
        each filtered over the whole series these points were taken from, file by file."""
        from ..machine.lags import lag_of_columns

        if not getattr(model, "lags", ()):
            return {}
        root, idx = self.lag_source if self.lag_source is not None else (self, None)
        cache = root.__dict__.setdefault("_lag_cache", {})
        out = {}
        for key, col, tau, time in model.lags:
            if key not in cache:
                cache[key] = lag_of_columns(root.covariates, col, tau, time, root.file)
            out[key] = cache[key] if idx is None else cache[key][idx]
        return out

    # ---- the rows of the linear model ------------------------------------------------
    def project(self, cols: np.ndarray) -> np.ndarray:
        """(n, 3, m) columns of the 3-D error -> the same columns as readings (``proj @``)."""
        if self.proj is None:
            return cols
        return np.einsum("nij,njm->nim", self.proj, cols)

    def sensitivity(self, model) -> np.ndarray:
        """(N, 3, n_parameters) d(readings)/d(parameter), mm/mm or mm/rad."""
        cov = {c: self.covariates[c] for c in model.covariates}
        cov.update(self.lag_values(model))
        out = self.project(model.sensitivity(self.positions, self.probe, covariates=cov))
        if self.proj2 is not None:
            out = out + np.einsum("nij,njm->nim", self.proj2, model.sensitivity(
                self.positions, self.probe2, covariates=cov))
        return out

    def twist(self, model) -> np.ndarray:
        """(N, 3, 12) d(readings)/d(rigid twist) of the workpiece end (0-5) and the tool end
        (6-11) of the chain (the generated ``setup_sensitivity``, projected)."""
        pos = model.positions(self.positions)

        def at(p):
            s = model.module.setup_sensitivity(**pos, Xp=p[:, 0], Yp=p[:, 1], Zp=p[:, 2])
            return np.moveaxis(np.broadcast_to(s, (3, 12, self.n)), -1, 0)

        out = self.project(at(self.probe))
        if self.proj2 is not None:
            out = out + np.einsum("nij,njm->nim", self.proj2, at(self.probe2))
        return out

    def symbol_sensitivity(self, model) -> np.ndarray:
        """(N, 3, n_symbols) d(readings)/d(nominal symbol) in ``model.symbols`` order (probe
        offset components, axis positions, layout parameters, frame offsets and angles; the
        generated ``symbol_sensitivity``, projected), mm/mm or mm/rad."""
        names = model.symbols
        if not names:
            return np.zeros((self.n, 3, 0))
        pos = model.positions(self.positions)
        p = self.probe
        s = model.module.symbol_sensitivity(**pos, Xp=p[:, 0], Yp=p[:, 1], Zp=p[:, 2])
        return self.project(np.moveaxis(np.broadcast_to(s, (3, len(names), self.n)), -1, 0))

    @property
    def setup_labels(self) -> list:
        """Keys of the set-up columns (``dx`` ... for the default placement)."""
        return list(PLACEMENT) if self.setup is None else self.setup.labels

    @property
    def setup_units(self) -> list:
        """Report unit (``um`` or ``urad``) of each set-up column."""
        if self.setup is None:
            return ["um"] * 3 + ["urad"] * 3
        return [u for us in self.setup.units for u in us]

    @property
    def setup_priors(self) -> list:
        """Per set-up column: None (unknown) or the standard uncertainty (mm / rad) of its
        known value 0."""
        if self.setup is None:
            return [None] * 6
        return [u for us in self.setup.priors for u in us]

    def setup_columns(self, twist: np.ndarray) -> np.ndarray:
        """(N, 3, m) set-up columns, given this block's projected twist sensitivity."""
        if self.setup is None:
            return twist[:, :, :6]
        return self.setup.block(twist)

    def reference_sigma(self) -> float:
        """The median standard uncertainty of the readings (mm; 1 um when none is given)."""
        u = self._sigmas()
        return float(np.median(u))

    def _sigmas(self) -> np.ndarray:
        u = (np.full(self.n, np.nan) if self.sigma is None
             else np.asarray(self.sigma, dtype=float))
        fallback = float(np.median(u[np.isfinite(u)])) if np.isfinite(u).any() else 1e-3
        return np.where(np.isfinite(u), u, fallback)

    def point_weights(self) -> np.ndarray:
        """Relative weight of each point's readings: ``(u_ref / u)^2`` (1 for equal
        uncertainties), ``u_ref`` = :meth:`reference_sigma`."""
        if self.weight is not None:
            return self.weight
        u = self._sigmas()
        return (float(np.median(u)) / u) ** 2


def stack(parts: list) -> Observations:
    """One :class:`Observations` of several files' (each with its own ``files`` entry); the
    default placement of a part becomes that file's own set-up group."""
    if len(parts) == 1:
        return parts[0]
    axes = list(parts[0].positions)
    covs = set(parts[0].covariates)
    for p in parts[1:]:
        covs &= set(p.covariates)
    setups = [p.setup if p.setup is not None else
              placement_setup(p.n, p.files[0].name if p.files else f"file{i + 1}")
              for i, p in enumerate(parts)]

    def cat(get, default):
        return np.concatenate([get(p) if get(p) is not None else default(p) for p in parts])

    files, file_idx = [], []
    for p in parts:
        fi = p.files or (FileInfo(f"file{len(files) + 1}", "deviations"),)
        idx = np.zeros(p.n, int) if p.file is None else p.file
        file_idx.append(idx + len(files))
        files += list(fi)
    eye = np.eye(3)
    return Observations(
        {a: np.concatenate([p.positions[a] for p in parts]) for a in axes},
        np.concatenate([p.probe for p in parts]),
        np.concatenate([p.deviation for p in parts]),
        {c: np.concatenate([p.covariates[c] for p in parts]) for c in sorted(covs)},
        [w for p in parts for w in p.warnings],
        cat(lambda p: p.proj, lambda p: np.broadcast_to(eye, (p.n, 3, 3))),
        cat(lambda p: p.rows, lambda p: np.full(p.n, 3)),
        # weights: from each reading's stated uncertainty (sigma) unless a part sets them
        None if all(p.weight is None for p in parts) else
        cat(lambda p: p.weight, lambda p: p.point_weights()),
        stack_setups(setups),
        np.concatenate(file_idx),
        cat(lambda p: p.row, lambda p: np.arange(p.n)),
        tuple(files),
        cat(lambda p: p.sigma, lambda p: np.full(p.n, np.nan)),
        {k: np.concatenate([p.info[k] for p in parts]) for k in parts[0].info
         if all(k in p.info and np.ndim(p.info[k]) == np.ndim(parts[0].info[k])
                for p in parts)},
        *_pairs(parts))


def _pairs(parts) -> tuple:
    """(probe2, proj2) of stacked parts: None when no part has a second point, else the parts
    without one get a zero projection."""
    if all(p.proj2 is None for p in parts):
        return None, None
    return (np.concatenate([p.probe if p.probe2 is None else p.probe2 for p in parts]),
            np.concatenate([np.zeros((p.n, 3, 3)) if p.proj2 is None else p.proj2
                            for p in parts]))
