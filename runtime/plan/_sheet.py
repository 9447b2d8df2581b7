"""``plan.html``: the set-up sheet -- what to mount where, in which order, how long it takes,
and a figure of the working volume (workpiece frame; three views) with every pivot and its
circle, every sphere placement, every station and the poses it reads."""

from __future__ import annotations

from html import escape

import numpy as np

from .. import plotstyle
from ..report.page import document
from . import _candidates, _report

VIEWS = (("X", "Y", 0, 1), ("X", "Z", 0, 2), ("Y", "Z", 1, 2))
MARKERS = {"ballbar": "o", "sphere": "s", "distances": "^", "interferometer": "D", "artifact": "P"}


#: what each marker stands for (the figure's legend)
KEYS = {"ballbar": "ballbar pivot", "sphere": "sphere", "distances": "station",
        "interferometer": "laser line start", "artifact": "ball plate's first ball"}
#: labels closer than this share of a view's span are one label ("C57, C63")
MERGE = 0.02


@plotstyle.styled
def figure(plan) -> bytes:
    """PNG of :func:`views`."""
    return plotstyle.png(views(plan))


def views(plan):
    """The matplotlib figure of the three views (module docstring): the title above, the key
    below (a legend of the markers), set-ups at the same place in a view labelled once ("C57,
    C63"), labels of set-ups close together moved apart instead of overlapping."""
    from matplotlib.lines import Line2D

    model = plan.model
    tool = next((i.tool for i in plan.instruments if any(i.tool)), (0.0, 0.0, 0.0))
    lo, hi = _candidates.volume(model, tool)
    fig, axes = plotstyle.figure(1, 3, height=4.2)
    kinds = []
    for ax, (a, b, i, j) in zip(axes, VIEWS):
        ax.add_patch(_box(lo[i], lo[j], hi[i] - lo[i], hi[j] - lo[j]))
        marks = []
        for k, pf in enumerate(plan.files):
            pos = {x: np.asarray(pf.columns[x], float) for x in model.axes}
            probe = np.column_stack([pf.columns[c] for c in ("Xp", "Yp", "Zp")])
            t = model.nominal_position(pos, probe)
            colour = f"C{k % 10}"
            ax.plot(t[:, i], t[:, j], ".", ms=2, color=colour, alpha=0.5)
            for s, _ in pf.setups:
                g = s.geometry
                p = g.get("pivot", g.get("centre", g.get("station", g.get("start"))))
                ax.plot(p[i], p[j], MARKERS[s.kind], color=colour, ms=7, mec="k")
                marks.append((float(p[i]), float(p[j]), s.label))
                kinds.append(s.kind)
        _labels(ax, marks, max(hi[i] - lo[i], hi[j] - lo[j], 1.0))
        ax.set_xlabel(plotstyle.label(a, "mm"))
        ax.set_ylabel(plotstyle.label(b, "mm"))
        ax.set_aspect("equal", adjustable="datalim")
    fig.suptitle(f"{model.name}: where each set-up goes (workpiece frame)")
    handles = [Line2D([], [], marker=MARKERS[k], ls="none", color="0.7", mec="k", ms=7,
                      label=KEYS[k]) for k in dict.fromkeys(kinds)]
    handles += [Line2D([], [], marker=".", ls="none", color="0.4", label="tool point at "
                       "each reading"),
                Line2D([], [], ls="--", color="0.4", label="working volume")]
    fig.legend(handles=handles, loc="outside lower center", ncols=min(len(handles), 4),
               fontsize=8, frameon=False)
    return fig


def _labels(ax, marks, span) -> None:
    """Annotate ``marks`` [(x, y, label)]: labels at one place (within :data:`MERGE` of the
    span) joined; each label put right above its mark, or moved down (then left of the mark)
    in steps of 11 points until its box (estimated: 4.8 points a character, 9 high, a view
    about 190 points for 1.15 spans) overlaps no marker and no label placed before."""
    groups: list = []
    for x, y, lab in marks:
        for g in groups:
            if abs(g[0] - x) <= MERGE * span and abs(g[1] - y) <= MERGE * span:
                g[2].append(lab)
                break
        else:
            groups.append([x, y, [lab]])
    unit = 190.0 / (1.15 * span)            # points per mm
    boxes = [(x * unit - 4, y * unit - 4, x * unit + 4, y * unit + 4) for x, y, _ in groups]
    for x, y, labs in sorted(groups, key=lambda g: (-g[1], g[0])):
        text = ", ".join(labs)
        w = 4.8 * len(text)
        tries = [(4.0, 4.0 - 11.0 * k) for k in range(4)] + \
                [(-4.0 - w, 4.0 - 11.0 * k) for k in range(4)]
        px, py = x * unit, y * unit
        for dx, dy in tries:
            box = (px + dx, py + dy, px + dx + w, py + dy + 9.0)
            if not any(box[0] < b[2] and b[0] < box[2] and box[1] < b[3] and b[1] < box[3]
                       for b in boxes):
                break
        boxes.append(box)
        ax.annotate(text, (x, y), textcoords="offset points", xytext=(dx, dy), fontsize=8)


