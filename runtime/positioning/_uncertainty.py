"""Measurement uncertainty of the ISO 230-2 figures (A, E, M, R, B) and their verdicts.

The budget follows the structure of ISO/TR 230-9:2005 (estimation of measurement uncertainty
for machine tool tests, basic equations: contributions combined in quadrature, U = 2 u_c) and
the contributors ISO 230-2:2014 Annex A names for a linear positioning test with a laser
interferometer.  L is the measured travel (last minus first target), n the cycles per
direction, S the largest unidirectional repeatability estimator S_i of the run.  Standard
uncertainties in um:

* instrument (``u_DEVICE``): the interferometer's accuracy over L, ``instrument_ppm`` (a
  maximum permissible error, rectangular): u = ppm * 1e-6 * L / sqrt(3);
* alignment (``u_MISALIGNMENT``): a beam offset D over L gives the cosine error
  e = D^2 / (2 L), always a shortening, rectangular on [0, e]: u = e / sqrt(12);
* temperature, after correction to 20 degC with the coefficient alpha (``--cte-ppm-per-K``):
  the temperature reading, u = L alpha u(T), and the coefficient, u = L |T - 20| u(alpha)
  (``u_M,MACHINE``); not evaluated without a correction (noted);
* environmental variation (``u_EVE``): the drift range EVE of a separate drift test,
  rectangular: u = EVE / (2 sqrt(3)); not included when not measured (noted);
* repeatability, from the run itself: E is a range of means of n readings:
  u = S sqrt(2 / n); M of means of 2 n readings: u = S / sqrt(n); B a difference of two means
  of n readings: u = S sqrt(2 / n); R = 4 S (at most) carries the uncertainty of an estimated
  standard deviation, u(S) = S / sqrt(2 (n - 1)): u = 4 u(S); A = a range of x + 2 S values:
  u = sqrt(2 S^2 / n + 2 (2 u(S))^2).

E, M and A collect every contribution; R and B are differences at one target, where the
instrument, alignment and temperature terms cancel: only EVE and the repeatability remain.

Verdicts (``tolerance_um``): ISO 14253-1 per quantity, :func:`volerr.conformance.verdict`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import conformance
from ..units import UM_PER_MM

QUANTITIES = ("A", "E", "M", "R", "B")
#: contributions that act on each quantity (the rest cancel, module docstring)
_ACTS_ON = {"instrument": "AEM", "alignment": "AEM", "temperature": "AEM",
            "cte": "AEM", "environment": "AEMRB", "repeatability": "AEMRB"}


@dataclass(frozen=True)
class BudgetInputs:
    """What the user states about the test: instrument accuracy (ppm of length, rectangular),
    beam alignment offset over the travel (mm), standard uncertainties of the material
    temperature (K) and of the expansion coefficient (ppm/K), the environmental variation
    error of a drift test (um, None: not measured)."""

    instrument_ppm: float = 0.5
    alignment_mm: float = 0.1
    temperature_u_K: float = 0.2
    cte_u_ppm_per_K: float = 1.0
    eve_um: float | None = None


def budget(ev, thermal, inputs: BudgetInputs) -> dict:
    """Standard uncertainties (um) of every contribution and the expanded uncertainty U (k = 2)
    of A, E, M, R, B for the evaluation ``ev`` (:class:`volerr.positioning.Evaluation`) with
    the thermal correction ``thermal`` (None: not corrected).

    Returns ``{"contributions_um": {name: u}, "uncertainty_um": {Q: U}, "notes": [...],
    "inputs": {...}}``."""
    L = float(ev.run.targets[-1] - ev.run.targets[0])          # mm
    n = ev.run.n_cycles
    S = float(max(np.max(ev.s_fwd), np.max(ev.s_bwd))) * UM_PER_MM
    uS = S / math.sqrt(2 * (n - 1))
    notes = []
    c = {"instrument": inputs.instrument_ppm * 1e-6 * L * UM_PER_MM / math.sqrt(3),
         "alignment": (inputs.alignment_mm ** 2 / (2 * L) * UM_PER_MM / math.sqrt(12)
                       if L > 0 else 0.0)}
    if thermal is not None:
        dT = abs(thermal.temperature_C[1] - 20.0)
        c["temperature"] = L * thermal.cte_ppm_per_K * inputs.temperature_u_K * 1e-3
        c["cte"] = L * dT * inputs.cte_u_ppm_per_K * 1e-3
    else:
        notes.append("temperature contribution not evaluated: no correction to 20 degC "
                     "(give --cte-ppm-per-K and the material temperature)")
    if inputs.eve_um is not None:
        c["environment"] = inputs.eve_um / (2 * math.sqrt(3))
    else:
        notes.append("environmental variation error (EVE) not measured: not included "
                     "(give --eve-um from a drift test)")
    rep = {"E": S * math.sqrt(2 / n), "M": S / math.sqrt(n), "B": S * math.sqrt(2 / n),
           "R": 4 * uS, "A": math.sqrt(2 * S ** 2 / n + 2 * (2 * uS) ** 2)}
    U = {}
    for q in QUANTITIES:
        var = sum(v ** 2 for k, v in c.items() if q in _ACTS_ON[k]) + rep[q] ** 2
        U[q] = 2.0 * math.sqrt(var)
    return {"budgets": _budgets(c, rep, L, thermal, inputs),"contributions_um": {**{k: float(v) for k, v in c.items()},
                                 **{f"repeatability_{q}": float(v) for q, v in rep.items()}},
            "uncertainty_um": {q: float(v) for q, v in U.items()},
            "coverage_factor": 2, "travel_mm": L, "notes": notes,
            "inputs": {"instrument_ppm": inputs.instrument_ppm,
                       "alignment_mm": inputs.alignment_mm,
                       "temperature_u_K": inputs.temperature_u_K,
                       "cte_u_ppm_per_K": inputs.cte_u_ppm_per_K, "eve_um": inputs.eve_um}}


def _budgets(c: dict, rep: dict, L: float, thermal, inputs: BudgetInputs) -> dict:
    """Per quantity its GUM budget (:mod:`volerr.report.budget`): each contribution of
    :func:`budget` as the source's standard uncertainty in its own unit times its
    sensitivity (the same numbers, written as u(x_i) and c_i), U = 2 u_c."""
    from ..report.budget import budget as gum, source

    s = {"instrument": lambda: source("instrument (interferometer accuracy, rectangular)",
                                      inputs.instrument_ppm / math.sqrt(3), "ppm", L * 1e-3),
         "alignment": lambda: source("alignment (cosine error, rectangular)", c["alignment"],
                                     "um"),
         "temperature": lambda: source("material temperature reading", inputs.temperature_u_K,
                                       "K", L * thermal.cte_ppm_per_K * 1e-3),
         "cte": lambda: source("expansion coefficient", inputs.cte_u_ppm_per_K, "ppm/K",
                               L * abs(thermal.temperature_C[1] - 20.0) * 1e-3),
         "environment": lambda: source("environmental variation (EVE, rectangular)",
                                       c["environment"], "um")}
    out = {}
    for q in QUANTITIES:
        srcs = [s[k]() for k in c if q in _ACTS_ON[k]]
        srcs.append(source("repeatability (from the run)", rep[q], "um"))
        out[q] = gum(q, "um", srcs, k=2.0)
    return out


def verdicts(figures_um: dict, U: dict, tolerance_um: dict) -> dict:
    """Per toleranced quantity its ISO 14253-1 verdict (upper limit = the tolerance), and the
    overall one: ``{"verdicts": {Q: v}, "verdict": v}``."""
    per = {q: conformance.verdict(figures_um[f"{q}_um"], t, U[q])
           for q, t in tolerance_um.items()}
    return {"verdicts": per, "verdict": conformance.overall(per.values())}


def decisive_targets(ev, quantity: str) -> list:
    """(target index, direction or None) of the readings that make ``quantity`` what it is:
    where its maximum and minimum lie (A, E, M), its largest R_i or |B_i| (R, B)."""
    if quantity == "M":
        return [(int(np.argmax(ev.mean)), None), (int(np.argmin(ev.mean)), None)]
    if quantity in ("R", "B"):
        v = ev.R_i if quantity == "R" else np.abs(ev.reversal)
        return [(int(np.argmax(v)), None)]
    xm = np.stack([ev.mean_fwd, ev.mean_bwd], axis=1)
    s = np.stack([ev.s_fwd, ev.s_bwd], axis=1) if quantity == "A" else 0.0 * xm
    hi, lo = xm + 2 * s, xm - 2 * s
    i, d = np.unravel_index(np.argmax(hi), hi.shape)
    k, e = np.unravel_index(np.argmin(lo), lo.shape)
    return [(int(i), int(d)), (int(k), int(e))]
