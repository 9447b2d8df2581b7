"""The result of ``volerr history show``: :class:`History` (``to_dict()`` is the JSON), its
console lines and its HTML page (one chart per parameter: values with +-2 u bars, the
Shewhart limits, the events, the trend with its 95 % band and the tolerance; the EWMA chart
beneath).  The analysis is :mod:`volerr.history.analysis`; figures in volerr's style
(:mod:`volerr.plotstyle`)."""

from __future__ import annotations

import html
import math
from dataclasses import dataclass

import numpy as np

from ..report.page import document
from ..results import ResultMixin, Row, as_table
from . import analysis as an

def _convert(value: float, unit: str, to: str, name: str) -> float:
    """``value`` in ``unit`` expressed in ``to`` (:func:`volerr.units.convert`)."""
    from ..units import convert

    return convert(value, unit, to, f"--tolerance {name}")


@dataclass(repr=False)
class History(ResultMixin):
    """A machine's history analysed (module docstring); ``data`` is the JSON
    (``to_dict()``), ``summary()`` the lines ``volerr history show`` prints, ``table()`` its
    numbers (:meth:`table`), ``figures()`` one chart per parameter, ``write_json`` /
    ``write_html`` the command's ``--json`` / ``--html``; the JSON's keys as attributes
    (``h.events``, ``h.forecast``; ``h.trends`` is the fitted lines, ``h["trends"]`` or
    ``h.to_dict()["trends"]`` their JSON)."""
    data: dict
    series: dict
    trends: dict

    @classmethod
    def build(cls, machine: str, entries: list, tolerances: dict) -> "History":
        from ..errors import require
        from ..units import match_name

        series = an.series_of(entries)
        events, slopes, trends, control, forecast = [], [], {}, {}, {}
        fits = {}
        for name, s in series.items():
            control[name] = an.control(s)
            ch = an.changes(s)
            st = [c for c in ch if c["kind"] == an.STEP]
            events += [{"date": e["date"], "parameter": name, "change": e["change"],
                        "unit": s.unit, "std": e["std"], "previous_date": e["previous_date"]}
                       for e in st]
            slopes += [{"date": e["date"], "parameter": name, "change_per_day": e["change"],
                        "unit": s.unit, "std": e["std"]} for e in ch if e["kind"] == an.SLOPE]
            tr = an.trend(s, ch[-1]["index"] if ch else 0)
            fits[name] = (st, tr)
            if tr is not None:
                v, u = tr.at(tr.t0)
                trends[name] = {"slope_per_day": tr.b, "unit": s.unit,
                                "std": math.sqrt(tr.cov[1, 1]), "since": tr.since, "n": tr.n,
                                "value_at_last": v, "value_at_last_std": u,
                                "scaled_by_scatter": tr.scaled}
        for name, (value, unit) in tolerances.items():
            if name == "map":
                forecast["map"] = _map_forecast(entries, series, fits, value)
                continue
            typed, name = name, match_name(name, list(series), "--tolerance")
            require(name is not None, f"--tolerance {typed}: not a parameter of this history "
                                      f"({', '.join(list(series)[:10])})")
            require(name not in forecast, f"--tolerance: {typed} given twice")
            tol = _convert(value, unit, series[name].unit, name)
            tr = fits[name][1]
            f = (an.forecast(tr, tol) if tr is not None else
                 {"date": None, "interval": [None, None], "note": "no trend (fewer than "
                  f"{an.MIN_TREND_POINTS} entries since the last event)"})
            forecast[name] = {**f, "tolerance": tol, "unit": series[name].unit}
        events.sort(key=lambda e: (e["date"], e["parameter"]))
        slopes.sort(key=lambda e: (e["date"], e["parameter"]))
        data = {"machine": machine, "layout": entries[0].layout,
                "entries": [_entry_dict(e) for e in entries], "events": events,
                "slope_changes": slopes,
                "trends": trends, "forecast": forecast, "control": control,
                "method": METHOD, "budgets": _budgets(series, fits)}
        return cls(data, series, {n: f for n, f in fits.items()})

    def __getitem__(self, key):
        return self.data[key]

    def write_html(self, path, inputs=()):
        """The history page (``--html``); returns its path."""
        from ..fileio import write_text

        return write_text(path, self.html(), inputs=list(inputs))

    def figures(self) -> dict:
        """``{parameter: Figure}``: the chart of each parameter (values, limits, trend)."""
        return {n: parameter_figure(self, n) for n in self.series}

    def summary(self) -> str:
        """What ``volerr history show`` prints."""
        return "\n".join(self.summary_lines())

    def _rows(self) -> list:
        """The numbers the command prints: each event (``"EY0C step 2025-03-31"``, the step
        in the parameter's unit), each trend (``"EX0C slope since 2025-01-06"``, per day:
        unit ``um/d``, ``urad/d``), each forecast's tolerance (``"EX0C tolerance"``, no
        uncertainty) and the volumetric error now of a ``map`` forecast, then every
        parameter's latest entry (``"EX0C latest 2025-06-30"``); std k = 1."""
        d = self.data
        rows = [Row(f"{e['parameter']} step {e['date']}", e["change"], e["std"], e["unit"])
                for e in d["events"]]
        rows += [Row(f"{n} slope since {t['since']}", t["slope_per_day"], t["std"],
                     f"{t['unit']}/d") for n, t in d["trends"].items()]
        for n, f in d["forecast"].items():
            rows.append(Row(f"{n} tolerance", f["tolerance"], None, f["unit"]))
            if "now_um" in f:
                rows.append(Row("map now", f["now_um"], None, "um"))
        rows += [Row(f"{n} latest {s.dates[-1]}", float(s.y[-1]), float(s.s[-1]), s.unit)
                 for n, s in self.series.items()]
        return rows

    def table(self):
        """Name, value, standard uncertainty (k = 1), unit, k of every number the command
        prints (:meth:`_rows`): a :class:`pandas.DataFrame`, or a list of
        :class:`volerr.results.Row` without pandas."""
        return as_table(self._rows())

    def html(self) -> str:
        return render_html(self)

    def summary_lines(self) -> list:
        d = self.data
        n_cal = sum(e["kind"] == "calibration" for e in d["entries"])
        out = [f"{d['machine']} ({d['layout']}): {len(d['entries'])} entries ({n_cal} "
               f"calibrations, {len(d['entries']) - n_cal} checks), "
               f"{d['entries'][0]['date']} to {d['entries'][-1]['date']}; "
               f"{len(d['events'])} events"]
        for e in d["events"]:
            out.append(f"  event {e['date']}: {e['parameter']} {e['change']:+.4g} +- "
                       f"{e['std']:.2g} {e['unit']}")
        for n, t in d["trends"].items():
            if abs(t["slope_per_day"]) > 2 * t["std"]:
                out.append(f"  trend {n}: {t['slope_per_day'] * 30:+.3g} +- "
                           f"{t['std'] * 30:.2g} {t['unit']} per 30 days since {t['since']}")
        for n, f in d["forecast"].items():
            lo, hi = f["interval"]
            out.append(f"  {n} leaves its tolerance: {f['date'] or 'not foreseen'}"
                       + (f" (95 %: {lo or 'open'} to {hi or 'open'})" if f["date"] else ""))
        return out


