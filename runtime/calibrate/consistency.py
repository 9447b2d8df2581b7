"""Consistency of the files of a campaign with their stated uncertainties and with each other.

Every reading carries its instrument's stated standard uncertainty ``u`` (the weights of the
fit are ``1 / u^2``), so the weighted residual sum of squares ``chi2`` of a fit is, for data
that agree with the model and with each other, a chi-square variable with ``dof`` = readings
(plus priors) minus the rank of the design.  Two statistics per file:

* **internal**: ``chi2_f = sum (r / u)^2`` over the file's readings in the fit of all files,
  against its share of the degrees of freedom, the sum of the redundancy numbers of its
  readings ``1 - h_ii`` (``= readings - trace(G^+ G_f)``).  The Birge ratio ``sqrt(chi2_f /
  redundancy_f)`` is 1 for a file whose scatter matches its stated uncertainty, with a spread
  of about ``1 / sqrt(2 redundancy_f)``;
* **with the rest** (leave one file out): ``delta_chi2 = chi2(all) - chi2(all but f)`` on
  ``dof_f = readings_f + priors_f - (rank(all) - rank(all but f))`` degrees of freedom: what
  adding the file costs.  It is compared with the chi-square distribution of the stated
  uncertainties -- or, when the rest's own variance factor ``chi2(all but f) / dof(all but
  f)`` exceeds 1 (every file's uncertainty understated), with that factor (an F test: a file
  is then inconsistent only when it is worse than the others).  Readings better than their
  stated uncertainty are never an inconsistency.

A file whose p-value is below ``alpha / files`` (Bonferroni) is inconsistent; the worst is
named, left out, and the test repeated on the others until none is (data snooping by files:
one biased file does not make the others look bad).  All from the per-file normal equations
(no refit of the rows).
"""

from __future__ import annotations

import math

import numpy as np

#: overall false-alarm probability of the file test (divided among the files)
ALPHA = 0.01
#: relative eigenvalue below which a direction counts as undetermined
TOL = 1e-12


def _solve(G, b, yy) -> tuple[float, int]:
    """(weighted residual sum of squares, rank) of the least-squares problem with normal
    equations ``G x = b`` and ``yy = y' W y``."""
    d = np.sqrt(np.maximum(np.diag(G), 0.0))
    on = d > 0
    if not on.any():
        return float(yy), 0
    C = G[np.ix_(on, on)] / np.outer(d[on], d[on])
    w, V = np.linalg.eigh(C)
    keep = w > TOL * max(float(w[-1]), 1e-300)
    bb = V[:, keep].T @ (b[on] / d[on])
    return float(yy - np.sum(bb ** 2 / w[keep])), int(keep.sum())


def _sum(items, idx):
    return sum(items[i] for i in idx)


def leave_one_out(fit, n_read: list, active: list, u_ref: float) -> dict:
    """Per file of ``active`` (indices): {"chi2", "dof", "rest_chi2", "rest_dof"} of adding it
    to the others (chi2 absolute: in units of the stated uncertainties)."""
    G = _sum(fit.G_files, active)
    b = _sum(fit.b_files, active)
    yy = _sum(fit.yy_files, active)
    chi_all, rank_all = _solve(G, b, yy)
    n_all = sum(n_read[i] + fit.priors_files[i] for i in active)
    out = {}
    for f in active:
        rest = [i for i in active if i != f]
        chi_rest, rank_rest = _solve(G - fit.G_files[f], b - fit.b_files[f],
                                     yy - fit.yy_files[f])
        dof = n_read[f] + fit.priors_files[f] - (rank_all - rank_rest)
        n_rest = sum(n_read[i] + fit.priors_files[i] for i in rest)
        out[f] = {"chi2": max(chi_all - chi_rest, 0.0) / u_ref ** 2, "dof": int(dof),
                  "rest_chi2": max(chi_rest, 0.0) / u_ref ** 2,
                  "rest_dof": int(n_rest - rank_rest), "all_dof": int(n_all - rank_all)}
    return out


