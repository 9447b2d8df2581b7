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
bidirectional deviation x_i at each target, ``E<axis><axis>_std_um`` = pooled unidirectional
repeatability estimator sqrt((S_i_up^2 + S_i_dn^2) / 2) (the scatter of one positioning from
a given direction; the reversal is not in it) and ``RV_<axis>_um`` = reversal B_i.
"""

from __future__ import annotations

import base64
import html
import io
from pathlib import Path

import numpy as np

from ..tables import ErrorTable
from ..units import MM_PER_M, UM_PER_MM

from ._evaluate import Evaluation

STANDARD = "ISO 230-2:2014, clause 3 (standard test cycle, linear axis)"
_ROWS = (("A", "A_fwd", "A_bwd", "accuracy of positioning"),
         ("E", "E_fwd", "E_bwd", "systematic positioning error"),
         ("M", None, None, "range of mean bidirectional positional deviation"),
         ("R", "R_fwd", "R_bwd", "repeatability of positioning"),
         ("B", None, None, "reversal value (max |B_i|)"),
         ("B_avg", None, None, "mean reversal value"))


def run_dict(ev: Evaluation, thermal=None, notes=()) -> dict:
    """JSON-ready dictionary of one evaluated run (keys in the module docstring)."""
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
    return out


def report_dict(evaluations, thermals=None, notes=None) -> dict:
    """One run: its dictionary; several: ``{"runs": [...]}``."""
    thermals = thermals or [None] * len(evaluations)
    notes = notes or [()] * len(evaluations)
    runs = [run_dict(e, t, n) for e, t, n in zip(evaluations, thermals, notes)]
    return runs[0] if len(runs) == 1 else {"runs": runs}


def _label(ev: Evaluation, k: int, n: int) -> str:
    name = Path(ev.run.source).name if ev.run.source else f"run {k + 1}"
    return f"{ev.run.axis} axis: {name}" if n > 1 else f"{ev.run.axis} axis ({name})"


def plot_runs(evaluations, path=None) -> bytes:
    """The standard's plot, one panel per run side by side: mean deviation per direction with
    +-2S bands, the bidirectional mean, every reading, and A B E M R in a box.  Returns the PNG
    bytes (and writes them to ``path`` when given)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = len(evaluations)
    fig, axes = plt.subplots(1, n, figsize=(9.5 * n, 5.2), squeeze=False, sharey=True)
    for k, (ev, ax) in enumerate(zip(evaluations, axes[0])):
        t = ev.run.targets
        um = UM_PER_MM
        for d, (mean, s, col, arrow, name) in enumerate(
                ((ev.mean_fwd, ev.s_fwd, "tab:red", "\u2191", "forward"),
                 (ev.mean_bwd, ev.s_bwd, "tab:blue", "\u2193", "backward"))):
            x = ev.run.deviation[:, d, :] * um
            ax.plot(np.repeat(t, x.shape[1]), x.ravel(), ".", color=col, ms=3, alpha=0.5)
            ax.plot(t, mean * um, "-o", color=col, ms=3,
                    label=f"mean {name} x\u0304{arrow} \u00b1 2S{arrow}")
            ax.fill_between(t, (mean - 2 * s) * um, (mean + 2 * s) * um, color=col, alpha=0.15)
        ax.plot(t, ev.mean * um, "k--", lw=1.2, label="mean bidirectional x\u0304")
        ax.axhline(0.0, color="0.6", lw=0.6)
        f = ev.figures_um()
        box = (f"A = {f['A_um']:.2f} \u00b5m (\u2191 {f['A_fwd_um']:.2f}, \u2193 {f['A_bwd_um']:.2f})\n"
               f"B = {f['B_um']:.2f} \u00b5m (mean {f['B_avg_um']:+.2f})\n"
               f"E = {f['E_um']:.2f} \u00b5m (\u2191 {f['E_fwd_um']:.2f}, \u2193 {f['E_bwd_um']:.2f})\n"
               f"M = {f['M_um']:.2f} \u00b5m\n"
               f"R = {f['R_um']:.2f} \u00b5m (\u2191 {f['R_fwd_um']:.2f}, \u2193 {f['R_bwd_um']:.2f})")
        ax.text(1.02, 0.0, box, transform=ax.transAxes, fontsize=8, family="monospace",
                va="bottom", ha="left", bbox=dict(boxstyle="round", fc="white", ec="0.5",
                                                  alpha=0.9))
        ax.set_xlabel(f"target position {ev.run.axis} (mm)")
        if k == 0:
            ax.set_ylabel("positional deviation (\u00b5m)")
        ax.set_title(f"{_label(ev, k, n)}\n{ev.run.n_targets} targets, {ev.run.n_cycles} "
                     f"cycles, ISO 230-2", fontsize=10)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    data = buf.getvalue()
    if path is not None:
        from ..fileio import write_bytes
        write_bytes(path, data)
    return data


