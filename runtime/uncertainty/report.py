"""HTML report of a task-specific uncertainty: result table, contributions, plots inline."""

from __future__ import annotations

import base64
import html


def num(value, spec: str) -> str:
    """``format(value, spec)`` without negative zero: a value that prints as zero (-0.0 or
    a tiny negative rounded away) prints with the sign of +0, e.g. ``+0.000``, not ``-0.000``."""
    s = format(float(value), spec)
    try:
        zero = float(s) == 0.0
    except ValueError:
        return s
    return format(0.0, spec) if zero else s


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
