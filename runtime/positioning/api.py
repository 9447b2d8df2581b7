"""``volerr.iso230_2(...)``: the Python API of ``volerr iso230-2`` (:mod:`volerr.results`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import require
from ..results import ResultMixin


@dataclass(repr=False)
class Iso230_2(ResultMixin):
    """Result of :func:`iso230_2`: ``data`` the ``--json`` report (A, B, E, M, R ... in um,
    with their expanded uncertainty U at k = 2 per ISO/TR 230-9), ``evaluations`` per run."""

    data: dict
    evaluations: list
    notes: list = field(default_factory=list)
    identification: dict | None = None

    def summary(self) -> str:
        """What ``volerr iso230-2`` prints."""
        from . import summary_lines

        return "\n".join(summary_lines(self.data)[0])

    def _rows(self) -> list:
        from ..results import Row

        out = []
        for r in self.data["runs"] if "runs" in self.data else [self.data]:
            U = r.get("uncertainty_um") or {}
            k = (r.get("uncertainty_budget") or {}).get("coverage_factor", 2)
            for key in ("A", "E", "M", "R", "B"):
                u = U.get(key)
                out.append(Row(f"{r.get('axis', '')}:{key}", r[f"{key}_um"],
                               None if u is None else u / k, "um", 1.0))
        return out

    def png(self) -> bytes:
        """The plot of the runs (deviation against target per direction, the verdicts)."""
        from . import plot_runs

        per_run = self.data["runs"] if "runs" in self.data else [self.data]
        return plot_runs(self.evaluations, verdicts_per_run=[r.get("verdicts") for r in per_run])

    def _write_own(self, outs, options: dict, inputs: list) -> None:
        """``volerr iso230-2``'s ``--errors-out DIR`` (:meth:`write_error_tables`)."""
        if options.get("errors_out"):
            self.write_error_tables(outs.path("--errors-out"), inputs=inputs)

    def write_error_tables(self, folder, inputs=()) -> list:
        """``FOLDER/<axis>.csv`` per run (mean bidirectional deviation, its standard
        uncertainty, the single-reading repeatability and the reversal; 'volerr formats
        tables'), readable by ``volerr map --errors FOLDER``; returns the paths."""
        from pathlib import Path

        from . import error_table_csv
        from ..fileio import write_text

        refuse_one_axis_twice([ev.run.axis for ev in self.evaluations])
        return [write_text(Path(folder) / f"{ev.run.axis}.csv", error_table_csv(ev),
                           inputs=list(inputs)) for ev in self.evaluations]

    def write_html(self, path, inputs=(), png: bytes | None = None):
        """The certificate page (``--html``); ``png``: the plot (:meth:`png`) when already
        drawn, else drawn here."""
        import datetime
        from importlib.metadata import version

        from . import report_html
        from ..fileio import write_text

        made = f"Evaluated with volerr {version('volerr')} on {datetime.date.today().isoformat()}."
        return write_text(path, report_html(self.data, self.png() if png is None else png,
                                            list(inputs), made,
                                            identification=self.identification),
                          inputs=list(inputs))


def correction_conditions(cte_ppm_per_K: float | None = None,
                          material_temp_C: float | None = None) -> dict:
    """The correction to 20 degC as test conditions of the report (``--cte-ppm-per-K``
    in ppm/K, ``--material-temp-C`` in degC; those not given are left out)."""
    out = {}
    if cte_ppm_per_K is not None:
        out["expansion coefficient"] = f"{cte_ppm_per_K:g} ppm/K (corrected to 20 \u00b0C)"
    if material_temp_C is not None:
        out["material temperature"] = f"{material_temp_C:g} \u00b0C"
    return out


def refuse_one_axis_twice(axes: list) -> None:
    """The error tables are one file per axis: two runs of one axis are refused (one line)."""
    dup = sorted({a for a in axes if axes.count(a) > 1})
    require(not dup, f"--errors-out writes one table per axis: {len(axes)} runs of axis "
                     f"{dup[0] if dup else ''}; evaluate them one at a time")


