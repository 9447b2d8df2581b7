"""Outputs of an ISO 230-2 evaluation: JSON dictionary, the standard's plot, an HTML
certificate and an error table for an error directory.

JSON (um for deviations, mm for targets): one run gives its keys at the top level; several runs
give ``{"runs": [run, run, ...]}`` with the same keys in each run.  Keys of a run: ``file``,
``format``, ``axis``, ``n_targets``, ``n_cycles``, ``cycles``, the axis figures ``A_um A_fwd_um
A_bwd_um B_um B_avg_um R_um R_fwd_um R_bwd_um E_um E_fwd_um E_bwd_um M_um``, the per-target
arrays ``targets_mm mean_fwd_um mean_bwd_um mean_um reversal_um s_fwd_um s_bwd_um R_i_fwd_um
R_i_bwd_um R_i_um`` (the repeatabilities at each position carry the standard's index ``_i`` so
that they do not collide with the axis figures ``R_um R_fwd_um R_bwd_um``),
``temperature_correction``
(``{"applied": false}`` or what was done), ``conditions`` (other temperature columns: min,
mean, max degC), ``ignored_columns`` (columns of the file not used), ``notes`` and
``standard``.

Error table (``DIR/<axis>.csv``, :mod:`volerr.tables` format): ``E<axis><axis>_um`` = mean
bidirectional deviation x_i at each target, ``E<axis><axis>_s_um`` = the pooled unidirectional
single-reading repeatability S_i = sqrt((S_i_up^2 + S_i_dn^2) / 2) (the scatter of one
positioning from a given direction; the reversal is not in it), ``E<axis><axis>_std_um`` =
S_i / sqrt(2 n), the standard uncertainty of the mean x_i, and ``RV_<axis>_um`` = reversal
B_i.
"""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np

from ..tables import ErrorTable
from ..units import MM_PER_M, UM_PER_MM

from .. import conformance
from ..certificate import html_table, verdict_html
from ..report.page import document
from ..plotstyle import embedded_img, figure, label, png, styled
from ..units import num
from ._evaluate import Evaluation
from ._uncertainty import BudgetInputs, QUANTITIES, budget, decisive_targets, verdicts

STANDARD = "ISO 230-2:2014, clause 3 (standard test cycle, linear axis)"
_ROWS = (("A", "A_fwd", "A_bwd", "accuracy of positioning"),
         ("E", "E_fwd", "E_bwd", "systematic positioning error"),
         ("M", None, None, "range of mean bidirectional positional deviation"),
         ("R", "R_fwd", "R_bwd", "repeatability of positioning"),
         ("B", None, None, "reversal value (max |B_i|)"),
         ("B_avg", None, None, "mean reversal value"))


def run_dict(ev: Evaluation, thermal=None, notes=(), inputs=None, tolerance=None) -> dict:
    """JSON-ready dictionary of one evaluated run (keys in the module docstring); with the
    measurement uncertainty ``uncertainty_um`` {A, E, M, R, B: U (k = 2)} of
    :func:`volerr.positioning._uncertainty.budget` and, with ``tolerance`` (um), the ISO
    14253-1 ``verdicts`` per quantity and the ``verdict``."""
    run = ev.run
    out = {"file": run.source, "format": run.format, "axis": run.axis,
           "n_targets": run.n_targets, "n_cycles": run.n_cycles, "cycles": list(run.cycles),
           "standard": STANDARD}
    out.update(ev.figures_um())
    out.update(ev.per_target_um())
    out["temperature_correction"] = thermal.as_dict() if thermal is not None else {
        "applied": False}
    out["conditions"] = {k: {"min": v[0], "mean": v[1], "max": v[2]}
                         for k, v in run.conditions.items()}
    if run.temperature is not None and thermal is None:
        t = run.temperature
        out["conditions"]["material_T_C"] = {"min": float(t.min()), "mean": float(t.mean()),
                                             "max": float(t.max())}
    out["ignored_columns"] = list(run.ignored_columns)
    out["notes"] = list(notes)
    b = budget(ev, thermal, inputs or BudgetInputs())
    out["uncertainty_um"] = b["uncertainty_um"]
    out["uncertainty_budget"] = {k: b[k] for k in ("contributions_um", "coverage_factor",
                                                   "travel_mm", "inputs", "notes")}
    out["uncertainty_budget"]["method"] = ("ISO/TR 230-9 (contributions in quadrature, k = 2) "
                                           "with the contributors of ISO 230-2:2014 Annex A")
    out["budgets"] = b["budgets"]
    if tolerance:
        out["tolerance_um"] = dict(tolerance)
        out.update(verdicts(out, b["uncertainty_um"], tolerance))
        out["decision_rule"] = conformance.RULE
    return out


