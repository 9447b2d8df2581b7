"""Close the loop: fit measured deviations, trace the residual to a missing effect, augment the
layout, report the error before and after on held-out points.

Steps (:func:`run_loop`):

1. read the measured-deviation CSV (INTERFACE.md) and check it against the layout; refuse a
   file whose points all stand at one position and readings that determine none of the
   declared model's parameters (:mod:`volerr.loop.checks`);
2. hold out a random ``test_fraction`` of the points; everything below is decided on the
   others (the training points) and judged on the held-out ones;
3. fit the declared model (:mod:`volerr.estimate.design`): component errors as Legendre series, degree by
   cross-validation, squareness, location errors, the instrument's rigid placement;
   gauge fixed by convention, plan-specific unidentifiable combinations reported;
4. robust weights of the points (IRLS on the declared fit): gross outliers are down-weighted
   and flagged, not explained;
5. candidate effects "parameter P varies with covariate C" generated from the chain
   (:mod:`volerr.loop.candidates`), screened and selected (:mod:`volerr.loop.select`), forward
   stepwise: the candidate with the best BIC gain is accepted when the gain is strong (dBIC < -10) *and* its cross-validated
   residual is significantly smaller (paired t > 3 on the per-point squared errors);
   stop when no candidate passes; then a backward check drops any effect that, given all
   the others, no longer gains dBIC < -10 (a later effect made it redundant);
6. write the augmented layout (the original with ``[effects.*]`` tables), derive its fitting
   functions (sensitivities; the full module only when written or asked for) and fit it with
   their columns: it gives the "after" figures;

All fits run on columns generated per block of points (:mod:`volerr.estimate.blocks`): normal
equations, cross-products and residuals are accumulated blockwise, never the (3N, p) design.
7. report: :class:`Report` (with the ranked residual sources before and after) (``write_json``, ``write_html``).

Units: deviations in mm inside, um in reports; angular parameters urad; thermal um/m/K.
"""

from __future__ import annotations

import json
import math
import re
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..estimate import blocks
from . import candidates as cands
from . import checks
from . import select as sel
from ..errors import require
from ..estimate.design import (Data, solve_normal, data_ranges, declared_design, point_norm,
                               rms, rows_of)
from ..estimate.steps import (DEGREE_CV_POINTS, Declared, Split, choose_degree,  # noqa: F401
                              declared_step, split_points)
from ..fileio import json_text
from ..instruments.deviations import columns_to_data, read_deviations  # noqa: F401
from ..machine.layout import layout_text, parse_layout
from ..machine import derivation
from ..machine.model import Model, load
from ..results import ResultMixin

from .select import BIC_GAIN, CV_T, MAX_EFFECTS  # noqa: F401  (former names)
from .symbols import describe

ROBUST_K = 4.0       # robust sigmas of the 3-D residual length kept at full weight
OUTLIER_Z = 5.0      # robust sigmas beyond which a point is flagged as an outlier


# ---- report ---------------------------------------------------------------------
@dataclass(repr=False)
class Report(ResultMixin):
    """Result of :func:`run_loop`; ``data`` is the json report (INTERFACE.md keys first)."""

    data: dict
    plot_data: "Figures | None" = None     # what the html report, figures() and error tables need
    augmented_text: str = ""
    generated: object = ""      # module text, or a function deriving it when first asked
    quality: object = None      # the residual rule (volerr.fit_quality.FitQuality)

    @property
    def generated_text(self) -> str:
        """The augmented layout's generated module (derived on first access)."""
        if callable(self.generated):
            self.generated = self.generated()
        return self.generated

    def __getitem__(self, key):
        return self.data[key]

    @property
    def effects(self) -> list:
        return self.data["effects"]

    def write_json(self, path, inputs=()) -> Path:
        from ..fileio import write_text

        return write_text(path, json_text(self.data, default=_json),
                          inputs=list(inputs))

    def figures(self) -> dict:
        """``{"residuals", "maps", "functions", "interactions", "effect:NAME" ...}``: the
        report page's figures as :class:`matplotlib.figure.Figure` (residuals in um against
        every axis and covariate, before and after; the error maps; the fitted component
        errors with +-2 standard deviations; each effect's evidence); none without the data
        behind them (``plot_data``)."""
        from . import report as rp

        fg = self.plot_data
        if fg is None:
            return {}
        out = {"residuals": rp.figure_residuals(fg), "maps": rp.figure_maps(fg),
               "functions": rp.figure_functions(self),
               "interactions": rp.figure_interactions(fg, self.data["residual_sources"])}
        out.update({f"effect:{e['name']}": rp.figure_effect(fg, e) for e in self.effects})
        return {k: f for k, f in out.items() if f is not None}

    def write_html(self, path, inputs=()) -> Path:
        from ..fileio import write_text
        from .report import render_html

        return write_text(path, render_html(self), inputs=list(inputs))

    def error_tables(self, n_grid: int = 41, which: str = "after") -> tuple[dict, dict]:
        """The fitted error functions of the declared model (effects removed: the machine at
        the reference state, T = 20 degC, t = 0 ...) as error tables over the measured range.

        Returns ``({axis: volerr.tables.table.ErrorTable}, constants {name: value})`` in mm / rad,
        with ``std`` columns (standard deviation of the fit).  Translational errors are zero at
        the start of the measured range (their constants belong to the instrument placement);
        straightness slopes are carried by squareness (gauge: see :mod:`volerr.estimate.design`).
        ``which="before"``: the declared model's own fit (effects unmodelled, no std)."""
        from ..estimate.design import series_basis
        from ..tables.table import ErrorTable

        fg = self.plot_data
        model, ranges, deg = fg.model, fg.ranges, fg.degree
        coef, labels, var = fg.c_all, fg.aug_labels, fg.cov_diag
        if which == "before":
            coef, labels = fg.c_before, fg.before_labels
            var = np.zeros(len(coef))
        index = {lab: j for j, lab in enumerate(labels)}
        tables, constants = {}, {}
        for a in model.axes:
            q = np.linspace(*ranges[a], n_grid)
            P = series_basis(model, a, q, ranges, deg)
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

    def write_error_tables(self, directory, inputs=(), accept_residual: bool = False,
                           accept_implausible: bool = False, shown=None) -> Path:
        """Write :meth:`error_tables` as an error directory (``X.csv`` ... ``constants.csv``);
        refused for a fit far above the readings' uncertainty unless ``accept_residual``
        (:mod:`volerr.fit_quality`), and for values beyond what a machine of the layout's
        travel can have unless ``accept_implausible`` (:mod:`volerr.tables.plausible`; a
        refusal names ``shown``, default ``directory``)."""
        from ..fit_quality import forced_note, require_writable
        from ..tables.table import write_error_dir

        require_writable(self.quality, accept_residual, f"error tables {directory}")
        tables, constants = self.error_tables()
        note = self.data.get("forced") or (forced_note(self.quality.marked()) if
                                           accept_residual and self.quality else None)
        comments = {w: [note] for w in ["constants", *tables]} if note else None
        return write_error_dir(directory, tables, constants or None, inputs=list(inputs),
                               comments=comments, machine=self.plot_data.model,
                               accept_implausible=accept_implausible, shown=shown)

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


