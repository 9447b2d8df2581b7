"""The baselines as candidates of the drift loop's selection, and the prediction interval of
the model chosen (:func:`volerr.loop.drift.fit.run_drift` calls :func:`choose` per channel).

Three families compete per channel, scored by the SAME blocked cross-validation (the folds of
:func:`volerr.loop.drift.basis.folds`; a fold of whole runs predicted from the run's first
reading, a fold of stretches from the run's zero fitted on the other stretches):

* ``constant``: a zero per run (the training mean of each run; a held-out run its first
  reading): the declared model;
* ``static``: the static multiple linear regression on all temperatures (their change since
  the run's start) plus a zero per run, ridge-free least squares on the training readings;
* ``lag``: the terms the selection chose (heat input and sensors through lags).

A fourth candidate, ``regularised`` (:mod:`volerr.loop.drift.shrink`): every column the
lag selection may take at once, shrunk by ridge with weights growing with the lag; it is the
channel's model where its CV error is significantly below both baselines' (the rule below),
unless the lag model's is significantly below its own as well; the lag model's terms are
named wherever the lag model beats both baselines (``named``), even where the regularised
fit predicts (it names no effect itself).

The rule (:func:`volerr.selection.rules.significantly_below`): every fold's CV residuals are
cut into ``SUB_BLOCKS`` consecutive blocks (nearly equal: on FL_THERMAL 35-50 min of readings)
and the lag model is the channel's model only when, against each baseline, the paired t over
those blocks of ``baseline's - lag model's`` mean square is at least the one-sided 95 %
Student quantile (n - 1 degrees of freedom).  The mean of those differences is the
difference of the pooled CV mean squares, the score the selection minimises; the t asks that
it stand out of its block-to-block scatter.  Blocks within folds, not the folds alone: six
folds leave 5 degrees of freedom, and on FL_THERMAL's publication split (training on the
first 60 %) no channel's gain was significant at the folds' level although the lag model's
pooled CV mean square was half the static regression's and its held-out MAE 2-6x lower.
Blocks of residuals 15 s apart are autocorrelated: the t of short blocks is optimistic,
which is why they are kept at tens of minutes.  Otherwise the better baseline (the lower
cross-validated mean square; a tie to the constant) is the channel's model and the report
says so.  (A lag model whose terms are all plain temperatures is a sub-model of the static
regression: there the static regression is the more complex and must be significantly
below the lag model instead.)

Many runs (:func:`volerr.loop.drift.basis.many_runs`: folds of whole runs and at least
``basis.MANY_RUNS`` training runs): the unit of
the paired test is the run, one CV mean square per training run (n - 1 degrees of freedom),
not ``SUB_BLOCKS`` blocks of every fold: a run's level error is one error, and its blocks are
not independent of each other.  The static regression, judged the same way, is then the
better baseline only when significantly below the constant run by run (many near-collinear
temperatures fit within runs and need not carry across them).

The prediction interval of the model chosen: :mod:`volerr.loop.drift.interval`.

Judged afterwards on the held-out readings (:func:`held_out_verdict`; it changes no choice):
the named effects are the lag model's terms, named wherever the CV finds the lag model
significantly below both baselines, even where another family predicts.  Whether that
diagnosis holds on readings no choice saw is issue 44's bar for a model: the lag model's
held-out MAE at most ``HELD_OUT_REL`` x the better baseline's (static regression or
constant, the lower held-out MAE) + ``HELD_OUT_ABS_UM``.  Where it is above, the terms
describe the training readings, not a transfer.
"""

from __future__ import annotations

import math

import numpy as np

from ...selection.linalg import solve_scaled
from ...selection.rules import TIE_SCORE_REL, paired_t, significantly_below, t95
from . import basis

FAMILIES = ("constant", "static", "lag")
#: consecutive blocks each fold's CV residuals are cut into for the paired test
SUB_BLOCKS = 8
LEVEL = 0.95
NAMES = {"constant": "a constant (each run's zero)",
         "static": "the static regression on all temperatures",
         "lag": "the lag model",
         "regularised": "the regularised fit over the lag bank"}
RIVAL = {"static": "static regression", "constant": "constant",
         "regularised": "regularised fit over the lag bank"}
