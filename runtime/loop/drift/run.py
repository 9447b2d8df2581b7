"""The loop on drift runs, start to end: drift files in, a :class:`DriftReport` out.

:func:`loop_drift` reads the files into one :class:`~volerr.loop.drift.series.DriftSeries`
(:mod:`~volerr.loop.drift.series`), holds out readings (:mod:`~volerr.loop.drift.split`) and
calls :func:`analyse` on that one data type: the directed channels become rows of the
layout's model (:mod:`~volerr.loop.drift.rows`), every channel (or quantity) is fitted
(:mod:`~volerr.loop.drift.fit`), and the JSON is assembled here (its fields: INTERFACE.md,
"Thermal drift tests ... and the loop on measured heat").

Effects: the terms of one channel with the same covariate (the heat input, a sensor, a
difference of two sensors) form one effect ("two time constants where one is not enough");
each names its ``channels``, ``covariates``, ``basis``, ``lag_s`` ``{value, std,
range_k2}`` (its first term's; every term in ``terms``; ``range_k2``:
:mod:`volerr.loop.drift.tau_range`) and its coefficients with standard uncertainties (blocked
jackknife) in ``parameters``/``std``; uncertainties are printed with k = 2.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...errors import require
from . import basis
from . import family
from . import fit as core
from . import interval as band
from . import rows as rows_mod
from .report import DriftReport
from .series import DriftSeries, read_runs, stack_runs
from .split import extrapolation, held_out


def loop_drift(layout: str, paths, window=None, files=(), differences: bool = False,
               progress=None) -> DriftReport:
    """The loop on drift files ``paths`` and the held-out ``files`` (read beside them, every
    run of theirs held out; ``window`` ``"A:B"`` holds out the readings with A <= t < B; see
    :mod:`volerr.loop.drift.fit`).  BLAS runs on one thread meanwhile, as in the 3-D loop
    (:func:`volerr.loop.run.loop`): the systems are a few hundred rows by at most a few
    hundred columns, where more threads only wait (``lstsq`` of 453 x 94: 97 ms CPU with the
    default threads on this 2-core machine under load, 3.5 ms with one)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        return _loop_drift(layout, paths, window, files, differences, progress)


def _loop_drift(layout, paths, window, files, differences, progress) -> DriftReport:
    from ...instruments.drift import test_position
    from ...machine.model import load

    model = load(layout)
    named = {Path(p).resolve() for p in paths}
    for f in files:
        require(Path(f).is_file(), f"--holdout-files: data file not found: {f}")
    runs, left = read_runs(list(paths) + [f for f in files if Path(f).resolve() not in named])
    s = stack_runs(runs, left)
    s.test, said = held_out(s, window, files)
    directed = rows_mod.rows_of(s.directions, s.heights) is not None
    position = test_position(runs[0], model) if directed else {}
    rep = analyse(model, s, position, said, differences, progress)
    origins = {r.file: r.time_origin_s for r in runs if r.time_origin_s}
    if origins:           # timestamps in the time column (instruments.drift._time)
        rep.data["time_origins_s"] = origins
    return rep


