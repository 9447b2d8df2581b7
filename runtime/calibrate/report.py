"""HTML page of ``volerr calibrate``: the identified parameters with their standard
uncertainties and coverage bars, what the campaign does not determine (and which file sees
what), the plans that would determine it, the residuals of every file, the consistency of the
files, artifact poses and station positions, the volumetric map's size and uncertainty, the
ISO 10360-2 length errors of the identified model beside the step gauges, the set-up
estimates.  Figures in volerr's style (:mod:`volerr.plotstyle`); numbers without negative
zero."""

from __future__ import annotations

import html

import numpy as np

from ..plotstyle import embedded_img, figure, label, png, styled, unit
from ..fit_quality import fit_html
from ..report.page import document
from ..units import num


@styled
def parameter_figure(params: dict, truth: dict | None = None):
    """Identified values with +-2 u bars (k = 2), one panel per unit; ``truth``: planted
    values drawn beside them (simulated campaigns)."""
    from matplotlib.ticker import MaxNLocator

    units = list(dict.fromkeys(v["unit"] for v in params.values()))
    rows = max(sum(v["unit"] == u for v in params.values()) for u in units)
    fig, axes = figure(1, len(units), width=4.6 * len(units) + 0.4,
                       height=0.42 * rows + 1.9, squeeze=False)
    for ax, u in zip(axes[0], units):
        names = [n for n, v in params.items() if v["unit"] == u]
        y = np.arange(len(names))
        ax.errorbar([params[n]["value"] for n in names], y,
                    xerr=[2 * params[n]["std"] for n in names], fmt="o", capsize=3,
                    label="identified, ± 2 u (k = 2)")
        if truth is not None:
            ax.plot([truth.get(n, 0.0) for n in names], y, "x", color="C3", ms=9,
                    label="planted")
        ax.axvline(0, color="0.6", lw=0.8)
        ax.set_yticks(y)
        ax.set_yticklabels(names)
        ax.invert_yaxis()
        ax.set_xlabel(label("value", u))
        # three panels share the page's 10 in: six ticks of "-0.010" overlapped (seen)
        ax.xaxis.set_major_locator(MaxNLocator(nbins=4 if len(units) > 2 else 6))
        ax.grid(axis="x", alpha=0.3)
        ax.legend(loc="best")
    return fig


@styled
def residual_figure(cal):
    """Residual of every reading after the fit on all readings, per file, against its row."""
    res = cal.residuals
    files = cal.data["instruments"]
    fig, axes = figure(len(res), 1, height=2.1 * len(res) + 0.6, squeeze=False)
    for ax, (f, (pts, r, k)) in zip(axes[:, 0], sorted(res.items())):
        names = ("reading",) if int(np.max(k)) == 1 else ("x", "y", "z")
        for i, name in enumerate(names):
            ax.plot(np.arange(len(pts)), r[:, i], ".", ms=2.5, label=name)
        ax.axhline(0, color="0.6", lw=0.8)
        ax.set_ylabel(label("residual", "um"))
        ax.set_title(f"{files[f]['file']} ({files[f]['kind']}): RMS "
                     f"{num(files[f]['rms_residual'], '.3g')} µm")
        if len(names) > 1:
            ax.legend(markerscale=3, loc="upper right")
    axes[-1, 0].set_xlabel("data row of the file")
    return fig


@styled
def length_figure(iso: dict):
    """ISO 10360-2 length errors of the identified model (k = 2 bars) and the measured
    step-gauge length errors beside the prediction."""
    panels = [k for k in ("predicted", "step_gauges") if iso.get(k)]
    fig, axes = figure(1, len(panels), width=5.0 * len(panels) + 0.4, height=4.0,
                       squeeze=False)
    for ax, key in zip(axes[0], panels):
        if key == "predicted":
            for k, line in enumerate(iso["predicted"]):
                L, E, u = (np.asarray(line[c]) for c in ("lengths_mm", "E_um", "u_um"))
                ax.errorbar(L, E, yerr=2 * u, fmt="o-", ms=3, capsize=2, color=f"C{k}",
                            label=line["line"])
            ax.set_title("ISO 10360-2 E of the identified model (bars k = 2)")
        else:
            for k, g in enumerate(iso["step_gauges"]):
                L = np.asarray(g["lengths_mm"])
                ax.errorbar(L, g["measured_um"], yerr=2 * np.asarray(g["u_measured_um"]),
                            fmt="o", ms=4, capsize=2, color=f"C{k}",
                            label=f"{g['file']} {g['placement']} measured")
                ax.errorbar(L, g["predicted_um"], yerr=2 * np.asarray(g["u_predicted_um"]),
                            fmt="-", color=f"C{k}", alpha=0.7, label="identified model")
            ax.set_title("step gauges: measured and predicted (bars k = 2)")
        ax.axhline(0, color="0.6", lw=0.8)
        ax.set_xlabel(label("L", "mm"))
        ax.set_ylabel(label("E", "um"))
        ax.grid(alpha=0.3)
        ax.legend()
    return fig