def report_dict(evaluations, thermals=None, notes=None, *, inputs=None, tolerance=None,
                identification=None) -> dict:
    """One run: its dictionary; several: ``{"runs": [...]}`` (and the overall ``verdict``).

    ``inputs``: :class:`BudgetInputs` of the measurement uncertainty (default values when
    None); ``tolerance``: quantity -> tolerance, um (``A E M R B``): verdicts per ISO
    14253-1; ``identification``: :class:`volerr.certificate.Identification` (JSON key
    ``identification``)."""
    thermals = thermals or [None] * len(evaluations)
    notes = notes or [()] * len(evaluations)
    runs = [run_dict(e, t, n, inputs, tolerance)
            for e, t, n in zip(evaluations, thermals, notes)]
    out = runs[0] if len(runs) == 1 else {"runs": runs}
    if len(runs) > 1 and tolerance:
        out["verdict"] = conformance.overall(r["verdict"] for r in runs)
        out["decision_rule"] = conformance.RULE
    if identification is not None:
        out["identification"] = identification.as_dict()
    return out


def _label(ev: Evaluation, k: int, n: int) -> str:
    name = Path(ev.run.source).name if ev.run.source else f"run {k + 1}"
    return f"{ev.run.axis} axis: {name}" if n > 1 else f"{ev.run.axis} axis ({name})"


#: colour of a verdict's mark on the plot
_MARK = {"fail": "#c62828", "undecided": "#e08a00"}


@styled
def plot_runs(evaluations, path=None, verdicts_per_run=None) -> bytes:
    """The standard's plot, one panel per run (stacked): mean deviation per direction with
    +-2 S bands (k = 2), the bidirectional mean, every reading, and A B E M R in a box.
    ``verdicts_per_run``: per run {quantity: verdict}; the readings that decide a quantity
    that fails (red) or is undecided (amber) are ringed and labelled.  Returns the PNG bytes
    (and writes them to ``path`` when given)."""
    n = len(evaluations)
    fig, axes = figure(n, 1, height=4.8 * n, squeeze=False)
    for k, (ev, ax) in enumerate(zip(evaluations, axes[:, 0])):
        t = ev.run.targets
        um = UM_PER_MM
        for d, (mean, s, col, arrow, name) in enumerate(
                ((ev.mean_fwd, ev.s_fwd, "tab:red", "\u2191", "forward"),
                 (ev.mean_bwd, ev.s_bwd, "tab:blue", "\u2193", "backward"))):
            x = ev.run.deviation[:, d, :] * um
            ax.plot(np.repeat(t, x.shape[1]), x.ravel(), ".", color=col, ms=3, alpha=0.5)
            ax.plot(t, mean * um, "-o", color=col, ms=3,
                    label=f"mean {name} x\u0304{arrow}, band \u00b12 S{arrow} (k = 2)")
            ax.fill_between(t, (mean - 2 * s) * um, (mean + 2 * s) * um, color=col, alpha=0.15)
        ax.plot(t, ev.mean * um, "k--", lw=1.2, label="mean bidirectional x\u0304")
        ax.axhline(0.0, color="0.6", lw=0.6)
        marks = {}   # (target, direction) -> [(quantity, verdict)]
        for q, v in ((verdicts_per_run or [{}] * n)[k] or {}).items():
            if v in _MARK:
                for at in decisive_targets(ev, q):
                    marks.setdefault(at, []).append((q, v))
        for (i, d), qv in marks.items():
            y = (ev.mean if d is None else (ev.mean_fwd, ev.mean_bwd)[d])[i] * um
            worst = "fail" if any(v == "fail" for _, v in qv) else "undecided"
            ax.plot(t[i], y, "o", ms=14, mfc="none", mec=_MARK[worst], mew=2.2)
            text = "; ".join(f"{', '.join(q for q, w in qv if w == v)}: {v}"
                             for v in ("fail", "undecided") if any(w == v for _, w in qv))
            # on a white ground: the labels lay over the bands and lines (seen on the page)
            ax.annotate(text, (t[i], y), xytext=(9, 7), textcoords="offset points",
                        color=_MARK[worst], fontweight="bold", zorder=5,
                        bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none",
                              "alpha": 0.85})
        f = ev.figures_um()
        ax.set_xlabel(label(f"target position {ev.run.axis}", "mm"))
        ax.set_ylabel(label("positional deviation", "um"))
        ax.set_title(f"{_label(ev, k, n)}: {ev.run.n_targets} targets, {ev.run.n_cycles} "
                     f"cycles, ISO 230-2\nA {num(f['A_um'], '.2f')}, E "
                     f"{num(f['E_um'], '.2f')}, M {num(f['M_um'], '.2f')}, R "
                     f"{num(f['R_um'], '.2f')}, B {num(f['B_um'], '.2f')} (mean "
                     f"{num(f['B_avg_um'], '+.2f')}) \u00b5m")
        # below the panel: inside it hid the forward band at 200-300 mm (seen on the page)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=3, fontsize=9)
    data = png(fig)
    if path is not None:
        from ..fileio import write_bytes
        write_bytes(path, data)
    return data


