"""Several positioning runs evaluated together, as ``volerr iso230-2`` does: each file read,
optionally corrected to 20 degC, evaluated, with the standard's notes; and the lines printed."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ._evaluate import Evaluation, evaluate
from ._io import read_run
from ._report import report_dict, standard_notes
from ._thermal import ThermalCorrection, correct_to_20C


@dataclass
class RunSet:
    """The evaluations of several runs, with their thermal corrections (None: not corrected)
    and notes, in file order."""

    evaluations: list[Evaluation] = field(default_factory=list)
    thermals: list[ThermalCorrection | None] = field(default_factory=list)
    notes: list[list[str]] = field(default_factory=list)

    def report(self, **kwargs) -> dict:
        """:func:`volerr.positioning.report_dict` of the runs (``inputs``, ``tolerance``,
        ``identification`` passed on)."""
        return report_dict(self.evaluations, self.thermals, self.notes, **kwargs)


def evaluate_files(files, axes, cte_ppm_per_K: float | None = None,
                   material_temp_C: float | None = None,
                   cte_reference_mm: float = 0.0) -> RunSet:
    """Read, correct and evaluate positioning runs.

    Parameters
    ----------
    files : sequence of path
        Run files (long or wide CSV, :func:`volerr.positioning.read_run`).
    axes : sequence of str
        The axis letter of each file, same length as ``files``.
    cte_ppm_per_K : float, optional
        Expansion coefficient, ppm/K; given: every run is corrected to 20 degC
        (:func:`volerr.positioning.correct_to_20C`).
    material_temp_C : float, optional
        Material temperature, degC, for files without a ``T_C`` column.
    cte_reference_mm : float
        Position where the expansion is zero, mm.

    Returns
    -------
    RunSet
    """
    out = RunSet()
    for f, a in zip(files, axes):
        r = read_run(f, a)
        th = None
        if cte_ppm_per_K is not None:
            r, th = correct_to_20C(r, cte_ppm_per_K, material_temp_C, cte_reference_mm)
        out.evaluations.append(evaluate(r))
        out.thermals.append(th)
        out.notes.append(standard_notes(r, th is not None))
    return out


def summary_lines(report: dict) -> tuple[list[str], list[str]]:
    """The printed lines of ``report`` (:func:`report_dict`): one result line per run (um) and
    the notes, prefixed with the file name."""
    from ..units import num

    runs = report["runs"] if "runs" in report else [report]
    lines, notes = [], []
    for r in runs:
        name = Path(r["file"]).name
        U = r.get("uncertainty_um", {})

        def q(key):
            text = f"{key} {num(r[key + '_um'], '.2f')}"
            if key in U:
                text += f" (U {num(U[key], '.2f')})"
            if key in r.get("verdicts", {}):
                text += f" {r['verdicts'][key].upper()}"
            return text
        lines.append(f"{name}: axis {r['axis']}, {r['n_targets']} targets x "
                     f"{r['n_cycles']} cycles: {'  '.join(q(k) for k in 'AEMRB')}  "
                     f"(B_avg {num(r['B_avg_um'], '+.2f')}) um"
                     f"{'; U expanded, k = 2 (ISO/TR 230-9)' if U else ''}")
        if r.get("verdict"):
            lines.append(f"  verdict {r['verdict'].upper()} (ISO 14253-1, tolerance reduced / "
                         f"widened by U, k = 2)")
        notes.extend(f"{name}: {n}" for n in r["notes"])
    return lines, notes