def _f(v, spec: str = ".3g") -> str:
    return "" if v is None else num(v, spec)


def _list(values, spec: str) -> str:
    return ", ".join(num(v, spec) for v in values)


def _lab_sections(d) -> str:
    """Consistency of the files, instrument results (poses, stations), the volumetric map and
    the ISO 10360-2 length errors."""
    out = []
    c = d.get("consistency")
    if c:
        rows = "".join(_row([e["file"], e["kind"], _f(e["chi2"], ".4g"),
                             _f(e["redundancy"], ".4g"), _f(e["birge_ratio"]),
                             _f(e["birge_spread"]), _f(e["loo_birge_ratio"]), _f(e["p_value"]),
                             "yes" if e["consistent"] else "NO"]) for e in c["files"])
        named = (f"<p><strong>Inconsistent with the rest:</strong> "
                 f"{html.escape(', '.join(c['inconsistent']))}</p>" if c["inconsistent"]
                 else "<p>Every file is consistent with its stated uncertainties and with the "
                      "others.</p>")
        out.append(f"""<h2>Consistency of the files</h2>
<p>{html.escape(c['method'])} (alpha = {c['alpha']}).  A Birge ratio of 1 means the residuals
match the stated uncertainties.</p>{named}
<table><tr><th>file</th><th>kind</th><th>chi2</th><th>redundancy</th><th>Birge ratio</th>
<th>its spread</th><th>Birge ratio against the rest</th><th>p</th><th>consistent</th></tr>
{rows}</table>""")
    poses = d.get("poses")
    if poses:
        rows = "".join(_row([g, _list(e["origin_mm"], ".4f"), _list(e["origin_std_um"], ".2g"),
                             _list(e["rotation_vector_deg"], ".5f"),
                             _list(e["rotation_std_urad"], ".2g")])
                       for g, e in poses.items())
        out.append(f"""<h2>Artifact poses</h2><p>Origin of the artifact frame in the workpiece
frame and its rotation (rotation vector) as identified with the machine.</p>
<table><tr><th>placement</th><th>origin / mm</th><th>u / µm</th><th>rotation vector / deg</th>
<th>u / µrad</th></tr>{rows}</table>""")
    stations = d.get("stations")
    if stations:
        rows = "".join(_row([g, _list(e["position_mm"], ".4f"), _list(e["position_std_um"], ".2g"),
                             _f(e["dead_path_mm"], ".4f"), _f(e["dead_path_std_um"], ".2g")])
                       for g, e in stations.items())
        out.append(f"""<h2>Stations of the tracking interferometer</h2>
<table><tr><th>station</th><th>position / mm</th><th>u / µm</th><th>dead path / mm</th>
<th>u / µm</th></tr>{rows}</table>""")
    m = d.get("volumetric_map")
    if m:
        rot = "".join(f", {a} at {num(v, '.4g')} deg" for a, v in m.get("rotary_deg", {}).items())
        out.append(f"""<h2>Volumetric error map</h2><p>{html.escape(m['note'])}.  Grid
{' x '.join(map(str, m['grid']))} over {html.escape(_box(m['box_mm']) + rot)}: largest error
{_f(m['max_length_um'])} µm (RMS {_f(m['rms_length_um'])} µm); standard uncertainty up to
{_f(m['u_max_um'], '.2g')} µm (RMS {_f(m['u_rms_um'], '.2g')} µm).</p>{_holds(m)}""")
    iso = d.get("iso10360")
    if iso and not iso.get("predicted") and not iso.get("step_gauges"):
        out.append(f"<h2>ISO 10360-2 length errors</h2><p>Not shown: "
                   f"{html.escape(iso.get('predicted_omitted', 'no length test applies'))}.</p>")
    elif iso:
        rows = "".join(_row([e["line"], _list(e["lengths_mm"], ".0f"), _list(e["E_um"], ".3g"),
                             _list(e["u_um"], ".2g")]) for e in iso.get("predicted", []))
        gauges = "".join(_row([f"{g['file']} {g['placement']}", _f(g["lengths_mm"][-1], ".0f"),
                               _f(g["measured_um"][-1]), _f(g["predicted_um"][-1]),
                               _f(g["max_abs_En"])]) for g in iso.get("step_gauges", []))
        fig = embedded_img(png(length_figure(iso)), "ISO 10360-2 length errors")
        out.append(f"""<h2>ISO 10360-2 length errors</h2><p>{html.escape(iso['note'])}.
Largest |E| predicted: {_f(iso.get('max_abs_E_um'))} µm.</p>{_holds(iso)}
<table><tr><th>line</th><th>L / mm</th><th>E / µm</th><th>u / µm</th></tr>{rows}</table>
""" + (f"""<table><tr><th>step gauge</th><th>longest L / mm</th><th>measured E / µm</th>
<th>predicted E / µm</th><th>max |En|</th></tr>{gauges}</table>""" if gauges else "") + fig)
    return "\n".join(out)


