"""The predicted result of a plan: what ``calibrate`` (no options) will report once the files
are filled, computed on the same path -- the files read by the instruments' readers (readings
zero), calibrate's gauge fixing, its normal equations (weights ``(u_ref / u)^2``, the priors of
known set-up values), its estimability rule and its solution's column choice -- with the
a-posteriori variance factor replaced by its expectation, 1 (readings with noise ``u_um``):

    C = u_ref^2 (A^T W A)^-1   (kept columns, unit-scaled as calibrate scales them)

so that a plan executed and calibrated gives ``std`` equal to ``predicted_std`` up to the
noise of the variance factor (relative standard deviation about ``1 / sqrt(2 dof)``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import instruments
from ..calibrate import estimability, terms
from ..calibrate.run import SOLVE_TOL, _normal_equations, reading_weights
from ..estimate import blocks
from ..estimate.design import data_ranges, gauge_mask, identifiability_gram, parameter_labels
from ..estimate.steps import split_points
from . import _information

#: the degree of the component series the prediction assumes (calibrate chooses it by
#: cross-validation when component errors are requested; constants have none)
DEGREE = 1


@dataclass
class Prediction:
    """``parameters`` {name: {"predicted_std", "unit"}}, ``unidentifiable`` [name],
    ``why`` {name: text}, ``map_u_um`` {"max", "rms"}, ``determined`` set of names."""

    parameters: dict
    unidentifiable: list
    why: dict = field(default_factory=dict)
    map_u_um: dict = field(default_factory=dict)

    @property
    def determined(self) -> set:
        return set(self.parameters)


def predict(model, parts: list, chosen: list, tool=(0.0, 0.0, 0.0)) -> Prediction:
    """The prediction for the files' Observations ``parts`` and the requested ``chosen``
    parameter names (module docstring)."""
    obs = instruments.stack(parts)
    ranges = data_ranges(model, obs)
    keep, _ = gauge_mask(model, obs, DEGREE, ranges, chosen, constants=False)
    design = blocks.Design(model, obs, DEGREE, ranges, keep)
    labels = list(design.labels)
    w, u_ref = reading_weights(obs)
    fit = _normal_equations(design, obs, split_points(obs.n, 0, 0.25, None), np.sqrt(w))
    est, partners = estimability.estimable(fit.G)
    keep_d, _ = identifiability_gram(fit.G, labels)
    kept = np.flatnonzero(keep_d)
    sc = fit.scale[kept]
    S = np.outer(sc, sc)
    cov = blocks.eig_inverse(fit.G[np.ix_(kept, kept)] / S, SOLVE_TOL) / S * u_ref ** 2
    std = dict(zip(kept.tolist(), np.sqrt(np.maximum(np.diag(cov), 0.0)).tolist()))
    name_of = terms.namer(model, ranges)
    params, unident, why = {}, [], {}
    for j, lab in enumerate(labels):
        if lab[0] == "setup":
            continue
        name = name_of(lab)
        if est[j] and j in std:
            r = terms.report(lab, 0.0, std[j], model, ranges)
            params[name] = {"predicted_std": r["std"], "unit": r["unit"]}
        else:
            unident.append(name)
            why[name] = _why(fit.G[j, j], [name_of(labels[k]) for k in partners.get(j, [])])
    pred = Prediction(params, unident, why)
    pred.map_u_um = map_uncertainty(model, design, labels, kept, cov, ranges, tool)
    return pred


def _why(diag: float, partners: list) -> str:
    if diag <= 0:
        return "no reading of the plan depends on it"
    setup = [p for p in partners if p.startswith("setup:")]
    if partners and len(setup) == len(partners):
        return ("it acts on the readings as the instruments' own set-up unknowns do "
                f"({', '.join(setup[:3])})")
    if partners:
        return f"confounded with {', '.join(partners[:4])}"
    return "its column lies in the span of the others"


def map_uncertainty(model, design, labels, kept, cov, ranges, tool) -> dict:
    """``{"max", "rms"}`` um: the standard uncertainty of the volumetric error's components
    over the map grid (:func:`volerr.plan._information.grid`) from the kept columns."""
    params = [k for k in kept if labels[k][0] != "setup"]
    if not params:
        return {"max": 0.0, "rms": 0.0}
    pos = [kept.tolist().index(k) for k in params]
    C = cov[np.ix_(pos, pos)]
    plabs = [labels[k] for k in params]
    all_labels = parameter_labels(model, DEGREE)
    keep = np.array([lab in plabs for lab in all_labels])
    J = _information.map_rows(model, [lab for lab in all_labels if lab in plabs], keep,
                              DEGREE, ranges, tool)
    order = [plabs.index(lab) for lab in all_labels if lab in plabs]
    C = C[np.ix_(order, order)]
    var = np.einsum("kin,kl,lin->ni", J, C, J)
    u = 1e3 * np.sqrt(np.maximum(var, 0.0))
    return {"max": round(float(u.max()), 5), "rms": round(float(np.sqrt(np.mean(u ** 2))), 5)}
