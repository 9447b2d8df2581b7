"""Close the loop: fit measured deviations, trace the residual to a missing effect, augment the
layout, report the error before and after on held-out points.

Steps (:func:`run_loop`):

1. read the measured-deviation CSV (INTERFACE.md) and check it against the layout;
2. hold out a random ``test_fraction`` of the points; everything below is decided on the
   others (the training points) and judged on the held-out ones;
3. fit the declared model (:mod:`volerr.loop.fit`): component errors as Legendre series, degree by
   cross-validation, squareness, location errors, the instrument's rigid placement;
   gauge fixed by convention, plan-specific unidentifiable combinations reported;
4. candidate effects (:mod:`volerr.loop.candidates`), forward stepwise: the candidate with the best
   BIC gain is accepted when the gain is strong (dBIC < -10) *and* its cross-validated
   residual is significantly smaller (paired t > 3 on the per-point squared errors);
   stop when no candidate passes; then a backward check drops any effect that, given all
   the others, no longer gains dBIC < -10 (a later effect made it redundant);
5. write the augmented layout (the original with ``[effects.*]`` tables), derive and generate
   it, and fit it: it gives the "after" figures, and its derived sensitivities are checked
   against the numeric columns used during the search;
6. report: :class:`Report` (``write_json``, ``write_html``).

Units: deviations in mm inside, um in reports; angular parameters urad; thermal um/m/K.
"""

from __future__ import annotations

import csv
import json
import math
import re
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from volerr.loop import candidates as cands
from volerr.machine.expressions import evaluate
from volerr.errors import InputError, require
from volerr.loop.fit import (Data, Problem, data_ranges, declared_design, gauge_mask,
                  identifiability, point_norm, require_points, rms, rotary_rad, rows_of,
                  twist_columns, weakly_determined)
from volerr.machine.layout import layout_text, parse_layout
from volerr.machine import derivation
from volerr.machine.model import Model, load

BIC_GAIN = 10.0      # minimum BIC improvement (natural-log units) to accept an effect
CV_T = 3.0           # minimum paired t of the held-out improvement
MAX_EFFECTS = 8
DEGREE_CV_POINTS = 2500  # training points used to choose the degree (a random subset)
AXIS_NAMES = "XYZUVWABC"


# ---- input ------------------------------------------------------------------------
def read_deviations(path, model: Model) -> Data:
    """Read a measured-deviation CSV and check it against ``model`` (InputError on defects)."""
    p = Path(path)
    require(p.is_file(), f"data file not found: {path}")
    try:
        with open(p, newline="", encoding="utf-8-sig") as fh:
            first = fh.readline()
            fh.seek(0)
            # comma-separated as INTERFACE.md says; a header without commas but with
            # semicolons or tabs (spreadsheet exports) is read with that separator
            delim = ","
            if "," not in first:
                delim = ";" if ";" in first else "\t" if "\t" in first else ","
            rows = [r for r in csv.reader(fh, delimiter=delim) if any(c.strip() for c in r)]
    except (UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"{p.name}: not a readable CSV ({exc})") from None
    require(len(rows) >= 2, f"{p.name}: no data rows")
    header = [h.strip() for h in rows[0]]
    require(len(set(header)) == len(header), f"{p.name}: duplicate column names")
    body = rows[1:]
    for i, r in enumerate(body):
        require(len(r) == len(header), f"{p.name}: row {i + 2} has {len(r)} fields, "
                f"the header {len(header)}")
    cols = {}
    for j, h in enumerate(header):
        raw = [r[j].strip() for r in body]
        vals = []
        bad = None
        for i, s in enumerate(raw):
            try:
                vals.append(float(s))
            except ValueError:
                bad = bad if bad is not None else i
                vals.append(math.nan)
        if bad is not None and all(_not_number(s) for s in raw):
            comma = next((s for s in raw if re.fullmatch(r"[+-]?\d*,\d+([eE][+-]?\d+)?", s)),
                         None)
            require(comma is None, f"{p.name}: column {h}: {comma!r} has a decimal comma; "
                    f"write numbers with a decimal point")
            continue  # a label column (text): ignored
        if bad is not None:
            raise InputError(f"{p.name}: column {h} row {bad + 2}: {raw[bad]!r} is not a number")
        v = np.asarray(vals)
        k = int(np.flatnonzero(~np.isfinite(v))[0]) if not np.all(np.isfinite(v)) else -1
        require(k < 0, f"{p.name}: column {h} row {k + 2} is NaN or infinite")
        cols[h] = v
    return columns_to_data(cols, model, p.name)


def _not_number(s: str) -> bool:
    try:
        float(s)
        return False
    except ValueError:
        return True