#: issue 44's bar for a model on held-out readings: its MAE at most HELD_OUT_REL x the
#: better baseline's + HELD_OUT_ABS_UM (um; a relative and an absolute allowance: 5 % of the
#: baseline, and 0.2 um where both are near the readings' noise)
HELD_OUT_REL = 1.05
HELD_OUT_ABS_UM = 0.2
HELD_OUT_RULE = (f"confirmed where the lag model's held-out MAE <= {HELD_OUT_REL:g} x the "
                 f"better baseline's (static regression or constant, the lower held-out MAE) "
                 f"+ {HELD_OUT_ABS_UM:g} um (issue 44's bar for a model)")


def cv_residuals(ch, D) -> np.ndarray:
    """Blocked-CV residual (N,) um of the model with the design ``D`` (run indicators first)
    at every training reading (NaN elsewhere): fold k predicted by the fit on the other
    training folds (a fold of whole runs from the run's first reading plus the terms)."""
    y, fold, n_runs = ch.y, ch.fold, ch.n_runs
    r = np.full(len(y), np.nan)
    first = ch.s.run_zeros(y)
    K = int(fold.max()) + 1
    parts = [(D[fold == k].T @ D[fold == k], D[fold == k].T @ y[fold == k]) for k in range(K)]
    G, h = sum(p[0] for p in parts), sum(p[1] for p in parts)
    for k in range(K):
        m = fold == k
        b = solve_scaled(G - parts[k][0], h - parts[k][1])   # the fit on the other folds
        if basis.whole_runs(ch.rule):
            pred = first[ch.s.run[m]] + D[m, n_runs:] @ b[n_runs:]
        else:
            pred = D[m] @ b
        r[m] = y[m] - pred
    return r


def block_mse(fold, r, sub: int = SUB_BLOCKS) -> np.ndarray:
    """The mean squares (um^2) of the CV residuals ``r`` over ``sub`` consecutive blocks of
    every fold (nearly equal blocks, in fold then time order)."""
    out = []
    for k in range(int(fold.max()) + 1):
        for part in np.array_split(np.flatnonzero(fold == k), sub):
            if len(part):
                out.append(float(np.mean(r[part] ** 2)))
    return np.array(out)


def by_runs(ch) -> bool:
    """Whether the paired test's unit is the run (module docstring): folds of whole runs and
    at least ``basis.MANY_RUNS`` training runs (:func:`volerr.loop.drift.basis.many_runs`)."""
    runs = np.unique(ch.s.run[ch.fold >= 0])
    return basis.whole_runs(ch.rule) and len(runs) >= basis.MANY_RUNS


def unit_mse(ch, r) -> np.ndarray:
    """The mean squares (um^2) of the CV residuals ``r`` per unit of the paired test: per
    training run (:func:`by_runs`), else per block (:func:`block_mse`)."""
    if not by_runs(ch):
        return block_mse(ch.fold, r)
    tr = ch.fold >= 0
    return np.array([float(np.mean(r[tr & (ch.s.run == k)] ** 2))
                     for k in np.unique(ch.s.run[tr])])


def without_each(ch, D) -> list:
    """Per term of the lag model with the design ``D`` (run indicators first, then one column
    per term): whether these data decide it, by the rule the families are judged by
    (:func:`volerr.selection.rules.significantly_below` over the units of
    :func:`unit_mse`): the model with it must be significantly below the model without it
    (the same terms otherwise, their time constants as they stand).  Where it is not, the
    model without it is an alternative the cross-validation cannot tell apart.  Returns
    [{"cv_decided": bool, "cv_without": {"cv_rms_um", "paired_t"}}] (the paired t of the
    units' (without - with) mean squares, positive where the term helps; um)."""
    tr = ch.fold >= 0
    full = unit_mse(ch, cv_residuals(ch, D))
    out = []
    for j in range(ch.n_runs, D.shape[1]):
        r = cv_residuals(ch, np.delete(D, j, axis=1))
        mse = unit_mse(ch, r)
        out.append({"cv_decided": bool(significantly_below(full, mse)),
                    "cv_without": {"cv_rms_um": round(math.sqrt(float(np.mean(r[tr] ** 2))), 6),
                                   "paired_t": round(paired_t(mse - full), 3)}})
    return out


