"""``volerr.uncertainty(...)``: the Python API of ``volerr uncertainty`` (:mod:`volerr.results`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import require
from ..results import ResultMixin


@dataclass(repr=False)
class Uncertainty(ResultMixin):
    """Result of :func:`uncertainty`: ``data`` the ``--json`` document (per quantity the
    result in mm, the bias in um, the standard uncertainty u (k = 1) and expanded U (k = 2)
    in um, the 95 % coverage interval), ``values`` the Monte Carlo samples (mm, one column
    per quantity), ``summary_stats`` the estimate per quantity."""

    data: dict
    values: np.ndarray
    names: tuple
    summary_stats: object = None

    def summary(self) -> str:
        """What ``volerr uncertainty`` prints."""
        from .report import summary_lines

        return "\n".join(summary_lines(self.data))

    def _rows(self) -> list:
        from ..results import Row

        return [Row(n, q["result_mm"], q["standard_uncertainty_um"] / 1e3, "mm", 1.0)
                for n, q in self.data["quantities"].items()]

    def figures(self) -> dict:
        """``{"histogram": Figure}``: the samples of every quantity about the estimate, the
        95 % coverage interval and estimate +- U (k = 2)."""
        from .plots import histogram_figure

        return {"histogram": histogram_figure(self.values, self.names, self.summary_stats,
                                              self.title)}

    @property
    def title(self) -> str:
        return f"{self.data['layout']} {self.data['evaluation']} ({len(self.values)} samples)"

    def write_html(self, path, inputs=()):
        """The report page (histogram, convergence, the sources and contributions)."""
        from ..fileio import write_text
        from . import plots, report

        figs = [plots.histogram_png(self.values, self.names, self.summary_stats, self.title),
                plots.convergence_png(self.values, self.names, self.title)]
        return write_text(path, report.html_report(self.data, figs, CAPTIONS),
                          inputs=list(inputs))


#: the captions of the report page's two figures
CAPTIONS = ("Distribution of the Monte Carlo readings about their mean (the estimate): red, the "
            "probabilistically symmetric 95 % coverage interval; blue dashed, estimate \u00b1 U "
            "(k = 2).",
            "Convergence: running mean (about the final mean) and running standard "
            "uncertainty u (k = 1) against the number of samples.")


def check_options(noise_um, correlation_mm, spec_acceptance, samples, digits, max_samples,
                  seed, chunks, workers, contributions) -> None:
    """Option values first, before any file is read or anything is decided (the command's
    messages)."""
    def finite(v):
        return v is not None and math.isfinite(v)

    require(finite(noise_um) and noise_um >= 0, "--noise-um must be >= 0")
    require(finite(correlation_mm) and correlation_mm >= 0, "--correlation-mm must be >= 0")
    require(finite(spec_acceptance) and 0 < spec_acceptance < 1,
            "--spec-acceptance must lie in (0, 1)")
    require(samples is None or 2 <= samples <= 10**8, "--samples must be between 2 and 1e8")
    require(1 <= digits <= 4, "--digits must be between 1 and 4")
    require(max_samples >= 2, "--max-samples must be >= 2")
    require(seed >= 0, "--seed must be a non-negative integer")
    require(chunks >= 1, "--chunks must be >= 1")
    require(workers >= 1, "--workers must be >= 1")
    require(0 <= contributions <= 10 ** 6, "--contributions must be between 0 and 1e6")
    require(max_samples <= 10 ** 9, "--max-samples must be at most 1e9")


def _backend(name: str) -> str:
    """The backend to use; a missing numba is one warning line on stderr, then numpy."""
    import sys
    import warnings

    from ..machine.fused import resolve_backend
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        backend = resolve_backend(name)
    for w in caught:
        print(f"volerr: warning: {w.message}", file=sys.stderr)
    return backend


def uncertainty(layout, task, evaluate: str, *, errors=None, method: str = "linear",
                degree: int | None = None, extrapolate: bool = False, spec: str | None = None,
                noise_um: float = 0.0, table_std: str = "systematic",
                repeatability: bool = False, correlation_mm: float = 0.0,
                spec_acceptance: float = 0.5, temperature=None, probe_map=None,
                samples: int | None = None, adaptive: bool = False, digits: int = 2,
                max_samples: int = 1_000_000, seed: int = 0, chunks: int = 1,
                scheduler: str = "none", scheduler_address: str | None = None,
                workers: int = 2, contributions: int = 2000, backend: str = "numpy",
                bias: str = "corrected", progress: bool = False) -> Uncertainty:
    """Task-specific measurement uncertainty by Monte Carlo (``volerr uncertainty``; a
    virtual CMM, ISO/TS 15530-4, JCGM 101).

    Parameters
    ----------
    layout : str or path
        Layout name or file.
    task : str or path
        Probing points ``X,Y,Z[,i,j,k]`` (mm; 'volerr formats task').
    evaluate : str
        The evaluation (``distance``, ``sphere``, ... :data:`volerr.uncertainty.EVALUATIONS`).
    errors : path, optional
        Error directory with ``_std`` / ``_u95`` columns (the machine's identified errors);
        ``method``, ``degree``, ``extrapolate``: how its tables are interpolated.
    spec : str, optional
        ``"E0=A+L/K"`` (um, L in mm): machines that pass this ISO 10360-2 specification.
    noise_um : float
        Probing noise per point, standard deviation (um).
    table_std, repeatability, correlation_mm, spec_acceptance, temperature, probe_map
        As the command's options; ``temperature`` a :class:`volerr.uncertainty.Temperature`,
        ``probe_map`` a probe map read by :func:`volerr.probe.read_probe_map`.
    samples : int, optional
        Monte Carlo samples (default 10 000); ``adaptive``, ``digits``, ``max_samples``: the
        adaptive procedure of JCGM 101 7.9 instead.
    seed, chunks, scheduler, scheduler_address, workers, backend
        Reproducible chunked sampling (the same seed and chunks, the same numbers).
    contributions : int
        Samples of the one-at-a-time contribution analysis (0: none).
    bias : {"corrected", "uncorrected"}
        Report the result corrected for the bias of the known errors, or the reading with an
        interval that contains the bias.

    Returns
    -------
    Uncertainty
        ``to_dict()`` is ``--json``: per quantity ``result_mm``, ``bias_um``,
        ``standard_uncertainty_um`` (k = 1), ``expanded_uncertainty_um`` (k = 2) and the 95 %
        coverage interval.
    """
    from ..machine.model import load
    from ..tables import ErrorFunctions
    from . import ensemble, montecarlo as mc, report, tasks

    check_options(noise_um, correlation_mm, spec_acceptance, samples, digits, max_samples,
                  seed, chunks, workers, contributions)
    require(evaluate in tasks.EVALUATIONS, f"unknown evaluation {evaluate!r} "
                                           f"(one of {', '.join(tasks.EVALUATIONS)})")
    model = load(layout)
    tk = tasks.read_task(task, model.axes)
    funcs = (ErrorFunctions.from_dir(errors, model, method=method, degree=degree,
                                     extrapolate=extrapolate) if errors else None)
    parsed = ensemble.parse_spec(spec) if spec else None
    require(funcs is not None or parsed is not None or noise_um > 0 or probe_map is not None
            or temperature is not None,
            "nothing is uncertain: give --errors, --spec, --noise-um or temperatures")
    ens = ensemble.Ensemble.build(funcs, parsed, noise_um, table_std, correlation_mm,
                                  temperature, probe_map, seed,
                                  spec_acceptance=spec_acceptance, repeatability=repeatability)
    prob = mc.prepare(model, str(layout), tk, evaluate, ens, seed=seed,
                      backend=_backend(backend))
    require(prob.sources, "nothing is random: the tables have no _std / _u95 columns (their _s "
                          "columns need --repeatability) and no noise, spec or temperature "
                          "uncertainty is given")
    adaptive_info = None
    with mc.Runner(scheduler, chunks, workers, scheduler_address, progress=progress) as runner:
        if adaptive:
            values, info, adaptive_info = mc.run_adaptive(prob, runner, digits,
                                                          max_samples=max_samples)
        else:
            values, info = mc.run(prob, 10_000 if samples is None else samples, runner)
    stats = mc.summarize(prob, values)
    doc = report.result_document(
        prob, values, stats, info, layout=model.name, task=str(task), evaluation=evaluate,
        seed=seed, chunks=chunks, scheduler=scheduler,
        machine=report.machine_text(parsed, errors if funcs else None, table_std,
                                    repeatability),
        noise_um=noise_um, adaptive=adaptive_info, digits=digits,
        contributions=mc.contributions(prob, contributions) if contributions else None,
        bias=bias, table_uncertainty=ens.table_columns, task_points=tk.n_points)
    return Uncertainty(doc, values, tuple(prob.names), stats)
