"""Plans that separate what a campaign leaves undetermined.

Identifiability is a property of the plan, not of the readings: a hypothetical extension of a
file's plan (another tool length, another sphere placement, a circle in another plane, a
calibrated bar ...; each instrument module's ``extensions``) adds design rows without any
measurement.  Stacking them on the campaign's normal equations shows which undetermined
parameters the extension would determine (:func:`volerr.calibrate.estimability.estimable`).
"""

from __future__ import annotations

import numpy as np

from .. import instruments
from ..estimate import blocks
from . import estimability, terms


def suggest(model, parts: list, design, labels: list, G: np.ndarray, undetermined: list,
            u_ref: float, identifiability: dict | None = None) -> list:
    """``[{"adds", "makes_identifiable"}]``: the extensions of the files ``parts`` (their
    Observations) that determine some of ``undetermined`` (report names), best first; a last
    entry ``{"adds": "no extension ...", "makes_identifiable": [], "still_undetermined",
    "why"}`` names what none of them determines and why."""
    if not undetermined:
        return []
    name_of = terms.namer(model, design.ranges)
    names = [name_of(lab) for lab in labels]
    setup_c = [j for j, lab in enumerate(labels) if lab[0] == "setup"]
    params = [j for j, lab in enumerate(labels) if lab[0] != "setup"]
    # extra columns (reversals ...) come last; an extension's plan holds none of them
    n_design = sum(1 for j in params if labels[j][1] != "extra")
    m_c = len(setup_c)
    param_keep = design.keep[len(design.data.setup_labels):]
    kinds = instruments.kinds()
    out = []
    for part in parts:
        kind = part.files[0].kind if part.files else "deviations"
        maker = getattr(kinds.get(kind), "extensions", None)
        if maker is None:
            continue
        for text, ext in maker(model, part):
            keep_e = np.concatenate([np.ones(len(ext.setup_labels), bool), param_keep])
            d_e = blocks.Design(model, ext, design.degree, design.ranges, keep_e)
            w = ext.point_weights() * (u_ref / ext.reference_sigma()) ** 2
            G_e, _, _ = blocks.normal(d_e, np.arange(ext.n), np.sqrt(w), np.zeros(3 * ext.n))
            m_e = len(ext.setup_labels)
            for j, u in enumerate(ext.setup_priors):
                if u and G_e[j, j] > 0:
                    G_e[j, j] += (u_ref / u) ** 2
            size = m_c + m_e + len(params)
            comb = np.zeros((size, size))
            idx_c = np.r_[np.arange(m_c), m_c + m_e + np.arange(len(params))]
            comb[np.ix_(idx_c, idx_c)] += G[np.ix_(setup_c + params, setup_c + params)]
            idx_e = np.r_[m_c + np.arange(m_e), m_c + m_e + np.arange(n_design)]
            comb[np.ix_(idx_e, idx_e)] += G_e
            est, _ = estimability.estimable(comb)
            now = [names[params[k]] for k in range(len(params))
                   if est[m_c + m_e + k] and names[params[k]] in undetermined]
            if now:
                out.append({"adds": f"{part.files[0].name}: {text}" if part.files else text,
                            "makes_identifiable": now})
    out.sort(key=lambda e: -len(e["makes_identifiable"]))
    helped = {n for e in out for n in e["makes_identifiable"]}
    left = [n for n in undetermined if n not in helped]
    if left:
        out.append({"adds": "no extension of these instruments' plans that was tried",
                    "makes_identifiable": [], "still_undetermined": left,
                    "why": _why(left, identifiability or {})})
    return out


def _why(names: list, identifiability: dict) -> str:
    """Plain words for parameters no extension determined."""
    datum = [n for n in names if identifiability.get(n, {}).get("confounded_with")
             and all(p.startswith("setup:") for p in identifiability[n]["confounded_with"])]
    unseen = [n for n in names if not identifiability.get(n, {}).get("seen_by")
              and n not in datum]
    parts = []
    if datum:
        parts.append(f"{', '.join(datum)} act on the readings exactly as the instruments' own "
                     f"set-up unknowns do (a datum of the set-up: a sphere centre, a pivot, a "
                     f"tool length), so no plan of these instruments determines them")
    if unseen:
        parts.append(f"{', '.join(unseen)} do not act on any reading of these instruments")
    rest = [n for n in names if n not in datum and n not in unseen]
    if rest:
        parts.append(f"{', '.join(rest)} stay confounded with other parameters (see "
                     f"identifiability); another instrument is needed")
    return "; ".join(parts) + "."