def equivalent_families(mse: dict, cv_rms: dict, fam: str, has_terms: bool) -> list:
    """The families the cross-validation cannot tell from the reported ``fam``: neither's
    unit mean squares (``mse`` family -> (n,)) significantly below the other's (the rule of
    :func:`choose`), the lowest CV RMS first: [{"family", "cv_rms_um", "paired_t"}] (the
    paired t of (family's - reported's) mean squares: positive where the family is the
    worse).  The lag model without terms is the constant and is not listed."""
    out = [{"family": f, "cv_rms_um": round(cv_rms[f], 6),
            "paired_t": round(paired_t(mse[f] - mse[fam]), 3)}
           for f in mse if f != fam and (f != "lag" or has_terms)
           and not significantly_below(mse[fam], mse[f])
           and not significantly_below(mse[f], mse[fam])]
    return sorted(out, key=lambda x: (x["cv_rms_um"], x["family"]))


def choose(ch, designs: dict, has_terms: bool, nested: bool = False,
           regularised=None) -> dict:
    """The family of the channel by the module's rule: ``designs`` family -> design matrix;
    ``has_terms`` False: the lag model has no term (it is the constant); ``nested``: its
    terms are plain temperatures (no lag, no heat input): a sub-model of the static
    regression, which then must be significantly below it to be preferred;
    ``regularised``: the blocked-CV residuals (N,) of the regularised fit over the lag bank
    (:mod:`volerr.loop.drift.shrink`), a fourth candidate (None: three).  Returns
    {"family", "cv_rms_um" {family: um}, "t" {"static_vs_constant", "lag_vs_constant",
    "lag_vs_static"; with the fourth "regularised_vs_constant", "regularised_vs_static",
    "lag_vs_regularised"}, "rule", "cv_resid" (N,) of the chosen family, "equivalent" the
    families the cross-validation cannot tell from it (:func:`equivalent_families`)}."""
    resid = {f: cv_residuals(ch, designs[f]) for f in FAMILIES if f in designs}
    if regularised is not None:
        resid["regularised"] = regularised
    mse = {f: unit_mse(ch, r) for f, r in resid.items()}
    tr = ch.fold >= 0
    cv_rms = {f: math.sqrt(float(np.mean(r[tr] ** 2))) for f, r in resid.items()}
    pairs = [("static", "constant"), ("lag", "constant"), ("lag", "static")]
    if regularised is not None:
        pairs += [("regularised", "constant"), ("regularised", "static"),
                  ("lag", "regularised")]
    t = {f"{a}_vs_{b}": paired_t(mse[b] - mse[a]) for a, b in pairs}
    # the better baseline: the lower CV mean square (a tie to the constant, the simpler); run
    # by run, the static regression must be significantly below the constant (many runs)
    fam = "static" if cv_rms["static"] < cv_rms["constant"] * (1 - TIE_SCORE_REL) else "constant"
    if by_runs(ch) and not significantly_below(mse["static"], mse["constant"]):
        fam = "constant"
    reg_ok = regularised is not None and all(significantly_below(mse["regularised"], mse[b])
                                             for b in ("static", "constant"))
    if reg_ok:
        fam = "regularised"
    # a lag model of plain temperatures only is a sub-model of the static regression: there
    # the static regression is the more complex one and must beat it significantly
    beats_static = (not significantly_below(mse["static"], mse["lag"]) if nested else
                    significantly_below(mse["lag"], mse["static"]))
    named = has_terms and significantly_below(mse["lag"], mse["constant"]) and beats_static
    if named and (not reg_ok or significantly_below(mse["lag"], mse["regularised"])):
        fam = "lag"
    K = len(mse["lag"])
    units = ("training runs (one CV mean square per run: the run is the unit of "
             "independence)" if by_runs(ch) else
             f"blocks ({SUB_BLOCKS} per blocked CV fold)")
    return {"family": fam, "named": named and fam in ("lag", "regularised"),
            "cv_rms_um": cv_rms, "t": t, "t_crit": t95(K - 1),
            "cv_resid": resid[fam], "paired_units": "runs" if by_runs(ch) else "blocks",
            "equivalent": equivalent_families(mse, cv_rms, fam, has_terms),
            "rule": _rule_text(K, regularised is not None, units)}


def _rule_text(K: int, regularised: bool, units: str) -> str:
    if not regularised:
        return (f"lag model only if, against each baseline, the paired t over {K} {units} "
                f"of (baseline's - lag model's CV mean square) >= {t95(K - 1):.3f} "
                f"(one-sided 95 %, {K - 1} df); else the baseline of lower CV mean square")
    return (f"the regularised fit over the lag bank if, against each baseline, the paired t "
            f"over {K} {units} of (baseline's - its CV mean square) >= {t95(K - 1):.3f} "
            f"(one-sided 95 %, {K - 1} df), unless the lag model is so below it; the lag "
            f"model if so below each baseline (its terms named wherever it is, the prediction "
            f"the regularised fit's unless the lag model beats it too); else the baseline of "
            f"lower CV mean square")