def analyse(model, s: DriftSeries, position: dict, split: str, differences: bool = False,
            progress=None) -> DriftReport:
    """The loop on the series ``s`` (its ``test`` mask set; ``split`` says how) of a machine
    ``model`` held at ``position`` (the first run's axis values): channels with a direction
    are rows of the layout's model, the quantities of the chain they read are modelled,
    each channel predicted by its row of them."""
    rows = _rows(s, position, model)
    m, resid = (s, {}) if rows is None else rows_mod.modelled_series(s, rows)
    res = core.run_drift(m, differences=differences, progress=progress)
    data = {"layout": model.name, "kind": "drift",
            "runs": [f if not r else f"{f}[{r}]" for f, r in s.runs], "split": split,
            "n_points": int(len(s.t_s) * len(s.channels)), "n_train": int(s.train.sum()),
            "n_test": int(s.test.sum()), "fold_rule": res["fold_rule"],
            "n_folds": res["n_folds"], "channels": {}, "quantities": {}, "effects": [],
            "budgets": {},
            "not_significant": [], "not_reported": [], "unidentifiable": [],
            "extrapolation": extrapolation(s), "inputs_left_out": list(s.left_out),
            "kept_out": basis.kept_out(s)}
    if res["room_undecided"]:  # what a training in a held room cannot decide (basis.py)
        data["room_undecided"] = {**res["room_undecided"], "rule": basis.ROOM_RULE}
    if s.environments:        # each run's environment (the folds' groups, basis.folds)
        data["environments"] = {(f if not r else f"{f}[{r}]"): e
                                for (f, r), e in zip(s.runs, s.environments)}
        if res["fold_rule"] == "environments":
            data["fold_environments"] = list(dict.fromkeys(
                e for r, e in enumerate(s.environments) if np.any(s.train & (s.run == r))))
    qpred = {label: _prediction(m, r) for label, r in res["channels"].items()}
    pred = {k: qpred[k] for k in s.channels if k not in resid}
    if rows is not None:
        pred.update(rows_mod.map_back(s, rows, qpred, resid))
        data["quantities"] = {q.symbol: _quantity(q, rows) for q in rows.quantities}
    pred = {k: pred[k] for k in s.channels}
    for label, p in pred.items():
        c = data["channels"][label] = _metrics(s, s.channels[label], p["before"], p["after"],
                                               p["static"])
        c.update(_family(s, label, p, res["channels"].get(label), res["room_undecided"],
                         data["kept_out"]))
        c["direction"] = s.directions.get(label, "?")
        if label in resid:
            c["row"] = rows.row(label)
            c["row_residual_rms_um"] = rows_mod.residual_rms(s, resid[label])
    quantity = {q.symbol: q for q in (rows.quantities if rows is not None else ())}
    for label, r in res["channels"].items():
        if label in quantity:
            data["quantities"][label].update(_choice(r["choice"], bool(r["terms"])))
        if not r["choice"]["named"]:
            data["not_reported"] += [f"{label}: {_basis(sp)}" for sp in r["terms"]]
            continue
        data["effects"] += _effects(label, r, m, quantity.get(label), data["budgets"])
        data["not_significant"] += [f"{label}: {_basis(sp)}" for sp in r["fit"].get("dropped", [])]
    tr = list(data["channels"].values())
    data["rms_before_um"] = _pool(tr, "rms_before_um")
    data["rms_after_um"] = _pool(tr, "rms_after_um")
    data["max_before_um"] = max(c["max_abs_before_um"] for c in tr)
    data["max_after_um"] = max(c["max_abs_after_um"] for c in tr)
    _judge_held_out(data, pred)
    return DriftReport(data, s, pred)


def _judge_held_out(data: dict, pred: dict) -> None:
    """The held-out verdict (:func:`volerr.loop.drift.family.held_out_verdict`: does the lag
    model, the model the named effects come from, hold on the held-out readings?) of every
    channel whose lag terms are named (its own or its quantities'), and of every effect: its
    channel's, or for a quantity read by several channels the one of least margin
    (``bound_um - lag_model_mae_um``; ``"channel"`` names it), so an effect is confirmed
    where every channel it is judged on is.  None (JSON null) where nothing is held out.
    Changes no choice and no figure."""
    data["held_out_rule"] = family.HELD_OUT_RULE
    chs = data["channels"]
    for label, c in chs.items():
        if "family" in c:
            c["held_out_reported"] = family.reported_held_out(c)
        if pred[label]["terms"]:
            c["held_out"] = family.held_out_verdict(c)
    for e in data["effects"]:
        judged = [(k, chs[k]["held_out"]) for k in e["channels"] if "held_out" in chs.get(k, {})]
        if not judged or any(v is None for _, v in judged):
            e["held_out"] = None
            continue
        k, v = min(judged, key=lambda kv: kv[1]["bound_um"] - kv[1]["lag_model_mae_um"])
        e["held_out"] = {"channel": k, **v}


def _rows(s, position, model):
    """The rows of the directed channels, named in the layout at the test ``position``
    (None: no channel has a direction)."""
    rows = rows_mod.rows_of(s.directions, s.heights)
    if rows is not None:
        rows_mod.name_in_layout(rows, model, position,
                                taken=[k for k in s.channels if k not in rows.channels])
    return rows


