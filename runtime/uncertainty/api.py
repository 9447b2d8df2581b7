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

    def png(self) -> bytes:
        """The ``--plot`` figure as PNG: the histogram of :meth:`figures`."""
        from .plots import histogram_png

        return histogram_png(self.values, self.names, self.summary_stats, self.title)

    def write_html(self, path, inputs=(), histogram: bytes | None = None):
        """The report page (histogram, convergence, the sources and contributions);
        ``histogram``: the histogram's PNG when already drawn, else drawn here."""
        from ..fileio import write_text
        from . import plots, report

        if histogram is None:
            histogram = plots.histogram_png(self.values, self.names, self.summary_stats,
                                            self.title)
        figs = [histogram, plots.convergence_png(self.values, self.names, self.title)]
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


def temperature_model(part_cte=None, part_dt=None, scale_cte=None, scale_dt=None,
                      compensated: bool = False):
    """The task's temperatures as :class:`volerr.uncertainty.ensemble.Temperature`, from
    ``(value, u)`` pairs (the command's ``--part-cte`` ... options); ``None`` when none is
    given.

    Parameters
    ----------
    part_cte, scale_cte : (float, float), optional
        Expansion coefficient of the part / the scale and its standard uncertainty, 1/K
        (11.5e-6, not 11.5: a coefficient in ppm/K is refused, naming the unit).
    part_dt, scale_dt : (float, float), optional
        Temperature of the part / the scale minus 20 degC and its standard uncertainty, K.
    compensated : bool
        The CMM corrects the nominal expansion; only the uncertainties remain.
    """
    from ..units import check_cte
    from .ensemble import Temperature

    vals = {"part_cte": part_cte, "part_dt": part_dt, "scale_cte": scale_cte,
            "scale_dt": scale_dt}
    if all(v is None for v in vals.values()):
        return None
    kw = {}
    for k, v in vals.items():
        v = v or (0.0, 0.0)
        require(all(abs(x) < 1e3 for x in v) and v[1] >= 0,
                f"--{k.replace('_', '-')}: value and a non-negative u")
        if k.endswith("cte"):   # in 1/K: 11.5 (ppm/K typed) refused, naming the unit
            check_cte(v[0], f"--{k.replace('_', '-')}", "1/K")
        kw[k], kw[f"u_{k}"] = float(v[0]), float(v[1])
    return Temperature(**kw, compensated=compensated)


def _sample(prob, samples, adaptive: bool, digits: int, max_samples: int, runner) -> tuple:
    """``(values, info, adaptive_info)``: the Monte Carlo samples of ``prob`` drawn by
    ``runner`` (``samples``, default 10 000, or the adaptive procedure of JCGM 101 7.9;
    ``adaptive_info`` None without it)."""
    from . import montecarlo as mc

    with runner:
        if adaptive:
            return mc.run_adaptive(prob, runner, digits, max_samples=max_samples)
        values, info = mc.run(prob, 10_000 if samples is None else samples, runner)
    return values, info, None


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
                bias: str = "corrected", progress=False, accept_implausible=False) -> Uncertainty:
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
        ``method``/``degree``/``extrapolate``/``accept_implausible``: as the ``--`` options.
    spec : str, optional
        ``"E0=A+L/K"`` (um, L in mm): machines that pass this ISO 10360-2 specification.
    noise_um : float
        Probing noise per point, standard deviation (um).
    table_std, repeatability, correlation_mm, spec_acceptance, temperature, probe_map
        As the command's options; ``temperature`` a :class:`volerr.uncertainty.Temperature`
        or the keywords of :func:`temperature_model` (``{"part_cte": (value, u), ...}``),
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
    if isinstance(temperature, dict):
        temperature = temperature_model(**temperature)
    require(evaluate in tasks.EVALUATIONS, f"unknown evaluation {evaluate!r} "
                                           f"(one of {', '.join(tasks.EVALUATIONS)})")
    model = load(layout)
    tk = tasks.read_task(task, model.axes)
    funcs = (ErrorFunctions.from_dir(errors, model, method, degree, extrapolate,
                                     accept_implausible) if errors else None)
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
    values, info, adaptive_info = _sample(prob, samples, adaptive, digits, max_samples,
                                          mc.Runner(scheduler, chunks, workers,
                                                    scheduler_address, progress=progress))
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