# ---- steps of the loop ----------------------------------------------------------------
@dataclass
class Robust:
    """Robust point weights (N,), 0..1, the robust noise scale (mm per coordinate) and the
    points flagged as outliers."""

    weights: np.ndarray
    sigma: float
    outliers: np.ndarray

    def rows(self) -> np.ndarray:
        return np.repeat(np.sqrt(self.weights), 3)


#: median of the length of a d-dimensional standard normal vector (chi(d)), d = 1, 2, 3
CHI_MEDIAN = np.array([np.nan, 0.6745, 1.1774, 1.5382])


def robust_weights(design, y, points, n: int, iterations: int = 8) -> Robust:
    """IRLS on the residual length of each point (its readings: 3 for a 3-D deviation, 1 for a
    ballbar length), standardised by the instrument's uncertainty: weight 1 up to
    ``ROBUST_K`` robust standard deviations, then a bisquare down to 0 at twice that; the
    scale from the median of the lengths, each divided by the median of a chi variable of its
    dimension (1.538 sigma for three readings), so gross outliers neither inflate the noise
    estimate nor hide smaller ones.  The weights returned are the instruments' relative weights
    (1 / u^2) times the robust ones.

    ``design``: :class:`volerr.estimate.blocks.Design`; ``points``: the points fitted (their rows
    of ``y``).  The normal equations of all points at their instrument weight are accumulated
    once; each iteration subtracts those of the down-weighted points (few) and predicts
    blockwise, from the blocks of that first pass where they fit in
    :data:`volerr.estimate.blocks.KEEP_BYTES` (else generated again)."""
    data = design.data
    base = data.point_weights()[points]
    dims = data.readings_per_point()[points]
    w = np.ones(len(points))
    rows = rows_of(points)
    kept = blocks.Kept.of(design, points)        # the blocks, for every pass
    G1, b1, colsq = blocks.normal(design, points, np.sqrt(base), y, kept)
    scale = blocks.unit_scale(colsq, len(rows))
    sigma = 0.0
    for _ in range(iterations):
        low = np.flatnonzero(w < 1.0)
        if len(low) > len(points) // 2:
            G, b, _ = blocks.normal(design, points, np.sqrt(base * w), y)
        else:       # G1 minus the down-weighted points' share (1 - w) A_i^T A_i
            G, b = G1.copy(), b1.copy()
            for At, idx, d in _low_blocks(design, kept, points, low, base * (1.0 - w)):
                At *= d
                G -= At @ At.T
                b -= At @ (blocks.yrows(y, idx) * d)
        c = solve_normal(G / np.outer(scale, scale), b / scale) / scale
        r = point_norm(y[rows] - blocks.predict(design, points, c, kept)) * np.sqrt(base)
        sigma = max(float(np.median((r / CHI_MEDIAN[dims])[w > 0])), 1e-12)
        z = r / sigma
        w_new = np.where(z <= ROBUST_K, 1.0,
                         np.clip(1 - ((z - ROBUST_K) / ROBUST_K) ** 2, 0, 1) ** 2)
        if np.allclose(w_new, w):
            break
        w = w_new
    weights = np.ones(n)
    weights[points] = w * base
    flagged = points[z > OUTLIER_Z]
    return Robust(weights, sigma, flagged)


