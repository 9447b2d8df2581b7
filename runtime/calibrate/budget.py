"""The uncertainty budget of every identified parameter of ``volerr calibrate`` (GUM, JCGM
100:2008 5.1; ISO/TR 230-9), from the numbers the estimator already holds.

The weighted least-squares estimate is x = G^-1 sum_f A_f^T W_f y_f with G = sum_f G_f, the
normal matrices of the files (each with the priors of its set-up unknowns).  The readings of
different files are uncorrelated, so the a-priori covariance splits exactly into one term per
file (the sandwich form):

    C0 = u_ref^2 G^-1 = sum_f u_ref^2 G^-1 G_f G^-1,

term f being what the reading noise of file f (its stated uncertainty: the instrument's
calibration and resolution, as given in the file) and its set-up unknowns propagate into
the parameters through the parameters' covariance (correlated columns share each file's
noise).  The a-posteriori variance factor s0^2 (weighted residual sum of squares per degree
of freedom) widens the covariance when above 1: the model's residual, the scatter the stated
uncertainties do not explain, contributes (max(s0, 1)^2 - 1) C0.  Hence per parameter

    u^2 = sum_f u_f^2 + u_model^2 = max(s0, 1)^2 C0_jj,

the standard uncertainty the report states (:func:`volerr.calibrate.run._solve`).  Every
source enters with sensitivity 1 (each is already in the parameter's unit); U = 2 u.
"""

from __future__ import annotations

import math

import numpy as np

from ..report.budget import budget, source
from . import terms


def budgets(cal, fit, u_ref: float) -> dict:
    """``{parameter name: budget}`` (:func:`volerr.report.budget.budget`) of every reported
    parameter of the calibration ``cal`` with normal equations ``fit`` and reference reading
    uncertainty ``u_ref`` (mm)."""
    out = cal.solution
    if out.Gi is None or not len(out.kept):
        return {}
    kept = out.kept
    sc = fit.scale[kept]
    S = np.outer(sc, sc)
    # the full terms (natural units) kept for the budgets of combinations
    out.budget_terms = [out.Gi @ (Gf[np.ix_(kept, kept)] / S) @ out.Gi / S * u_ref ** 2
                        for Gf in fit.G_files]
    per_file = [np.diag(m) for m in out.budget_terms]
    a_priori = np.diag(out.Gi) / sc ** 2 * u_ref ** 2
    widen = max(out.s0, 1.0) ** 2 - 1.0
    files = [e["file"] for e in cal.data["instruments"]]
    name_of = terms.namer(cal.model, cal.ranges)
    params = cal.data["parameters"]
    model_name = (f"model residual (a-posteriori factor s0 = {out.s0:.3g}"
                  + (" > 1 widens the stated u)" if widen > 0 else " <= 1: stated u kept)"))
    result = {}
    for pos, j in enumerate(kept):
        p = params.get(name_of(cal.labels[j]))
        if p is None or not out.std[pos] > 0:
            continue
        factor = p["std"] / out.std[pos]          # report unit per internal unit
        srcs = [source(f"readings of {name} (stated u, set-up)",
                       math.sqrt(max(v[pos], 0.0)) * factor, p["unit"])
                for name, v in zip(files, per_file)]
        srcs.append(source(model_name, math.sqrt(widen * a_priori[pos]) * factor, p["unit"]))
        result[name_of(cal.labels[j])] = budget(name_of(cal.labels[j]), p["unit"], srcs, 2.0)
    return result


def combination_budget(cal, weights: dict, name: str, factor: float, unit: str):
    """The budget of ``factor`` times the combination ``weights`` of :meth:`Calibration.
    combination` (its std in ``unit``), from the per-file terms :func:`budgets` kept: c^T
    C_f c per file and the model residual's widening; None when the combination is not
    determined or the terms were not computed."""
    out = cal.solution
    terms_f = getattr(out, "budget_terms", None)
    c = cal.combination_vector(weights)
    if c is None or terms_f is None:
        return None
    ck = c[out.kept]
    per_file = [float(ck @ m @ ck) for m in terms_f]
    a_priori = sum(per_file)          # C0 = sum_f C_f (module docstring)
    widen = max(out.s0, 1.0) ** 2 - 1.0
    srcs = [source(f"readings of {e['file']} (stated u, set-up)",
                   math.sqrt(max(v, 0.0)) * abs(factor), unit)
            for e, v in zip(cal.data["instruments"], per_file)]
    srcs.append(source(f"model residual (a-posteriori factor s0 = {out.s0:.3g})",
                       math.sqrt(widen * max(a_priori, 0.0)) * abs(factor), unit))
    return budget(name, unit, srcs, 2.0)
