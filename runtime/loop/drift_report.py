"""The report of the loop on drift runs (:func:`loop_drift`): JSON (INTERFACE.md "Thermal
drift tests ... and the loop on measured heat"), the console, the predictions CSV and the
HTML page with one time-series figure per channel.

Effects: the terms of one channel with the same covariate (the heat input, a sensor, a
difference of two sensors) form one effect ("two time constants where one is not enough");
each names its ``channels``, ``covariates``, ``basis``, ``lag_s`` ``{value, std}`` (its first
term's; every term in ``terms``) and its coefficients with standard uncertainties (blocked
jackknife) in ``parameters``/``std``; uncertainties are printed with k = 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import require
from ..fileio import json_text
from . import drift as core
from . import drift_basis as basis
from . import drift_rows as rows_mod
from .drift_split import extrapolation, extrapolation_line, held_out

K_PRINT = 2.0      # coverage factor of the printed uncertainties (the loop's console, 3-D too)



def load_series(paths) -> basis.DriftSeries:
    """Drift files (paths) -> one :class:`~volerr.loop.drift_basis.DriftSeries` (every run
    its own zero and its own lag start); runs must log the same channels and inputs."""
    return _series(_runs(paths))


def _runs(paths) -> list:
    from ..instruments.drift import read_runs

    runs = [r for p in paths for r in read_runs(p)]
    first = runs[0]
    for r in runs[1:]:
        require(set(r.channels) == set(first.channels) and set(r.inputs) == set(first.inputs),
                f"{r.name}: its channels and logged inputs differ from {first.name}'s; the "
                f"runs of one loop log the same ones")
    return runs


def _series(runs) -> basis.DriftSeries:
    first = runs[0]
    cat = np.concatenate
    return basis.DriftSeries(
        cat([r.t_s for r in runs]), cat([np.full(r.n, i) for i, r in enumerate(runs)]),
        [(r.file, r.run) for r in runs],
        {k: cat([r.inputs[k] for r in runs]) for k in first.inputs},
        {k: cat([r.channels[k] for r in runs]) for k in first.channels},
        dict(first.directions), dict(first.heights))


@dataclass
class DriftReport:
    """Result of :func:`loop_drift`: ``data`` the JSON, ``rows`` the predictions, ``series``
    and ``pred`` what the figures need."""

    data: dict
    series: basis.DriftSeries
    pred: dict = field(default_factory=dict)

    def __getitem__(self, key):
        return self.data[key]

    @property
    def effects(self) -> list:
        return self.data["effects"]

    def write_json(self, path, inputs=()) -> Path:
        from ..fileio import write_text

        return write_text(path, json_text(self.data), inputs=list(inputs))

    def write_predictions(self, path, inputs=()) -> Path:
        """CSV ``file,run,t_s,channel,measured_um,before_um,after_um,split`` (every reading)."""
        from ..fileio import write_text

        s = self.series
        lines = ["file,run,t_s,channel,measured_um,before_um,after_um,split"]
        for label, p in self.pred.items():
            y = s.channels[label]
            for i in range(len(s.t_s)):
                f, r = s.runs[s.run[i]]
                lines.append(f"{f},{r},{s.t_s[i]:.10g},{label},{y[i]:.10g},{p['before'][i]:.10g},"
                             f"{p['after'][i]:.10g},{'test' if s.test[i] else 'train'}")
        return write_text(path, "\n".join(lines) + "\n", inputs=list(inputs))

    def write_html(self, path, inputs=()) -> Path:
        from ..fileio import write_text
        from .drift_figure import render_html

        return write_text(path, render_html(self), inputs=list(inputs))

    def summary(self) -> str:
        """The whole console text of ``volerr loop`` on drift runs."""
        return "\n".join(self.summary_lines())

    def to_dict(self) -> dict:
        return self.data

    def summary_lines(self) -> list:
        d = self.data
        out = [f"{d['layout']}: drift runs {', '.join(d['runs'])}; {d['split']}; "
               f"{d['n_train']} training, {d['n_test']} held-out readings; choices by blocked "
               f"cross-validation over {d['n_folds']} {d['fold_rule']}"]
        if d.get("extrapolation"):
            out.insert(0, "  " + extrapolation_line(d["extrapolation"]))
        for label, c in d["channels"].items():
            out.append(f"  channel {label}: held-out MAE {c['mae_before_um']:.3f} -> "
                       f"{c['mae_after_um']:.3f} um (static regression on all temperatures "
                       f"{c['mae_static_um']:.3f}), RMS {c['rms_before_um']:.3f} -> "
                       f"{c['rms_after_um']:.3f}, max {c['max_abs_before_um']:.3f} -> "
                       f"{c['max_abs_after_um']:.3f} um")
        for sym, q in d.get("quantities", {}).items():
            rows = ", ".join(f"{c} {w:+.4g}" for c, w in q["rows"].items())
            own = ", ".join(q["layout_parameters"]) or "none"
            out.append(f"  {sym} ({q['unit']}): {q['description']}, rows {rows}; the layout's "
                       f"parameters it is at this position: {own}")
        for e in d["effects"]:
            what = e["channel"] if not e.get("quantity") else \
                f"{e['quantity']} (channels {', '.join(e['channels'])})"
            out.append(f"  {e['kind']} {e['name']}: {what} varies with {e['basis']}")
            for t in e["terms"]:
                out.append("    " + _term_line(t))
        for n in d["not_significant"]:
            out.append(f"  not significant (|value| < {core.SIG_K:g} u), left out: {n}")
        return out


def _term_line(t: dict) -> str:
    k = K_PRINT
    c = f"{t['value']:.4g} +- {k * t['std']:.2g} {t['unit']} (k = {k:g})"
    lag = t.get("lag_s")
    if lag:
        u = f" +- {k * lag['std']:.0f}" if lag.get("std") is not None else " (u not determined)"
        c += f", tau = {lag['value']:.0f}{u} s (k = {k:g})"
    if t.get("alternatives"):
        c += "; these data cannot tell it from " + ", ".join(
            a["covariate"] + (f" through {a['lag_s']:.0f} s" if a.get("lag_s") else "")
            for a in t["alternatives"])
    return f"{t['basis']}: {c}"


def loop_drift(layout: str, paths, window=None, files=(), differences: bool = False,
               progress=None) -> DriftReport:
    """The loop on drift files ``paths`` and the held-out ``files`` (read beside them, every
    run of theirs held out; see :mod:`volerr.loop.drift`).  Channels with a direction are
    rows of the layout's model (:mod:`volerr.loop.drift_rows`): the quantities of the chain
    they read are modelled, each channel predicted by its row of them."""
    from ..machine.model import load

    model = load(layout)
    named = {Path(p).resolve() for p in paths}
    runs = _runs(list(paths) + [f for f in files if Path(f).resolve() not in named])
    s = _series(runs)
    s.test, said = held_out(s, window, files)
    rows = _rows(s, runs[0], model)
    m, resid = (s, {}) if rows is None else rows_mod.modelled_series(s, rows)
    res = core.run_drift(m, differences=differences, progress=progress)
    data = {"layout": model.name, "kind": "drift",
            "runs": [f if not r else f"{f}[{r}]" for f, r in s.runs], "split": said,
            "n_points": int(len(s.t_s) * len(s.channels)), "n_train": int(s.train.sum()),
            "n_test": int(s.test.sum()), "fold_rule": res["fold_rule"],
            "n_folds": res["n_folds"], "channels": {}, "quantities": {}, "effects": [],
            "not_significant": [], "static_regression": {}, "unidentifiable": [],
            "extrapolation": extrapolation(s)}
    R = (s.run[:, None] == np.arange(len(s.runs))[None, :]).astype(float)
    qpred = {label: _prediction(m, R, r) for label, r in res["channels"].items()}
    pred = {k: qpred[k] for k in s.channels if k not in resid}
    if rows is not None:
        pred.update(rows_mod.map_back(s, rows, qpred, resid))
        data["quantities"] = {q.symbol: _quantity(q, rows) for q in rows.quantities}
    pred = {k: pred[k] for k in s.channels}
    for label, p in pred.items():
        c = data["channels"][label] = _metrics(s, s.channels[label], p["before"], p["after"],
                                               p["static"])
        c["direction"] = s.directions.get(label, "?")
        if label in resid:
            c["row"] = rows.row(label)
            c["row_residual_rms_um"] = rows_mod.residual_rms(s, resid[label])
    quantity = {q.symbol: q for q in (rows.quantities if rows is not None else ())}
    for label, r in res["channels"].items():
        data["effects"] += _effects(label, r, m, quantity.get(label))
        data["not_significant"] += [f"{label}: {_basis(sp)}" for sp in r["fit"].get("dropped", [])]
    tr = list(data["channels"].values())
    data["rms_before_um"] = _pool(tr, "rms_before_um")
    data["rms_after_um"] = _pool(tr, "rms_after_um")
    data["max_before_um"] = max(c["max_abs_before_um"] for c in tr)
    data["max_after_um"] = max(c["max_abs_after_um"] for c in tr)
    return DriftReport(data, s, pred)


def _rows(s, run, model):
    """The rows of the directed channels, named in the layout at the first run's position
    (None: no channel has a direction)."""
    from ..instruments.drift import _test_position

    rows = rows_mod.rows_of(s.directions, s.heights)
    if rows is not None:
        rows_mod.name_in_layout(rows, model, _test_position(run, model),
                                taken=[k for k in s.channels if k not in rows.channels])
    return rows


def _prediction(m, R, r) -> dict:
    f = r["fit"]
    after = core.predict(m, R, f["design"], np.concatenate([f["zeros"], f["coef"]]), r["y"])
    return {"before": r["before"], "after": after, "static": r["static"], "terms": r["terms"]}


def _quantity(q, rows) -> dict:
    return {"kind": q.kind, "axis": q.axis, "about": q.about, "unit": q.unit,
            "description": q.describe(), "channels": list(q.channels),
            "rows": {k: float(rows.A[rows.channels.index(k), rows.quantities.index(q)])
                     for k in q.channels},
            "layout_parameters": dict(q.layout_parameters)}


def _pool(chs, key) -> float:
    return float(math.sqrt(np.mean([c[key] ** 2 for c in chs])))


def _metrics(s, y, before, after, static) -> dict:
    te = s.test
    out = {"n_test": int(te.sum())}
    for name, p in (("before", before), ("after", after), ("static", static)):
        e = (y - p)[te]
        out[f"mae_{name}_um"] = float(np.mean(np.abs(e)))
        out[f"rms_{name}_um"] = float(np.sqrt(np.mean(e ** 2)))
        out[f"max_abs_{name}_um"] = float(np.max(np.abs(e)))
    return out


def _basis(sp) -> str:
    what = (f"(S_rpm/S_ref)^{sp['p']:g}" if sp["source"] == "heat" else
            sp["source"] if not sp["minus"] else f"({sp['source']} - {sp['minus']})")
    return f"lag({what}, {sp['tau_s']:.0f} s)" if sp["tau_s"] > 0 else what


def _effects(label, r, s, q=None) -> list:
    """The channel's (or the quantity ``q``'s) terms grouped by covariate (module
    docstring)."""
    f = r["fit"]
    groups: dict = {}
    for i, sp in enumerate(r["terms"]):
        key = ("heat",) if sp["source"] == "heat" else (sp["source"], sp["minus"])
        groups.setdefault(key, []).append(i)
    S_ref = float(np.abs(s.inputs[basis.SPEED][s.train]).max()) if basis.SPEED in s.inputs else None
    unit = q.unit if q is not None else "um"
    out = []
    for key, idx in groups.items():
        sp0 = r["terms"][idx[0]]
        heat = key == ("heat",)
        covs = [basis.SPEED] if heat else [c for c in key if c]
        terms = []
        for i in idx:
            sp = r["terms"][i]
            t = {"basis": _basis(sp), "value": float(f["coef"][i]), "std": float(f["coef_std"][i]),
                 "unit": unit if heat else f"{unit}/K",
                 "lag_s": ({"value": round(sp["tau_s"], 1), "std": None if f["tau_std"][i] is None
                            else round(f["tau_std"][i], 1)} if sp["tau_s"] > 0 else None),
                 "alternatives": sp["alternatives"], "cv_rms_um": sp["cv_rms_um"]}
            terms.append(t)
        name = f"{'KH' if heat else 'KT'}_{label}_{'_'.join(covs)}".replace(" ", "")
        e = {"kind": "thermal", "name": name, "channel": label,
             "channels": list(q.channels) if q is not None else [label],
             "quantity": q.symbol if q is not None else None,
             "covariate": covs[0], "covariates": covs, "parameter": _parameter(s, label, q),
             "basis": " + ".join(t["basis"] for t in terms),
             "lag_s": terms[0]["lag_s"], "terms": terms,
             "parameters": {f"{name}_{j}": t["value"] for j, t in enumerate(terms)},
             "std": {f"{name}_{j}": t["std"] for j, t in enumerate(terms)},
             "units": {f"{name}_{j}": t["unit"] for j, t in enumerate(terms)},
             "evidence": {"cv_rms_um": terms[-1]["cv_rms_um"]}}
        if heat:
            e["heat_exponent"] = sp0["p"]
            e["S_ref_rpm"] = S_ref
        out.append(e)
    return out


def _parameter(s, label, q=None) -> str:
    """The chain's quantity the effect acts on (its symbol, what it is, the channels whose
    rows it is part of), or a ``?`` channel's own zero."""
    if q is not None:
        return (f"{q.symbol}: {q.describe()} at the test position ({q.unit}; read by "
                f"{', '.join(q.channels)})")
    return f"channel {label} (direction not known: modelled on its own)"