def _low_blocks(design, kept, points, low, v):
    """(columns (p, 3m), points (m,), row weights sqrt(v) (3m,)) of the points ``low`` (positions
    in ``points``), block by block: taken from the blocks ``kept`` at ``points`` where given
    (the columns of a point are the same in any block), else generated."""
    if kept is None:
        for _, part in blocks.blocks(low):
            yield design.block(points[part]), points[part], blocks.wrows(np.sqrt(v[part]))
        return
    for k, (s, idx) in enumerate(blocks.blocks(points)):
        m = low[(low >= s.start) & (low < s.start + len(idx))] - s.start
        if len(m):
            cols = np.concatenate([m, m + len(idx), m + 2 * len(idx)])   # component-major
            yield kept[k][:, cols], idx[m], blocks.wrows(np.sqrt(v[s][m]))


def selection_step(model, dat, decl: Declared, spl: Split, ranges, degree, families,
                   robust: Robust, y, lag_caches=None) -> tuple[sel.Selection, list]:
    """``lag_caches``: the lagged series of an earlier selection on the same data (a dict
    filled here), reused."""
    covs, warns = cands.covariates(dat.covariates, model)
    candidates = [c for c in cands.build(model, dat, ranges, degree, covs, decl.gauge)
                  if c.kind in families]
    w_rows = robust.rows()
    shared = lag_caches if lag_caches is not None else {}
    ctx = sel.Context(model, dat, None, None, spl.train,    # sensitivities per block
                      np.sqrt(robust.weights[spl.train]), ranges,
                      {k: shared.setdefault(k, {}) for k in sel.SHARED_LAG_CACHES})
    return sel.select(candidates, ctx, decl.design, y, spl.folds, w_rows,
                      sel.SCREEN_POINTS), warns


@dataclass
class Augmented:
    """The augmented layout (text), model (from a reduced module: the fitting functions) and
    design; :meth:`source` derives its full generated module (text)."""

    text: str
    layout: object
    model: Model
    design: blocks.Design
    labels: list
    _source: str | None = None

    def source(self) -> str:
        if self._source is None:
            self._source = "" if self.layout is None else derivation.derive_source(self.layout)
        return self._source


def augment_step(model, dat, decl: Declared, selection, degree, ranges,
                 source=None) -> Augmented:
    """``source``: the layout as the user named it (a file path or a shipped name)."""
    if not selection.accepted:
        return Augmented("", None, model, decl.design, decl.labels)
    text = augmented_layout_text(model, selection.accepted, source)
    lay = parse_layout(text, f"{model.name}_aug.toml")
    aug = Model(lay, derivation.module_from_source(derivation.fit_source(lay), lay.name))
    labels = declared_design(aug, dat.subset(np.arange(1)), degree, ranges).labels
    n_new = len(aug.parameters) - len(model.parameters)
    keep = np.concatenate([decl.keep, np.ones(n_new, bool)])
    return Augmented(text, lay, aug, blocks.Design(aug, dat, degree, ranges, keep),
                     [lab for lab, m in zip(labels, keep) if m])


@dataclass
class Outcome:
    """Held-out residual rows before (declared) and after (augmented), fits on all points;
    ``contrib``: effect name -> its contribution rows (3N,) at all points (fit on all)."""

    r_before: np.ndarray
    r_after: np.ndarray
    contrib: dict
    c_all: np.ndarray
    c_before: np.ndarray
    res_before: np.ndarray
    res_after: np.ndarray
    sigma2: float
    cov_diag: np.ndarray
    test_inliers: np.ndarray
    chi2_dof: tuple = (0.0, 1.0)    # the augmented fit's sum (r / u_ref)^2 w and its dof (mm^2)


def _fits(design, spl: Split, sw, y):
    """Weighted fits on the training points and on all points (one pass over the rows):
    (column scale, coefficients train, coefficients all, scaled Gram of all points).  The
    columns are scaled to unit RMS over all rows, unweighted (as :class:`Problem`)."""
    p = design.p
    G = np.zeros((2, p, p))
    b = np.zeros((2, p))
    ss = np.zeros(p)
    for k, pts in enumerate((spl.train, spl.test)):
        for _, idx in blocks.blocks(pts):
            At = design.block(idx)
            ss += np.einsum("ij,ij->i", At, At)
            w = blocks.wrows(sw[idx])
            At *= w
            G[k] += At @ At.T
            b[k] += At @ (blocks.yrows(y, idx) * w)
    scale = blocks.unit_scale(ss, len(y))
    S = np.outer(scale, scale)
    c_tr = solve_normal(G[0] / S, b[0] / scale) / scale
    G_all = (G[0] + G[1]) / S
    c_all = solve_normal(G_all, (b[0] + b[1]) / scale) / scale
    return c_tr, c_all, G_all, scale


def _residuals(design, n, test, y, c_tr, c_all, groups=None):
    """Blockwise: residual rows at all points (fit ``c_all``), held-out residual rows at
    ``test`` (fit ``c_tr``), and the contribution rows of each column group."""
    groups = groups or {}
    res = np.empty(3 * n)
    r_test = np.empty(3 * n)
    contrib = {g: np.empty(3 * n) for g in groups}
    for _, idx in blocks.blocks(np.arange(n)):
        At = design.block(idx)
        rr = rows_of(idx)
        pm = len(idx)
        res[rr] = y[rr] - blocks.to_point_major(c_all @ At, pm)
        r_test[rr] = y[rr] - blocks.to_point_major(c_tr @ At, pm)
        for g, js in groups.items():
            contrib[g][rr] = blocks.to_point_major(c_all[js] @ At[js], pm)
    return res, r_test[rows_of(test)], contrib