def _f(v: float) -> str:
    return f"{v:.2f}"


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
            f"{tc['reference_mm']:g} mm, T = {tc['temperature_C']['min']:.2f} .. "
            f"{tc['temperature_C']['max']:.2f} \u00b0C ({tc['temperature_source']}), "
            f"correction {tc['correction_um']['min']:.2f} .. "
            f"{tc['correction_um']['max']:.2f} \u00b5m")


def _conditions_text(r: dict) -> str:
    c = r["conditions"]
    return "; ".join(f"{k}: {v['min']:.2f} .. {v['max']:.2f} (mean {v['mean']:.2f})"
                     for k, v in c.items()) or "not recorded"


def _conditions_rows(runs) -> str:
    """Rows of the conditions table: axis, targets, cycles, format, temperatures, correction."""
    return "".join([
        _trow(runs, "axis", lambda r: r["axis"]),
        _trow(runs, "targets", lambda r: f"{r['n_targets']} from {r['targets_mm'][0]:g} to "
                                         f"{r['targets_mm'][-1]:g} mm"),
        _row(runs, "cycles per direction", "n_cycles"),
        _trow(runs, "input format", lambda r: r["format"]),
        _trow(runs, "temperatures (\u00b0C)", _conditions_text),
        _trow(runs, "temperature correction", _temperature_correction_text),
    ])


def _results_rows(runs) -> str:
    """Rows of the results table: A, E, M, R, B, B_avg (um), directions in small print."""
    e = html.escape
    results = []
    for key, up, dn, name in _ROWS:
        results.append(f"<tr><th class='l'>{e(key)} \u2014 {e(name)}</th>" + "".join(
            f"<td>{_f(r[key + '_um'])}" + (f" <span class='s'>(\u2191 {_f(r[up + '_um'])}, "
                                          f"\u2193 {_f(r[dn + '_um'])})</span>" if up else "")
            + "</td>" for r in runs) + "</tr>")
    return "".join(results)


_TARGET_COLUMNS = (("targets_mm", "P_i (mm)"), ("mean_fwd_um", "x\u0304\u2191"),
                   ("mean_bwd_um", "x\u0304\u2193"), ("mean_um", "x\u0304"),
                   ("reversal_um", "B_i"), ("s_fwd_um", "S\u2191"), ("s_bwd_um", "S\u2193"),
                   ("R_i_fwd_um", "R_i\u2191"), ("R_i_bwd_um", "R_i\u2193"),
                   ("R_i_um", "R_i"))


def _target_tables(runs) -> str:
    """One per-target table (um) per run."""
    e = html.escape
    cols = _TARGET_COLUMNS
    tables = []
    for r in runs:
        body = "".join("<tr>" + "".join(f"<td>{r[k][i]:g}</td>" if k == "targets_mm" else
                                        f"<td>{_f(r[k][i])}</td>" for k, _ in cols) + "</tr>"
                       for i in range(r["n_targets"]))
        tables.append(f"<h3>{e(Path(r['file']).name)} \u2014 per target (\u00b5m)</h3>"
                      f"<table><tr>{''.join(f'<th>{e(h)}</th>' for _, h in cols)}</tr>{body}"
                      f"</table>")
    return "".join(tables)