@dataclass(repr=False)
class Iso10360(ResultMixin):
    """Result of :func:`iso10360`: ``data`` the ``--json`` document (E0 = measured minus true
    length per position, length and repetition, um; the test uncertainty U, k = 2; with an
    MPE the ISO 14253-1 verdicts), ``result`` the :class:`volerr.uncertainty.iso10360.TestResult`,
    ``identification`` the certificate's :class:`volerr.certificate.Identification`."""

    data: dict
    result: object
    identification: object = None

    def summary(self) -> str:
        """What ``volerr iso10360`` prints."""
        from .iso10360 import console_lines

        return "\n".join(console_lines(self.result, self.data))

    def _rows(self) -> list:
        """One row per position and length: E0 (um, the mean of the repetitions) with the
        standard uncertainty of the test, U(L) / k (k = 2, ISO 14253-5)."""
        from ..results import Row
        from .iso10360 import row_name

        res, U = self.result, self.data.get("uncertainty_um") or {}
        u = U.get("E0")
        out = []
        for i, name in enumerate(res.names):
            for j, L in enumerate(res.lengths[i]):
                out.append(Row(row_name(name, L),
                               float(np.mean(res.E_um[i, j])), None if u is None else u / 2.0,
                               "um", 1.0))
        return out

    @property
    def title(self) -> str:
        """The title of the plot and the certificate (the verdict with an MPE)."""
        return f"{self.data['layout']}: simulated ISO 10360-2" + (
            f", {self.data['verdict']}" if self.data.get("mpe") else "")

    def write_outputs(self, outs, options: dict, ident=None, inputs=(), title=None,
                      roles=("plot", "json", "html")) -> None:
        """:meth:`volerr.results.ResultMixin.write_outputs` with the test's identification
        (``ident`` and the artefact's conditions, :attr:`identification`) and :attr:`title`."""
        super().write_outputs(outs, options, self.identification or ident, inputs,
                              title or self.title, roles)

    def png(self) -> bytes:
        """The certificate picture: E0 against L with the MPE and the undecided zone."""
        from . import iso10360 as iso

        return iso.plot_png(self.result, self.title)

    def write_html(self, path, inputs=()):
        """The certificate page (``--html``)."""
        from importlib.metadata import version
        from ..fileio import write_text
        from .iso10360_report import report_html

        return write_text(path, report_html(self.data, self.png(), self.identification,
                                            f"Evaluated with volerr {version('volerr')}."),
                          inputs=list(inputs))


def iso10360(layout, errors, *, probe=(0.0, 0.0, 0.0), volume: str = "travel",
             mpe: str | None = None, noise_um: float = 0.0, seed: int = 0,
             artefact_u: str = "0.1+L/2000", artefact_cte_ppm_per_K: float = 11.5,
             artefact_cte_u_ppm_per_K: float = 1.0, temperature_C: float = 20.0,
             temperature_u_K: float = 0.2, method: str = "linear", degree: int | None = None,
             extrapolate: bool = False, identification=None,
             accept_implausible: bool = False) -> Iso10360:
    """The simulated ISO 10360-2 length measuring test (``volerr iso10360``): 7 positions (4
    space diagonals, lines along X, Y, Z through the centre), 5 lengths, 3 repetitions.

    Parameters
    ----------
    layout : str, path or volerr.Model
        Layout name or file.
    errors : path or volerr.tables.ErrorFunctions
        Error directory (``X.csv`` ... ``constants.csv``) or error functions made from one.
    probe : (3,) mm
        Probe offset (E0 is tested with 0 0 0).
    volume : {"travel", "measured"}
        The box of the test: the layout's travel or the part the error tables cover.
    mpe : str, optional
        MPE line ``"E0=A+L/K"`` (A um, L mm) to judge against (ISO 14253-1 verdicts).
    noise_um : float
        Probing noise per point, standard deviation, um; ``seed`` its seed.
    artefact_u : str
        Expanded calibration uncertainty of the reference lengths, ``"A+L/K"`` um (L mm).
    artefact_cte_ppm_per_K, artefact_cte_u_ppm_per_K : float
        Expansion coefficient of the artefact and its standard uncertainty, ppm/K.
    temperature_C, temperature_u_K : float
        Artefact temperature during the test (degC) and its standard uncertainty (K).
    method, degree, extrapolate
        How the tables are interpolated (as ``--method``, ``--degree``, ``--extrapolate``).
    accept_implausible : bool
        ``--accept-implausible``: table values beyond what a machine of the layout's travel
        can have used instead of refused (:mod:`volerr.tables.plausible`).
    identification : volerr.certificate.Identification, optional
        Machine, instrument, operator, date of the certificate (the artefact's temperature
        and expansion coefficient are added to its conditions).

    Returns
    -------
    Iso10360
        ``to_dict()`` is ``--json`` (um; U at k = 2).
    """
    from dataclasses import replace

    from ..certificate import Identification
    from ..cmm.volmap import volume as box
    from ..machine.model import Model, load
    from ..tables.functions import ErrorFunctions
    from . import iso10360 as iso

    model = layout if isinstance(layout, Model) else load(layout)
    funcs = errors if isinstance(errors, ErrorFunctions) else ErrorFunctions.from_dir(
        errors, model, method=method, degree=degree, extrapolate=extrapolate,
        accept_implausible=accept_implausible)
    spec = iso.parse_spec(mpe, "--mpe") if mpe is not None else None
    tu = iso.artefact_uncertainty(artefact_u, artefact_cte_ppm_per_K, artefact_cte_u_ppm_per_K,
                              temperature_C, temperature_u_K)
    ident = identification or Identification()
    ident = replace(ident, conditions={
        **ident.conditions,
        "artefact temperature": f"{temperature_C:g} \u00b0C (u = {temperature_u_K:g} K)",
        "artefact expansion coefficient": f"{artefact_cte_ppm_per_K:g} ppm/K (u = "
                                          f"{artefact_cte_u_ppm_per_K:g} ppm/K)"})
    res = iso.simulate(model, funcs, tuple(probe), box(model, funcs, volume),
                       noise_um=noise_um, seed=seed, spec=spec, uncertainty=tu)
    doc = {"layout": model.name, "errors": str(errors if errors is not funcs else
                                               (funcs.source or "")),
           "probe_mm": [float(v) for v in probe], "repetitions": int(res.E_um.shape[-1]),
           **res.as_dict(), "identification": ident.as_dict()}
    return Iso10360(doc, res, ident)