def _f(v: float) -> str:
    return num(v, ".2f")


def _row(runs, label, key) -> str:
    e = html.escape
    return f"<tr><th class='l'>{e(label)}</th>" + "".join(
        f"<td>{e(str(r[key])) if not isinstance(r[key], float) else _f(r[key])}</td>"
        for r in runs) + "</tr>"


def _trow(runs, label, fn) -> str:
    e = html.escape
    return f"<tr><th class='l'>{e(label)}</th>" + "".join(
        f"<td>{e(fn(r))}</td>" for r in runs) + "</tr>"


def _temperature_correction_text(r: dict) -> str:
    tc = r["temperature_correction"]
    if not tc["applied"]:
        return "none"
    return (f"to 20 \u00b0C, \u03b1 = {tc['cte_ppm_per_K']:g} ppm/K, P_ref = "
            f"{tc['reference_mm']:g} mm, T = {_f(tc['temperature_C']['min'])} .. "
            f"{_f(tc['temperature_C']['max'])} \u00b0C ({tc['temperature_source']}), "
            f"correction {_f(tc['correction_um']['min'])} .. "
            f"{_f(tc['correction_um']['max'])} \u00b5m")


def _conditions_text(r: dict) -> str:
    c = r["conditions"]
    return "; ".join(f"{k}: {_f(v['min'])} .. {_f(v['max'])} (mean {_f(v['mean'])})"
                     for k, v in c.items()) or "not recorded"


def _conditions_rows(runs) -> str:
    """Rows of the conditions table: axis, targets, cycles, format, temperatures, correction."""
    return "".join([
        _trow(runs, "axis", lambda r: r["axis"]),
        _trow(runs, "targets", lambda r: f"{r['n_targets']} from {r['targets_mm'][0]:g} to "
                                         f"{r['targets_mm'][-1]:g} mm"),
        _row(runs, "cycles per direction", "n_cycles"),
        _trow(runs, "input format", lambda r: r["format"]),
        _trow(runs, "temperatures / \u00b0C", _conditions_text),
        _trow(runs, "temperature correction", _temperature_correction_text),
    ])


def _results_rows(runs) -> str:
    """Rows of the results table: per quantity the value (directions in small print), its
    expanded uncertainty U (k = 2), the tolerance and the ISO 14253-1 verdict, per run."""
    e = html.escape
    results = []
    for key, up, dn, name in _ROWS:
        cells = []
        for r in runs:
            value = (f"{_f(r[key + '_um'])}" + (f" <span class='s'>(\u2191 {_f(r[up + '_um'])}, "
                                                 f"\u2193 {_f(r[dn + '_um'])})</span>"
                                                 if up else ""))
            U = r["uncertainty_um"].get(key)
            tol = r.get("tolerance_um", {}).get(key)
            v = r.get("verdicts", {}).get(key)
            cells.append(f"<td>{value}</td><td>{_f(U) if U is not None else ''}</td>"
                         f"<td>{_f(tol) if tol is not None else ''}</td>"
                         f"<td>{verdict_html(v) if tol is not None else ''}</td>")
        results.append(f"<tr><th class='l'>{e(key)} \u2014 {e(name)}</th>{''.join(cells)}</tr>")
    return "".join(results)


_TARGET_COLUMNS = (("targets_mm", "P_i / mm"), ("mean_fwd_um", "x\u0304\u2191 / \u00b5m"),
                   ("mean_bwd_um", "x\u0304\u2193 / \u00b5m"), ("mean_um", "x\u0304 / \u00b5m"),
                   ("reversal_um", "B_i / \u00b5m"), ("s_fwd_um", "S\u2191 / \u00b5m"),
                   ("s_bwd_um", "S\u2193 / \u00b5m"), ("R_i_fwd_um", "R_i\u2191 / \u00b5m"),
                   ("R_i_bwd_um", "R_i\u2193 / \u00b5m"), ("R_i_um", "R_i / \u00b5m"))