def columns_to_data(cols: dict, model: Model, where: str = "data") -> Data:
    """Column dict (CSV names) -> :class:`Data`, checking axes, units and ranges."""
    used = set()

    def find(name, units, what):
        hits = [f"{name}{u}" for u in units if f"{name}{u}" in cols]
        require(len(hits) <= 1, f"{where}: both {' and '.join(hits)} given for {what}")
        if hits:
            used.add(hits[0])
            return hits[0]
        return None

    positions = {}
    for a in model.axes:
        unit = ("", "_deg") if a in model.rotary_axes else ("", "_mm")
        c = find(a, unit, f"axis {a}")
        require(c is not None, f"{where}: missing axis column {a} (layout {model.name} has "
                f"axes {' '.join(model.axes)})")
        positions[a] = cols[c]
    extra_axes = [h for h in cols if re.fullmatch(rf"[{AXIS_NAMES}](_mm|_deg)?", h)
                  and h[0] not in model.axes]
    require(not extra_axes, f"{where}: axis column {extra_axes[0] if extra_axes else ''} is "
            f"not an axis of layout {model.name} ({' '.join(model.axes)}): layout mismatch")
    n = len(next(iter(positions.values())))
    require(n >= 20, f"{where}: too few points ({n}); the loop needs at least 20")
    for a, v in positions.items():
        lo, hi = model.travel[a]
        margin = 0.05 * (hi - lo)
        out = np.flatnonzero((v < lo - margin) | (v > hi + margin))
        require(len(out) == 0, f"{where}: {a} = {v[out[0]] if len(out) else 0:g} lies outside "
                f"the travel [{lo:g}, {hi:g}] of layout {model.name}: layout mismatch")
    probe = np.zeros((n, 3))
    pc = [find(c, ("", "_mm"), f"probe offset {c}") for c in ("Xp", "Yp", "Zp")]
    require(all(c is None for c in pc) or all(c is not None for c in pc),
            f"{where}: give all of Xp, Yp, Zp or none")
    if pc[0] is not None:
        probe = np.column_stack([cols[c] for c in pc])
    dev = np.zeros((n, 3))
    for i, d in enumerate(("dx", "dy", "dz")):
        require(d not in cols, f"{where}: deviation column {d} has no unit suffix "
                f"(use {d}_um or {d}_mm)")
        c_um, c_mm = find(d, ("_um",), d), find(d, ("_mm",), d)
        require(not (c_um and c_mm), f"{where}: both {d}_um and {d}_mm given")
        for bad in (f"{d}_nm", f"{d}_m", f"{d}_in", f"{d}_urad", f"{d}_rad"):
            require(bad not in cols, f"{where}: deviation column {bad}: unit not supported "
                    f"(use {d}_um or {d}_mm)")
        require(c_um or c_mm, f"{where}: missing deviation column {d}_um (or {d}_mm)")
        dev[:, i] = cols[c_um] * 1e-3 if c_um else cols[c_mm]
    big = float(np.max(np.abs(dev)))
    require(big < 5.0, f"{where}: deviations up to {big:g} mm are implausible for an error "
            f"map: wrong unit (um given as mm?) or nominal instead of deviation values")
    covs = {c: v for c, v in cols.items() if c not in used and not c.startswith(("dx", "dy",
                                                                                  "dz"))}
    missing = [c for c in model.covariates if c not in covs]
    require(not missing, f"{where}: layout {model.name} needs covariate column {missing[0] if missing else ''}")
    return Data(positions, probe, dev, covs)


# ---- effect columns ---------------------------------------------------------------
def term_columns(model: Model, data: Data, sens: np.ndarray, frame, terms) -> tuple:
    """(N, 3, m) columns of the parameters of ``terms`` [(parameter, target, basis)]."""
    params = list(dict.fromkeys(t[0] for t in terms))
    out = np.zeros((data.n, 3, len(params)))
    values = {**rotary_rad(model, data.positions), **data.covariates}
    index = {p: j for j, p in enumerate(model.parameters)}
    for pn, target, basis in terms:
        b = np.broadcast_to(evaluate(basis, values), (data.n,))
        if "." in target:
            side, key = target.split(".")
            col = twist_columns(side, key, data, frame)
        else:
            col = sens[:, :, index[target]]
        out[:, :, params.index(pn)] += col * b[:, None]
    return out, params


# ---- reporting helpers ----------------------------------------------------------------
def _unit_of(kind: str, target: str, basis: str) -> tuple[float, str]:
    """Report factor and unit of an effect parameter."""
    angular = (target[1] in "ABC" and "." not in target) or ".e" in target
    if kind == "thermal":
        # KT * A * (T - 20): 1/K -> um/m/K; KT0 * (T - 20), the scale's fixed point: mm/K -> um/K
        return (1e3, "um/K") if basis.startswith("(") else (1e6, "um/m/K")
    if kind == "drift":
        per = ("h" if "/3600" in basis or "/60" in basis or basis in ("t_h", "time_h")
               else "unit")
        return 1e3, f"um/{per}"
    return (1e6, "urad") if angular else (1e3, "um")