METHOD = ("control charts against the first calibration: Shewhart individuals +-3 sigma "
          "(ISO 7870-2), EWMA lambda 0.2, L 3 (ISO 7870-6), sigma from the stated "
          "uncertainties; events: steps in the level by weighted least squares with one slope, "
          "added while the likelihood ratio exceeds chi2(1) at 1 - 0.01/m (Bonferroni over the "
          "m positions); trends: generalised least-squares line after the last event (slope per "
          "day; the checks on one reference share its error); forecast: the date the trend reaches the tolerance, 95 % interval from the "
          "line's confidence band (Fieller)")


def _entry_dict(e) -> dict:
    d = {"date": e.date, "kind": e.kind, "source": e.source, "sha256": e.sha256,
         "parameters": {n: {"value": v.value, "std": v.std, "unit": v.unit,
                            "status": v.status}
                        for n, v in sorted(e.values.items())}}
    if e.kind == "check":
        d["verdict"] = e.verdict
        d["reference_sha256"] = e.reference_sha256
    d["files"] = e.files
    return d


def _map_forecast(entries, series, fits, tol: float) -> dict:
    """``map=`` (:mod:`volerr.history.volume`): dates from the parameters' trends."""
    from . import volume

    units = {n: s.unit for n, s in series.items()}
    used, A, left = volume.sensitivities(entries[0].layout, units)
    if not used:
        return {"date": None, "interval": [None, None], "tolerance": tol, "unit": "um",
                "parameters": [], "left_out": left,
                "note": "no constant parameter (location, squareness) with a value in the "
                        "history"}
    t_last = max(float(s.t[-1]) for s in series.values())
    lines = []
    for n in used:
        tr = fits[n][1]
        if tr is None:
            s = series[n]
            lines.append((float(s.y[-1]), 0.0, np.zeros((2, 2)), float(s.t[-1])))
        else:
            lines.append((tr.a, tr.b, tr.cov, tr.t0))
    f = volume.forecast(A, lines, tol, t_last)
    lo, hi = f["interval_days"]
    return {"date": an.date_of(f["date_day"]) if f["date_day"] is not None else None,
            "interval": [an.date_of(lo) if lo is not None else None,
                         an.date_of(hi) if hi is not None else None],
            "tolerance": tol, "unit": "um", "now_um": f["now_um"], "parameters": used,
            "left_out": left}