def verdict(family: str, cv_rms: dict, t: dict, has_terms: bool, t_crit: float,
            named: bool = False) -> str:
    """One sentence: which model the channel reports, and why (``named``: the lag model's
    terms are named, :func:`choose`)."""
    reg = "regularised" in cv_rms
    figs = (f"CV RMS lag model {cv_rms['lag']:.3f}, "
            + (f"regularised fit {cv_rms['regularised']:.3f}, " if reg else "")
            + f"static regression {cv_rms['static']:.3f}, constant {cv_rms['constant']:.3f} um")
    if family == "lag":
        return (f"the lag model beats both baselines{' and the regularised fit' if reg else ''}"
                f" significantly ({figs})")
    rivals = ("static", "constant") + (("regularised",) if reg else ())
    lost = [b for b in rivals if not t[f"lag_vs_{b}"] >= t_crit] or ["static"]
    worst = min(t[f"lag_vs_{b}"] for b in lost)
    what = " and the ".join(RIVAL[b] for b in lost)
    why = (f"no lag term earns a place" if not has_terms else
           f"no lag model beats the {what} here (paired t {worst:.2f} < {t_crit:.2f})")
    if family == "regularised" and named:
        tr = t["lag_vs_regularised"]
        return (f"the lag model beats both baselines significantly but not the regularised "
                f"fit over the lag bank (paired t {tr:.2f} < {t_crit:.2f}; {figs}): the "
                f"model is {NAMES['regularised']}; the lag model's terms are named as the "
                f"diagnosis")
    if family == "regularised":
        return (f"{why}; {NAMES['regularised']} beats both baselines significantly ({figs}): "
                f"the model is {NAMES['regularised']} (it names no effect)")
    if not has_terms:
        return f"{why}: the model is {NAMES[family]} ({figs})"
    return (f"no lag model beats the {what} here (paired t {worst:.2f} < {t_crit:.2f}; {figs}):"
            f" the model is {NAMES[family]}")


def reported_held_out(c: dict) -> dict | None:
    """Whether the model the channel reports (its family, whichever) holds on the held-out
    readings, by the bar of :func:`held_out_verdict` (its JSON ``c``: ``n_test``,
    ``family``, ``mae_after_um``, ``baselines``).  None where no reading is held out.  Where
    it fails, the choice the training readings made did not carry over (say a room held
    constant in training and varying in the held-out runs): named, not mended by choosing
    on the held-out readings.  Returns {"family", "mae_um", "baseline_mae_um", "baseline",
    "bound_um", "within"}."""
    if not c.get("n_test") or "family" not in c:
        return None
    base, ref, bound = _held_out_bar(c)
    mae = c["mae_after_um"]
    return {"family": c["family"], "mae_um": mae, "baseline_mae_um": ref, "baseline": base,
            "bound_um": bound, "within": bool(mae <= bound)}


def _held_out_bar(c: dict) -> tuple:
    """(the better baseline on the held-out readings, its held-out MAE, the bar ``HELD_OUT_REL``
    x that + ``HELD_OUT_ABS_UM``), um; a tie to the static regression."""
    b = c["baselines"]
    base = "static" if b["static"]["mae_um"] <= b["constant"]["mae_um"] else "constant"
    ref = b[base]["mae_um"]
    return base, ref, HELD_OUT_REL * ref + HELD_OUT_ABS_UM


def held_out_verdict(c: dict) -> dict | None:
    """Whether the lag model holds on the held-out readings of a channel (its JSON ``c``:
    ``n_test``, ``lag_model``, ``baselines``; the rule of the module docstring, ``bound_um``
    its bound, um).  None where no reading is held out (not judged).  The baseline is the
    one of lower held-out MAE (a tie to the static regression).  Returns
    {"lag_model_mae_um", "baseline_mae_um", "baseline", "bound_um", "confirmed"}."""
    if not c.get("n_test"):
        return None
    base, ref, bound = _held_out_bar(c)
    lag = c["lag_model"]["mae_um"]
    return {"lag_model_mae_um": lag, "baseline_mae_um": ref, "baseline": base,
            "bound_um": bound, "confirmed": bool(lag <= bound)}