def _box(box: dict) -> str:
    """``X -90.62 .. 158.6 mm, Y ...`` of a box ``{axis: [lo, hi]}``."""
    return ", ".join(f"{a} {num(lo, '.4g')} .. {num(hi, '.4g')} mm" for a, (lo, hi) in
                     box.items())


def _holds(entry: dict) -> str:
    """What a map or a length test holds: the names written as 0, the combinations."""
    text = (f"Not determined, 0 in it: {', '.join(entry.get('undetermined', [])) or 'none'}."
            + (f"  Determined only in combination, entered under one of their names: "
               f"{'; '.join(entry['combinations'])}." if entry.get("combinations") else ""))
    return f"<p>{html.escape(text)}</p>"


def _combinations(d) -> str:
    """The section on combinations (what is written under a name not determined alone)."""
    combos = d.get("combinations", [])
    written = {c["written_as"] for c in combos}
    zero = [n for n in d.get("unidentifiable", []) if n not in written]
    rows = "".join(_row([c["expression"], num(c["value"], ".4g"), num(c["std"], ".2g"),
                         unit(c["unit"]), c["written_as"]]) for c in combos)
    table = (f"""<table><tr><th>combination</th><th>value</th><th>u</th><th>unit</th>
<th>written as</th></tr>{rows}</table>""" if combos else "")
    return f"""<h2>Determined only in combination</h2>
<p>The campaign determines these combinations, not their terms one by one; the error directory,
the map and the ISO 10360 numbers hold each under the name given (a comment line in the
error directory says so).  Every other parameter not determined is written as 0:
{html.escape(', '.join(zero) or 'none')}.</p>{table}"""


def _row(cells) -> str:
    return "<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in cells) + "</tr>"


def render_html(cal) -> str:
    d = cal.data
    params = "".join(_row([n, num(v["value"], ".4g"), num(v["std"], ".2g"), unit(v["unit"])])
                     for n, v in d["parameters"].items()) or _row(["none", "", "", ""])
    ident = "".join(_row([n, "yes" if v["identifiable"] else "NO", ", ".join(v["seen_by"]),
                          ", ".join(v["not_seen_by"]), ", ".join(v["confounded_with"])])
                    for n, v in d["identifiability"].items())
    plan = "".join(_row([e["adds"], ", ".join(e["makes_identifiable"]) or
                         "; ".join([", ".join(e.get("still_undetermined", [])),
                                    e.get("why", "")])]) for e in d.get("plan", [])) \
        or _row(["nothing to add: every fitted parameter is determined", ""])
    inst = "".join(_row([i["file"], i["kind"], i["n"], i["n_readings"],
                         num(i["rms_residual"], ".3g"), num(i["heldout_rms"], ".3g"),
                         num(i["normalised_rms"], ".3g")]) for i in d["instruments"])
    setup = "".join(_row([g, k, num(v["value"], ".4g"), num(v["std"], ".2g"), unit(v["unit"]),
                          "yes" if v["determined"] else "no"])
                    for g, keys in d["setup"].items() for k, v in keys.items())
    figs = []
    if d["parameters"]:
        figs.append(embedded_img(png(parameter_figure(d["parameters"])),
                                 "identified parameters with expanded uncertainty bars"))
    if cal.residuals:
        figs.append(embedded_img(png(residual_figure(cal)), "residuals per file"))
    return document(f"Calibration of {d['layout']}", f"""\
<h1>Calibration of {html.escape(d['layout'])} from {len(d['instruments'])} file(s)</h1>
{fit_html(d)}<p>{html.escape(d['method'])}.  Degree of the component series: {d['degree']}; a-posteriori
variance factor {num(d['variance_factor'], '.3g')} (1 when the residuals match the stated
reading uncertainties).  Standard uncertainties u (k = 1); the figure's bars ± 2 u (k = 2).</p>
<h2>Identified parameters</h2>
<table><tr><th>parameter</th><th>value</th><th>u</th><th>unit</th></tr>{params}</table>
{''.join(figs)}
{_combinations(d)}
<h2>What the campaign determines</h2>
<p>A parameter is identifiable when its column is not in the span of all other columns (the
instruments' set-up unknowns included); a file sees it when its readings depend on it once its
own set-up unknowns are removed.  Fixed by convention (not parameters):
{html.escape(', '.join(d['gauge_fixed']) or 'none')}.</p>
<table><tr><th>parameter</th><th>identifiable</th><th>seen by</th><th>not seen by</th>
<th>confounded with</th></tr>{ident}</table>
<h2>Plans that would determine the rest</h2>
<table><tr><th>add</th><th>determines</th></tr>{plan}</table>
<h2>Files</h2>
<table><tr><th>file</th><th>kind</th><th>rows</th><th>readings</th><th>RMS / µm</th>
<th>held-out RMS / µm</th><th>RMS / stated u</th></tr>{inst}</table>
{_lab_sections(d)}
<h2>Set-up estimates</h2>
<table><tr><th>set-up</th><th>unknown</th><th>value</th><th>u</th><th>unit</th>
<th>determined</th></tr>{setup}</table>""")
