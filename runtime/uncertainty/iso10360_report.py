"""The certificate page of a (simulated) ISO 10360-2 length test: identification, the MPE,
the test uncertainty, the verdict per ISO 14253-1, the plot and every E0 value.  Input: the
JSON document of ``volerr iso10360`` (:meth:`volerr.uncertainty.iso10360.TestResult.as_dict`
plus ``layout``, ``errors``, ``probe_mm``)."""

from __future__ import annotations

import html

from ..certificate import Identification, html_table, verdict_html
from ..conformance import RULE
from ..report.page import document
from ..plotstyle import embedded_img
from ..units import num


def _cell(E: float, verdict: str | None) -> str:
    style = {"fail": " style='color:#c62828;font-weight:bold'",
             "undecided": " style='color:#b26a00;font-weight:bold'"}.get(verdict or "", "")
    return f"<td{style}>{num(E, '+.3f')}</td>"


def report_html(doc: dict, png: bytes | None, identification: Identification | None = None,
                generated: str = "") -> str:
    """A one-page certificate (plain HTML, the plot embedded, no network needed)."""
    e = html.escape
    ident = identification or Identification()
    rows = []
    for pos in doc["positions"]:
        for j, L in enumerate(pos["lengths_mm"]):
            vs = pos.get("verdicts", [[None] * len(pos["E_um"][j])] * len(pos["lengths_mm"]))[j]
            rows.append(f"<tr><td class='l'>{e(pos['line'])}</td><td>{L:.1f}</td>"
                        + "".join(_cell(E, v) for E, v in zip(pos["E_um"][j], vs))
                        + f"<td>{num(pos['U_um'][j], '.3f')}</td></tr>")
    reps = len(doc["positions"][0]["E_um"][0]) if doc["positions"] else 0
    if "verdict" in doc:
        c = doc["verdict_counts"]
        verdict = (f"<p class='verdict'>Verdict: {verdict_html(doc['verdict'])} against MPE "
                   f"{e(doc['mpe'])} &mdash; {c['pass']} values pass, {c['undecided']} "
                   f"undecided, {c['fail']} fail; {e(RULE)}.</p>")
    else:
        verdict = "<p class='verdict'>No MPE given (<code>--mpe</code>): no verdict.</p>"
    img = embedded_img(png, "ISO 10360-2 length errors") if png else ""
    return document(f"ISO 10360-2 length test: {doc['layout']}", f"""\
<h1>Length measuring test &mdash; ISO 10360-2 (simulated on the model of {e(doc['layout'])})</h1>
<p>E0 = indicated minus calibrated length, bidirectional, 7 positions &times; 5 lengths &times;
{reps} repetitions, computed from the error tables <code>{e(str(doc['errors']))}</code> with the
probe offset {' '.join(f'{v:g}' for v in doc['probe_mm'])} mm. {e(generated)}</p>
<h2>Identification</h2>
{html_table(ident)}
{verdict}
<p class="s">Test uncertainty: {e(doc['test_uncertainty']['formula'])}; largest U =
{num(doc['uncertainty_um']['E0'], '.3f')} &micro;m.</p>
<h2>Plot</h2>
{img}
<p class="s">Shaded: MPE &plusmn; U (k = 2), where a value is undecided; ringed: values that fail
(red) or are undecided (amber).</p>
<h2>Length errors</h2>
<table><tr><th class='l'>position</th><th>L / mm</th>{''.join(f'<th>E0 #{k + 1} / &micro;m</th>' for k in range(reps))}<th>U (k = 2) / &micro;m</th></tr>
{''.join(rows)}</table>""")