def run_axes(axis: str, n: int) -> list:
    """The axis of each of ``n`` runs from ``"X"`` (all) or ``"X,Y,..."`` (one per run)."""
    axes = [a.strip().upper() for a in axis.split(",")]
    require(len(axes) in (1, n), f"--axis: give one axis or one per RUN file ({n}), got "
                                 f"{len(axes)}")
    return axes * n if len(axes) == 1 else axes


def iso230_2(runs, axis: str = "X", *, tolerance: str | None = None,
             instrument_ppm: float = 0.5, alignment_mm: float = 0.1,
             temperature_u_K: float = 0.2, cte_u_ppm_per_K: float = 1.0,
             eve_um: float | None = None, cte_ppm_per_K: float | None = None,
             material_temp_C: float | None = None, cte_reference_mm: float = 0.0,
             identification=None, errors_out: bool = False) -> Iso230_2:
    """ISO 230-2 evaluation of positioning runs (``volerr iso230-2``).

    Parameters
    ----------
    runs : str, path or list
        RUN files (``target_mm,cycle,direction,deviation_um``; 'volerr formats iso230-2');
        deviation = actual minus target, um.
    axis : str
        One axis, or a comma list with one per run.
    tolerance : str, optional
        ``"A=..,E=.."`` tolerances in um: verdicts per ISO 14253-1.
    instrument_ppm, alignment_mm, temperature_u_K, cte_u_ppm_per_K, eve_um
        The ISO/TR 230-9 uncertainty budget (ppm, mm, K, ppm/K, um), as the command's options.
    cte_ppm_per_K, material_temp_C, cte_reference_mm
        Correction to 20 degC (ppm/K, degC, mm).
    identification : dict, optional
        What identifies the instrument and the machine in the report (as the command's
        identification options give it).
    errors_out : bool
        The error tables will be written (:meth:`Iso230_2.write_error_tables`): refused at
        once when two runs have the same axis.

    Returns
    -------
    Iso230_2
        ``to_dict()`` is ``--json`` (keys ``A_um B_um E_um M_um R_um`` ... per run).
    """
    from .. import conformance
    from . import BudgetInputs, evaluate_files
    from pathlib import Path

    for opt, v in (("instrument-ppm", instrument_ppm), ("alignment-mm", alignment_mm),
                   ("temperature-u-K", temperature_u_K), ("cte-u-ppm-per-K", cte_u_ppm_per_K),
                   ("eve-um", eve_um)):
        if v is not None:
            require(math.isfinite(v) and 0.0 <= v <= 1e3,
                    f"--{opt} must be a number between 0 and 1000, got {v:g}")
    inputs = [runs] if isinstance(runs, str) or hasattr(runs, "__fspath__") else list(runs)
    require(len({Path(f).resolve() for f in inputs}) == len(inputs),
            "the same RUN file is given twice")
    require(material_temp_C is None or cte_ppm_per_K is not None,
            "--material-temp-C is used only with --cte-ppm-per-K")
    axes = run_axes(axis, len(inputs))
    if errors_out:
        refuse_one_axis_twice(axes)
    tol = (conformance.parse_tolerances(tolerance, ("A", "E", "M", "R", "B"))
           if tolerance is not None else None)
    rs = evaluate_files(inputs, axes, cte_ppm_per_K, material_temp_C, cte_reference_mm)
    report = rs.report(inputs=BudgetInputs(instrument_ppm, alignment_mm, temperature_u_K,
                                           cte_u_ppm_per_K, eve_um), tolerance=tol,
                       identification=identification)
    from . import summary_lines

    per_run = report["runs"] if "runs" in report else [report]
    notes = summary_lines(report)[1] + [f"{r['file']}: {n}" for r in per_run
                                        for n in r["uncertainty_budget"]["notes"]]
    return Iso230_2(report, rs.evaluations, notes, identification=identification)


