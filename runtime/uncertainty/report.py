"""Reports of a task-specific uncertainty: the JSON document of ``volerr uncertainty``
(:func:`result_document`), its printed lines (:func:`summary_lines`) and the HTML report (result
table, contributions, plots inline).  Estimates and intervals in mm, bias and uncertainties in
um."""

from __future__ import annotations

import base64
import html

from ..units import UM_PER_MM


from ..units import num  # noqa: F401  (no negative zero; re-exported)


def machine_text(spec=None, errors=None, table_std: str = "") -> str:
    """What the simulated machines are: ``"spec E0=..."``, ``"tables DIR (meaning of std)"`` or
    ``"perfect"``."""
    if spec is not None:
        return "spec " + spec.text()
    if errors is not None:
        return f"tables {errors} ({table_std})"
    return "perfect"


def result_document(problem, values, summary: dict, info: dict, *, layout: str, task: str,
                    evaluation: str, seed: int, chunks: int, scheduler: str, machine: str,
                    noise_um: float, adaptive=None, digits: int | None = None,
                    contributions=None) -> dict:
    """The JSON document of one Monte Carlo run.

    Parameters
    ----------
    problem : volerr.uncertainty.montecarlo.Problem
        The prepared problem (block size, sources).
    values : ndarray, shape (n_samples, n_quantities)
        The Monte Carlo values, mm.
    summary : dict
        :func:`volerr.uncertainty.montecarlo.summarize` of ``values``.
    info : dict
        Run information; with ``candidates`` and ``kept`` for a constrained (spec) ensemble.
    adaptive : volerr.uncertainty.montecarlo.Adaptive, optional
        The adaptive run's record (JCGM 101 7.9); ``digits`` its significant digits.
    contributions : list, optional
        :func:`volerr.uncertainty.montecarlo.contributions`.
    layout, task, evaluation, seed, chunks, scheduler, machine, noise_um
        Recorded as given (``noise_um`` in um).

    Returns
    -------
    dict
        Keys ``layout task evaluation quantities samples seed block_size chunks scheduler
        machine noise_um sources`` and, when present, ``spec_acceptance adaptive
        contributions``.
    """
    doc = {"layout": layout, "task": task, "evaluation": evaluation, "quantities": summary,
           "samples": int(values.shape[0]), "seed": seed, "block_size": problem.block_size,
           "chunks": chunks, "scheduler": scheduler, "machine": machine, "noise_um": noise_um,
           "sources": [s.name for s in problem.sources]}
    if "candidates" in info:
        doc["spec_acceptance"] = {"candidates": info["candidates"], "kept": info["kept"],
                                  "fraction": info["kept"] / info["candidates"]}
    if adaptive is not None:
        doc["adaptive"] = {"runs": adaptive.runs, "samples_per_run": adaptive.per_run,
                           "converged": adaptive.converged, "digits": digits,
                           "tolerance_um": [d * UM_PER_MM for d in adaptive.delta_mm]}
    if contributions is not None:
        doc["contributions"] = contributions
    return doc


def summary_lines(doc: dict) -> list[str]:
    """The lines printed after a run: per quantity estimate (mm), bias, u, U (um) and the 95 %
    coverage interval (mm)."""
    lines = [f"{doc['layout']} {doc['evaluation']}: {doc['samples']} samples, seed {doc['seed']}"]
    for name, q in doc["quantities"].items():
        lo, hi = q["coverage_interval_mm"]
        lines.append(f"  {name:9s} {num(q['estimate_mm'], '.6f')} mm  bias "
                     f"{num(q['bias_um'], '+.3f')} um  u {q['standard_uncertainty_um']:.3f} um  "
                     f"U {q['expanded_uncertainty_um']:.3f} um  95% [{num(lo, '.6f')}, "
                     f"{num(hi, '.6f')}] mm")
    return lines


def _img(png: bytes) -> str:
    return f'<img src="data:image/png;base64,{base64.b64encode(png).decode()}">'


def html_report(doc: dict, pngs=()) -> str:
    """``doc``: the JSON document of ``volerr uncertainty``; ``pngs``: plots to embed."""
    e = html.escape
    rows = []
    for name, q in doc["quantities"].items():
        lo, hi = q["coverage_interval_mm"]
        rows.append(f"<tr><td>{e(name)}</td><td>{num(q['estimate_mm'], '.6f')}</td>"
                    f"<td>{num(q['bias_um'], '.3f')}</td><td>{q['standard_uncertainty_um']:.3f}</td>"
                    f"<td>{q['expanded_uncertainty_um']:.3f}</td>"
                    f"<td>[{num(lo, '.6f')}, {num(hi, '.6f')}]</td></tr>")
    contrib = []
    for c in doc.get("contributions", []):
        cells = "".join(f"<td>{v:.3f}</td>" for v in c["standard_uncertainty_um"].values())
        contrib.append(f"<tr><td>{e(c['source'])}</td>{cells}</tr>")
    names = "".join(f"<th>u({e(n)}) / um</th>" for n in doc["quantities"])
    meta = "".join(f"<li>{e(k)}: {e(str(v))}</li>" for k, v in doc.items()
                   if k not in ("quantities", "contributions"))
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>volerr uncertainty: {e(doc['layout'])}</title>
<style>body{{font-family:sans-serif;max-width:1100px;margin:auto}}
td,th{{border:1px solid #bbb;padding:3px 8px;text-align:right}}table{{border-collapse:collapse}}</style>
</head><body>
<h1>Task-specific uncertainty (Monte Carlo, JCGM 101)</h1>
<ul>{meta}</ul>
<table><tr><th>quantity</th><th>estimate / mm</th><th>bias (known errors) / um</th>
<th>u / um</th><th>U (k=2) / um</th><th>95 % interval (prob. symmetric) / mm</th></tr>
{''.join(rows)}</table>
<h2>Contributions (one source at a time)</h2>
<table><tr><th>source</th>{names}</tr>{''.join(contrib)}</table>
{''.join(_img(p) for p in pngs)}
</body></html>
"""