@dataclass
class Report:
    """Result of :func:`run_loop`; ``data`` is the json report (INTERFACE.md keys first)."""

    data: dict
    figures: dict = field(default_factory=dict)   # name -> (plot function args) for html
    augmented_text: str = ""
    generated_text: str = ""

    def __getitem__(self, key):
        return self.data[key]

    @property
    def effects(self) -> list:
        return self.data["effects"]

    def write_json(self, path, inputs=()) -> Path:
        from volerr.fileio import write_text

        return write_text(path, json.dumps(self.data, indent=2, default=_json) + "\n",
                          inputs=list(inputs))

    def write_html(self, path, inputs=()) -> Path:
        from volerr.fileio import write_text
        from volerr.loop.report import render_html

        return write_text(path, render_html(self), inputs=list(inputs))

    def error_tables(self, n_grid: int = 41, which: str = "after") -> tuple[dict, dict]:
        """The fitted error functions of the declared model (effects removed: the machine at
        the reference state, T = 20 degC, t = 0 ...) as error tables over the measured range.

        Returns ``({axis: volerr.tables.table.ErrorTable}, constants {name: value})`` in mm / rad,
        with ``std`` columns (standard deviation of the fit).  Translational errors are zero at
        the start of the measured range (their constants belong to the instrument placement);
        straightness slopes are carried by squareness (gauge: see :mod:`volerr.loop.fit`).
        ``which="before"``: the declared model's own fit (effects unmodelled, no std)."""
        from volerr.loop.fit import legendre, unit
        from volerr.tables.table import ErrorTable

        fg = self.figures
        model, ranges, deg = fg["model"], fg["ranges"], fg["degree"]
        coef, labels, var = fg["c_all"], fg["aug_labels"], fg["cov_diag"]
        if which == "before":
            coef, labels = fg["c_before"], fg["before_labels"]
            var = np.zeros(len(coef))
        index = {lab: j for j, lab in enumerate(labels)}
        tables, constants = {}, {}
        for a in model.axes:
            q = np.linspace(*ranges[a], n_grid)
            P = legendre(unit(q, *ranges[a]), deg)
            vals, std = {}, {}
            for p in model.parameters:
                if model.parameter_axis.get(p) != a:
                    continue
                js = [(k, index[(p, k)]) for k in range(deg + 1) if (p, k) in index]
                v = sum((P[:, k] * coef[j] for k, j in js), np.zeros(n_grid))
                sd = np.sqrt(sum((P[:, k] ** 2 * var[j] for k, j in js), np.zeros(n_grid)))
                if p[1] in "XYZ":
                    v = v - v[0]
                vals[p], std[p] = v, sd
            tables[a] = ErrorTable(a, q, vals, std=std)
        for p in model.parameters:
            if model.parameter_axis.get(p) is None and (p, None) in index:
                constants[p] = float(coef[index[(p, None)]])
        return tables, constants

    def write_error_tables(self, directory, inputs=()) -> Path:
        """Write :meth:`error_tables` as an error directory (``X.csv`` ... ``constants.csv``)."""
        from volerr.tables.table import write_error_dir

        tables, constants = self.error_tables()
        return write_error_dir(directory, tables, constants or None, inputs=list(inputs))

    def summary(self) -> str:
        d = self.data
        found = ", ".join(f"{e['kind']} ({e['name']})" for e in d["effects"]) or "none"
        return (f"{d['layout']}: {d['n_points']} points; held-out RMS {d['rms_before_um']:.3f} "
                f"-> {d['rms_after_um']:.3f} um, max {d['max_before_um']:.3f} -> "
                f"{d['max_after_um']:.3f} um; effects found: {found}")