def outcome_step(decl: Declared, aug: Augmented, spl: Split, robust: Robust, y,
                 groups=None) -> Outcome:
    """Fits of the declared and the augmented model (weighted; on the training points and on
    all points), blockwise.  ``groups``: effect name -> column indices of the augmented design
    whose contribution is wanted."""
    w_rows = robust.rows()
    sw = np.sqrt(robust.weights)
    n = len(robust.weights)
    cb_tr, c_before, _, _ = _fits(decl.design, spl, sw, y)
    res_before, r_before, _ = _residuals(decl.design, n, spl.test, y, cb_tr, c_before)
    ca_tr, c_all, G, scale = _fits(aug.design, spl, sw, y)
    res_after, r_after, contrib = _residuals(aug.design, n, spl.test, y, ca_tr, c_all, groups)
    wG = np.linalg.eigvalsh(G)
    n_readings = float(np.sum(robust.weights * decl.design.data.readings_per_point()))
    dof = max(n_readings - int(np.sum(wG > 1e-12 * wG[-1])), 1.0)
    sigma2 = float(np.sum((res_after * w_rows) ** 2)) / dof
    cov_diag = np.diag(np.linalg.pinv(G, rcond=1e-12)) * sigma2 / scale ** 2
    inl = point_norm(r_after) <= OUTLIER_Z * math.sqrt(sigma2)
    return Outcome(r_before, r_after, contrib, c_all, c_before, res_before, res_after, sigma2,
                   cov_diag, inl, (sigma2 * dof, dof))


def effect_columns(selection, aug: Augmented) -> dict:
    """Effect name -> column indices of its parameters in the augmented design."""
    col = {lab[0]: j for j, lab in enumerate(aug.labels)}
    return {s.cand.name: [col[pn] for pn in s.params] for s in selection.accepted}


def effects_step(selection, aug: Augmented, out: Outcome, n: int) -> list:
    """The json entries of the accepted effects (values in report units, evidence)."""
    col = {lab[0]: j for j, lab in enumerate(aug.labels)}
    effects = []
    for s in selection.accepted:
        c = s.cand
        pars, units, std = {}, {}, {}
        contrib = out.contrib[c.name]
        for pn in s.params:
            f, u = c.units.get(pn, (1e3, "um"))
            j = col[pn]
            pars[pn] = round(float(out.c_all[j]) * f, 6)
            std[pn] = round(float(math.sqrt(max(out.cov_diag[j], 0.0))) * f, 6)
            units[pn] = u
        info = {k: (round(v, 6) if isinstance(v, float) else v) for k, v in c.info.items()}
        if c.kind == "thermal" and len(c.terms) == 2 and c.terms[0][2].startswith(
                info.get("axis", "?") + "*"):
            k1, k0 = (float(out.c_all[col[t[0]]]) for t in c.terms)
            sd1 = math.sqrt(max(out.cov_diag[col[c.terms[0][0]]], 0.0))
            if k1 != 0.0 and abs(k1) > 3.0 * sd1:   # only for a significant scale term
                info["fixed_point_mm"] = round(-k0 / k1, 3)
        if c.kind == "periodic":
            a_s, a_c = (pars[t[0]] for t in c.terms)
            info["amplitude_um"] = round(math.hypot(a_s, a_c), 4)
            info["phase_rad"] = round(math.atan2(a_c, a_s), 4)   # a sin(2 pi q / P + phase)
        ev = {k: v for k, v in s.evidence.items() if k != "alternatives"}
        ev["contribution_rms_um"] = round(1e3 * rms(contrib), 4)
        ev["contribution_max_um"] = round(1e3 * float(np.max(point_norm(contrib))), 4)
        effects.append({"kind": c.kind, "name": c.name, "parameters": pars, "units": units,
                        "std": std, "description": describe(aug.model, info, pars, units),
                        "parameter": info.get("parameter"),
                        "covariate": info.get("covariate"), "basis": info.get("basis"),
                        "target": sorted({t[1] for t in c.terms}), "info": info,
                        "terms": [{"parameter": t[0], "target": t[1], "basis": t[2]}
                                  for t in c.terms], "evidence": ev,
                        **_lag_entry(info), "alternatives": [], "separate_by": None})
    return effects


def effect_budgets(effects: list, sigma2: float) -> dict:
    """The GUM budget (:mod:`volerr.report.budget`) of every effect parameter's std: the
    a-posteriori scatter of the weighted residuals, sigma = sqrt(sigma2) (um; the fit's
    ``noise_estimate_um``), times the parameter's sensitivity to it, sqrt((A^T W A)^-1_jj)
    in its unit per um (taken as the stated std / sigma, so that the rounded std the report
    states is the combined u); keyed ``effect:parameter`` as the result rows."""
    from ..report.budget import budget, source

    sigma = 1e3 * math.sqrt(max(sigma2, 0.0))
    out = {}
    for e in effects:
        for pn, std in e["std"].items():
            name, unit = f"{e['name']}:{pn}", e["units"][pn]
            out[name] = budget(name, unit, [source(
                "scatter of the residuals after the fit (a posteriori, sigma)", sigma, "um",
                std / sigma if sigma > 0 else 0.0)], 2.0)
    return out


