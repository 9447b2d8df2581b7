"""Reports of a task-specific uncertainty: the JSON document of ``volerr uncertainty``
(:func:`result_document`), its printed lines (:func:`summary_lines`) and the HTML report
(readable header, result statement, contributions, plots inline).  Estimates and intervals in
mm, bias and uncertainties in um.

The result statement (GUM 3.2.4 and 6; ISO 14253-2 practice).  The Monte Carlo reading of the
virtual CMM has a known *bias* b (the reading of the machine with its known errors minus the
nominal value of the task) and a standard uncertainty u; U = 2 u.  Two ways to state it:

* ``corrected`` (default, GUM 3.2.4: a result is corrected for recognised systematic
  effects): the corrected estimate y_c = y - b with U; coverage interval = the Monte Carlo
  interval of the reading shifted by -b.
* ``uncorrected``: the reading y itself, with an interval that contains the bias: the
  Monte Carlo interval [lo, hi] widened on the side of the bias, [lo - max(b, 0), hi +
  max(-b, 0)] (it holds both the reading's interval and the corrected one; U- and U+ differ).
"""

from __future__ import annotations

import html
import math
from pathlib import Path

from ..plotstyle import embedded_img
from ..report.page import document
from ..units import MM_PER_UM, UM_PER_MM, num  # noqa: F401  (num re-exported)

from ..choices import BIAS_MODES  # noqa: E402,F401  (stated once, light)


def machine_text(spec=None, errors=None, table_std: str = "", repeatability: bool = False) -> str:
    """What the simulated machines are, in words."""
    if spec is not None:
        return "machines that pass the ISO 10360-2 specification " + spec.text()
    if errors is not None:
        how = ("_std read as the uncertainty of the tabulated values" if table_std != "repeatability"
               else "_std read as a single-reading repeatability (--table-std repeatability)")
        rep = "; _s repeatability drawn per point" if repeatability else ""
        return f"error tables of {Path(str(errors)).name} ({how}{rep})"
    return "a perfect machine (only the other sources are random)"


def statement(q: dict, bias: str = "corrected") -> dict:
    """The result stated per ``bias`` (module docstring): ``result_mm``,
    ``result_interval_mm``, ``result_U_minus_um``, ``result_U_plus_um``."""
    b = q["bias_um"] * MM_PER_UM
    lo, hi = q["coverage_interval_mm"]
    if bias == "corrected":
        value, ilo, ihi = q["estimate_mm"] - b, lo - b, hi - b
    else:
        value, ilo, ihi = q["estimate_mm"], lo - max(b, 0.0), hi + max(-b, 0.0)
    return {"result_mm": value, "result_interval_mm": [ilo, ihi],
            "result_U_minus_um": (value - ilo) * UM_PER_MM,
            "result_U_plus_um": (ihi - value) * UM_PER_MM}


