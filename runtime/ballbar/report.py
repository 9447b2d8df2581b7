"""The ballbar report page: the polar plot, the ISO 230-4 table and the diagnosis (HTML)."""

from __future__ import annotations

import html

from ..plotstyle import embedded_img
from ..fit_quality import fit_html
from ..report.page import document
from ..units import num


def render(ev, polar: bytes | None = None) -> str:
    """The page of a ballbar evaluation ``ev``; ``polar``: the polar plot's PNG bytes when
    already drawn (:func:`volerr.ballbar.plots.polar_png`), else drawn here."""
    from .plots import polar_png

    if polar is None:
        polar = polar_png(ev.traces, ev.results)
    img = embedded_img(polar, "ballbar polar plot")
    rows = "".join(
        f"<tr><td>{html.escape(r['file'])}</td><td>{html.escape(r['placement'])}</td>"
        f"<td>{r['plane']}</td><td>{num(r['radius_mm'], 'g')}</td><td>{r['direction']}</td>"
        f"<td>{num(r['G_um'], '.3f')}</td><td>{_num(r.get('H_um'))}</td>"
        f"<td>{num(r['F_min_um'], '.3f')}</td><td>{num(r['F_max_um'], '.3f')}</td>"
        f"<td>{num(r['centre_offset_um'][0], '.2f')}, {num(r['centre_offset_um'][1], '.2f')}</td></tr>"
        for r in ev.data["traces"])
    diag = "".join(f"<tr><td>{html.escape(d['parameter'])}</td><td>{num(d['value'], '.4g')}</td>"
                   f"<td>{num(d['std'], '.2g')}</td><td>{html.escape(d['unit'])}</td></tr>"
                   for d in ev.data["diagnosis"]) or (
        f"<tr><td colspan=4>none: {html.escape(ev.data.get('diagnosis_note', ''))}</td></tr>")
    return document("Ballbar evaluation", f"""\
<h1>Ballbar evaluation (ISO 230-4), layout {html.escape(ev.data['layout'])}</h1>
{fit_html(ev.data)}{img}
<p>Radial deviation of each trace about its least-squares circle (the grey ring), magnified;
angles from the plane's first axis towards its second (a rotary sweep: the reading against the
swept axis' angle).</p>
<table><tr><th>file</th><th>placement</th><th>plane</th><th>radius / mm</th><th>direction</th>
<th>G / µm</th><th>H / µm</th><th>F min / µm</th><th>F max / µm</th><th>centre offset / µm</th>
</tr>{rows}</table>
<p>G: circular deviation (radial range about the least-squares centre); H: circular
hysteresis (largest radial difference of the CCW and CW paths at the same angle); F: radial
deviation about the pivot.</p>
<h2>Diagnosis (ISO 230-1 parameters, standard uncertainty k = 1)</h2>
<table><tr><th>parameter</th><th>value</th><th>u</th><th>unit</th></tr>{diag}</table>
<p>Fitted with the layout's observation model of the ballbar: only what the traces determine
is listed (with the bar length unknown, only the scale mismatch of the two axes).</p>""")


def _num(v) -> str:
    return "-" if v is None else num(v, ".3f")


def write_html(path, ev, inputs=(), polar: bytes | None = None):
    """Write :func:`render` of ``ev`` to ``path`` (``polar``: the plot's PNG when drawn)."""
    from ..fileio import write_text

    return write_text(path, render(ev, polar), inputs=list(inputs))