def _lag_entry(info: dict) -> dict:
    """``lag_s`` of an effect through a lag (:mod:`volerr.loop.lags`), else nothing."""
    if info.get("lag_s") is None:
        return {}
    return {"lag_s": {"value": info["lag_s"], "std": info.get("lag_std_s")}}


def alternatives_step(effects: list, selection, decl: Declared, spl: Split, robust: Robust,
                      y) -> None:
    """Each effect's ``alternatives`` (explanations the campaign cannot tell from it,
    :func:`volerr.loop.lags.alternatives`: covariate, lag, basis, held-out RMS of the model
    with it in the effect's place) and ``separate_by`` (what campaign would separate them)."""
    from .lags import separate_by

    sw = np.sqrt(robust.weights)
    for e, s in zip(effects, selection.accepted):
        alts = s.evidence.get("alternatives") or []
        for x in alts:
            cols = [x["cols"] if o is s else o.cols for o in selection.accepted]
            design = decl.design.plus(cols)
            c_tr, c_all, _, _ = _fits(design, spl, sw, y)
            _, r_test, _ = _residuals(design, len(sw), spl.test, y, c_tr, c_all)
            info = x["cand"].info
            e["alternatives"].append({
                "covariate": info.get("covariate"), "lag_s": info.get("lag_s"),
                "basis": info.get("basis"), "parameter": info.get("parameter"),
                "name": x["cand"].name, "held_out_rms_um": round(1e3 * rms(r_test), 4),
                "delta_bic": x["delta_bic"], "cv_paired_t": x["cv_paired_t"]})
        if alts:
            e["separate_by"] = separate_by(s.cand.info, alts[0]["cand"].info)


def _replicate_sigma(dat: Data, res_rows, weights) -> tuple[float, int] | None:
    """Pure-error standard deviation (mm per reading) from replicated points (same positions,
    probe offset and instrument projection), and its degrees of freedom; None without
    replicates."""
    parts = [dat.positions[a] for a in dat.positions] + [dat.probe]
    if dat.proj is not None:
        parts.append(dat.proj.reshape(dat.n, 9))
    key = np.column_stack(parts)
    _, inv, counts = np.unique(np.round(key, 6), axis=0, return_inverse=True,
                               return_counts=True)
    inv = inv.ravel()
    rows = dat.readings_per_point()
    rep = (counts[inv] > 1) & (weights > 0.5 * dat.point_weights())
    if rep.sum() < 10:
        return None
    r = res_rows.reshape(-1, 3)[rep]
    g = inv[rep]
    means = np.zeros((inv.max() + 1, 3))
    np.add.at(means, g, r)
    cnt = np.bincount(g, minlength=inv.max() + 1)[:, None]
    means = means / np.maximum(cnt, 1)
    ss = float(np.sum((r - means[g]) ** 2))
    groups, first = np.unique(g, return_index=True)
    dof = int(rows[rep].sum() - rows[rep][first].sum())
    return (math.sqrt(ss / dof), dof) if dof > 0 else None


def residual_note(dat, out: Outcome, sources_after, robust: Robust) -> str | None:
    """One sentence when the augmented residual is still clearly above the noise: replicate
    points (F test of lack of fit) where the plan has them, else the screening's BIC."""
    if not sources_after:
        return None
    top = sources_after[0]
    what = (f"the top remaining source is {top['parameter']} varying with {top['covariate']} "
            f"({top['basis']}, {top['explained_um']:.3g} um)")
    rep = _replicate_sigma(dat, out.res_after, robust.weights)
    if rep is not None:
        s_pe, dof = rep
        ratio = out.sigma2 / max(s_pe ** 2, 1e-300)
        if ratio > 1.0 + 4.0 * math.sqrt(2.0 / dof) and ratio > 1.2:
            return (f"The augmented residual is still above the noise of the replicated points "
                    f"({1e3 * math.sqrt(out.sigma2):.3g} vs {1e3 * s_pe:.3g} um): {what}.")
        return None
    if top["delta_bic"] < -2 * sel.BIC_GAIN:
        return (f"The augmented residual still holds structure (lack of fit, dBIC "
                f"{top['delta_bic']:.0f}, not confirmed on held-out points): {what}.")
    return None


@dataclass
class Figures:
    """What the HTML report and the error tables need (fits on all points)."""

    model: Model
    data: Data
    ranges: dict
    degree: int
    res_before: np.ndarray
    res_after: np.ndarray
    test: np.ndarray
    r_before: np.ndarray
    r_after: np.ndarray
    selected: list
    contrib: dict               # effect name -> contribution rows (3N,), mm
    c_all: np.ndarray
    aug_labels: list
    c_before: np.ndarray
    before_labels: list
    cov_diag: np.ndarray
    weights: np.ndarray


def _load(layout, data) -> tuple[Model, Data]:
    from .. import instruments

    model = load(layout)
    if isinstance(data, Data):
        return model, data
    if hasattr(data, "columns") and callable(data.columns):
        return model, columns_to_data(data.columns(), model, "campaign")
    if isinstance(data, (list, tuple)):          # files of any instruments, one campaign
        return model, instruments.read_files(list(data), model)
    return model, instruments.read_files([data], model)


