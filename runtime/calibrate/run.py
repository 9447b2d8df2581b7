"""``volerr calibrate``: identify a layout's parameters from the files of any instruments, mixed
in one campaign, by weighted least squares on the layout's derived observation model.

Steps (:func:`calibrate`):

1. read every file as :class:`volerr.instruments.Observations` (its kind from its columns or
   ``KIND:FILE``) and stack them: one design, each file with its own set-up unknowns;
2. choose the parameters fitted (``--parameters``; the others are held at zero) and, for
   component errors, the degree of their Legendre series by cross-validation;
3. fix the gauge by convention (:func:`volerr.estimate.design.gauge_mask`: what no
   measurement of the chain can determine, e.g. the offsets of translational errors against
   the instruments' positions);
4. accumulate the weighted normal equations (weights ``1 / u^2`` of each reading) per file, on
   all readings and on the training readings (a random ``test_fraction`` of the points is
   held out);
5. estimability of every parameter from the stacked Gram matrix and which file sees it
   (:mod:`volerr.calibrate.estimability`); the solution takes the columns in the gauge order
   and leaves out those in the span of the ones before (their value 0);
6. the covariance ``s0^2 (A^T W A)^-1`` with the a-posteriori variance factor ``s0^2`` (weighted
   residual sum of squares per degree of freedom), set-up estimates per file / placement,
   residual RMS per file on all readings and on the held-out ones.

Units: readings mm inside; reports um, urad, um/mm ... (:mod:`volerr.calibrate.terms`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import instruments
from ..errors import require
from ..estimate import blocks
from ..estimate.design import data_ranges, gauge_mask, identifiability_gram
from ..estimate.steps import choose_degree, split_points
from ..machine.model import Model, load
from . import estimability, terms

#: relative eigenvalue below which the solution leaves a direction out (unit-scaled columns)
SOLVE_TOL = 1e-12


@dataclass
class Calibration:
    """Result of :func:`calibrate`: ``data`` the JSON report (INTERFACE.md keys first) and what
    the error tables and the HTML page need."""

    data: dict
    model: Model
    ranges: dict
    degree: int
    labels: list                 # design columns (set-up first)
    coef: np.ndarray             # mm / rad per column (0 where left out)
    std: np.ndarray              # standard uncertainty per column (0 where left out)
    residuals: dict = field(default_factory=dict)   # file -> (positions, residual um, rows)
    solution: "Solution | None" = None
    parts: list = field(default_factory=list)       # the files' Observations

    def combination(self, weights: dict) -> tuple[float, float] | None:
        """(value, standard uncertainty) of ``sum w_label * coefficient`` (mm / rad), or None
        when the campaign does not determine that combination."""
        sol = self.solution
        c = np.zeros(len(self.labels))
        for lab, w in weights.items():
            if lab not in self.labels:
                return None
            c[self.labels.index(lab)] = w
        d = np.where(sol.norms > 0, sol.norms, 1.0)
        if np.linalg.norm(sol.null.T @ (c / d)) > 1e-6 * np.linalg.norm(c / d):
            return None
        ck = c[sol.kept]
        return float(c @ self.coef), float(np.sqrt(max(ck @ sol.cov @ ck, 0.0)))

    def __getitem__(self, key):
        return self.data[key]

    def error_tables(self, n_grid: int = 41):
        """The identified error functions as error tables over the measured range and the
        constants: ``({axis: ErrorTable}, {name: value}, {name: std})``, mm / rad.  An axis
        none of whose component errors was fitted gets no table (zero errors everywhere, no
        range); columns left out (not determined) are zero."""
        from ..estimate.design import series_basis
        from ..tables.table import ErrorTable

        from .mapping import function_std

        model, ranges, deg = self.model, self.ranges, self.degree
        index = {lab: j for j, lab in enumerate(self.labels)}
        tables, constants, cstd = {}, {}, {}
        for a in model.axes:
            q = np.linspace(*ranges[a], n_grid)
            P = series_basis(model, a, q, ranges, deg)
            vals, std = {}, {}
            if not any((p, k) in index for p in model.parameters
                       if model.parameter_axis.get(p) == a for k in range(deg + 1)):
                continue
            for p in model.parameters:
                if model.parameter_axis.get(p) != a:
                    continue
                js = [(k, index[(p, k)]) for k in range(deg + 1) if (p, k) in index]
                vals[p] = sum((P[:, k] * self.coef[j] for k, j in js), np.zeros(n_grid))
                std[p] = function_std(self, P, js)
            if vals:
                tables[a] = ErrorTable(a, q, vals, std=std)
        for p in model.parameters:
            j = index.get((p, None))
            if j is not None:
                constants[p] = float(self.coef[j])
                cstd[p] = float(self.std[j])
        return tables, constants, cstd

    def write_error_tables(self, directory, inputs=()) -> Path:
        from ..tables.table import write_error_dir

        tables, constants, cstd = self.error_tables()
        return write_error_dir(directory, tables, constants or None, cstd or None,
                               inputs=list(inputs))

    def write_json(self, path, inputs=()) -> Path:
        from ..fileio import json_text, write_text

        return write_text(path, json_text(self.data), inputs=list(inputs))

    def write_html(self, path, inputs=()) -> Path:
        from ..fileio import write_text
        from .report import render_html

        return write_text(path, render_html(self), inputs=list(inputs))

    def summary(self) -> str:
        d = self.data
        files = "; ".join(f"{i['file']} ({i['kind']}, {i['n']} rows): RMS "
                          f"{i['rms_residual']:.3f} um, held-out {i['heldout_rms']:.3f} um"
                          for i in d["instruments"])
        return (f"{d['layout']}: {len(d['parameters'])} parameters identified, "
                f"{len(d['unidentifiable'])} not determined by these data; {files}")


def default_parameters(obs) -> str:
    """``location`` when every file is a sphere / R-test (a kinematics cycle identifies the
    rotary axes' location errors), else ``all``; the files' declared ``# parameters:`` (a
    ``volerr plan`` request) first."""
    declared = {f.parameters for f in obs.files if f.parameters}
    require(len(declared) <= 1, "the files declare different '# parameters:' lines; give "
                                "--parameters")
    if declared:
        return declared.pop()
    kinds = {f.kind for f in obs.files}
    return "location" if kinds == {"sphere"} else "all"


def reading_weights(obs) -> tuple[np.ndarray, float]:
    """Relative weights (N,) of the points' readings, ``(u_ref / u)^2``, and ``u_ref`` (mm)."""
    return obs.point_weights(), obs.reference_sigma()