def _json(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(type(o))


def _progress(total: int, enabled):
    from tqdm import tqdm

    disable = (not sys.stderr.isatty()) if enabled is None else not enabled
    return tqdm(total=total, file=sys.stderr, disable=disable, desc="volerr loop",
                bar_format="{desc}: {n}/{total} {postfix}")


# ---- the loop -------------------------------------------------------------------------
def _choose_degree(model, data, train, folds, ranges, max_degree, extra=None):
    """Degree of the component series by cross-validation on the training points (``extra``: effect
    columns (rows, m) included in every model compared)."""
    design = declared_design(model, data, max_degree, ranges)
    keep, _ = gauge_mask(model, data, max_degree, ranges)
    y = data.deviation.ravel()
    if len(train) > DEGREE_CV_POINTS:  # the degree needs no more points than this
        train = np.sort(np.random.default_rng(0).choice(train, DEGREE_CV_POINTS, replace=False))
        folds = None
    scores = {}
    for k in range(1, max_degree + 1):
        m = keep & np.array([lab[1] is None or lab[0] == "setup" or lab[1] <= k
                             for lab in design.labels])
        if 3 * len(train) < 2 * m.sum() + 10:
            break
        A = design.A[:, :, m].reshape(-1, m.sum())
        if extra is not None and extra.shape[1]:
            A = np.concatenate([A, extra], axis=1)
        prob = Problem(A, y)
        scores[k] = rms(_cv(prob, folds, train))
        best_k = min(scores, key=scores.get)
        if k - best_k >= 2:   # two degrees without a gain: stop
            break
    require(scores, f"too few points for the basis: {len(train)} training points cannot fit "
            f"even a degree-1 model of layout {model.name}")
    best = min(scores.values())
    return min(k for k, v in scores.items() if v <= best), scores


def _cv(prob: Problem, folds, points) -> np.ndarray:
    """Cross-validated residual rows: leave-one-point-out when ``folds`` is None, else k-fold
    with the given fold label per point."""
    if folds is None:
        return prob.loo_residuals(points)
    return prob.cv_residuals(folds, points)


def _periodic_best(cand, model, data, train, sens, resid, ranges):
    """Best period of a periodic candidate by the residual periodogram, refined."""
    comp, axis, periods = cand.period_search
    j = model.parameters.index(comp)
    s = sens[train, :, j]                       # (n, 3)
    r = resid.reshape(-1, 3)
    w = np.sum(r * s, axis=1)
    s2 = np.sum(s * s, axis=1)
    q = data.positions[axis][train]

    def gain(per):
        ph = 2 * np.pi * np.outer(q, 1.0 / np.atleast_1d(per))
        sn, cs = np.sin(ph), np.cos(ph)
        a, c = w @ sn, w @ cs
        ss, cc, sc = s2 @ (sn * sn), s2 @ (cs * cs), s2 @ (sn * cs)
        det = np.maximum(ss * cc - sc * sc, 1e-300)
        return (a * a * cc - 2 * a * c * sc + c * c * ss) / det

    g = gain(periods)
    i = int(np.argmax(g))
    f0 = 1.0 / periods[i]
    df = (1.0 / periods[min(i + 1, len(periods) - 1)] - 1.0 / periods[max(i - 1, 0)]) / 2 or f0 * 1e-3
    fine = 1.0 / np.linspace(max(f0 - df, 1e-12), f0 + df, 41)
    gf = gain(fine)
    return float(fine[int(np.argmax(gf))])


def _pinv_sym(G, tol=1e-12):
    """Pseudo-inverse of a symmetric PSD matrix by eigh (small matrices only)."""
    w, V = np.linalg.eigh(G)
    ok = w > tol * max(float(w[-1]), 1e-300)
    return (V[:, ok] / w[ok]) @ V[:, ok].T


class _Base:
    """The current design on the training rows, column-scaled, with its Gram pseudo-inverse.

    Everything is done through Gram matrices (tall SVD/QR are slow with threaded BLAS on a
    busy machine)."""

    def __init__(self, A, y):
        self.scale = np.sqrt(np.mean(A ** 2, axis=0))
        self.scale[self.scale == 0] = 1.0
        self.A = A / self.scale
        self.Gi = _pinv_sym(self.A.T @ self.A)
        self.r = y - self.A @ (self.Gi @ (self.A.T @ y))
        self.rss = float(self.r @ self.r)

    def score(self, B) -> tuple[float, int]:
        """(RSS reduction, effective rank) of adding the columns B."""
        sc = np.sqrt(np.mean(B ** 2, axis=0))
        sc[sc == 0] = 1.0
        Bs = B / sc
        C = self.A.T @ Bs
        M = Bs.T @ Bs - C.T @ self.Gi @ C
        w, V = np.linalg.eigh((M + M.T) / 2)
        ok = w > 1e-9 * len(Bs)          # columns (unit RMS) not inside the base span
        if not ok.any():
            return 0.0, 0
        g = V[:, ok].T @ (Bs.T @ self.r)
        return float(np.sum(g * g / w[ok])), int(ok.sum())


class _Context:
    """Data, split and settings of one loop run; :meth:`search` is the stepwise selection."""

    def __init__(self, model, dat, train, fold_t, ranges, y, families):
        self.model, self.dat, self.train, self.fold_t = model, dat, train, fold_t
        self.ranges, self.y, self.families = ranges, y, families

    def search(self, degree: int) -> dict:
        model, dat, train, fold_t, y = self.model, self.dat, self.train, self.fold_t, self.y
        design = declared_design(model, dat, degree, self.ranges)
        keep, gauge = gauge_mask(model, dat, degree, self.ranges)
        require_points(len(train), int(keep.sum()), f"declared model of degree {degree}")
        labels = [lab for lab, k in zip(design.labels, keep) if k]
        keep_d, unident = identifiability(design.A[:, :, keep].reshape(-1, keep.sum()), labels)
        keep = keep.copy()
        keep[np.flatnonzero(keep)[~keep_d]] = False     # what these data cannot separate
        A_all = design.A[:, :, keep].reshape(-1, keep.sum())
        weak = weakly_determined(A_all, [lab for lab, k in zip(design.labels, keep) if k])
        candidates = [c for c in cands.build(model, dat, self.ranges, degree)
                      if c.kind in self.families]
        tr_rows = rows_of(train)
        ytr = y[tr_rows]
        n3 = len(ytr)
        cache, selected, rejected = {}, [], set()
        cv_old = point_norm(_cv(Problem(A_all, y), fold_t, train)) ** 2
        while len(selected) < MAX_EFFECTS:
            base = _Base(A_all[tr_rows], ytr)
            scored = []
            for c in candidates:
                if c.name in rejected or any(c.name == s["cand"].name for s in selected):
                    continue
                if c.period_search is not None:
                    per = _periodic_best(c, model, dat, train, design.sens, base.r, self.ranges)
                    c = cands.Candidate(c.kind, c.name,
                                        cands.periodic_terms(c.info["component"],
                                                             c.info["axis"], per),
                                        {**c.info, "period": per}, c.period_search)
                key = (c.name, tuple(c.terms))
                if key not in cache:
                    cache[key] = term_columns(model, dat, design.sens, design.frame, c.terms)
                cols, params = cache[key]
                gain, rank = base.score(cols.reshape(-1, cols.shape[-1])[tr_rows])
                if rank == 0:
                    continue
                m_eff = rank + (1 if c.period_search is not None else 0)
                new = max(base.rss - gain, 1e-300)
                dbic = n3 * math.log(new / base.rss) + m_eff * math.log(n3)
                scored.append((dbic, gain, c, cols, params))
            scored.sort(key=lambda s: s[0])
            _prefer_first_of_ties(scored, candidates)
            accepted = False
            for dbic, gain, c, cols, params in scored[:3]:
                if dbic > -BIC_GAIN:
                    break
                A_try = np.concatenate([A_all, cols.reshape(-1, cols.shape[-1])], axis=1)
                cv_new = point_norm(_cv(Problem(A_try, y), fold_t, train)) ** 2
                d = cv_old - cv_new
                t = float(d.mean() / (d.std(ddof=1) / math.sqrt(len(d)) + 1e-300))
                if t < CV_T:
                    rejected.add(c.name)
                    continue
                alts = [s[2].name for s in scored if s[2].name != c.name and s[1] >= 0.98 * gain]
                selected.append({"cand": c, "params": params, "cols": cols, "evidence": {
                    "delta_bic": round(dbic, 2),
                    "rss_reduction_fraction": round(gain / base.rss, 5),
                    "cv_rms_before_um": round(1e3 * math.sqrt(cv_old.mean()), 4),
                    "cv_rms_after_um": round(1e3 * math.sqrt(cv_new.mean()), 4),
                    "cv_paired_t": round(t, 2),
                    "step": len(selected) + 1,
                    "indistinguishable_from": alts[:5]}})
                A_all = A_try
                cv_old = cv_new
                accepted = True
                break
            if not accepted:
                break
        selected, A_all = self._backward(A_all[:, :A_all.shape[1] - sum(
            s_["cols"].shape[-1] for s_ in selected)], selected, tr_rows, ytr)
        return {"design": design, "keep": keep, "gauge": gauge, "A_all": A_all,
                "unidentifiable": unident, "weak": weak,
                "selected": selected, "candidates": candidates}


    @staticmethod
    def _backward(A0, selected, tr_rows, ytr):
        """Backward check of the forward selection: an effect that a later one made redundant
        (e.g. per-round set-ups taken first for what is a linear drift in x, y and z) is
        dropped when, given all the others, it no longer gains dBIC < -BIC_GAIN.  Each kept
        effect gets ``delta_bic_given_others``.  Returns (selected, design columns)."""
        n3 = len(ytr)

        def stack(sel):
            return np.concatenate([A0] + [s_["cols"].reshape(-1, s_["cols"].shape[-1])
                                          for s_ in sel], axis=1)

        def dbic_without(sel, i):
            others = [s_ for j, s_ in enumerate(sel) if j != i]
            base = _Base(stack(others)[tr_rows], ytr)
            cols = sel[i]["cols"]
            gain, rank = base.score(cols.reshape(-1, cols.shape[-1])[tr_rows])
            m_eff = rank + (1 if sel[i]["cand"].period_search is not None else 0)
            new = max(base.rss - gain, 1e-300)
            return n3 * math.log(new / base.rss) + m_eff * math.log(n3)

        sel = list(selected)
        while len(sel) > 1:
            scores = [dbic_without(sel, i) for i in range(len(sel))]
            worst = int(np.argmax(scores))
            if scores[worst] <= -BIC_GAIN:
                for s_, d in zip(sel, scores):
                    s_["evidence"]["delta_bic_given_others"] = round(d, 2)
                break
            sel.pop(worst)
        if len(sel) == 1:
            sel[0]["evidence"]["delta_bic_given_others"] = sel[0]["evidence"]["delta_bic"]
        for k, s_ in enumerate(sel):
            s_["evidence"]["step"] = k + 1
        return sel, stack(sel)


def _prefer_first_of_ties(scored: list, candidates: list) -> None:
    """Among candidates that fit the data identically (same columns up to rounding, e.g. on a
    CMM ``EZX`` depending on ``Y`` and ``EZY`` depending on ``X``), put the one listed first
    by :func:`volerr.loop.candidates.build` in front, so that the choice does not depend on
    rounding; the others are reported as ``indistinguishable_from``."""
    if len(scored) < 2:
        return
    order = {c.name: i for i, c in enumerate(candidates)}
    d0 = scored[0][0]
    ties = [i for i, s in enumerate(scored) if abs(s[0] - d0) <= 1e-7 * abs(d0) + 1e-9]
    first = min(ties, key=lambda i: order.get(scored[i][2].name, len(order)))
    scored.insert(0, scored.pop(first))


def run_loop(layout, data, *, seed: int = 0, folds: int | None = None,
             test_fraction: float = 0.25,
             degree: int | None = None, max_degree: int = 10, out_dir=None,
             progress=None, families=cands.FAMILIES, inputs=()) -> Report:
    """Run the loop on ``data`` (CSV path, :class:`volerr.loop.simulate.Campaign` or
    :class:`volerr.loop.fit.Data`) for ``layout`` (name or layout file). Returns a :class:`Report`.

    ``out_dir``: where the augmented layout and its generated module are written (nothing is
    written when None; the texts are in the report object either way)."""
    t_start = time.perf_counter()
    model = load(layout)
    if isinstance(data, Data):
        dat = data
    elif hasattr(data, "columns") and callable(data.columns):
        dat = columns_to_data(data.columns(), model, "campaign")
    else:
        dat = read_deviations(data, model)
    require(folds is None or 2 <= folds <= 20, "folds must be between 2 and 20")
    require(0.05 <= test_fraction <= 0.5, "test fraction must be between 0.05 and 0.5")
    bar = _progress(7, progress)
    rng = np.random.default_rng(seed)
    n = dat.n
    perm = rng.permutation(n)
    n_test = max(1, int(round(test_fraction * n)))
    test, train = np.sort(perm[:n_test]), np.sort(perm[n_test:])
    fold_t = None if folds is None else rng.permutation(len(train)) % folds
    ranges = data_ranges(model, dat)
    y = dat.deviation.ravel()

    bar.set_postfix_str("degree by cross-validation")
    fixed_degree = degree is not None
    if fixed_degree:
        require(1 <= degree <= 12, "degree must be between 1 and 12")
        degree_scores = {}
    else:
        degree, degree_scores = _choose_degree(model, dat, train, fold_t, ranges, max_degree)
    bar.update()
    bar.set_postfix_str("candidate effects")
    ctx = _Context(model, dat, train, fold_t, ranges, y, families)
    state = ctx.search(degree)
    if state["selected"] and not fixed_degree:
        # the degree was chosen with the effects unmodelled: choose it again with them
        # (higher_order terms excluded: they stand for degree) and search again if it moved
        keepers = [s_ for s_ in state["selected"] if s_["cand"].kind != "higher_order"]
        extra = np.concatenate([s_["cols"].reshape(-1, s_["cols"].shape[-1])
                                for s_ in keepers], axis=1) if keepers else None
        degree2, scores2 = _choose_degree(model, dat, train, fold_t, ranges, max_degree, extra)
        if degree2 != degree:
            degree, degree_scores = degree2, scores2
            state = ctx.search(degree)
    bar.update()
    design, keep, gauge = state["design"], state["keep"], state["gauge"]
    labels = [lab for lab, k in zip(design.labels, keep) if k]
    A_all, selected, candidates = state["A_all"], state["selected"], state["candidates"]
    unident = state["unidentifiable"]
    _explain(unident, dat, model)

    # ---- augment: layout file, derivation, generated module ---------------------------
    bar.set_postfix_str("augment, derive, generate")
    aug_text = gen_text = ""
    aug_model = model
    derived_check = None
    if selected:
        aug_text = augmented_layout_text(model, selected)
        aug_layout = parse_layout(aug_text, f"{model.name}_aug.toml")
        gen_text = derivation.generate_source(aug_layout)
        aug_model = Model(aug_layout, derivation.module_from_source(gen_text, aug_layout.name))
    bar.update()

    # ---- before / after on held-out points -------------------------------------------
    bar.set_postfix_str("held-out before/after")
    before_prob = Problem(design.A[:, :, keep].reshape(-1, keep.sum()), y)
    c_b = before_prob.fit(train)
    r_before = y[rows_of(test)] - before_prob.predict(c_b, test)
    if selected:
        ad = declared_design(aug_model, dat, degree, ranges)
        n_new = len(aug_model.parameters) - len(model.parameters)
        keep_aug = np.concatenate([keep, np.ones(n_new, bool)])
        A_aug = ad.A[:, :, keep_aug].reshape(-1, keep_aug.sum())
        # the derived model's effect columns against the numeric ones used in the search
        numeric = A_all[:, keep.sum():]
        derived = A_aug[:, keep.sum():]
        derived_check = float(np.max(np.abs(numeric - derived)) /
                              max(np.max(np.abs(numeric)), 1e-300))
        aug_labels = [lab for lab, k in zip(ad.labels, keep_aug) if k]
    else:
        A_aug, aug_labels = before_prob.A * before_prob.scale, labels
    after_prob = Problem(A_aug, y)
    c_a = after_prob.fit(train)
    r_after = y[rows_of(test)] - after_prob.predict(c_a, test)
    bar.update()

    # ---- final estimates on all points ------------------------------------------------
    bar.set_postfix_str("estimates and residual analysis")
    c_all = after_prob.fit()
    res_after_all = y - after_prob.predict(c_all)
    c_before = before_prob.fit()
    res_before_all = y - before_prob.predict(c_before)
    G = after_prob.A.T @ after_prob.A
    wG = np.linalg.eigvalsh(G)
    dof = max(len(y) - int(np.sum(wG > 1e-12 * wG[-1])), 1)
    sigma2 = float(res_after_all @ res_after_all) / dof
    cov_diag = np.diag(np.linalg.pinv(G, rcond=1e-12)) * sigma2 / after_prob.scale ** 2
    effects = []
    col_index = {lab[0]: j for j, lab in enumerate(aug_labels)}
    for s in selected:
        c = s["cand"]
        pars, units, std = {}, {}, {}
        contrib = np.zeros(len(y))
        for pn in s["params"]:
            term = next(t for t in c.terms if t[0] == pn)
            f, u = _unit_of(c.kind, term[1], term[2])
            j = col_index[pn]
            pars[pn] = round(float(c_all[j]) * f, 6)
            std[pn] = round(float(math.sqrt(max(cov_diag[j], 0.0))) * f, 6)
            units[pn] = u
            contrib += after_prob.A[:, j] * after_prob.scale[j] * c_all[j]
        info = {k: (round(v, 6) if isinstance(v, float) else v) for k, v in c.info.items()}
        if c.kind == "thermal" and len(c.terms) == 2:
            k1, k0 = (float(c_all[col_index[t[0]]]) for t in c.terms)
            if k1 != 0.0:   # expansion about A0: KT (A - A0) (T - 20), A0 = -KT0 / KT
                info["fixed_point_mm"] = round(-k0 / k1, 3)
        if c.kind == "periodic":
            a_s, a_c = (pars[t[0]] for t in c.terms)
            info["amplitude_um"] = round(math.hypot(a_s, a_c), 4)
            info["phase_rad"] = round(math.atan2(a_c, a_s), 4)   # a sin(2 pi q / P + phase)
        ev = dict(s["evidence"])
        ev["contribution_rms_um"] = round(1e3 * rms(contrib), 4)
        ev["contribution_max_um"] = round(1e3 * float(np.max(point_norm(contrib))), 4)
        effects.append({"kind": c.kind, "name": c.name, "parameters": pars, "units": units,
                        "std": std, "target": sorted({t[1] for t in c.terms}), "info": info,
                        "terms": [{"parameter": t[0], "target": t[1], "basis": t[2]}
                                  for t in c.terms], "evidence": ev})
    # points far off the final fit: chi-square(3) of |r|^2 / sigma^2 above 30 (p ~ 1e-6)
    thresh = math.sqrt(30.0 * sigma2)
    far = np.flatnonzero(point_norm(res_after_all) > thresh)
    outliers = {"threshold_um": round(1e3 * thresh, 4), "count": int(len(far)),
                "data_rows": [int(i) + 1 for i in far[:100]]}
    variables = {**{a: dat.positions[a] for a in model.axes}, **dat.covariates}
    analysis = {v: {"before_trend_um": _trend(res_before_all, x),
                    "after_trend_um": _trend(res_after_all, x)}
                for v, x in variables.items() if np.ptp(x) > 0}
    bar.update()

    paths = {}
    if out_dir is not None and selected:
        from volerr.fileio import write_text

        out = Path(out_dir)
        inputs = list(inputs) + ([str(data)] if isinstance(data, (str, Path)) else [])
        paths["augmented_layout"] = str(write_text(out / f"{aug_model.name}.toml",
                                                   aug_text, inputs=inputs))
        paths["generated_module"] = str(write_text(out / f"{aug_model.name.lower()}.py",
                                                   gen_text, inputs=inputs))
    bar.update()
    bar.close()
    nb, na = point_norm(r_before), point_norm(r_after)
    report = {
        "layout": model.name,
        "n_points": int(n),
        "rms_before_um": round(1e3 * rms(r_before), 4),
        "rms_after_um": round(1e3 * rms(r_after), 4),
        "max_before_um": round(1e3 * float(nb.max()), 4),
        "max_after_um": round(1e3 * float(na.max()), 4),
        "effects": effects,
        "unidentifiable": unident,
        "weakly_determined": state["weak"],
        "n_train": int(len(train)),
        "n_test": int(len(test)),
        "degree": int(degree),
        "degree_cv_rms_um": {str(k): round(1e3 * v, 4) for k, v in degree_scores.items()},
        "gauge_fixed": _gauge_text(gauge),
        "noise_estimate_um": round(1e3 * math.sqrt(sigma2), 4),
        "outliers": outliers,
        "candidates_tested": len(candidates),
        "candidate_families": sorted({c.kind for c in candidates}),
        "residual_analysis": analysis,
        "augmented_layout": paths.get("augmented_layout"),
        "generated_module": paths.get("generated_module"),
        "augmented_parameters": [p for p in aug_model.parameters if p not in model.parameters],
        "augmented_covariates": list(aug_model.covariates),
        "derived_vs_numeric_max_rel_diff": derived_check,
        "seconds": round(time.perf_counter() - t_start, 2),
        "method": ("held-out: random {:.0%} of the points, never used for selection or "
                   "fitting; before = declared model, after = augmented model, both fitted "
                   "on the other points").format(test_fraction),
    }
    figs = {"model": model, "data": dat, "res_before": res_before_all, "ranges": ranges,
            "degree": degree, "cov_diag": cov_diag,
            "res_after": res_after_all, "test": test, "r_before": r_before, "r_after": r_after,
            "selected": selected, "after_prob": after_prob, "c_all": c_all,
            "aug_labels": aug_labels, "c_before": c_before,
            "before_labels": [lab for lab, k in zip(design.labels, keep) if k]}
    return Report(report, figs, aug_text, gen_text)


def _trend(res_rows, x) -> float:
    """RMS (um) of a cubic trend of the residual components against variable ``x``."""
    r = res_rows.reshape(-1, 3)
    x = np.asarray(x, dtype=float)
    u = (2 * x - x.min() - x.max()) / max(np.ptp(x), 1e-300)
    V = np.polynomial.legendre.legvander(u, 3)
    coef, *_ = np.linalg.lstsq(V, r, rcond=None)
    return round(1e3 * float(np.sqrt(np.mean(np.sum((V @ coef) ** 2, axis=1)))), 4)


def _gauge_text(gauge) -> list:
    """Group the gauge-fixed columns: 'EXX: constant', 'EYX: slope' ..."""
    words = {0: "constant", 1: "slope"}
    out = {}
    for p, k in gauge:
        if p == "setup":
            out.setdefault(f"setup.{k}", "fixed")
        else:
            out.setdefault(p, []).append(words.get(k, f"degree {k}") if k is not None else "value")
    return [f"{p}: {', '.join(v) if isinstance(v, list) else v}" for p, v in out.items()]


def _explain(groups, data: Data, model: Model | None = None) -> None:
    """Attach a plain-language reason to each unidentifiable group."""
    n_probes = len(np.unique(np.round(data.probe, 6), axis=0))
    still = {a for a, v in data.positions.items() if np.ptp(v) == 0}
    for g in groups:
        angular = [p for p in g["parameters"][:1] if p[:1] == "E" and len(p) == 3
                   and p[1] in "ABC"]
        axis = model.parameter_axis.get(g["parameters"][0]) if model is not None else None
        if axis in still:
            g["reason"] = (f"axis {axis} does not move in these data (all points at {axis} = "
                           f"{float(data.positions[axis][0]):g}): {g['parameters'][0]} cannot be "
                           f"determined as a function of {axis}; measure along {axis}")
        elif g.get("no_sensitivity"):
            g["reason"] = (f"{g['parameters'][0]} does not act on these data at all (zero "
                           f"sensitivity: e.g. an angular error with no lever arm); measure "
                           f"with probe/tool offsets that give it one")
        elif angular and n_probes <= 2:
            g["reason"] = (f"angular errors {' '.join(angular)} act only through probe/tool "
                           f"offsets (Abbe arms); with {n_probes} distinct offset(s) they "
                           "cannot be separated from the translational errors: measure with "
                           "several probe offsets")
        else:
            g["reason"] = ("these parameters enter the data only in this combination: the "
                           "plan does not vary the positions/offsets that would separate them")


# ---- augmented layout text ----------------------------------------------------------
def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float, np.floating, np.integer)):
        return repr(float(v)) if isinstance(v, (float, np.floating)) else str(int(v))
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return json.dumps(str(v))