def p_value(stat: dict) -> float | None:
    """p-value of a file's leave-one-out statistic: the chi-square test of the stated
    uncertainties, or the F test against the rest's variance factor when that exceeds 1 (the
    stated uncertainties too small for every file: a file is then inconsistent only when it
    is worse than the others)."""
    from scipy import stats

    if stat["dof"] <= 0:
        return None
    if stat["rest_dof"] >= 1 and stat["rest_chi2"] > stat["rest_dof"]:
        F = (stat["chi2"] / stat["dof"]) / (stat["rest_chi2"] / stat["rest_dof"])
        return float(stats.f.sf(F, stat["dof"], stat["rest_dof"]))
    return float(stats.chi2.sf(stat["chi2"], stat["dof"]))


def check(fit, sol, obs, u_ref: float, alpha: float = ALPHA) -> dict:
    """The report's ``consistency`` entry (module docstring): ``{"method", "alpha", "files":
    [{"file", "kind", "chi2", "redundancy", "birge_ratio", "birge_spread", "loo_chi2",
    "loo_dof", "loo_birge_ratio", "rest_variance_factor", "p_value", "consistent"}],
    "inconsistent": [file, ...] (in the order found)}``."""
    files = obs.files
    n_files = len(fit.G_files)
    file_of = obs.file if obs.file is not None else np.zeros(obs.n, int)
    rows = obs.readings_per_point()
    n_read = [int(rows[file_of == f].sum()) for f in range(n_files)]
    kept = sol.kept
    sc = fit.scale[kept]
    entries = []
    for f in range(n_files):
        Gf = fit.G_files[f][np.ix_(kept, kept)] / np.outer(sc, sc)
        red = n_read[f] + fit.priors_files[f] - float(np.sum(sol.Gi * Gf))
        chi = sol.rss_files.get(f, 0.0) / u_ref ** 2
        birge = math.sqrt(chi / red) if red > 0.5 else None
        entries.append({"file": files[f].name if f < len(files) else f"file{f + 1}",
                        "kind": files[f].kind if f < len(files) else "deviations",
                        "chi2": round(chi, 4), "redundancy": round(red, 3),
                        "birge_ratio": None if birge is None else round(birge, 4),
                        "birge_spread": None if red <= 0.5 else round(1 / math.sqrt(2 * red),
                                                                        4),
                        "loo_chi2": None, "loo_dof": None, "loo_birge_ratio": None,
                        "rest_variance_factor": None, "p_value": None, "consistent": True})
    active = list(range(n_files))
    found = []
    first = True
    while len(active) >= 2:
        stats_ = leave_one_out(fit, n_read, active, u_ref)
        pv = {f: p_value(s) for f, s in stats_.items()}
        if first:
            for f, s in stats_.items():
                e = entries[f]
                e.update({"loo_chi2": round(s["chi2"], 4), "loo_dof": s["dof"],
                          "loo_birge_ratio": (round(math.sqrt(s["chi2"] / s["dof"]), 4)
                                              if s["dof"] > 0 else None),
                          "rest_variance_factor": (round(s["rest_chi2"] / s["rest_dof"], 4)
                                                   if s["rest_dof"] > 0 else None),
                          "p_value": None if pv[f] is None else float(f"{pv[f]:.4g}")})
            first = False
        limit = alpha / len(active)
        bad = [f for f in active if pv[f] is not None and pv[f] < limit]
        if not bad:
            break
        worst = min(bad, key=lambda f: pv[f])
        entries[worst]["consistent"] = False
        if entries[worst]["p_value"] is None or pv[worst] < entries[worst]["p_value"]:
            entries[worst]["p_value"] = float(f"{pv[worst]:.4g}")
        found.append(entries[worst]["file"])
        active.remove(worst)
    return {"method": "per file: chi2 of its readings (r/u)^2 in the fit of all files against "
                      "its redundancy (Birge ratio, spread ~ 1/sqrt(2 redundancy)); "
                      "consistency with the rest: the chi2 the file adds to the fit of the "
                      "others on its degrees of freedom, tested against the stated "
                      "uncertainties (F test against the others' variance factor when that "
                      "exceeds 1); a file with p < alpha / files is inconsistent, named, left "
                      "out, and the test repeated",
            "alpha": alpha, "files": entries, "inconsistent": found}
