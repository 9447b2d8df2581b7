"""Plausible machines: what is known about a machine -> random draws of its errors at a task.

An :class:`Ensemble` is the known (systematic) part plus independent *sources*; each source
draws, from a numpy Generator, its contribution for ``n`` sampled machines/measurements at the
task's P points:

* :class:`TableParameter` -- one error function of a table with an uncertainty column, read
  with its one meaning (``volerr formats tables``).  ``_std`` (or ``_u95`` / 2), the standard
  uncertainty of the tabulated value, is drawn ``mode="systematic"``: the values at the table
  nodes are perturbed (independent N(0, std_i) per node, or correlated along the axis with a
  Gaussian correlation of length ``correlation_mm``) and the error function is rebuilt with
  the same method (linear / cubic / poly of the chosen degree) -- one function per machine,
  so the errors at all task points are correlated as the function makes them.  ``_s``, the
  repeatability of one reading, is drawn ``mode="repeatability"`` when asked for
  (``repeatability=True``): independent per probing point with the interpolated s (Pahk's
  random component).  Old tables whose ``_std`` held a single-reading scatter are read with
  ``table_std="repeatability"``: their ``_std`` is drawn that way.
* :class:`ConstantParameter` -- squareness / location constant with its std, one per machine.
* :class:`Noise` -- probing noise, independent per point: along the probing direction when the
  task gives one, else isotropic (each coordinate).
* :class:`TemperatureSource` -- part and scale: expansion coefficients and temperature
  deviations from 20 C with their standard uncertainties; the reading is scaled about the
  task's centroid by ``1 + a_p dT_p - a_s dT_s`` (minus its nominal value when the CMM
  compensates temperature).
* :class:`SpecMachines` -- specification only (ISO 10360-2 MPE_E0 = A + L/K): constrained
  Monte Carlo after Phillips et al. (NIST, Precision Engineering 25, 2001): every parameter of
  the layout gets a smooth random function (Legendre series of degree 1..``degree`` over the
  travel, zero at the lower travel end; squareness a random constant); the simulated length
  test (:mod:`.iso10360`, with the probing noise in each repetition) is run on each candidate
  and only machines whose 105 length errors all lie within the MPE are kept.  The prior's
  scale is set by a pilot of candidates so that ``acceptance`` (default 0.5) of the noise-free
  candidates pass; kept machines are then what the specification allows.

Measured coordinate of a probing point: m = s - e(q) + noise - p(n) n  (e = actual - nominal
volumetric error; p the probe error map value in the probing direction n, sign of Pahk eq. 13:
a positive probe error reads the point displaced against the probing direction).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..machine import iso_names
from ..errors import InputError, require
from ..units import MM_PER_UM

from . import iso10360
from .iso10360 import Spec, parse_spec  # noqa: F401  (re-exported)


@dataclass
class Draw:
    """Contribution of one source for n samples: ``errors`` name -> (n, P) or (n, 1) mm/rad;
    ``noise`` (n, P, 3) mm added to the readings; ``factor`` (n,) relative scale of the
    readings about the centroid; ``info`` counters."""

    errors: dict = field(default_factory=dict)
    noise: np.ndarray | None = None
    factor: np.ndarray | None = None
    info: dict = field(default_factory=dict)


class Source:
    """A random influence; ``prepare`` binds it to the task points, ``draw`` samples it."""

    name = "source"

    def prepare(self, model, task, ctx) -> "Source":
        return self

    def draw(self, rng, n: int, model) -> Draw:  # pragma: no cover - interface
        raise NotImplementedError


# ---------------------------------------------------------------------------------------------
@dataclass
class TableParameter(Source):
    """One tabulated error function with its standard deviations (see module docstring)."""

    parameter: str
    axis: str
    nodes: np.ndarray
    std: np.ndarray
    method: str = "linear"
    degree: int | None = None
    mode: str = "systematic"
    correlation_mm: float = 0.0
    B: np.ndarray | None = None        # (P, n_nodes) node values -> values at the task points
    L: np.ndarray | None = None        # (n_nodes, n_nodes) factor of the node covariance
    sigma_points: np.ndarray | None = None
    column: str = "std"                # the table column drawn: std (or u95) or s

    @property
    def name(self):
        return self.parameter if self.column != "s" else f"{self.parameter} repeatability"

    def prepare(self, model, task, ctx):
        from ..tables.functions import make_function

        q = np.asarray(task.positions[self.axis], dtype=float)
        if self.mode == "repeatability":
            self.sigma_points = np.interp(q, self.nodes, self.std)
            return self
        k = self.nodes.size
        eye = np.eye(k)
        self.B = np.stack([np.asarray(make_function(self.nodes, eye[j], self.method,
                                                    self.degree)(q), float) for j in range(k)],
                          axis=1)
        if self.correlation_mm > 0:
            d = self.nodes[:, None] - self.nodes[None, :]
            C = np.exp(-0.5 * (d / self.correlation_mm) ** 2) * np.outer(self.std, self.std)
            w, v = np.linalg.eigh(C)
            self.L = v * np.sqrt(np.clip(w, 0, None))
        else:
            self.L = np.diag(self.std)
        return self

    def draw(self, rng, n, model):
        if self.mode == "repeatability":
            z = rng.standard_normal((n, self.sigma_points.size))
            return Draw(errors={self.parameter: z * self.sigma_points})
        z = rng.standard_normal((n, self.nodes.size))
        return Draw(errors={self.parameter: (z @ self.L.T) @ self.B.T})


@dataclass
class ConstantParameter(Source):
    parameter: str
    std: float

    @property
    def name(self):
        return self.parameter

    def draw(self, rng, n, model):
        return Draw(errors={self.parameter: rng.standard_normal((n, 1)) * self.std})


@dataclass
class Noise(Source):
    """Probing noise, standard deviation ``sigma_mm`` per point (see module docstring)."""

    sigma_mm: float
    directions: np.ndarray | None = None
    n_points: int = 0
    name: str = "probing noise"

    def prepare(self, model, task, ctx):
        self.directions = task.directions
        self.n_points = task.n_points
        return self

    def draw(self, rng, n, model):
        if self.directions is not None:
            z = rng.standard_normal((n, self.n_points))
            return Draw(noise=z[..., None] * self.sigma_mm * self.directions)
        return Draw(noise=rng.standard_normal((n, self.n_points, 3)) * self.sigma_mm)


@dataclass
class Temperature:
    """Temperatures and expansion: coefficients 1/K, deviations from 20 C in K, each with its
    standard uncertainty.  ``compensated``: the CMM corrects with the nominal values."""

    part_cte: float = 0.0
    u_part_cte: float = 0.0
    part_dt: float = 0.0
    u_part_dt: float = 0.0
    scale_cte: float = 0.0
    u_scale_cte: float = 0.0
    scale_dt: float = 0.0
    u_scale_dt: float = 0.0
    compensated: bool = False

    def nominal_factor(self) -> float:
        return self.part_cte * self.part_dt - self.scale_cte * self.scale_dt

    @property
    def is_random(self) -> bool:
        return any(v > 0 for v in (self.u_part_cte, self.u_part_dt, self.u_scale_cte,
                                   self.u_scale_dt))


@dataclass
class TemperatureSource(Source):
    temperature: Temperature
    name: str = "temperature"

    def draw(self, rng, n, model):
        t = self.temperature
        z = rng.standard_normal((4, n))
        ap = t.part_cte + t.u_part_cte * z[0]
        dp = t.part_dt + t.u_part_dt * z[1]
        a_s = t.scale_cte + t.u_scale_cte * z[2]
        ds = t.scale_dt + t.u_scale_dt * z[3]
        # deviation of the factor from the known (nominal) one, which the known part carries
        return Draw(factor=ap * dp - a_s * ds - t.nominal_factor())


# ---------------------------------------------------------------------------------------------
@dataclass
class SpecMachines(Source):
    """Constrained Monte Carlo from an ISO 10360-2 specification (see module docstring)."""

    spec: Spec
    noise_mm: float = 0.0
    degree: int = 3
    acceptance: float = 0.5
    probe: tuple = (0.0, 0.0, 0.0)
    seed: int = 0
    max_candidates_factor: int = 200
    name: str = "machine (spec)"
    params: tuple = ()
    amp: np.ndarray | None = None
    v_task: dict = field(default_factory=dict)
    v_test: dict = field(default_factory=dict)
    test: object = None
    mpe_mm: np.ndarray | None = None
    scale: float = 1.0

    def _vander(self, q, lo, hi):
        t = 2 * (np.asarray(q, float) - lo) / (hi - lo) - 1
        V = np.polynomial.legendre.legvander(t, self.degree)
        V0 = np.polynomial.legendre.legvander(np.array([-1.0]), self.degree)
        return (V - V0)[:, 1:]  # degrees 1..degree, zero at the lower travel end

    def prepare(self, model, task, ctx):
        require(not model.rotary_axes, f"{model.name}: the constrained Monte Carlo from a "
                                       f"specification needs a CMM layout (three linear axes)")
        require(not model.covariates, f"{model.name}: layouts with declared effects are not "
                                      f"supported by --spec")
        require(self.degree >= 1, "spec degree must be >= 1")
        box = iso10360.linear_box(model)
        self.test = iso10360.length_test(model, box, self.probe)
        diag = float(np.linalg.norm([box[a][1] - box[a][0] for a in "XYZ"]))
        mpe_max = float(self.spec.mpe_um(diag)) * MM_PER_UM
        self.mpe_mm = self.spec.mpe_um(self.test.lengths) * MM_PER_UM
        paxis = model.parameter_axis
        self.params = tuple(model.parameters)
        k = np.arange(1, self.degree + 1)
        amp = []
        for p in self.params:
            base = mpe_max if iso_names.is_length(p) else mpe_max / diag
            amp.append(base / k if paxis[p] is not None else np.array([base]))
        self.amp = amp
        self.v_task = {a: self._vander(task.positions[a], *box[a]) for a in "XYZ"}
        self.v_test = {a: self._vander(self.test.positions[a], *box[a]) for a in "XYZ"}
        self.paxis = paxis
        # pilot: prior scale such that ``acceptance`` of noise-free candidates pass
        rng = np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=(0,)))
        self.scale = 1.0
        coef = self._coefficients(rng, 400)
        ratio = np.max(np.abs(self._length_errors(model, coef, None))
                       / self.mpe_mm[None, :, :, None], axis=(1, 2, 3))
        q = float(np.quantile(ratio, self.acceptance))
        require(q > 0, "the layout's errors do not change any test length (degenerate layout)")
        self.scale = 1.0 / q
        return self

    def _coefficients(self, rng, m):
        return [rng.standard_normal((m, a.size)) * a * self.scale for a in self.amp]

    def _values(self, coef, vander):
        out = {}
        for p, c in zip(self.params, coef):
            ax = self.paxis[p]
            if ax is None:
                out[p] = c
                continue
            V = vander[ax]  # (P, D): a short sum of broadcast products beats a thin matmul
            v = c[:, :1] * V[:, 0]
            for k in range(1, V.shape[1]):
                v += c[:, k:k + 1] * V[:, k]
            out[p] = v
        return out

    def _length_errors(self, model, coef, noise):
        e = iso10360.evaluate_errors(model, self.test, self._values(coef, self.v_test))
        return iso10360.length_errors(self.test, e, noise)

    def draw(self, rng, n, model):
        kept, tried, got = [], 0, 0
        cap = self.max_candidates_factor * max(n, 1)
        reps = self.test.repetitions
        while got < n:
            m = max(2 * (n - got), 32)
            coef = self._coefficients(rng, m)
            noise = None
            if self.noise_mm > 0:
                noise = rng.standard_normal((m,) + self.test.lengths.shape + (reps, 2)) * self.noise_mm
            E = self._length_errors(model, coef, noise)
            ok = np.all(np.abs(E) <= self.mpe_mm[None, :, :, None], axis=(1, 2, 3))
            tried += m
            idx = np.flatnonzero(ok)[: n - got]
            if idx.size:
                kept.append([c[idx] for c in coef])
                got += idx.size
            if got < n and tried >= cap:
                raise InputError(f"no sampled machine satisfies the specification "
                                 f"{self.spec.text()}: {got} of {tried} candidates passed the "
                                 f"simulated ISO 10360-2 test (probing noise too large for "
                                 f"the MPE?)")
        coef = [np.concatenate([k[j] for k in kept]) for j in range(len(self.params))]
        return Draw(errors=self._values(coef, self.v_task), info={"candidates": tried,
                                                                  "kept": n})


# ---------------------------------------------------------------------------------------------
@dataclass
class Ensemble:
    """Known errors + random sources.  ``funcs``: :class:`volerr.tables.ErrorFunctions` or None
    (perfect machine); ``probe_map``: callable of unit directions (P, 3) -> mm, or None."""

    funcs: object = None
    sources: list = field(default_factory=list)
    temperature: Temperature | None = None
    probe_map: object = None
    table_columns: list = field(default_factory=list)

    @classmethod
    def build(cls, funcs=None, spec: Spec | None = None, noise_um: float = 0.0,
              mode: str = "systematic", correlation_mm: float = 0.0,
              temperature: Temperature | None = None, probe_map=None, seed: int = 0,
              spec_probe=(0.0, 0.0, 0.0), spec_acceptance: float = 0.5,
              repeatability: bool = False) -> "Ensemble":
        """The uncertainty sources of a task-specific Monte Carlo.

        Parameters
        ----------
        funcs : volerr.tables.ErrorFunctions, optional
            Error tables with std / u95 columns (perturbed per ``mode``).
        spec : Spec, optional
            ISO 10360-2 specification: machines drawn and kept when they pass the simulated
            test (constrained Monte Carlo).
        noise_um : float
            Probing noise, standard deviation per point, um.
        mode : {"systematic", "repeatability"}
            How the tables' ``_std`` columns are drawn: as what they are, the uncertainty of
            the tabulated function (one perturbed function per machine), or, for old tables
            whose ``_std`` held a single-reading scatter, per point.
        repeatability : bool
            Also draw the tables' ``_s`` columns (repeatability of one reading), independently
            at every probing point.
        correlation_mm : float
            Correlation length of the node perturbations along an axis, mm (0: independent).
        temperature : Temperature, optional
            Part and scale expansion and their uncertainties.
        probe_map : volerr.probe.ProbeMap, optional
            Probe error map added at each point's probing direction.
        seed : int
            Seed of the spec prior scale search.
        spec_probe : (3,) mm
            Probe offset of the simulated spec test.
        spec_acceptance : float
            Fraction of prior candidates that pass the test (sets the prior scale), in (0, 1).
        """
        require(mode in ("systematic", "repeatability"),
                f"unknown table std mode {mode!r} (systematic, repeatability)")
        require(np.isfinite(noise_um) and noise_um >= 0, "--noise-um must be >= 0")
        require(correlation_mm >= 0, "--correlation-mm must be >= 0")
        require(funcs is None or spec is None, "give --errors or --spec, not both")
        sources, columns = [], []
        if funcs is not None:
            for ax, t in funcs.tables.items():
                for name in t.values:
                    s, col = t.std.get(name), "std"
                    if s is None and name in t.u95:
                        s, col = t.u95[name] / 2.0, "u95"
                    if s is not None and np.any(s > 0):
                        sources.append(TableParameter(name, ax, t.positions, s, funcs.method,
                                                      funcs.degrees.get(name), mode,
                                                      correlation_mm))
                        columns.append(_column_use(name, ax, col, mode))
                    r = t.s.get(name)
                    if r is not None and np.any(r > 0):
                        if repeatability:
                            sources.append(TableParameter(name, ax, t.positions, r,
                                                          funcs.method, None, "repeatability",
                                                          column="s"))
                        columns.append(_column_use(name, ax, "s", "repeatability"
                                                   if repeatability else "not used"))
            for name, s in funcs.constants_std.items():
                if s > 0:
                    sources.append(ConstantParameter(name, s))
        noise_mm = noise_um * MM_PER_UM
        if spec is not None:
            if noise_mm == 0 and spec.pftu_um is not None:
                # PFTU is the range of 25 radial residuals; mean range of 25 N(0,1) = 3.931
                noise_mm = spec.pftu_um * MM_PER_UM / 3.931
            require(0 < spec_acceptance < 1, "--spec-acceptance must lie in (0, 1)")
            sources.append(SpecMachines(spec, noise_mm, probe=tuple(spec_probe), seed=seed,
                                        acceptance=spec_acceptance))
        if noise_mm > 0:
            sources.append(Noise(noise_mm))
        if temperature is not None and temperature.is_random:
            sources.append(TemperatureSource(temperature))
        return cls(funcs, sources, temperature, probe_map, columns)


#: how a table column is drawn, in words (reports)
DRAWN = {"systematic": "one perturbed error function per simulated machine (systematic for "
                       "every point of the task)",
         "repeatability": "independently at every probing point",
         "not used": "not used (give --repeatability to draw it at every probing point)"}


def _column_use(name: str, axis: str, column: str, mode: str) -> dict:
    """What the Monte Carlo did with one uncertainty column of a table (JSON / HTML)."""
    from ..tables.table import UNCERTAINTY_COLUMNS

    meaning = UNCERTAINTY_COLUMNS[column]
    if column != "s" and mode == "repeatability":
        meaning = "read as the repeatability of one reading (--table-std repeatability)"
    return {"parameter": name, "axis": axis, "column": f"{name}_{column}", "meaning": meaning,
            "drawn": DRAWN[mode]}