def _search(model, dat, spl, ranges, y, degree, max_degree, fixed_degree, families):
    """Declared fit, robust weights, selection; the degree chosen again with the effects."""
    checks.determined(model, dat, ranges)
    degree_scores = {}
    if not fixed_degree:
        # robust weights of a preliminary fit first: outliers must not choose the degree
        pre = declared_step(model, dat, min(max_degree, 6), ranges, spl.train)
        w0 = robust_weights(pre.design, y, np.arange(dat.n), dat.n).weights
        degree, degree_scores = choose_degree(model, dat, spl.train, spl.folds, ranges,
                                               max_degree, weights=w0)
    decl = declared_step(model, dat, degree, ranges, spl.train)
    robust = robust_weights(decl.design, y, np.arange(dat.n), dat.n)
    lag_caches: dict = {}
    selection, warns = selection_step(model, dat, decl, spl, ranges, degree, families,
                                      robust, y, lag_caches)
    keepers = [s for s in selection.accepted if s.cand.kind != "higher_order"]
    if keepers and not fixed_degree:
        # the degree was chosen with the effects unmodelled: choose it again with them
        extra = np.concatenate([s.cols.reshape(-1, s.cols.shape[-1]) for s in keepers], axis=1)
        degree2, scores2 = choose_degree(model, dat, spl.train, spl.folds, ranges,
                                          max_degree, extra, robust.weights)
        if degree2 != degree:
            degree, degree_scores = degree2, scores2
            decl = declared_step(model, dat, degree, ranges, spl.train)
            robust = robust_weights(decl.design, y, np.arange(dat.n), dat.n)
            selection, warns = selection_step(model, dat, decl, spl, ranges, degree,
                                              families, robust, y, lag_caches)
    return degree, degree_scores, decl, robust, selection, warns


def run_loop(layout, data, *, seed: int = 0, folds: int | None = None,
             test_fraction: float = 0.25,
             degree: int | None = None, max_degree: int = 10, out_dir=None,
             progress=None, families=cands.FAMILIES, inputs=(),
             holdout_time: str | None = None, accept_residual: bool = False,
             where: str = "loop") -> Report:
    """Run the loop on ``data`` (CSV path, :class:`volerr.loop.simulate.Campaign` or
    :class:`volerr.estimate.design.Data`) for ``layout`` (name or layout file). Returns a :class:`Report`.

    ``out_dir``: where the augmented layout and its generated module are written (nothing is
    written when None; the texts are in the report object either way).  ``holdout_time``
    ``"A:B"`` (units s, min, h): hold out the points with A <= t < B of the time column
    (:func:`volerr.loop.drift.split.parse_window`) instead of the default stretches.
    A fit far above the readings' declared uncertainty is refused (InputError naming
    ``where``, nothing written) unless ``accept_residual`` (then marked forced;
    :mod:`volerr.fit_quality`)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        return _run(layout, data, seed, folds, test_fraction, degree, max_degree, out_dir,
                    progress, families, inputs, holdout_time, (accept_residual, where))


def _split(dat, seed, test_fraction, folds, holdout_time=None) -> Split:
    """The held-out points: ``holdout_time`` ``"A:B"`` (the points with A <= t < B), else
    with a time column whole stretches of time
    (:func:`volerr.loop.drift.split.stretch_split`), else drawn at random (``seed``)."""
    from ..machine.lags import TIME_COLUMNS
    from .drift.split import not_from_end, parse_window, stretch_split

    spl = split_points(dat.n, seed, test_fraction, folds)
    time = next((c for c in TIME_COLUMNS if c in dat.covariates), None)
    require(holdout_time is None or time is not None, "--holdout-time needs a time column "
            "(t_s, t_min, t_h) in the data")
    if time is None:
        return spl
    if holdout_time is not None:
        a, b = parse_window(holdout_time)
        t = np.asarray(dat.covariates[time], float) * TIME_COLUMNS[time]
        not_from_end(t, holdout_time, a, b)
        test = (t >= a) & (t < b)
        require(test.any() and (~test).sum() >= 20, f"--holdout-time {holdout_time}: holds "
                f"out {int(test.sum())} of {dat.n} points (some, and all but 20 at most)")
    else:
        test = stretch_split(dat.covariates[time], dat.file, test_fraction)
    if not test.any() or test.all():
        return spl
    train = np.flatnonzero(~test)
    fold_t = None if folds is None else \
        np.random.default_rng(seed).permutation(len(train)) % folds
    return Split(train, np.flatnonzero(test), fold_t)


def _run(layout, data, seed, folds, test_fraction, degree, max_degree, out_dir, progress,
         families, inputs, holdout_time=None, gate=(False, "loop")) -> Report:
    t_start = time.perf_counter()
    model, dat = _load(layout, data)
    checks.one_position(dat)
    require(folds is None or 2 <= folds <= 20, "folds must be between 2 and 20")
    require(0.05 <= test_fraction <= 0.5, "test fraction must be between 0.05 and 0.5")
    if degree is not None:
        require(1 <= degree <= 12, "degree must be between 1 and 12")
    bar = _progress(4, progress)
    spl = _split(dat, seed, test_fraction, folds, holdout_time)
    ranges = data_ranges(model, dat)
    y = dat.deviation.ravel()
    bar.set_postfix_str("degree, screening and selection")
    degree, degree_scores, decl, robust, selection, warns = _search(
        model, dat, spl, ranges, y, degree, max_degree, degree is not None, families)
    _explain(decl.unidentifiable, dat, model)
    bar.update()
    bar.set_postfix_str("augment, derive, generate")
    aug = augment_step(model, dat, decl, selection, degree, ranges,
                       layout if isinstance(layout, (str, Path)) else None)
    bar.update()
    bar.set_postfix_str("held-out before/after")
    out = outcome_step(decl, aug, spl, robust, y, effect_columns(selection, aug))
    effects = effects_step(selection, aug, out, dat.n)
    alternatives_step(effects, selection, decl, spl, robust, y)
    from ..fit_quality import forced_note, require_fit

    quality = require_fit(fit_quality(dat, out), *gate)     # refused: nothing written
    bar.update()
    paths = _write_augmented(out_dir, aug, selection, inputs, data)
    bar.update()
    bar.close()
    n_tr = float(robust.weights[spl.train].sum())
    src_before = sel.sources(selection.first, n_tr, selection.accepted)
    src_after = sel.sources(selection.last, n_tr)
    report = _report_dict(model, dat, spl, degree, degree_scores, decl, robust, selection,
                          aug, out, effects, warns + list(dat.warnings), paths, test_fraction)
    report["residual_sources"] = src_before
    report["residual_sources_after"] = src_after
    report["residual_note"] = residual_note(dat, out, src_after, robust)
    report["instruments"] = instrument_residuals(dat, spl, out)
    report["fit"] = quality.to_dict()
    report["seconds"] = round(time.perf_counter() - t_start, 2)
    if forced_note(quality):
        report["forced"] = forced_note(quality)
    figs = Figures(model, dat, ranges, degree, out.res_before, out.res_after, spl.test,
                   out.r_before, out.r_after, selection.accepted, out.contrib, out.c_all,
                   aug.labels, out.c_before, decl.labels, out.cov_diag, robust.weights)
    return Report(report, figs, aug.text, aug.source, quality)  # module: derived when asked


def fit_quality(dat, out: Outcome):
    """The augmented fit's residual against the readings' declared uncertainty
    (:mod:`volerr.fit_quality`): ``chi2 = sum w (r / u)^2`` with the robust weights ``w`` of
    the fit (gross outliers down-weighted, counted in ``outliers``), its degrees of freedom
    the robustly weighted readings minus the augmented model's rank."""
    from ..fit_quality import judge

    u_ref = dat.reference_sigma()
    rss, dof = out.chi2_dof
    return judge(rss / u_ref ** 2, dof,
                 f"u of each reading as declared in its file, else its instrument's default "
                 f"(deviations: 1 um); median {1e3 * u_ref:.3g} um")


