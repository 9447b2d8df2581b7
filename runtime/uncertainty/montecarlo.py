"""Monte Carlo engine (JCGM 101): seeded sample blocks, chunks, dask, adaptive stopping.

Reproducibility: the samples are cut into *blocks* of fixed size ``block_size`` (250).  Block
``b`` draws from its own stream ``SeedSequence(seed, spawn_key=(1, b))`` -- the b-th child
that ``SeedSequence(seed).spawn`` would give on a sequence keyed ``(1,)`` -- so the values of
sample ``j`` depend only on ``seed`` and ``j``, never on how blocks are grouped into chunks or
which worker runs them: 1 chunk, 7 chunks or a dask cluster give identical numbers.  Each
chunk is one vectorised generated-code call per block ((n, P) arrays), then the evaluation.

Adaptive stopping (JCGM 101 7.9): runs of M = max(100 / (1 - p), 10^4) samples (rounded up to
whole blocks); after h >= 2 runs the standard deviations of the h run values of the estimate,
the standard uncertainty and both coverage-interval endpoints, divided by sqrt(h), must all be
<= delta / 2 for every quantity, delta = 1/2 10^l the numerical tolerance of u written with
``n_dig`` significant digits (u = c 10^l, c an n_dig-digit integer; 7.9.2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import require
from ..units import UM_PER_MM

from .tasks import EVALUATIONS, check_task, check_travel, evaluate

BLOCK_SIZE = 250
_MODELS: dict = {}


def _model(layout: str):
    """Model by layout name or path, cached per process (workers reload it by name)."""
    if layout not in _MODELS:
        from ..machine.model import load
        _MODELS[layout] = load(layout)
    return _MODELS[layout]


@dataclass
class Problem:
    """A prepared Monte Carlo problem (picklable: arrays and plain sources only).

    ``nominal`` (P, 3) nominal probe-tip points, mm; ``known_errors`` name -> (P,) mm / rad;
    ``known_probe`` (P, 3) mm (the probe-map term of the reading); ``known_factor`` relative
    scale of the readings from temperature; ``nominal_values`` / ``known_values``
    (n_quantities,) mm of the perfect and of the known machine; ``backend`` ``"numpy"`` or
    ``"numba"`` (the fused compiled kernel of :mod:`volerr.machine.fused`, same values)."""

    layout: str
    evaluation: str
    positions: dict
    probe: np.ndarray
    nominal: np.ndarray
    known_errors: dict
    known_probe: np.ndarray
    known_factor: float
    sources: list
    seed: int = 0
    block_size: int = BLOCK_SIZE
    nominal_values: np.ndarray | None = None
    known_values: np.ndarray | None = None
    backend: str = "numpy"

    @property
    def names(self) -> tuple:
        return EVALUATIONS[self.evaluation]

    @property
    def model(self):
        return _model(self.layout)

    def readings(self, errors: dict, noise=None, factor=None) -> np.ndarray:
        """Measured points (S, P, 3) mm for ``errors`` (name -> arrays broadcastable to (S, P))."""
        model = self.model
        full = {p: errors.get(p, 0.0) for p in model.parameters}
        p = self.probe
        kw = dict(**self.positions, Xp=p[:, 0], Yp=p[:, 1], Zp=p[:, 2], **full)
        e = None
        if self.backend == "numba":
            from ..machine import fused
            try:
                e = fused.evaluate_numba(model.module.volumetric_error, kw)
            except ValueError:  # not fusable or not 2-D: the generated function below
                e = None
        if e is None:
            comp = model.module.volumetric_error(**kw)
            shape = np.broadcast_shapes(*(np.shape(c) for c in comp), self.nominal.shape[:1])
            e = np.stack([np.broadcast_to(c, shape) for c in comp], axis=-1)
        m = self.nominal - e + self.known_probe
        if noise is not None:
            m = m + noise
        f = self.known_factor + (0.0 if factor is None else np.asarray(factor)[..., None, None])
        if np.any(f != 0):
            c = self.nominal.mean(axis=0)
            m = c + (1.0 + f) * (m - c)
        return m if m.ndim == 3 else m[None]

    def block(self, b: int, n: int) -> tuple[np.ndarray, dict]:
        """Values (n, n_quantities) mm of samples b*block_size ... + n, and source counters."""
        model = self.model
        rng = np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=(1, int(b))))
        errors = dict(self.known_errors)
        noise, factor, info = None, None, {}
        for src in self.sources:
            d = src.draw(rng, n, model)
            for k, v in d.errors.items():
                errors[k] = errors[k] + v if k in errors else v
            if d.noise is not None:
                noise = d.noise if noise is None else noise + d.noise
            if d.factor is not None:
                factor = d.factor if factor is None else factor + d.factor
            for k, v in d.info.items():
                info[k] = info.get(k, 0) + v
        m = self.readings(errors, noise, factor)
        if m.shape[0] != n:
            m = np.broadcast_to(m, (n,) + m.shape[1:])
        return evaluate(self.evaluation, m), info


def prepare(model, layout_ref: str, task, evaluation: str, ensemble, seed: int = 0,
            block_size: int = BLOCK_SIZE, backend: str = "numpy") -> Problem:
    """Bind ``ensemble`` (:class:`~.ensemble.Ensemble`) to ``task`` on ``model``.

    Parameters
    ----------
    model : volerr.Model
        The machine's error model.
    layout_ref : str
        Layout name or file (what a dask worker loads the model from).
    task : volerr.uncertainty.tasks.Task
        Probing points (P,) per axis, mm / deg, with probe offsets and directions.
    evaluation : str
        One of :data:`volerr.uncertainty.tasks.EVALUATIONS` (distance, circle, sphere, plane).
    ensemble : volerr.uncertainty.ensemble.Ensemble
        The plausible machines and the other uncertainty sources.
    seed : int
        Seed of every random stream (results independent of chunking).
    block_size : int
        Samples per block (the unit of seeding and of work).
    backend : {"numpy", "numba"}
        How the volumetric error of the samples is evaluated: the generated numpy code, or
        its fused compiled kernel (``pip install 'volerr[fast]'``; 1-4 s of compilation the
        first time, cached on disk; pays from about 10^8 point evaluations).  Without numba,
        ``"numba"`` falls back to numpy with one :class:`volerr.machine.fused.FallbackWarning`.
        The values are the same (to rounding, 1e-12 relative).

    Returns
    -------
    Problem
        Everything a worker needs to draw blocks of samples.
    """
    require(evaluation in EVALUATIONS, f"unknown evaluation {evaluation!r} "
                                       f"(one of {', '.join(EVALUATIONS)})")
    require(isinstance(seed, int) and seed >= 0, "--seed must be a non-negative integer")
    require(block_size >= 1, "block size must be >= 1")
    require(not model.covariates, f"{model.name}: layouts with declared effects need "
                                  f"covariates, not supported here")
    from ..machine.fused import resolve_backend
    backend = resolve_backend(backend)
    # one check for every kind of machine knowledge (tables, spec, perfect machine)
    check_travel(model, task.positions)
    pos = model.positions(task.positions)
    n = task.n_points
    nominal = model.nominal_position(task.positions, task.probe)
    check_task(task, evaluation, nominal)
    known = {}
    if ensemble.funcs is not None:
        known = {k: np.asarray(v, float) for k, v in ensemble.funcs(task.positions).items()}
    known_probe = np.zeros((n, 3))
    if ensemble.probe_map is not None:
        require(task.directions is not None, "a probe error map needs the probing directions "
                                             "i,j,k in the task")
        pv = np.asarray(ensemble.probe_map(task.directions), float).reshape(n)
        known_probe = -pv[:, None] * task.directions
    t = ensemble.temperature
    kf = 0.0 if t is None or t.compensated else float(t.nominal_factor())
    sources = [s.prepare(model, task, None) for s in ensemble.sources]
    _MODELS.setdefault(layout_ref, model)
    prob = Problem(layout_ref, evaluation, pos, np.asarray(task.probe, float), nominal, known,
                   known_probe, kf, sources, seed, block_size, backend=backend)
    prob.nominal_values = evaluate(evaluation, nominal)[0]
    prob.known_values = evaluate(evaluation, prob.readings(known))[0]
    return prob


def with_sources(problem: Problem, sources) -> Problem:
    """The same problem with other (prepared) sources (one-at-a-time contributions)."""
    from dataclasses import replace
    return replace(problem, sources=list(sources))


# ---------------------------------------------------------------------------------------------
def _blocks(problem, first_block: int, n: int):
    B = problem.block_size
    nb = math.ceil(n / B)
    return [(first_block + i, min(B, n - i * B)) for i in range(nb)]


def run_blocks(problem: Problem, blocks) -> tuple[np.ndarray, dict]:
    """Values of the given ``[(block, n), ...]``, concatenated, and summed counters."""
    vals, info = [], {}
    for b, n in blocks:
        v, i = problem.block(b, n)
        vals.append(v)
        for k, c in i.items():
            info[k] = info.get(k, 0) + c
    return np.concatenate(vals, axis=0), info


@dataclass
class Runner:
    """Where chunks run: ``scheduler`` ``"none"`` (this process) or ``"dask"`` (a
    LocalCluster of ``workers`` processes, or the cluster at ``address``)."""

    scheduler: str = "none"
    chunks: int = 1
    workers: int = 2
    address: str | None = None
    progress: bool = False
    _client: object = None
    _cluster: object = None

    def __post_init__(self):
        require(self.scheduler in ("none", "dask"), f"unknown scheduler {self.scheduler!r} "
                                                    f"(none, dask)")
        require(self.chunks >= 1, "--chunks must be >= 1")
        require(self.workers >= 1, "--workers must be >= 1")

    def __enter__(self):
        if self.scheduler == "dask":
            try:
                from dask.distributed import Client, LocalCluster
            except ImportError:
                from ..errors import InputError
                raise InputError("--scheduler dask needs dask: pip install 'volerr[dask]'") from None
            if self.address:
                try:
                    self._client = Client(self.address, timeout="10s")
                except OSError as exc:
                    from ..errors import InputError
                    raise InputError(f"cannot reach the dask scheduler at {self.address}: "
                                     f"{exc}") from None
            else:
                self._cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1,
                                             processes=True, dashboard_address=None)
                self._client = Client(self._cluster)
        return self

    def __exit__(self, *exc):
        if self._client is not None:
            self._client.close()
        if self._cluster is not None:
            self._cluster.close()
        self._client = self._cluster = None

    def map(self, problem: Problem, blocks) -> tuple[np.ndarray, dict]:
        n_chunks = max(1, min(self.chunks if self.scheduler == "none"
                              else max(self.chunks, 2 * self.workers), len(blocks)))
        groups = [list(g) for g in np.array_split(np.arange(len(blocks)), n_chunks) if len(g)]
        groups = [[blocks[i] for i in g] for g in groups]
        if self._client is None:
            from ..progress import on_terminal, progress

            if self.progress and on_terminal() and len(groups) < min(len(blocks), 50):
                # finer groups only to show progress: the values do not depend on grouping
                groups = [[blocks[i] for i in g] for g in
                          np.array_split(np.arange(len(blocks)), min(len(blocks), 50))]
            it = (progress(groups, desc="Monte Carlo", unit="group") if self.progress
                  else groups)
            parts = [run_blocks(problem, g) for g in it]
        else:
            from dask.distributed import wait  # noqa: F401
            fut = self._client.scatter(problem, broadcast=True, hash=False)
            futures = [self._client.submit(run_blocks, fut, g, pure=False) for g in groups]
            parts = self._client.gather(futures)
        info = {}
        for _, i in parts:
            for k, c in i.items():
                info[k] = info.get(k, 0) + c
        return np.concatenate([p for p, _ in parts], axis=0), info


def run(problem: Problem, samples: int, runner: Runner | None = None,
        first_block: int = 0) -> tuple[np.ndarray, dict]:
    """Draw ``samples`` Monte Carlo values of the task's quantities.

    Parameters
    ----------
    problem : Problem
        From :func:`prepare`.
    samples : int
        Number of samples M.
    runner : Runner, optional
        Where the blocks run (in process by default, or dask); values are identical.
    first_block : int
        Index of the first block (continuing a run draws new, independent blocks).

    Returns
    -------
    values : ndarray, shape (samples, n_quantities)
        The measured quantities of every sampled machine, mm.
    info : dict
        Counters of the sources (e.g. ``candidates`` and ``kept`` of a spec ensemble).
    """
    require(samples >= 2, "--samples must be >= 2")
    runner = runner or Runner()
    if runner._client is None and runner.scheduler == "dask":
        with runner:
            return runner.map(problem, _blocks(problem, first_block, samples))
    return runner.map(problem, _blocks(problem, first_block, samples))


def numerical_tolerance(u: float, n_dig: int = 2) -> float:
    """JCGM 101 7.9.2: u = c 10^l with c an n_dig-digit integer -> delta = 1/2 10^l."""
    if not u > 0:
        return 0.0
    l = math.floor(math.log10(u)) - n_dig + 1
    return 0.5 * 10.0 ** l


def interval(values, p: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
    """Probabilistically symmetric coverage interval: the (1-p)/2 and (1+p)/2 quantiles."""
    return (np.quantile(values, (1 - p) / 2, axis=0), np.quantile(values, (1 + p) / 2, axis=0))


@dataclass
class Adaptive:
    """Record of an adaptive run: runs h, samples per run M, converged, tolerances (mm)."""

    runs: int = 0
    per_run: int = 0
    converged: bool = False
    delta_mm: list = field(default_factory=list)
    history: list = field(default_factory=list)


def run_adaptive(problem: Problem, runner: Runner | None = None, n_dig: int = 2,
                 p: float = 0.95, max_samples: int = 1_000_000):
    """Adaptive Monte Carlo (JCGM 101 7.9, see module docstring).

    Runs of M samples until the standard deviations of the run values of the estimate, u and
    both interval ends, divided by sqrt(h), are all <= delta / 2, delta the numerical tolerance
    of u written with ``n_dig`` significant digits; at most ``max_samples`` samples.

    Returns
    -------
    values : ndarray, shape (n_samples, n_quantities)
        All samples of all runs, mm.
    info : dict
        Source counters, as :func:`run`.
    adaptive : Adaptive
        Runs, samples per run, convergence and the tolerances (mm).
    """
    require(1 <= n_dig <= 4, "significant digits must be 1..4")
    B = problem.block_size
    M = max(math.ceil(100 / (1 - p)), 10_000)
    M = math.ceil(M / B) * B
    runner = runner or Runner()
    own = runner._client is None and runner.scheduler == "dask"
    if own:
        runner.__enter__()
    try:
        parts, stats, info, rec = [], [], {}, Adaptive(per_run=M)
        while True:
            v, i = runner.map(problem, _blocks(problem, len(parts) * (M // B), M))
            for k, c in i.items():
                info[k] = info.get(k, 0) + c
            parts.append(v)
            lo, hi = interval(v, p)
            stats.append(np.stack([v.mean(axis=0), v.std(axis=0, ddof=1), lo, hi]))
            h = len(parts)
            if h >= 2:
                s = np.std(np.array(stats), axis=0, ddof=1) / math.sqrt(h)  # (4, nq)
                u_all = np.concatenate(parts).std(axis=0, ddof=1)
                delta = np.array([numerical_tolerance(float(u), n_dig) for u in u_all])
                rec.history.append({"samples": h * M, "max_2s_over_delta": float(np.max(
                    np.where(delta > 0, 2 * s / np.where(delta > 0, delta, 1), 0)))})
                ok = (delta == 0) | np.all(2 * s <= delta, axis=0)
                rec.delta_mm = [float(d) for d in delta]
                if np.all(ok):
                    rec.converged = True
                    break
            if (h + 1) * M > max_samples:
                break
        rec.runs = len(parts)
        return np.concatenate(parts), info, rec
    finally:
        if own:
            runner.__exit__()


def summarize(problem: Problem, values, p: float = 0.95) -> dict:
    """JSON-ready results per quantity: estimate (mean) mm, bias of the known errors um,
    standard uncertainty um, expanded U (k = 2) um, coverage interval mm."""
    lo, hi = interval(values, p)
    mean = values.mean(axis=0)
    u = values.std(axis=0, ddof=1)
    out = {}
    for j, name in enumerate(problem.names):
        out[name] = {
            "estimate_mm": float(mean[j]),
            "nominal_mm": float(problem.nominal_values[j]),
            "bias_um": float((problem.known_values[j] - problem.nominal_values[j]) * UM_PER_MM),
            "standard_uncertainty_um": float(u[j] * 1e3),
            "expanded_uncertainty_um": float(2 * u[j] * 1e3),
            "coverage_interval_mm": [float(lo[j]), float(hi[j])],
            "coverage_probability": p,
        }
    return out


def contributions(problem: Problem, samples: int = 2000) -> list:
    """One source at a time (the others switched off; the known errors kept): standard
    uncertainty of each quantity, um, ranked by the first quantity.  A cheap ranking: it
    ignores interactions (there are none in the first-order model except through the fit)."""
    out = []
    for src in problem.sources:
        v, _ = run(with_sources(problem, [src]), samples)
        u = v.std(axis=0, ddof=1) * UM_PER_MM
        out.append({"source": src.name,
                    "standard_uncertainty_um": {n: float(x) for n, x in zip(problem.names, u)}})
    first = problem.names[0]
    out.sort(key=lambda d: -d["standard_uncertainty_um"][first])
    return out