def result_document(problem, values, summary: dict, info: dict, *, layout: str, task: str,
                    evaluation: str, seed: int, chunks: int, scheduler: str, machine: str,
                    noise_um: float, adaptive=None, digits: int | None = None,
                    contributions=None, bias: str = "corrected", table_uncertainty=None,
                    task_points: int | None = None) -> dict:
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
    bias : {"corrected", "uncorrected"}
        Which result the stated interval belongs to (module docstring).
    table_uncertainty : list, optional
        How each uncertainty column of the tables was used
        (:attr:`volerr.uncertainty.ensemble.Ensemble.table_columns`).
    layout, task, evaluation, seed, chunks, scheduler, machine, noise_um, task_points
        Recorded as given (``noise_um`` in um).

    Returns
    -------
    dict
        Keys ``layout task evaluation quantities samples seed block_size chunks scheduler
        machine noise_um sources bias table_uncertainty`` and, when present,
        ``spec_acceptance adaptive contributions``, then ``budgets`` (:func:`budgets`); each
        quantity also carries ``corrected_estimate_mm`` and the stated result
        (:func:`statement`).
    """
    quantities = {}
    for name, q in summary.items():
        quantities[name] = {**q, "corrected_estimate_mm": q["estimate_mm"]
                            - q["bias_um"] * MM_PER_UM, **statement(q, bias)}
    doc = {"layout": layout, "task": task, "evaluation": evaluation, "quantities": quantities,
           "samples": int(values.shape[0]), "seed": seed, "block_size": problem.block_size,
           "chunks": chunks, "scheduler": scheduler, "machine": machine, "noise_um": noise_um,
           "sources": [s.name for s in problem.sources], "bias": bias,
           "table_uncertainty": list(table_uncertainty or [])}
    if task_points is not None:
        doc["task_points"] = int(task_points)
    if "candidates" in info:
        doc["spec_acceptance"] = {"candidates": info["candidates"], "kept": info["kept"],
                                  "fraction": info["kept"] / info["candidates"]}
    if adaptive is not None:
        doc["adaptive"] = {"runs": adaptive.runs, "samples_per_run": adaptive.per_run,
                           "converged": adaptive.converged, "digits": digits,
                           "tolerance_um": [d * UM_PER_MM for d in adaptive.delta_mm]}
    if contributions is not None:
        doc["contributions"] = contributions
    doc["budgets"] = budgets(doc)
    return doc


def budgets(doc: dict) -> dict:
    """Per quantity the budget (:mod:`volerr.report.budget`, um) of the Monte Carlo standard
    uncertainty u: each group of sources (``doc["contributions"]``: the Monte Carlo run with
    only that group random, the others off) with its u_i as u(x_i) and one sensitivity
    c = u / sqrt(sum u_i^2) for all (the joint run against the root sum of squares of the
    one-at-a-time runs: 1 when the groups add in quadrature; it carries their interactions,
    the spec's acceptance of machines and the sampling), so that the combined u is the u the
    run states.  Without contributions (``--contributions 0``) one source, the joint run.
    The Monte Carlo's own standard error of u, u / sqrt(2 (M - 1)) for M samples (normal
    approximation, JCGM 101 7.9), is a note: it is the uncertainty of u, not a source."""
    from ..report.budget import budget, source

    m = int(doc["samples"])
    out = {}
    for name, q in doc["quantities"].items():
        u = float(q["standard_uncertainty_um"])
        one = [(c["source"], float(c["standard_uncertainty_um"][name]))
               for c in doc.get("contributions") or [] if name in c["standard_uncertainty_um"]]
        rss = math.sqrt(sum(v * v for _, v in one))
        notes = [f"Monte Carlo standard error of u: {u / math.sqrt(2 * max(m - 1, 1)):.3g} "
                 f"\u00b5m ({m} samples)."]
        if one and rss > 0:
            c = u / rss
            srcs = [source(f"{s} (Monte Carlo, only this group random)", v, "um", c)
                    for s, v in one]
            notes.append(f"c = u / \u221a(\u03a3 u(x_i)\u00b2) = {c:.4g}: the joint run over "
                         f"the one-at-a-time runs (interactions, acceptance, sampling; 1 "
                         f"when the groups add in quadrature).")
        else:
            srcs = [source("every source together (joint Monte Carlo; no one-at-a-time "
                           "runs: --contributions 0)", u, "um")]
        out[name] = budget(name, "um", srcs, 2.0, notes=notes)
    return out


def summary_lines(doc: dict) -> list[str]:
    """The lines printed after a run: per quantity the stated result with its interval
    (``--bias``), the reading, bias, u and U."""
    lines = [f"{doc['layout']} {doc['evaluation']}: {doc['samples']} samples, seed "
             f"{doc['seed']}; result {doc.get('bias', 'corrected')} for the bias of the known "
             f"errors"]
    for name, q in doc["quantities"].items():
        lo, hi = q["result_interval_mm"]
        lines.append(f"  {name:9s} {num(q['result_mm'], '.6f')} mm, 95 % [{num(lo, '.6f')}, "
                     f"{num(hi, '.6f')}] mm  (reading {num(q['estimate_mm'], '.6f')} mm, bias "
                     f"{num(q['bias_um'], '+.3f')} um, u {num(q['standard_uncertainty_um'], '.3f')} "
                     f"um (k = 1), U {num(q['expanded_uncertainty_um'], '.3f')} um (k = 2))")
    return lines


def header_rows(doc: dict) -> list:
    """(label, text) of the page header: task, machine, error sources, samples, convergence."""
    task = Path(str(doc["task"])).name
    pts = f", {doc['task_points']} probing points" if "task_points" in doc else ""
    rows = [("task", f"{doc['evaluation']} from {task}{pts}"),
            ("machine", f"{doc['layout']}: {doc['machine']}")]
    sources = ", ".join(doc["sources"]) or "none"
    if doc.get("noise_um"):
        sources += f" (probing noise {num(doc['noise_um'], 'g')} \u00b5m per point)"
    rows.append(("random sources", sources))
    groups = {}
    for t in doc.get("table_uncertainty", []):
        groups.setdefault((t["meaning"], t["drawn"]), []).append(t["column"])
    for (meaning, drawn), cols in groups.items():
        rows.append((f"table column{'s' if len(cols) > 1 else ''} {', '.join(cols)}",
                     f"{meaning}; drawn {drawn}"))
    rows.append(("samples", f"{doc['samples']} (seed {doc['seed']})"))
    if "adaptive" in doc:
        a = doc["adaptive"]
        conv = (f"adaptive (JCGM 101 7.9): {a['runs']} runs of {a['samples_per_run']}, "
                f"{'converged' if a['converged'] else 'NOT converged'} to {a['digits']} "
                f"significant digits of u")
    else:
        conv = ("fixed number of samples; stability: see the convergence plot (--adaptive "
                "stops on JCGM 101 7.9)")
    rows.append(("convergence", conv))
    if "spec_acceptance" in doc:
        s = doc["spec_acceptance"]
        rows.append(("constrained Monte Carlo", f"{s['kept']} of {s['candidates']} candidate "
                                                f"machines passed the specification"))
    rows.append(("result", "corrected for the bias of the known errors (estimate \u2212 bias, "
                           "with U)" if doc.get("bias", "corrected") == "corrected" else
                 "uncorrected: the reading, with an interval widened to contain the bias"))
    return rows


def html_report(doc: dict, pngs=(), captions=()) -> str:
    """``doc``: the JSON document of ``volerr uncertainty``; ``pngs``: plots to embed,
    ``captions``: one sentence each."""
    e = html.escape
    head = "".join(f"<tr><th class='l'>{e(k)}</th><td class='l'>{e(v)}</td></tr>"
                   for k, v in header_rows(doc))
    rows = []
    for name, q in doc["quantities"].items():
        lo, hi = q["result_interval_mm"]
        rows.append(f"<tr><td class='l'>{e(name)}</td><td>{num(q['nominal_mm'], '.6f')}</td>"
                    f"<td>{num(q['estimate_mm'], '.6f')}</td><td>{num(q['bias_um'], '+.3f')}</td>"
                    f"<td><b>{num(q['result_mm'], '.6f')}</b></td>"
                    f"<td>{num(q['standard_uncertainty_um'], '.3f')}</td>"
                    f"<td>{num(q['expanded_uncertainty_um'], '.3f')}</td>"
                    f"<td>[{num(lo, '.6f')}, {num(hi, '.6f')}]</td>"
                    f"<td>{'yes' if lo <= q['nominal_mm'] <= hi else 'no'}</td></tr>")
    contrib = []
    for c in doc.get("contributions", []):
        cells = "".join(f"<td>{num(v, '.3f')}</td>" for v in c["standard_uncertainty_um"].values())
        contrib.append(f"<tr><td class='l'>{e(c['source'])}</td>{cells}</tr>")
    names = "".join(f"<th>u({e(n)}) / \u00b5m</th>" for n in doc["quantities"])
    corrected = doc.get("bias", "corrected") == "corrected"
    result_head = ("corrected result y \u2212 b / mm" if corrected else "result (uncorrected) / mm")
    figs = "".join(f"<figure>{embedded_img(p, c or 'figure')}<figcaption>{e(c)}</figcaption>"
                   f"</figure>" for p, c in zip(pngs, list(captions) + [""] * len(pngs)))
    return document(f"volerr uncertainty: {doc['layout']}", f"""\
<h1>Task-specific uncertainty (Monte Carlo, JCGM 101)</h1>
<table>{head}</table>
<h2>Result</h2>
<table><tr><th class='l'>quantity</th><th>nominal / mm</th><th>Monte Carlo reading y / mm</th>
<th>bias b of the known errors / \u00b5m</th><th>{result_head}</th><th>u / \u00b5m</th>
<th>U (k = 2) / \u00b5m</th><th>95 % coverage interval of the result / mm</th>
<th>nominal inside</th></tr>
{''.join(rows)}</table>
<p>{'The result is corrected for the known bias (GUM 3.2.4): y &minus; b with U; the interval is the probabilistically symmetric 95 % interval of the Monte Carlo, shifted by &minus;b.' if corrected else 'The result is the reading itself; its interval is the 95 % Monte Carlo interval widened on the side of the bias so that it contains it (U&minus; and U+ differ).'}</p>
<h2>Contributions (one source at a time)</h2>
<table><tr><th class='l'>source</th>{names}</tr>{''.join(contrib)}</table>
{figs}""")