def instrument_residuals(dat, spl: Split, out: Outcome) -> list:
    """Held-out RMS before / after per file, in the file's own unit (um): the length of each
    held-out point's residual vector (its readings: three for a sphere, one for a ballbar), as
    the loop's RMS everywhere."""
    files = dat.files or ()
    if not files:
        return []
    file_of = dat.file if dat.file is not None else np.zeros(dat.n, int)
    row_of = dat.row if dat.row is not None else np.arange(dat.n)
    rows = dat.readings_per_point()
    ft = file_of[spl.test]
    out_list = []
    for f, fi in enumerate(files):
        m = ft == f
        n_read = int(rows[spl.test][m].sum())
        rb = out.r_before.reshape(-1, 3)[m]
        ra = out.r_after.reshape(-1, 3)[m]

        n_pts = int(m.sum())
        factor = 1e6 if fi.unit == "urad" else 1e3     # angular readings are rad inside

        def per_reading(r):
            return round(factor * math.sqrt(float(np.sum(r ** 2)) / n_pts), 4) if n_pts else None

        out_list.append({"file": fi.name, "kind": fi.kind, "unit": fi.unit,
                         "n": int(np.sum(file_of == f)),
                         "n_readings": int(rows[file_of == f].sum()), "n_heldout": n_read,
                         "rms_before_um": per_reading(rb), "rms_after_um": per_reading(ra),
                         "test_rows": sorted(int(r) for r in row_of[spl.test][m])})
    return out_list


def _write_augmented(out_dir, aug: Augmented, selection, inputs, data) -> dict:
    if out_dir is None or not selection.accepted:
        return {}
    from ..fileio import write_text

    out = Path(out_dir)
    inputs = list(inputs) + ([str(data)] if isinstance(data, (str, Path)) else
                             [str(d) for d in data] if isinstance(data, (list, tuple)) else [])
    return {"augmented_layout": str(write_text(out / f"{aug.model.name}.toml", aug.text,
                                               inputs=inputs)),
            "generated_module": str(write_text(out / f"{aug.model.name.lower()}.py",
                                               aug.source(), inputs=inputs))}