def report_html(report: dict, png: bytes, inputs, generated: str = "") -> str:
    """A one-page certificate-like report: conditions, results (runs side by side), the plot
    (embedded PNG) and the per-target table of every run.  Plain HTML, no network.

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
    """
    runs = report["runs"] if "runs" in report else [report]
    e = html.escape
    head = "".join(f"<th>{e(Path(r['file']).name)} ({e(r['axis'])})</th>" for r in runs)
    conditions = _conditions_rows(runs)
    results = [_results_rows(runs)]
    tables = [_target_tables(runs)]
    notes = [f"{Path(r['file']).name}: {n}" for r in runs for n in r["notes"]]
    files = "".join(f"<li><code>{e(str(p))}</code></li>" for p in inputs)
    img = base64.b64encode(png).decode("ascii")
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<title>ISO 230-2 positioning test</title>
<style>
body {{ font-family: sans-serif; max-width: 1100px; margin: 1.5em auto; color: #111; }}
h1 {{ font-size: 1.4em; border-bottom: 2px solid #333; padding-bottom: .3em; }}
table {{ border-collapse: collapse; margin: .5em 0 1em 0; font-size: .9em; }}
th, td {{ border: 1px solid #999; padding: .2em .6em; text-align: right; }}
th.l {{ text-align: left; background: #f2f2f2; }}
.s {{ color: #555; font-size: .85em; }}
img {{ max-width: 100%; border: 1px solid #ccc; }}
</style></head><body>
<h1>Positioning accuracy and repeatability &mdash; ISO 230-2</h1>
<p>Evaluation of laser-interferometer positioning runs by direct measurement of a single axis
according to {e(STANDARD)}. Deviations are actual minus target position, in &micro;m.
{e(generated)}</p>
<h2>Input files</h2><ul>{files}</ul>
<h2>Conditions of the run</h2>
<table><tr><th></th>{head}</tr>{conditions}</table>
<h2>Results (&micro;m)</h2>
<table><tr><th></th>{head}</tr>{''.join(results)}</table>
<p class="s">A, E and R bidirectional over both directions; &uarr; forward, &darr; backward
approach. E = max &minus; min of the mean unidirectional deviations of both directions.</p>
<h2>Plot</h2>
<img alt="ISO 230-2 plot" src="data:image/png;base64,{img}">
{''.join(tables)}
{'<h2>Notes</h2><ul>' + ''.join(f'<li>{e(n)}</li>' for n in notes) + '</ul>' if notes else ''}
</body></html>
"""


def error_table(ev: Evaluation) -> ErrorTable:
    """Error table of the run's axis (X, Y, Z only), mm:

    * ``E<a><a>`` = mean bidirectional deviation x_i = (mean_fwd + mean_bwd) / 2;
    * its ``std`` = the standard uncertainty (Type A) of that mean, S_i / sqrt(2 n) with S_i =
      sqrt((s_fwd^2 + s_bwd^2) / 2) the pooled single-reading repeatability and n the cycles
      per direction (2 n readings per target; the reversal is a fixed effect of the mean, not
      a scatter): what ``volerr uncertainty --table-std systematic`` (the default) needs, the
      uncertainty of the error function at each node;
    * the reversal B_i.

    The repeatability S_i itself is not a table column of :class:`ErrorTable`; see
    :func:`repeatability` and :func:`error_table_csv`."""
    from ..errors import require

    a = ev.run.axis
    require(a in "XYZ", f"--table-out: axis {a} has no ISO 230-1 positioning parameter in the "
                        f"error-table format (X, Y, Z only)")
    name = f"E{a}{a}"
    u_mean = repeatability(ev) / np.sqrt(2 * ev.run.n_cycles)
    return ErrorTable(a, ev.run.targets, {name: ev.mean}, {name: u_mean}, {}, ev.reversal)


def repeatability(ev: Evaluation) -> np.ndarray:
    """Pooled unidirectional single-reading repeatability S_i = sqrt((s_fwd^2 + s_bwd^2) / 2)
    at each target, mm, shape (m,)."""
    return np.sqrt(0.5 * (ev.s_fwd ** 2 + ev.s_bwd ** 2))


def error_table_csv(ev: Evaluation) -> str:
    """CSV text of :func:`error_table` plus the column ``S_<axis>_um``: the pooled
    single-reading repeatability S_i (um), the scatter of one positioning.  The error-table
    reader ignores that column (it is no error parameter); ``EXX_std_um`` is S_i / sqrt(2 n)."""
    from ..tables import table_to_csv

    t = error_table(ev)
    lines = table_to_csv(t).splitlines()
    S = repeatability(ev) * UM_PER_MM
    out = [lines[0] + f",S_{t.axis}_um"]
    out += [f"{ln},{float(f'{v:.12g}') + 0.0:.12g}" for ln, v in zip(lines[1:], S)]
    return "\n".join(out) + "\n"


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