def _target_tables(runs) -> str:
    """One per-target table (um) per run."""
    e = html.escape
    cols = _TARGET_COLUMNS
    tables = []
    for r in runs:
        body = "".join("<tr>" + "".join(f"<td>{r[k][i]:g}</td>" if k == "targets_mm" else
                                        f"<td>{_f(r[k][i])}</td>" for k, _ in cols) + "</tr>"
                       for i in range(r["n_targets"]))
        tables.append(f"<h3>{e(Path(r['file']).name)} \u2014 per target</h3>"
                      f"<table><tr>{''.join(f'<th>{e(h)}</th>' for _, h in cols)}</tr>{body}"
                      f"</table>")
    return "".join(tables)


_CONTRIBUTIONS = (("instrument", "instrument (interferometer accuracy over the travel)"),
                  ("alignment", "alignment (cosine error of the beam)"),
                  ("temperature", "material temperature reading"),
                  ("cte", "expansion coefficient"),
                  ("environment", "environmental variation (drift test)"))


def _budget_rows(runs) -> str:
    """Rows of the uncertainty budget: standard uncertainties (um) per contribution."""
    e = html.escape
    rows = []
    for key, name in _CONTRIBUTIONS:
        cells = "".join(f"<td>{_f(r['uncertainty_budget']['contributions_um'][key])}</td>"
                        if key in r["uncertainty_budget"]["contributions_um"]
                        else "<td>not included</td>" for r in runs)
        rows.append(f"<tr><th class='l'>{e(name)}</th>{cells}</tr>")
    for q in QUANTITIES:
        cells = "".join(f"<td>{_f(r['uncertainty_budget']['contributions_um'][f'repeatability_{q}'])}"
                        f"</td>" for r in runs)
        rows.append(f"<tr><th class='l'>repeatability, for {q}</th>{cells}</tr>")
    return "".join(rows)


def report_html(report: dict, png: bytes, inputs, generated: str = "", identification=None) -> str:
    """A one-page certificate: identification (machine, instrument, operator, date,
    temperatures, expansion coefficient), conditions, results with their measurement
    uncertainty U (k = 2, ISO/TR 230-9) and, with tolerances, the ISO 14253-1 verdicts; the
    plot (embedded PNG), the uncertainty budget and the per-target table of every run.
    Plain HTML, no network.

    Parameters
    ----------
    report : dict
        :func:`report_dict` of the evaluated runs (deviations um, targets mm).
    png : bytes
        The ISO 230-2 plot (:func:`plot_runs`).
    inputs : sequence of path
        The run files, listed in the report.
    generated : str
        A sentence on how and when the report was made.
    identification : volerr.certificate.Identification, optional
        The identification fields (not given: every field "not stated").
    """
    from ..certificate import Identification

    runs = report["runs"] if "runs" in report else [report]
    e = html.escape
    head = "".join(f"<th colspan='4'>{e(Path(r['file']).name)} ({e(r['axis'])})</th>"
                   for r in runs)
    head1 = "".join(f"<th>{e(Path(r['file']).name)} ({e(r['axis'])})</th>" for r in runs)
    sub = "".join("<th>value / \u00b5m</th><th>U (k = 2) / \u00b5m</th><th>tolerance / \u00b5m"
                  "</th><th>verdict</th>" for _ in runs)
    conditions = _conditions_rows(runs)
    results = _results_rows(runs)
    tables = _target_tables(runs)
    notes = [f"{Path(r['file']).name}: {n}" for r in runs
             for n in list(r["notes"]) + list(r["uncertainty_budget"]["notes"])]
    files = "".join(f"<li><code>{e(str(p))}</code></li>" for p in inputs)
    ident = identification or Identification()
    toleranced = any("tolerance_um" in r for r in runs)
    overall = report.get("verdict") if toleranced else None
    verdict_p = (f"<p class='verdict'>Verdict: {verdict_html(overall)} &mdash; "
                 f"{e(conformance.RULE)}.</p>" if toleranced else
                 "<p class='verdict'>No tolerance given (<code>--tolerance</code>): no "
                 "verdict.</p>")
    return document("ISO 230-2 positioning test", f"""\
<h1>Positioning accuracy and repeatability &mdash; ISO 230-2</h1>
<p>Evaluation of laser-interferometer positioning runs by direct measurement of a single axis
according to {e(STANDARD)}. Deviations are actual minus target position, in &micro;m.
{e(generated)}</p>
<h2>Identification</h2>
{html_table(ident)}
{verdict_p}
<h2>Input files</h2><ul>{files}</ul>
<h2>Conditions of the run</h2>
<table><tr><th></th>{head1}</tr>{conditions}</table>
<h2>Results</h2>
<table><tr><th></th>{head}</tr><tr><th></th>{sub}</tr>{results}</table>
<p class="s">A, E and R bidirectional over both directions; &uarr; forward, &darr; backward
approach. E = max &minus; min of the mean unidirectional deviations of both directions.
U: expanded measurement uncertainty (k = 2) after ISO/TR 230-9 (budget below).</p>
<h2>Plot</h2>
{embedded_img(png, "ISO 230-2 plot")}
<p class="s">Bands: &plusmn;2 S (k = 2) of one reading per direction; ringed: the readings that
decide a quantity that fails (red) or is undecided (amber).</p>
<h2>Measurement uncertainty (ISO/TR 230-9)</h2>
<table><tr><th>standard uncertainty u / &micro;m</th>{head1}</tr>{_budget_rows(runs)}</table>
<p class="s">Instrument, alignment and temperature act on A, E and M (ranges over the travel);
R and B are differences at one target, where they cancel. U = 2 u<sub>c</sub>.</p>
{tables}
{'<h2>Notes</h2><ul>' + ''.join(f'<li>{e(n)}</li>' for n in notes) + '</ul>' if notes else ''}""")