def _report_dict(model, dat, spl, degree, degree_scores, decl, robust, selection, aug, out,
                 effects, warnings, paths, test_fraction) -> dict:
    nb, na = point_norm(out.r_before), point_norm(out.r_after)
    # outliers: off the FINAL fit by more than OUTLIER_Z of its own robust scale (median of
    # the 3-D residual length = 1.538 sigma per coordinate), not the declared fit's flags
    res_len = point_norm(out.res_after)
    scale = max(float(np.median(res_len)) / 1.538, 1e-12)
    thresh = OUTLIER_Z * scale
    far = np.flatnonzero(res_len > thresh)
    inl = na <= thresh
    variables = {**{a: dat.positions[a] for a in model.axes}, **dat.covariates}
    analysis = {v: {"before_trend_um": _trend(out.res_before, x),
                    "after_trend_um": _trend(out.res_after, x)}
                for v, x in variables.items() if np.ptp(x) > 0 and np.all(np.isfinite(x))}
    rows_in = rows_of(np.flatnonzero(inl))
    return {
        "layout": model.name,
        "n_points": int(dat.n),
        "rms_before_um": round(1e3 * rms(out.r_before), 4),
        "rms_after_um": round(1e3 * rms(out.r_after), 4),
        "max_before_um": round(1e3 * float(nb.max()), 4),
        "max_after_um": round(1e3 * float(na.max()), 4),
        "effects": effects,
        "budgets": effect_budgets(effects, out.sigma2),
        "unidentifiable": decl.unidentifiable,
        "residual_sources": [],
        "residual_sources_after": [],
        "warnings": warnings,
        "inliers": {"n_test": int(inl.sum()),
                    "rms_before_um": round(1e3 * rms(out.r_before[rows_in]), 4),
                    "rms_after_um": round(1e3 * rms(out.r_after[rows_in]), 4)},
        "weakly_determined": decl.weak,
        "n_train": int(len(spl.train)),
        "n_test": int(len(spl.test)),
        "degree": int(degree),
        "degree_cv_rms_um": {str(k): round(1e3 * v, 4) for k, v in degree_scores.items()},
        "gauge_fixed": _gauge_text(decl.gauge),
        "noise_estimate_um": round(1e3 * math.sqrt(out.sigma2), 4),
        "outliers": {"threshold_um": round(1e3 * thresh, 4), "count": int(len(far)),
                     "z": OUTLIER_Z, "robust_sigma_um": round(1e3 * scale, 4),
                     "data_rows": [int(i) + 1 for i in far[:100]],
                     "method": f"counted on the final (augmented) fit: 3-D residual length "
                               f"beyond {OUTLIER_Z:g} robust sigma (sigma per coordinate = "
                               f"median length / 1.538); the fits weight points by IRLS on "
                               f"the declared fit (weight 1 up to {ROBUST_K:g} robust sigma, "
                               f"bisquare to 0 at {2 * ROBUST_K:g})"},
        "candidates_tested": selection.n_candidates,
        "candidate_families": sorted({s.cand.kind for s in selection.first}),
        "residual_analysis": analysis,
        "augmented_layout": paths.get("augmented_layout"),
        "generated_module": paths.get("generated_module"),
        "augmented_parameters": [p for p in aug.model.parameters if p not in model.parameters],
        "augmented_covariates": list(aug.model.covariates),
        "seconds": 0.0,
        "method": ("held-out: random {:.0%} of the points, never used for selection or "
                   "fitting; before = declared model, after = augmented model, both fitted "
                   "on the other points").format(test_fraction),
    }


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


def augmented_layout_text(model: Model, selected, source=None) -> str:
    """The layout text with one ``[effects.NAME]`` table per selected effect (name + _aug).
    ``source``: the layout file (or shipped name) ``model`` was read from; else the layout's
    own path (when it is a file there) or its name."""
    if source is None:
        source = (model.layout.path if model.layout.path and Path(model.layout.path).is_file()
                  else model.name)
    text, _ = layout_text(source)
    new_name = f"{model.name}_aug"
    text, k = re.subn(r'(?m)^name\s*=\s*"[^"]*"', f'name = "{new_name}"', text, count=1)
    require(k == 1, f"layout {model.name}: no top-level name line to rename")
    parts = [text.rstrip("\n"), ""]
    for s in selected:
        c = s.cand
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
    ``kind``: ``"thermal"`` (the scale of X grows 11.5 um/m/K with T_C - 20), ``"periodic"``
    (a 2 um cyclic error of EXX, period 40 mm) or ``"thermal_lag"`` (four logged sensors over
    4 h, drives 2 h on then off; the scale of X grows 2 um/m/K with T_motorX through a 20 min
    lag).  Sized so that the loop on it takes a few seconds.  Returns ``("MB1", csv_path)``."""
    import tempfile

    from .simulate import demo_probes, simulate

    if isinstance(out, int) and not isinstance(out, bool):
        seed, out = out, None
    require(kind in ("thermal", "periodic", "thermal_lag"),
            "demo effect must be thermal, periodic or thermal_lag")
    model = load("MB1")
    effect = {"thermal": {"kind": "thermal", "axis": "X", "ppm_per_K": 11.5},
              "periodic": {"kind": "periodic", "component": "EXX", "period_mm": 40.0,
                           "um": 2.0},
              "thermal_lag": {"kind": "thermal_lag", "sensor": "T_motorX", "tau_min": 20.0,
                              "axis": "X", "ppm_per_K": 2.0}}[kind]
    logged = {"sensors": "T_motorX,T_coolant,T_column,T_air1", "duty": "on:2h,off:2h",
              "duration_h": 4.0} if kind == "thermal_lag" else {}
    camp = simulate("MB1", n_points=n_points, seed=seed, probes=demo_probes(model),
                    effects=[effect], noise_um=0.3, **logged)
    if out is None:
        out = Path(tempfile.mkdtemp(prefix="volerr_demo_")) / "MB1_campaign.csv"
    return "MB1", str(camp.write_csv(out))