def _prediction(m, r) -> dict:
    """The predictions (N,) um of one label: "lag" the lag model's, "after" the chosen
    family's (:mod:`volerr.loop.drift.family`), "static", "constant", "before"; "cv_resid"
    the chosen family's blocked-CV residuals; "terms" the lag terms where the lag model is
    the one reported (else none)."""
    f, c = r["fit"], r["choice"]
    lag = core.predict(m, f["design"], np.concatenate([f["zeros"], f["coef"]]), r["y"])
    fam = c["family"]
    return {"before": r["before"], "lag": lag, "after": lag if fam == "lag" else r[fam],
            "static": r["static"], "constant": r["constant"], "regularised": r["regularised"],
            "cv_resid": c["cv_resid"], "family": fam, "leverage": r["leverage"],
            "terms": r["terms"] if c["named"] else [], "alternative": r.get("alternative")}


def _quantity(q, rows) -> dict:
    return {"kind": q.kind, "axis": q.axis, "about": q.about, "unit": q.unit,
            "description": q.describe(), "channels": list(q.channels),
            "rows": {k: float(rows.A[rows.channels.index(k), rows.quantities.index(q)])
                     for k in q.channels},
            "layout_parameters": dict(q.layout_parameters)}


def _choice(choice, has_terms) -> dict:
    """The family chosen for a label and why (:mod:`volerr.loop.drift.family`)."""
    return {"family": choice["family"], "lag_terms_named": bool(choice["named"]),
            "cv_rms_um": {k: round(v, 6) for k, v in choice["cv_rms_um"].items()},
            "paired_t": {k: round(v, 3) for k, v in choice["t"].items()},
            "selection_rule": choice["rule"],
            "t_critical": round(choice["t_crit"], 3),
            "families_equivalent": choice.get("equivalent", []),
            "verdict": family.verdict(choice["family"], choice["cv_rms_um"], choice["t"],
                                      has_terms, choice["t_crit"], choice["named"])}


def _family(s, label, p, r, room=None, kept=()) -> dict:
    """A channel's baselines' held-out figures, the lag model's, its family (a channel of
    rows: the most complex of its quantities') and its prediction interval (``room``: what
    the training cannot decide, :func:`volerr.loop.drift.basis.room_undecided`; None:
    nothing; ``kept``: the inputs kept out, :func:`volerr.loop.drift.basis.kept_out`)."""
    y, te = s.channels[label], s.test
    figs = {}
    for name in ("static", "constant", "lag", "regularised"):
        e = (y - p[name])[te]
        figs[name] = {"mae_um": float(np.mean(np.abs(e))),
                      "rms_um": float(np.sqrt(np.mean(e ** 2))),
                      "max_abs_um": float(np.max(np.abs(e)))}
    out = {"baselines": {"static": figs["static"], "constant": figs["constant"]},
           "lag_model": figs["lag"], "regularised": figs["regularised"]}
    if r is not None:
        out.update(_choice(r["choice"], bool(r["terms"])))
        for name in ("static", "constant"):
            out["baselines"][name]["cv_rms_um"] = out["cv_rms_um"][name]
        out["lag_model"]["cv_rms_um"] = out["cv_rms_um"]["lag"]
        sh = r["shrink"]
        out["regularised"].update({"cv_rms_um": out["cv_rms_um"]["regularised"],
                                   "lambda_rel": sh["lambda_rel"],
                                   "edf": round(sh["edf"], 3), "n_columns": sh["n_columns"],
                                   "penalty": sh["penalty"]})
    else:
        out["family"] = p["family"]
    iv = band.interval(p["cv_resid"], y, p["after"], basis.folds(s)[0], te, p.get("leverage"))
    if room is not None:      # widened by the room's other reading (interval.py)
        band.widen_for_room(iv, y, p["after"], p.get("alternative"), te, room["alternative"])
    if kept:                  # widened by what a kept-out input may do (interval.py)
        band.widen_for_kept_out(iv, y, p["after"], te, _kept_out_terms(s, y - p["after"], kept))
    p["half_width"] = iv.pop("per_reading")
    out["interval"] = iv
    return out


def _kept_out_terms(s, resid, kept) -> list:
    """Per kept-out input (``kept``, :func:`volerr.loop.drift.basis.kept_out`): {"input",
    "coef_um_per_unit", "u", "change" (N,) its change since its run's zero as kept_out
    measures it}, the coefficient and its u fitted to the chosen family's residuals
    ``resid`` on the training readings (:func:`volerr.loop.drift.fit.kept_out_coef`)."""
    ref, fold = basis.reference(s), basis.folds(s)[0]
    out = []
    for e in kept:
        v = basis.entered(s, e["sensor"], ref)
        x = v - s.zero(v)
        b, u = core.kept_out_coef(s, resid, x, fold)
        out.append({"input": e["input"], "coef_um_per_unit": b, "u": u, "change": x})
    return out


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


