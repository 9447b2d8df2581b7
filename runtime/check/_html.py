"""The HTML page of a check: the verdict, the changes with their uncertainties (a bar chart of
each parameter's change over its standard uncertainty), what the check cannot tell apart, the
tolerance decisions."""

from __future__ import annotations

import html

from ..report.page import document


def _figure(d: dict) -> str:
    """An ``<img>`` (embedded PNG): change / std of every changed parameter, and the
    selection threshold."""
    from ..plotstyle import embedded_img, figure, png, styled

    @styled
    def draw() -> bytes:
        fig, ax = figure(height=2.8)
        rows = d["changed"]
        names = [c["parameter"] for c in rows] or ["(none)"]
        z = [c["change"] / c["std"] if c["std"] else 0.0 for c in rows] or [0.0]
        ax.barh(names, z, color="C3")
        t = d["threshold_chi2"] ** 0.5
        for s in (-t, t):
            ax.axvline(s, color="0.4", ls="--", lw=0.8)
        ax.set_xlabel("change / its standard uncertainty (dashed: the selection threshold)")
        return png(fig)

    return embedded_img(draw(), "changes over their standard uncertainties")


def _alternatives(c: dict) -> str:
    """The alternatives of a change, one text: 'EB0C +2.9 +- 0.7 urad; ...'."""
    return "; ".join(f"{a['parameter']} {a['change']:+.3g} +- {a['std']:.2g} {a['unit']}"
                     for a in c.get("alternatives", []))


def check_html(d: dict) -> str:
    """The page of a check's JSON ``d`` (:meth:`volerr.check.CheckResult.to_dict`)."""
    from ..fit_quality import fit_html
    from ..plotstyle import unit

    e = html.escape
    v = d["volumetric_change_um"]
    rows = "".join(
        f"<tr><td>{e(c['parameter'])}</td><td>{c['reference']:.4g}</td>"
        f"<td>{c['change']:+.4g}</td><td>{c['std']:.2g}</td><td>{e(unit(c['unit']))}</td>"
        f"<td>{e(', '.join(c.get('indistinguishable_from', [])))}</td>"
        f"<td>{e(_alternatives(c))}</td></tr>"
        for c in d["changed"])
    table = (f"<table><tr><th>parameter</th><th>reference</th><th>change</th><th>u (k = 1)"
             f"</th><th>unit</th><th>indistinguishable from</th>"
             f"<th>or (not told apart by this check)</th></tr>{rows}</table>"
             if rows else "<p>No parameter changed.</p>")
    apart = "".join(f"<li>{e(a)} and {e(b)}</li>" for a, b in d["indistinguishable"])
    tol = ""
    if d.get("tolerance"):
        t = d["tolerance"]
        tol = "<h2>Tolerance</h2><table><tr><th>quantity</th><th>value</th><th>U (k = 2)</th>" \
              "<th>limit</th><th>verdict</th></tr>" + "".join(
                  f"<tr><td>{e(i['quantity'])}</td><td>{i['value']:.4g} {e(unit(i['unit']))}</td>"
                  f"<td>{i['U']:.2g}</td><td>{i['limit']:g}</td><td>{e(i['verdict'])}</td>"
                  f"</tr>" for i in t["items"]) + f"</table><p>{e(t['rule'])}</p>"
    files = "".join(f"<li>{e(f['file'])} ({e(f['kind'])}, {f['n_readings']} readings, "
                    f"SHA-256 {e(f['sha256'][:16])}...)</li>" for f in d["files"])
    return document(f"volerr check: {d['layout']}", f"""\
<h1>Check of {e(d['layout'])}: {e(d['verdict'])}</h1>
{fit_html(d)}<p>Against the reference {e(str(d['reference']['file']))}{' on ' + e(d['date']) if d.get('date') else ''}.
Volumetric change over the working volume: max {v['max']:.3g} µm, RMS {v['rms']:.3g} µm.
Residual: Birge ratio {d['misfit']['birge_ratio']:.3g} on {d['misfit']['dof']} degrees of
freedom{' -- a change none of the reference parameters explains' if d['misfit']['unexplained'] else ''}.</p>
<h2>Changed</h2>{table}
{_figure(d)}
{'<h2>Cannot be told apart by this check</h2><ul>' + apart + '</ul>' if apart else ''}
{tol}<h2>Files</h2><ul>{files}</ul><p>{e(d['method'])}</p>""")
