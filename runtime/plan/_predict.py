"""The predicted result of a plan: what ``calibrate`` (no options) will report once the files
are filled, computed on calibrate's own steps (:mod:`volerr.calibrate.run`): the files read by
the instruments' readers (readings zero), the request and its defaults, the reversal terms from
the readings' directions, calibrate's gauge fixing, its normal equations (weights
``(u_ref / u)^2``, the priors of known set-up values), its estimability rule, its column choice
and combinations, and its report -- with the a-posteriori variance factor at its expectation,
1 (readings with noise ``u_um``)::

    C = u_ref^2 (A^T W A)^-1   (the kept columns, unit-scaled as calibrate scales them)

so that a plan executed and calibrated gives ``std`` equal to ``predicted_std`` up to the noise
of the variance factor (relative standard deviation about ``1 / sqrt(2 dof)``).  The degree of
the component series is the highest term requested (at least 1); ``calibrate`` chooses it by
cross-validation only when a whole component error (``EXX``, not ``EXX@slope``) is requested.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from .. import instruments
from ..calibrate import run as calibration
from ..calibrate import terms
from ..calibrate.budget import budgets
from ..calibrate.defaults import default_parameters
from ..estimate import blocks
from ..estimate.design import data_ranges, declared_design, gauge_mask, parameter_labels
from ..estimate.steps import split_points
from . import _information


@dataclass
class Prediction:
    """``parameters`` {name: {"predicted_std", "unit"}}, ``unidentifiable`` [name],
    ``why`` {name: text}, ``combinations`` (calibrate's entries with the predicted std),
    ``map_u_um`` {"max", "rms"}, ``gauge`` the names calibrate holds at zero by convention
    (what no measurement of the chain determines)."""

    parameters: dict
    unidentifiable: list
    why: dict = field(default_factory=dict)
    combinations: list = field(default_factory=list)
    map_u_um: dict = field(default_factory=dict)
    gauge: list = field(default_factory=list)
    budgets: dict = field(default_factory=dict)  # calibrate's budgets, the variance factor 1

    @property
    def determined(self) -> set:
        return set(self.parameters)


def request(model, parts, spec):
    """calibrate's :class:`volerr.calibrate.terms.Request` for these files and ``spec``."""
    obs = instruments.stack(parts)
    moving = calibration.moving_axes(model, data_ranges(model, obs))
    declared = spec if spec is not None else calibration.declared_parameters(obs)
    return terms.request(declared, model,
                         default_parameters(model, calibration.campaign_kinds(obs), moving))


def predict(model, parts: list, spec: str | None, tool=(0.0, 0.0, 0.0)) -> Prediction:
    """The prediction for the files' Observations ``parts`` and the request ``spec`` (the
    files' ``# parameters:`` declaration; None: calibrate's defaults for these instruments).
    As ``calibrate`` with no options: a reversal the readings cannot show is skipped."""
    obs = instruments.stack(parts)
    req = request(model, parts, spec)
    obs = calibration.with_directions(obs, parts, req.reversals)
    extra = calibration.reversal_terms(model, obs, req, explicit=False)
    ranges = data_ranges(model, obs)
    spl = split_points(obs.n, 0, 0.25, None)
    w, u_ref = calibration.reading_weights(obs)
    degree = max(1, req.max_term())
    keep, gauge = gauge_mask(model, obs, degree, ranges, req.parameters, constants=False)
    keep &= np.array([req.fits(lab) for lab in
                      declared_design(model, obs.subset(np.arange(1)), degree, ranges).labels])
    gauge = [g for g in gauge if req.fits(g)]
    design = blocks.Design(model, obs, degree, ranges, keep)
    labels = list(design.labels)
    if extra:
        design = design.plus([calibration.extra_columns(model, obs, extra)])
        labels += [(name, "extra") for name, *_ in extra]
    fit = calibration._normal_equations(design, obs, spl, np.sqrt(w))
    out = calibration._solve(design, labels, obs, spl, fit, np.sqrt(w), u_ref,
                             calibration._preferred(model, obs, labels, ranges))
    sc = fit.scale[out.kept]
    out.cov = out.Gi / np.outer(sc, sc) * u_ref ** 2     # the variance factor at 1
    out.std = np.sqrt(np.maximum(np.diag(out.cov), 0.0))
    out.s0 = 1.0
    report = calibration._report(model, obs, labels, ranges, degree, {}, req.parameters, gauge,
                                 out, spl, u_ref, {name: unit for name, _, _, unit in extra})
    params = {n: {"predicted_std": v["std"], "unit": v["unit"]}
              for n, v in report["parameters"].items()}
    ident = report["identifiability"]
    why = {n: _why(ident.get(n, {})) for n in report["unidentifiable"]}
    pred = Prediction(params, list(report["unidentifiable"]), why,
                      list(report.get("combinations", [])))
    pred.gauge = list(report.get("gauge_fixed", []))
    pred.budgets = budgets(SimpleNamespace(solution=out, data=report, model=model,
                                           ranges=ranges, labels=labels), fit, u_ref)
    pred.map_u_um = map_uncertainty(model, labels, out.kept, out.cov, degree, ranges, tool)
    return pred


def _why(entry: dict) -> str:
    partners = entry.get("confounded_with", [])
    if not entry.get("seen_by"):
        return "no reading of the plan depends on it"
    setup = [p for p in partners if p.startswith("setup:")]
    if partners and len(setup) == len(partners):
        return ("it acts on the readings as the instruments' own set-up unknowns do "
                f"({', '.join(setup[:3])})")
    if partners:
        return f"confounded with {', '.join(partners[:4])}"
    return "its column lies in the span of the others"


def map_uncertainty(model, labels, kept, cov, degree, ranges, tool) -> dict:
    """``{"max", "rms"}`` um: the standard uncertainty of the volumetric error's components
    over the map grid (:func:`volerr.plan._information.grid`) from the kept parameter columns
    (not the set-up columns, not the reversals)."""
    pos = [i for i, k in enumerate(kept) if labels[k][0] != "setup" and labels[k][1] != "extra"]
    if not pos:
        return {"max": 0.0, "rms": 0.0}
    plabs = [labels[kept[i]] for i in pos]
    all_labels = parameter_labels(model, degree)
    keep = np.array([lab in plabs for lab in all_labels])
    order = [plabs.index(lab) for lab in all_labels if lab in plabs]
    J = _information.map_rows(model, [lab for lab in all_labels if lab in plabs], keep,
                              degree, ranges, tool)
    C = cov[np.ix_(pos, pos)][np.ix_(order, order)]
    var = np.einsum("kin,kl,lin->ni", J, C, J)
    u = 1e3 * np.sqrt(np.maximum(var, 0.0))
    return {"max": round(float(u.max()), 5), "rms": round(float(np.sqrt(np.mean(u ** 2))), 5)}