def augmented_layout_text(model: Model, selected) -> str:
    """The layout text with one ``[effects.NAME]`` table per selected effect (name + _aug)."""
    text, _ = layout_text(model.layout.path if model.layout.path and
                          Path(model.layout.path).is_file() else model.name)
    new_name = f"{model.name}_aug"
    text, k = re.subn(r'(?m)^name\s*=\s*"[^"]*"', f'name = "{new_name}"', text, count=1)
    require(k == 1, f"layout {model.name}: no top-level name line to rename")
    parts = [text.rstrip("\n"), ""]
    for s in selected:
        c = s["cand"]
        parts.append(f"[effects.{c.name}]")
        parts.append(f"kind = {_toml_value(c.kind)}")
        for key, v in c.info.items():
            parts.append(f"{key} = {_toml_value(v)}")
        parts.append("terms = [")
        for pn, target, basis in c.terms:
            parts.append(f"  {{parameter = {_toml_value(pn)}, target = {_toml_value(target)}, "
                         f"basis = {_toml_value(basis)}}},")
        parts.append("]")
        parts.append("")
    return "\n".join(parts)


# ---- demo --------------------------------------------------------------------------
def demo_campaign(out=None, seed: int = 0, n_points: int = 900, kind: str = "thermal"):
    """A simulated MB1 campaign with one undeclared effect and five probe offsets.

    ``out``: CSV path to write (a temporary file when None; an int is taken as ``seed``).
    ``kind``: ``"thermal"`` (the scale of X grows 11.5 um/m/K with T_C - 20) or ``"periodic"``
    (a 2 um cyclic error of EXX, period 40 mm).  Sized so that the loop on it takes a few
    seconds.  Returns ``("MB1", csv_path)``."""
    import tempfile

    from volerr.loop.simulate import demo_probes, simulate

    if isinstance(out, int) and not isinstance(out, bool):
        seed, out = out, None
    require(kind in ("thermal", "periodic"), f"demo effect must be thermal or periodic")
    model = load("MB1")
    effect = {"thermal": {"kind": "thermal", "axis": "X", "ppm_per_K": 11.5},
              "periodic": {"kind": "periodic", "component": "EXX", "period_mm": 40.0,
                           "um": 2.0}}[kind]
    camp = simulate("MB1", n_points=n_points, seed=seed, probes=demo_probes(model),
                    effects=[effect], noise_um=0.3)
    if out is None:
        out = Path(tempfile.mkdtemp(prefix="volerr_demo_")) / "MB1_campaign.csv"
    return "MB1", str(camp.write_csv(out))