# -- HTML -----------------------------------------------------------------------------------
def _dates(t) -> list:
    import datetime as dt

    return [dt.date(1970, 1, 1) + dt.timedelta(days=float(x)) for x in t]


def parameter_figure(h: History, name: str):
    from ..plotstyle import figure, label, styled

    @styled
    def draw():
        s = h.series[name]
        st, tr = h.trends[name]
        c = h.data["control"][name]
        fig, (ax, ax2) = figure(2, 1, height=5.6, sharex=True)
        x = _dates(s.t)
        ax.errorbar(x, s.y, yerr=2 * s.s, fmt="o", ms=4, capsize=2,
                    label="entry, ± 2 u (k = 2)")
        ax.plot(x, [p["ucl"] for p in c["shewhart"]], "--", color="C3", lw=0.9,
                label="Shewhart limits (± 3 σ, ISO 7870-2)")
        ax.plot(x, [p["lcl"] for p in c["shewhart"]], "--", color="C3", lw=0.9)
        ax.axhline(c["centre"], color="0.5", lw=0.8)
        for e in st:
            ax.axvline(_dates([s.t[e["index"]]])[0], color="C1", lw=1.2)
        f = h.data["forecast"].get(name)
        if tr is not None:
            end = s.t[-1] + 0.3 * max(np.ptp(s.t), 1.0)
            if f and f.get("date") and f.get("interval", [None, None])[1]:
                end = max(end, an.day(f["interval"][1]) + 7.0)
            tt = np.linspace(s.t[len(s.t) - tr.n], end, 80)
            v = np.array([tr.at(t) for t in tt])
            ax.plot(_dates(tt), v[:, 0], color="C2", label="trend since the last change")
            ax.fill_between(_dates(tt), v[:, 0] - 1.96 * v[:, 1], v[:, 0] + 1.96 * v[:, 1],
                            color="C2", alpha=0.2, label="trend, 95 % band")
        if f:
            for sgn in (1, -1):
                ax.axhline(sgn * f["tolerance"], color="k", lw=0.8, ls=":")
            if f.get("date"):
                ax.axvline(_dates([an.day(f["date"])])[0], color="k", lw=1.0, ls="--",
                           label=f"leaves the tolerance {f['date']}")
        ax.set_ylabel(label(name, s.unit))
        # beside the panels: "best" still lay over the error bars (seen on the page)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9)
        ax2.plot(x, [p["z"] for p in c["ewma"]], "o-", ms=3, label="EWMA z")
        ax2.plot(x, [p["ucl"] for p in c["ewma"]], "--", color="C3", lw=0.9,
                 label="EWMA limits (ISO 7870-6)")
        ax2.plot(x, [p["lcl"] for p in c["ewma"]], "--", color="C3", lw=0.9)
        ax2.set_ylabel(label("EWMA", s.unit))
        ax2.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9)
        return fig

    return draw()