def calibrate(layout, files, *, parameters: str | None = None, degree: int | None = None,
              max_degree: int = 8, seed: int = 0, test_fraction: float = 0.25,
              extra_terms=(), plan: bool = True, progress=None) -> Calibration:
    """Identify ``layout``'s parameters from measurement ``files`` (paths or ``KIND:FILE``;
    or an :class:`volerr.instruments.Observations`).  Returns a :class:`Calibration`.

    ``extra_terms``: more columns ``(name, target, basis, (factor, unit))``: a parameter
    ``name`` that adds ``name * basis`` to the declared parameter ``target`` (e.g. a reversal
    ``("RV_X", "EXX", "dir_X/2", (1e3, "um"))``); the basis is an expression in the axis
    positions (rad for rotary axes) and the covariates of the files.  ``plan``: suggest the
    plan extensions that would determine what the campaign does not."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        return _run(layout, files, parameters, degree, max_degree, seed, test_fraction,
                    list(extra_terms), plan, progress)


def _progress(total: int, enabled):
    import sys

    from tqdm import tqdm

    disable = (not sys.stderr.isatty()) if enabled is None else not enabled
    return tqdm(total=total, file=sys.stderr, disable=disable, desc="volerr calibrate",
                bar_format="{desc}: {n}/{total} {postfix}")


def _run(layout, files, parameters, degree, max_degree, seed, test_fraction, extra_terms,
         plan, progress):
    t0 = time.perf_counter()
    require(0.05 <= test_fraction <= 0.5, "test fraction must be between 0.05 and 0.5")
    if degree is not None:
        require(1 <= degree <= 12, "degree must be between 1 and 12")
    model = layout if isinstance(layout, Model) else load(layout)
    bar = _progress(4, progress)
    bar.set_postfix_str("read")
    if isinstance(files, instruments.Observations):
        parts, obs = [files], files
    else:
        parts = instruments.read_parts(list(files), model)
        obs = instruments.stack(parts)
    chosen = terms.resolve(parameters, model, default_parameters(obs))
    ranges = data_ranges(model, obs)
    spl = split_points(obs.n, seed, test_fraction, None)
    w, u_ref = reading_weights(obs)
    series = any(model.parameter_axis.get(p) for p in chosen)
    degree_scores = {}
    bar.update()
    bar.set_postfix_str("degree")
    if degree is None:
        degree = 1
        if series:
            degree, degree_scores = choose_degree(model, obs, spl.train, None, ranges,
                                                  max_degree, weights=w, parameters=chosen)
    keep, gauge = gauge_mask(model, obs, degree, ranges, chosen, constants=False)
    design = blocks.Design(model, obs, degree, ranges, keep)
    labels = list(design.labels)
    if extra_terms:
        design = design.plus([extra_columns(model, obs, extra_terms)])
        labels += [(name, "extra") for name, *_ in extra_terms]
    bar.update()
    bar.set_postfix_str("normal equations")
    fit = _normal_equations(design, obs, spl, np.sqrt(w))
    bar.update()
    bar.set_postfix_str("solve, residuals")
    out = _solve(design, labels, obs, spl, fit, np.sqrt(w), u_ref)
    bar.update()
    bar.close()
    units = {name: unit for name, _, _, unit in extra_terms}
    report = _report(model, obs, labels, ranges, degree, degree_scores, chosen, gauge, out, spl,
                     u_ref, units)
    if plan and not extra_terms:
        from .plan import suggest

        report["plan"] = suggest(model, parts, design, labels, fit.G, report["unidentifiable"],
                                 u_ref, report["identifiability"])
    std = np.zeros(design.p)
    std[out.kept] = out.std
    cal = Calibration(report, model, ranges, degree, labels, out.coef, std, out.residuals, out,
                      parts)
    _lab_report(cal, fit, obs, u_ref)
    report["seconds"] = round(time.perf_counter() - t0, 2)
    return cal


def _lab_report(cal, fit, obs, u_ref) -> None:
    """What a calibration laboratory reports beside the parameters: the consistency of the
    files with each other (:mod:`volerr.calibrate.consistency`), the instruments' own results
    (artifact poses, station positions), the volumetric error map with its uncertainty
    (:mod:`volerr.calibrate.mapping`) and the ISO 10360-2 length errors of the identified model
    beside the measured step-gauge lengths (:mod:`volerr.calibrate.lengths`)."""
    from . import consistency, lengths, mapping

    report = cal.data
    report["consistency"] = consistency.check(fit, cal.solution, obs, u_ref)
    flags = {e["file"]: e for e in report["consistency"]["files"]}
    for entry in report["instruments"]:
        c = flags.get(entry["file"], {})
        entry["birge_ratio"] = c.get("birge_ratio")
        entry["consistent"] = c.get("consistent", True)
    kinds = instruments.kinds()
    for part in cal.parts:
        kind = part.files[0].kind if part.files else "deviations"
        maker = getattr(kinds.get(kind), "results", None)
        if maker is not None:
            for key, value in maker(part, report["setup"]).items():
                report.setdefault(key, {}).update(value)
    summary = mapping.summary(cal)
    if summary is not None:
        report["volumetric_map"] = summary
    iso = lengths.report(cal)
    if iso is not None:
        report["iso10360"] = iso


def extra_columns(model, obs, extra_terms) -> np.ndarray:
    """(N, 3, m) columns of ``extra_terms`` (see :func:`calibrate`): the readings'
    sensitivity to the target parameter times the basis."""
    from ..estimate.design import rotary_rad
    from ..machine.expressions import evaluate

    sens = obs.sensitivity(model)
    values = {**rotary_rad(model, obs.positions), **obs.covariates}
    out = np.zeros((obs.n, 3, len(extra_terms)))
    for k, (name, target, basis, _) in enumerate(extra_terms):
        require(target in model.parameters, f"{name}: {target} is not a parameter of "
                                            f"{model.name}")
        b = np.broadcast_to(evaluate(basis, values), (obs.n,))
        out[:, :, k] = sens[:, :, model.parameters.index(target)] * b[:, None]
    return out


@dataclass
class Normal:
    """Weighted normal equations of the design: all readings (``G``, ``b``), training readings
    (``G_tr``, ``b_tr``), and per file (``G_files`` with the priors of its set-up columns,
    ``b_files``, ``yy_files`` the weighted sum of squares of its readings, ``priors_files``
    the number of its priors)."""

    G: np.ndarray
    b: np.ndarray
    G_tr: np.ndarray
    b_tr: np.ndarray
    G_files: list
    scale: np.ndarray
    b_files: list = field(default_factory=list)
    yy_files: list = field(default_factory=list)
    priors_files: list = field(default_factory=list)


def _normal_equations(design, obs, spl, sw) -> Normal:
    p = design.p
    n_files = max(len(obs.files), 1)
    file_of = obs.file if obs.file is not None else np.zeros(obs.n, int)
    is_test = np.zeros(obs.n, bool)
    is_test[spl.test] = True
    G_files = [np.zeros((p, p)) for _ in range(n_files)]
    b_files = [np.zeros(p) for _ in range(n_files)]
    G_te, b_te = np.zeros((p, p)), np.zeros(p)
    yy_files = [0.0] * n_files
    y = obs.deviation.ravel()
    ss = np.zeros(p)
    for f in range(n_files):
        pts = np.flatnonzero(file_of == f)
        for s, idx in blocks.blocks(pts):
            At = design.block(idx)
            ss += np.einsum("ij,ij->i", At, At)
            wr = blocks.wrows(sw[idx])
            At *= wr
            yw = blocks.yrows(y, idx) * wr
            G_files[f] += At @ At.T
            b_files[f] += At @ yw
            yy_files[f] += float(yw @ yw)
            te = np.tile(is_test[idx], 3)
            if te.any():
                G_te += At[:, te] @ At[:, te].T
                b_te += At[:, te] @ yw[te]
    # columns the readings do not see at all (numerically): zeroed before any test
    off = np.zeros(p, bool)
    off[:len(design.labels)] = estimability.negligible(
        design.model, obs, design.labels, design.degree, design.ranges,
        ss[:len(design.labels)], obs.n_readings)
    if off.any():
        for M in G_files + [G_te]:
            M[off, :] = 0.0
            M[:, off] = 0.0
        for v in b_files + [b_te]:
            v[off] = 0.0
        ss[off] = 0.0
    # known set-up values (a calibrated bar length): a prior 0 +- u on the column
    u_ref = _u_ref(sw, obs)
    priors = dict(zip(obs.setup_labels, obs.setup_priors))
    priors_files = [0] * n_files
    for j, lab in enumerate(design.labels):
        u = priors.get(lab[1]) if lab[0] == "setup" else None
        if u:
            for f, Gf in enumerate(G_files):
                if Gf[j, j] > 0:
                    Gf[j, j] += (u_ref / u) ** 2
                    priors_files[f] += 1
    G, b = sum(G_files), sum(b_files)
    scale = blocks.unit_scale(ss, obs.n_readings)
    return Normal(G, b, G - G_te, b - b_te, G_files, scale, b_files, yy_files, priors_files)


def _u_ref(sw, obs) -> float:
    return reading_weights(obs)[1]


@dataclass
class Solution:
    kept: np.ndarray            # column indices in the solution
    cov: np.ndarray             # covariance of the kept columns (mm, rad)
    null: np.ndarray            # null space (p, k) of the unit-scaled columns
    norms: np.ndarray           # (p,) column norms (weighted)
    coef: np.ndarray            # (p,) mm / rad, 0 where left out
    coef_train: np.ndarray
    std: np.ndarray             # of the kept columns
    estimable: np.ndarray       # (p,) bool
    partners: dict
    seen: np.ndarray            # (files, p) bool
    s0: float                   # a-posteriori standard deviation of unit weight (u_ref = 1)
    dof: float
    rms_all: dict               # file index -> RMS um of all readings
    rms_test: dict              # file index -> RMS um of held-out readings
    n_test: dict
    residuals: dict
    rss_files: dict = field(default_factory=dict)   # file -> weighted residual SS (mm^2)
    Gi: np.ndarray | None = None                     # inverse of the unit-scaled kept Gram


def _solve(design, labels, obs, spl, fit: Normal, sw, u_ref: float) -> Solution:
    est, partners = estimability.estimable(fit.G)
    setup_idx = [j for j, lab in enumerate(labels) if lab[0] == "setup"]
    setup_of_file = [[j for j in setup_idx if Gf[j, j] > 0] for Gf in fit.G_files]
    seen = estimability.seen_by(fit.G_files, setup_of_file)
    keep_d, _ = identifiability_gram(fit.G, labels)
    kept = np.flatnonzero(keep_d)
    sc = fit.scale[kept]
    S = np.outer(sc, sc)
    Gk = fit.G[np.ix_(kept, kept)] / S
    Gi = blocks.eig_inverse(Gk, SOLVE_TOL)
    coef = np.zeros(design.p)
    coef[kept] = Gi @ (fit.b[kept] / sc) / sc
    Gti = blocks.eig_inverse(fit.G_tr[np.ix_(kept, kept)] / S, SOLVE_TOL)
    coef_tr = np.zeros(design.p)
    coef_tr[kept] = Gti @ (fit.b_tr[kept] / sc) / sc
    # residuals, blockwise: all readings (fit on all) and held-out ones (fit on training)
    y = obs.deviation.ravel()
    file_of = obs.file if obs.file is not None else np.zeros(obs.n, int)
    is_test = np.zeros(obs.n, bool)
    is_test[spl.test] = True
    rows = obs.readings_per_point()
    rss_w = 0.0
    rms_all, rms_test, n_test, residuals, rss_files = {}, {}, {}, {}, {}
    for f in range(len(fit.G_files)):
        pts = np.flatnonzero(file_of == f)
        r_all = np.empty((len(pts), 3))
        r_tr = np.empty((len(pts), 3))
        for s, idx in blocks.blocks(pts):
            At = design.block(idx)
            yy = blocks.yrows(y, idx)
            n = len(idx)
            r_all[s] = (yy - coef @ At).reshape(3, n).T
            r_tr[s] = (yy - coef_tr @ At).reshape(3, n).T
        rss_files[f] = float(np.sum((r_all * sw[pts, None]) ** 2))
        rss_w += rss_files[f]
        k = rows[pts]
        n_read = max(int(k.sum()), 1)
        factor = unit_factor(obs, f)
        rms_all[f] = factor * math.sqrt(float(np.sum(r_all ** 2)) / n_read)
        te = is_test[pts]
        n_te = int(k[te].sum())
        n_test[f] = n_te
        rms_test[f] = (factor * math.sqrt(float(np.sum(r_tr[te] ** 2)) / n_te)
                       if n_te else float("nan"))
        residuals[f] = (pts, factor * r_all, k)
    rank = int(np.sum(np.linalg.eigvalsh(Gk) > SOLVE_TOL * np.linalg.eigvalsh(Gk)[-1]))
    dof = max(float(obs.n_readings - rank), 1.0)
    s0 = math.sqrt(rss_w / dof)                 # mm: the weights are relative to u_ref
    cov = Gi / np.outer(sc, sc) * s0 ** 2
    std = np.sqrt(np.maximum(np.diag(cov), 0.0))
    s0 /= u_ref                                  # the a-posteriori factor, dimensionless
    return Solution(kept, cov, estimability.null_space(fit.G),
                    np.sqrt(np.maximum(np.diag(fit.G), 0.0)), coef, coef_tr, std, est, partners,
                    seen, s0, dof, rms_all, rms_test, n_test, residuals, rss_files, Gi)


def unit_factor(obs, f: int) -> float:
    """Report factor of file ``f``'s readings: 1e6 (rad -> urad) for angular readings, else
    1e3 (mm -> um)."""
    files = obs.files
    return 1e6 if files and f < len(files) and files[f].unit == "urad" else 1e3


def _report(model, obs, labels, ranges, degree, degree_scores, chosen, gauge, out, spl, u_ref,
            units) -> dict:
    name_of = terms.namer(model, ranges)
    names = [name_of(lab) for lab in labels]
    std_of = dict(zip(out.kept.tolist(), out.std.tolist()))
    files = obs.files or (instruments.FileInfo("data", "deviations"),)
    params, unident, ident = {}, [], {}
    for j, lab in enumerate(labels):
        if lab[0] == "setup":
            continue
        name = names[j]
        seen = [files[f].name for f in range(len(files)) if out.seen[f, j]]
        ident[name] = {
            "identifiable": bool(out.estimable[j]),
            "seen_by": seen,
            "not_seen_by": [fi.name for fi in files if fi.name not in seen],
            "confounded_with": [names[k] for k in out.partners.get(j, [])][:6]}
        if out.estimable[j] and j in std_of:
            params[name] = terms.report(lab, out.coef[j], std_of[j], model, ranges,
                                        units.get(lab[0]))
        else:
            unident.append(name)
    setup = {}
    units = obs.setup_units
    setup_labels = obs.setup_labels
    for j, lab in enumerate(labels):
        if lab[0] != "setup":
            continue
        key = lab[1]
        i = setup_labels.index(key)
        group, _, k = key.rpartition(".") if "." in key else (files[0].name, "", key)
        factor = 1e6 if units[i] in ("urad", "ppm") else 1e3
        entry = {"value": float(out.coef[j]) * factor, "unit": units[i],
                 "std": float(std_of.get(j, 0.0)) * factor,
                 "determined": bool(out.estimable[j])}
        setup.setdefault(group, {})[k] = entry
    inst = []
    file_of = obs.file if obs.file is not None else np.zeros(obs.n, int)
    rows_in_file = obs.row if obs.row is not None else np.arange(obs.n)
    test_set = set(spl.test.tolist())
    for f, fi in enumerate(files):
        pts = np.flatnonzero(file_of == f)
        inst.append({
            "file": fi.name, "kind": fi.kind, "n": int(len(np.unique(rows_in_file[pts]))),
            "n_readings": int(obs.readings_per_point()[pts].sum()), "unit": fi.unit,
            "rms_residual": round(out.rms_all[f], 5),
            "heldout_rms": round(out.rms_test[f], 5), "n_heldout": out.n_test[f],
            "test_rows": sorted({int(rows_in_file[i]) for i in pts if int(i) in test_set}),
            "normalised_rms": round(out.rms_all[f] / (unit_factor(obs, f)
                                                      * _file_u(obs, pts, u_ref)), 4)})
    return {
        "layout": model.name,
        "parameters": params,
        "unidentifiable": unident,
        "setup": setup,
        "instruments": inst,
        "identifiability": ident,
        "fitted": list(chosen),
        "degree": int(degree),
        "degree_cv_rms_um": {str(k): round(1e3 * v, 4) for k, v in degree_scores.items()},
        "gauge_fixed": [name_of(g) for g in gauge],
        "variance_factor": round(out.s0 ** 2, 4),
        "dof": out.dof,
        "method": ("weighted least squares (weights 1/u^2 per reading) over all files; "
                   "standard uncertainties from the covariance scaled by the a-posteriori "
                   "variance factor; held-out: a random {:.0%} of the points, fitted on the "
                   "others").format(len(spl.test) / max(obs.n, 1)),
    }


def _file_u(obs, pts, u_ref) -> float:
    if obs.sigma is None:
        return u_ref
    u = np.asarray(obs.sigma)[pts]
    u = u[np.isfinite(u)]
    return float(np.sqrt(np.mean(u ** 2))) if len(u) else u_ref