@dataclass(repr=False)
class Iso230_3(ResultMixin):
    """Result of :func:`volerr.iso230_3`: ``data`` the ``--json`` document (per channel the
    drift range, max, min in um from the first reading, with their times in s; tilts in urad;
    per stage the change and range; a file of several runs: ``{"standard", "runs"}``),
    ``evaluations`` the :class:`volerr.positioning.iso230_3.DriftEvaluation` per run."""

    data: dict
    evaluations: list
    identification: object = None
    #: the run labels of the file (``"1"`` for a file of one run), as the plots are named
    runs: tuple = ()

    def summary(self) -> str:
        """What ``volerr iso230-3`` prints: a line per channel and tilt, per run."""
        return "\n".join(ln for ev in self.evaluations for ln in ev.summary_lines())

    def _rows(self) -> list:
        """Per run, channel and tilt: the drift range (um; urad for a tilt), the largest
        and the smallest drift, with the standard uncertainty of their budgets
        (:meth:`volerr.positioning.iso230_3.DriftEvaluation.budgets`)."""
        from ..results import Row

        out = []
        for ev in self.evaluations:
            pre = f"{ev.name}:" if len(self.evaluations) > 1 else ""
            gum = ev.budgets(pre)
            series = [(k, e, "um") for k, e in ev.channel_extremes().items()]
            series += [(tl.name, e, "urad") for tl, e in zip(ev.tilts,
                                                            ev.tilt_extremes().values())]
            for k, e, unit in series:
                out += [Row(f"{pre}{k}:{what}", float(v), gum[f"{pre}{k}:{what}"]["u"], unit,
                            1.0)
                        for what, v in (("range", e.range), ("max", e.max), ("min", e.min))]
        return out

    def figures(self) -> dict:
        """``{run name: Figure}``: drift, tilts, spindle speed and temperatures against time
        (um, urad, rpm, degC against h), one figure per run."""
        from .iso230_3 import drift_figure

        return {ev.name: drift_figure(ev) for ev in self.evaluations}

    def pngs(self) -> list:
        """The plot of every run (drift, tilts, spindle speed and temperatures against time),
        PNG bytes."""
        from .iso230_3 import plot

        return [plot(ev) for ev in self.evaluations]

    def plot_paths(self, path) -> list:
        """Where the ``--plot`` PNGs of :meth:`pngs` go: ``[path]`` for a file of one run,
        else ``STEM_<run>.png`` beside ``path`` per run (``[]`` when ``path`` is None)."""
        from pathlib import Path

        if path is None:
            return []
        p = Path(path)
        if len(self.evaluations) == 1:
            return [p]
        require(p.suffix.lower() == ".png", f"plot file must end in .png, got {path}")
        return [p.with_name(f"{p.stem}_{r}{p.suffix}") for r in self.runs]

    def _write_own(self, outs, options: dict, inputs: list) -> None:
        """``volerr iso230-3``'s ``--plot``: :meth:`pngs` at :meth:`plot_paths` (declared as
        one file for a file of one run, else as a group)."""
        from ..fileio import write_bytes

        plots = self.plot_paths(options.get("plot"))
        for k, png in enumerate(self.pngs() if plots else []):
            write_bytes(outs.path(outs.group_role("--plot", plots, k)), png, inputs=inputs)

    def write_html(self, path, inputs=()):
        """The test report (``--html``): identification, drift per channel and stage, plot."""
        import datetime

        from importlib.metadata import version
        from ..fileio import write_text
        from .iso230_3 import report_html

        made = (f"Evaluated with volerr {version('volerr')} on "
                f"{datetime.date.today().isoformat()}.")
        return write_text(path, report_html(self.evaluations, self.pngs(), made,
                                            identification=self.identification),
                          inputs=list(inputs))


def evaluate_drift_runs(runs, stage_column: str | None = None,
                        identification=None) -> Iso230_3:
    """The ISO 230-3 evaluation of drift runs already read
    (:func:`volerr.instruments.drift.read_runs`); :func:`volerr.iso230_3` reads the file."""
    from . import iso230_3

    runs = list(runs)
    evals = [iso230_3.evaluate(r, stage_column) for r in runs]
    return Iso230_3(iso230_3.report_dict(evals), evals, identification,
                    tuple(r.run for r in runs))