def _box(x, y, w, h):
    from matplotlib.patches import Rectangle

    return Rectangle((x, y), w, h, fill=False, ls="--", lw=1.0, ec="0.4")


def html(plan) -> str:
    """The set-up sheet as one HTML page (figure embedded)."""
    d = _report.data(plan)
    rows = []
    for f in d["files"]:
        for s in f["setups"]:
            rows.append(f"<tr><td class=l>{escape(f['file'])}</td><td class=l>"
                        f"{escape(f['nc'])}</td><td class=l>{escape(s['label'])}</td>"
                        f"<td class=l>{escape(s['text'])}</td><td>{s['readings']}</td></tr>")
    params = "".join(
        f"<tr><td class=l>{escape(n)}</td><td>{v['predicted_std']:.3g}</td>"
        f"<td class=l>{escape(v['unit'])}</td><td class=l>"
        f"{escape(', '.join(v['determined_alone_by']) or 'only the combination')}</td>"
        f"<td>{_base(d, n)}</td></tr>" for n, v in d["parameters"].items())
    why = "".join(f"<li>{escape(n)}: {escape(d['why_unidentifiable'][n])}</li>"
                  for n in d["unidentifiable"])
    m, b = d["map_u_um"], d["baseline"]["map_u_um"]
    img = plotstyle.embedded_img(figure(plan), "where each set-up goes")
    return document(f"volerr plan {d['layout']}", f"""\
<h1>Measurement plan: {escape(d['layout'])}</h1>
<p>{d['readings']} readings, about {d['minutes']:g} min (time model: volerr formats plan).
Criterion: {escape(d['criterion'])}. Run each NC program with its set-up mounted; fill the
reading columns of each file and give the files to <code>volerr calibrate {escape(d['layout'])}
FILES</code> (no options).</p>
<h2>Set-ups, in order</h2><table><tr><th class=l>file</th><th class=l>NC program</th>
<th class=l>set-up</th><th class=l>what goes where</th><th>readings</th></tr>{''.join(rows)}
</table>{img}
<h2>Predicted result</h2><table><tr><th class=l>parameter</th>
<th>predicted u (k = 1)</th><th class=l>unit</th><th class=l>determined alone by</th><th>u of the conventional plan</th></tr>{params}
</table><p>Map of the volumetric error over the working volume: predicted standard uncertainty
RMS {m['rms']:.3g} µm, max {m['max']:.3g} µm (k = 1); {_baseline_text(d, b)}.</p>
{'<h2>Not determined by this plan</h2><ul>' + why + '</ul>' if why else ''}""")


def _baseline_text(d, b) -> str:
    base = d["baseline"]
    if b["rms"] is None:
        return f"no conventional plan at this number of readings ({escape(base['why_none'])})"
    return (f"the conventional plan ({escape(base['name'])}, {base['readings']} readings): RMS "
            f"{b['rms']:.3g} µm, max {b['max']:.3g} µm")


def _base(d, name) -> str:
    b = d["baseline"]["parameters"].get(name)
    return f"{b['predicted_std']:.3g}" if b else "not determined"


@plotstyle.styled
def comparison_png(rows) -> bytes:
    """PNG of predicted (bars) against realised (dots) standard uncertainties; ``rows``
    [(label, predicted, realised, unit)]."""
    fig, ax = plotstyle.figure(height=max(3.0, 0.32 * len(rows) + 1.2))
    y = np.arange(len(rows))
    ax.barh(y, [r[1] for r in rows], color="C0", alpha=0.5, label="predicted (volerr plan)")
    ax.plot([r[2] for r in rows], y, "o", color="C3", label="realised (volerr calibrate)")
    ax.set_yticks(y, [f"{r[0]} / {plotstyle.unit(r[3])}" for r in rows])
    ax.invert_yaxis()
    ax.set_xlabel("standard uncertainty (k = 1), unit of each row")
    ax.legend(loc="lower right")
    return plotstyle.png(fig)