def error_table(ev: Evaluation) -> ErrorTable:
    """Error table of the run's axis (X, Y, Z only), mm:

    * ``E<a><a>`` = mean bidirectional deviation x_i = (mean_fwd + mean_bwd) / 2;
    * its ``std`` = the standard uncertainty (Type A) of that mean, S_i / sqrt(2 n) with S_i =
      sqrt((s_fwd^2 + s_bwd^2) / 2) the pooled single-reading repeatability and n the cycles
      per direction (2 n readings per target; the reversal is a fixed effect of the mean, not
      a scatter): what ``volerr uncertainty --table-std systematic`` (the default) needs, the
      uncertainty of the error function at each node;
    * the reversal B_i.

    * its ``s`` = the repeatability S_i of one reading (:func:`repeatability`)."""
    from ..errors import require

    a = ev.run.axis
    require(a in "XYZ", f"--table-out: axis {a} has no ISO 230-1 positioning parameter in the "
                        f"error-table format (X, Y, Z only)")
    name = f"E{a}{a}"
    S = repeatability(ev)
    u_mean = S / np.sqrt(2 * ev.run.n_cycles)
    return ErrorTable(a, ev.run.targets, {name: ev.mean}, {name: u_mean}, {}, ev.reversal,
                      {name: S})


def repeatability(ev: Evaluation) -> np.ndarray:
    """Pooled unidirectional single-reading repeatability S_i = sqrt((s_fwd^2 + s_bwd^2) / 2)
    at each target, mm, shape (m,)."""
    return np.sqrt(0.5 * (ev.s_fwd ** 2 + ev.s_bwd ** 2))


def error_table_csv(ev: Evaluation) -> str:
    """CSV text of :func:`error_table`: ``EXX_um, EXX_std_um`` (S_i / sqrt(2 n)), ``EXX_s_um``
    (S_i, one reading) and ``RV_X_um``."""
    from ..tables import table_to_csv

    return table_to_csv(error_table(ev))


def standard_notes(run, corrected: bool) -> list[str]:
    """Where the run falls short of the ISO 230-2 standard test (notes, not errors)."""
    notes = []
    if run.n_cycles < 5:
        notes.append(f"{run.n_cycles} cycles per direction; the standard test cycle has 5")
    travel = float(run.targets[-1] - run.targets[0])
    need = max(5, int(np.ceil(5 * travel / MM_PER_M)))
    if run.n_targets < need:
        notes.append(f"{run.n_targets} targets over {travel:g} mm; the standard asks for at "
                     f"least 5 per metre and at least 5 ({need})")
    if run.temperature is not None and not corrected:
        t = run.temperature
        if abs(float(t.mean()) - 20.0) > 0.05:
            notes.append(f"material temperature {float(t.mean()):.2f} degC recorded but not "
                         f"corrected to 20 degC (give --cte-ppm-per-K)")
    return notes