def render_html(h: History) -> str:
    from ..plotstyle import embedded_img, png

    d = h.data
    esc = html.escape
    rows = "".join(f"<tr><td>{esc(e['date'])}</td><td>{esc(e['parameter'])}</td>"
                   f"<td>{e['change']:+.4g}</td><td>{e['std']:.2g}</td><td>{esc(e['unit'])}"
                   f"</td></tr>" for e in d["events"]) or "<tr><td colspan=5>none</td></tr>"
    trows = "".join(f"<tr><td>{esc(n)}</td><td>{t['slope_per_day'] * 30:+.4g}</td>"
                    f"<td>{t['std'] * 30:.2g}</td><td>{esc(t['unit'])}</td>"
                    f"<td>{esc(t['since'])}</td><td>{t['n']}</td></tr>"
                    for n, t in d["trends"].items())
    frows = "".join(f"<tr><td>{esc(n)}</td><td>{f['tolerance']:g} {esc(f['unit'])}</td>"
                    f"<td>{esc(str(f['date']))}</td><td>{esc(str(f['interval'][0]))} to "
                    f"{esc(str(f['interval'][1]))}</td></tr>" for n, f in d["forecast"].items()) \
        or "<tr><td colspan=4>none: no tolerance given (--tolerance)</td></tr>"
    figs = "".join(f"<h3>{esc(n)}</h3>" + embedded_img(png(parameter_figure(h, n)), n)
                   for n in h.series)
    return document(f"History of {d['machine']}", f"""<h1>History of machine \
{esc(d['machine'])} ({esc(d['layout'])})</h1>
<p>{len(d['entries'])} entries from {esc(d['entries'][0]['date'])} to
{esc(d['entries'][-1]['date'])}. {esc(d['method'])}.</p>
<h2>Events</h2><table><tr><th>date</th><th>parameter</th><th>change</th><th>u (k = 1)</th>
<th>unit</th></tr>{rows}</table>
<h2>Trends</h2><table><tr><th>parameter</th><th>slope per 30 days</th><th>u (k = 1)</th>
<th>unit</th><th>since</th><th>entries</th></tr>{trows}</table>
<h2>Forecast</h2><table><tr><th>quantity</th><th>tolerance</th><th>leaves it on</th>
<th>95 % interval</th></tr>{frows}</table>
<h2>Parameters</h2>{figs}""")


def _budgets(series: dict, fits: dict) -> dict:
    """The budget of every uncertainty the rows state (:meth:`History._rows`): each step and
    trend slope from its WLS fit (:func:`volerr.history.analysis.wls_budget`), and each
    parameter's latest entry, whose u is the stored one of its report (one source)."""
    from ..report.budget import budget, source

    out = {}
    for name, s in series.items():
        steps, tr = fits[name]
        for e in steps:
            row = f"{name} step {e['date']}"
            out[row] = {**e["budget"], "quantity": row}
        if tr is not None and tr.budget is not None:
            row = f"{name} slope since {tr.since}"
            out[row] = {**tr.budget, "quantity": row, "unit": f"{s.unit}/d"}
        row = f"{name} latest {s.dates[-1]}"
        out[row] = budget(row, s.unit, [source(
            f"the entry of {s.dates[-1]} as stored (u of its report; its budget there)",
            float(s.s[-1]), s.unit)], 2.0)
    return out