def _effects(label, r, s, q=None, budgets=None) -> list:
    """The channel's (or the quantity ``q``'s) terms grouped by covariate (module
    docstring); the budget of every term's std (and its time constant's) into ``budgets``
    (:func:`_budget`)."""
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
            terms.append(_term(r["terms"][i], float(f["coef"][i]), float(f["coef_std"][i]),
                               f["tau_std"][i], unit,
                               f["tau_range"][i] if f.get("tau_range") else None))
        name = f"{'KH' if heat else 'KT'}_{label}_{'_'.join(covs)}".replace(" ", "")
        for j, (i, t) in enumerate(zip(idx, terms)):
            if budgets is not None:
                budgets.update(_budget(f"{name}_{j}", t, f, i))
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


def _term(sp, value: float, std: float, tau_std, unit: str, tau_range=None) -> dict:
    """A term's JSON: its basis, coefficient and standard uncertainty (``unit``: the
    quantity's; per K for a temperature), time constant (``lag_s``: value, the jackknife's
    ``std`` and the profile range ``range_k2`` [lo, hi] s, None an open end:
    :mod:`volerr.loop.drift.tau_range`; ``tau_range`` None: no range computed), its
    alternatives in its place and whether the CV tells the model from its absence
    (``cv_decided``, ``cv_without``: :func:`volerr.loop.drift.family.without_each`; a term
    not decided stays in the model and is named as such)."""
    lag = None
    if sp["tau_s"] > 0:
        lag = {"value": round(sp["tau_s"], 1),
               "std": None if tau_std is None else round(tau_std, 1)}
        if tau_range is not None:
            lag["range_k2"] = [None if v is None else round(v, 1) for v in tau_range]
    return {"basis": _basis(sp), "value": value, "std": std,
            "unit": unit if sp["source"] == "heat" else f"{unit}/K",
            "lag_s": lag,
            "alternatives": sp["alternatives"], "cv_rms_um": sp["cv_rms_um"],
            "tau_equivalent_s": _tau_span(sp), "cv_decided": sp.get("cv_decided"),
            "cv_without": sp.get("cv_without")}


def _tau_span(sp) -> list | None:
    """[lo, hi] s: the time constants of the term's own source its group holds
    (:func:`volerr.loop.drift.select.tau_equivalent`, on the grid) and its refined one."""
    span = sp.get("tau_equivalent_s")
    if span is None or not sp["tau_s"] > 0:
        return None
    return [round(min(span[0], sp["tau_s"]), 1), round(max(span[1], sp["tau_s"]), 1)]


def _budget(row: str, t: dict, f: dict, i: int) -> dict:
    """The GUM budgets (:mod:`volerr.report.budget`) of term ``i``'s coefficient (row
    ``row``) and time constant (``row:tau``): their blocked jackknife standard uncertainty,
    u^2 = (K - 1) / K sum_k (b_k - mean b)^2 over the K folds (:mod:`volerr.loop.drift.fit`),
    as one source per fold left out, u(x_k) = ``|b_k - mean b|``, sensitivity sqrt((K - 1) / K)
    (taken as the stated u over the root sum of squares of the deviations: the stated u is
    rounded)."""
    from ...report.budget import budget, source

    out = {}
    for key, dev, std, unit in (
            (row, f.get("coef_dev"), t["std"], t["unit"]),
            (f"{row}:tau", f.get("tau_dev"), (t.get("lag_s") or {}).get("std"), "s")):
        if dev is None or std is None:
            continue
        d = np.abs(np.asarray(dev)[:, i])
        rss = float(np.sqrt(np.sum(d ** 2)))
        K = len(d)
        out[key] = budget(key, unit, [
            source(f"fold {k + 1} of {K} left out (jackknife replicate)", float(v), unit,
                   std / rss if rss > 0 else 0.0) for k, v in enumerate(d)], 2.0)
    return out


def _parameter(s, label, q=None) -> str:
    """The chain's quantity the effect acts on (its symbol, what it is, the channels whose
    rows it is part of), or a ``?`` channel's own zero."""
    if q is not None:
        return (f"{q.symbol}: {q.describe()} at the test position ({q.unit}; read by "
                f"{', '.join(q.channels)})")
    return f"channel {label} (direction not known: modelled on its own)"
