"""Effects through a lag after selection: the time constant refined with its standard
uncertainty, and the explanations the campaign cannot tell apart (step 5 of
:func:`volerr.loop.run.run_loop`; the candidates: :func:`volerr.loop.candidates.lagged_covariates`).

Time constant: screening profiles ``tau`` on a geometric grid and refines it between the grid
neighbours (:func:`volerr.loop.select._profile`).  Here the accepted effect's ``tau`` is
profiled again on all training points, given the other accepted effects: the weighted RSS at
13 values ``tau exp(+-0.3)`` (one pass over the rows), a parabola in ``x = ln tau`` through the
best seven, then the same over ``exp(+-0.03)`` around its vertex (``PROFILE_SCALES``); its
vertex is the estimate and its curvature gives the standard uncertainty
``u(x) = sqrt(2 s^2 / RSS''(x))``, ``u(tau) = tau u(x)``, with ``s^2 = RSS / (n - p)``
(the profile-likelihood curvature: the other parameters re-fitted at every ``tau``).

Sensor selection (the rule ``docs/formats.md`` states): forward selection takes the candidate
with the best BIC, where a searched time constant costs one parameter and a difference of two
sensors ``T_a - T_b`` costs one more than a single sensor (the choice of its second sensor);
two accepted effects are replaced by one candidate whenever it explains the data at least as
well by BIC (:func:`volerr.loop.select._merge`); a lag is taken only where it gains more
than ``LAG_EARN`` BIC over the same parameter x the same sensor without one.  Then, for every accepted effect, each other
explanation among the leading candidates (another sensor, the same sensor with or without a
lag, another parameter) that, in place of the accepted effect, is within ``BIC_TIE`` of it
*and* whose cross-validated per-point squared residuals do not differ from the accepted
effect's significantly (|paired t| < ``fitting.CV_T`` over the cross-validation splits) or
whose cross-validated RMS is within ``CV_SAME`` (1 %) of it (nearly equal predictions make a
paired t large for a difference of no consequence) is an *alternative*: the campaign cannot
tell the two apart.  Where an alternative has the better BIC, the two swap places.  The effect then lists them
(``alternatives``) and says what campaign would separate them (``separate_by``).
"""

from __future__ import annotations

import math

import numpy as np

from . import fitting
from .candidates import extra_parameters as _extra
from ..selection.profile import profile_argmin, tau_std
from ..selection.rules import BIC_TIE, CV_SAME, LAG_EARN, paired_t

PROFILE_STEPS = np.linspace(-0.3, 0.3, 13)
PROFILE_SCALES = (1.0, 0.1)   # the coarse pass, then one 10 times narrower around its vertex
MAX_ALTERNATIVES = 3
NEAR = 0.9              # rivals explaining this share of the effect's RSS reduction are refined
BIC_SWAP = 1.0          # an alternative better by more than this is named instead


def prefer_plain(scored: list, top: int) -> None:
    """A lag must earn its place: a lag candidate among the ``top`` leaders gives way (in
    place) to the same parameter x the same sensor without a lag when that one's BIC is not
    worse by ``LAG_EARN`` or more (the plain sensor is the limit tau -> 0)."""
    for i in range(min(top, len(scored))):
        x = scored[i]
        if x.cand.search is None or x.cand.search.what != "lag_s":
            continue
        key = (x.cand.info.get("parameter"), x.cand.info.get("covariate"))
        plain = [j for j, o in enumerate(scored) if j > i and o.cand.info.get("lag_s") is None
                 and (o.cand.info.get("parameter"), o.cand.info.get("covariate")) == key
                 and o.dbic < x.dbic + LAG_EARN]
        if plain:
            scored.insert(i, scored.pop(min(plain, key=lambda j: scored[j].dbic)))


def refine(accepted: list, A0, ctx, train, w_rows, y) -> None:
    """Refine the time constant of every accepted lag effect (in place: candidate, columns,
    ``lag_s`` and ``lag_std_s`` in its info)."""
    for i, a in enumerate(accepted):
        if a.cand.search is None or a.cand.search.what != "lag_s":
            continue
        others = accepted[:i] + accepted[i + 1:]
        base = fitting.full_base(fitting.stack(A0, others), train, w_rows, y)
        tau, std = profile_tau(a.cand, ctx, base, float(a.cand.info["lag_s"]))
        a.cand = a.cand.fixed(tau)
        a.cand.info["lag_std_s"] = None if std is None else round(std, 1)
        a.cols, _ = ctx.columns(a.cand.terms, full=True)


def profile_tau(cand, ctx, base, tau0: float) -> tuple[float, float | None]:
    """(tau, standard uncertainty or None) from the RSS profile around ``tau0`` (s): a coarse
    pass over ``tau0 exp(+-0.3)``, then a pass 10 times narrower around its vertex.  The
    profile is not a parabola over +-15 % in ln tau (it rises faster towards short tau): a
    vertex of the coarse pass alone lies a few per cent short, many standard uncertainties."""
    x0 = math.log(tau0)
    for scale in PROFILE_SCALES:
        fit = _parabola(cand, ctx, base, x0, PROFILE_STEPS * scale)
        if fit is None:
            return round(math.exp(x0), 1), None
        x0, q, rss_min, rank = fit
    dof = max(base.n - len(base.scale) - rank - 1, 1)
    tau = math.exp(x0)
    return round(tau, 1), tau_std(tau, q, rss_min, dof)


def _parabola(cand, ctx, base, x0: float, steps):
    """The RSS profile at ``x0 + steps`` (x = ln tau; :func:`volerr.selection.profile.profile_argmin`):
    (vertex x, curvature coefficient q, least RSS, rank of that column group), or None where
    the profile is not convex."""
    def rss_at(xs):
        groups = [ctx.group(cand.fixed(math.exp(x)).terms) for x in xs]
        scores = base.score_many(groups)
        return np.array([base.rss - g for g, _ in scores]), [r for _, r in scores]

    return profile_argmin(rss_at, x0, steps)


def _explanation(cand) -> tuple:
    info = cand.info
    return (info.get("parameter"), info.get("covariate"), info.get("lag_s") is not None)


def alternatives(accepted: list, pool: list, A0, ctx, train, w_rows, y, folds) -> None:
    """Attach ``alternatives`` (candidates the campaign cannot tell from the accepted effect,
    by the rule of the module docstring) to each accepted effect's evidence (in place)."""
    for i, a in enumerate(accepted):
        others = accepted[:i] + accepted[i + 1:]
        A_o = fitting.stack(A0, others)
        base = fitting.full_base(A_o, train, w_rows, y)
        mine = _explanation(a.cand)
        # another accepted effect's parameter and sensor is that effect's cause: naming it
        # here (or swapping to it) would make two effects of one cause
        rivals, seen = [], {mine} | {_explanation(o.cand)[:2] for o in others}
        names = {o.cand.name for o in accepted}
        for x in pool:
            key = _explanation(x.cand)
            if key in seen or key[:2] in seen or x.cand.name in names:
                continue
            seen.add(key)
            rivals.append(x.cand)
        close, d_a = _close_rivals(a, rivals, ctx, base)
        cv_a = fitting.cv_sq(A_o.plus([a.cols]), y, folds, train, w_rows)
        found = []
        for d_x, c in close[:2 * MAX_ALTERNATIVES]:
            cols, _ = ctx.columns(c.terms, full=True)
            cv_x = fitting.cv_sq(A_o.plus([cols]), y, folds, train, w_rows)
            t = paired_t(cv_x - cv_a)
            ratio = math.sqrt(cv_x.mean() / max(cv_a.mean(), 1e-300))
            if abs(t) < fitting.CV_T or abs(ratio - 1.0) < CV_SAME:
                found.append({"cand": c, "cols": cols, "delta_bic": round(d_x - d_a, 2),
                              "cv_paired_t": round(t, 2)})
            if len(found) == MAX_ALTERNATIVES:
                break
        a.evidence["alternatives"] = _best_first(a, found)
        # the screening's list (RSS reduction within 2 % on a subset), less the rivals judged
        # here and told apart
        told = {c.name for c in rivals} - {x["cand"].name for x in a.evidence["alternatives"]}
        a.evidence["indistinguishable_from"] = [
            n for n in a.evidence.get("indistinguishable_from", [])
            if n not in told and n != a.cand.name]


def _best_first(a, found: list) -> list:
    """Name the explanation with the best BIC: when an alternative beats the accepted effect
    by more than ``BIC_SWAP`` (they are tied, the screening on a subset chose), the two swap
    places (in place); identical columns (a rotary axis' radial error and its location
    error) keep the order of the candidates."""
    if not found:
        return found
    earn = LAG_EARN if (found[0]["cand"].info.get("lag_s") is not None
                        and a.cand.info.get("lag_s") is None) else 0.0
    if found[0]["delta_bic"] > -BIC_SWAP - earn:
        return found
    best = found.pop(0)
    old = {"cand": a.cand, "cols": a.cols, "delta_bic": -best["delta_bic"],
           "cv_paired_t": -best["cv_paired_t"]}
    a.cand, a.cols, a.params = best["cand"], best["cols"], best["cand"].parameters
    for x in found:
        x["delta_bic"] = round(x["delta_bic"] - best["delta_bic"], 2)
    return sorted([old] + found, key=lambda x: x["delta_bic"])


def _close_rivals(a, rivals: list, ctx, base) -> tuple[list, float]:
    """([(dBIC, candidate)] of the rivals within ``BIC_TIE`` of the accepted effect ``a`` in
    its place, best first; a's dBIC).  Rivals that explain at least ``NEAR`` of what ``a``
    explains get their time constant refined on all training points first (as ``a`` had)."""
    scores = base.score_many([fitting.dense_group(a.cols)] + [ctx.group(c.terms) for c in rivals])
    g_a = scores[0][0]
    d_a = base.dbic(g_a, scores[0][1] + _extra(a.cand))
    near = [c for c, (g, r) in zip(rivals, scores[1:]) if r and g >= NEAR * g_a]
    near = sorted(near, key=lambda c: -scores[1 + rivals.index(c)][0])[:2 * MAX_ALTERNATIVES]
    refined = []
    for c in near:
        if c.search is not None and c.search.what == "lag_s":
            tau, std = profile_tau(c, ctx, base, float(c.info["lag_s"]))
            c = c.fixed(tau)
            c.info["lag_std_s"] = None if std is None else round(std, 1)
        refined.append(c)
    scores = base.score_many([ctx.group(c.terms) for c in refined]) if refined else []
    close = [(base.dbic(g, r + _extra(c)), c) for c, (g, r) in zip(refined, scores)
             if r and base.dbic(g, r + _extra(c)) - d_a < BIC_TIE]
    fitting.rank(close, {c.name: i for i, c in enumerate(rivals)}, dbic=lambda t: t[0],
                 name=lambda t: t[1].name)
    return close, d_a


def separate_by(a_info: dict, b_info: dict) -> str:
    """One sentence: what campaign would separate two explanations."""
    ca, cb = a_info.get("covariate"), b_info.get("covariate")
    pa, pb = a_info.get("parameter"), b_info.get("parameter")
    if ca != cb:
        return (f"a campaign in which {ca} and {cb} do not move together: another duty cycle "
                f"(drives switched on and off at other times, the coolant pump on its own "
                f"schedule) or one heat source switched alone")
    if pa != pb:
        return (f"measurements at other positions and probe offsets, where {pa} and {pb} act "
                f"differently")
    tau = a_info.get("lag_s") or b_info.get("lag_s")
    return (f"a campaign in which {ca} changes faster than the lag of {tau / 60:.0f} min "
            f"(shorter on/off periods of its heat source)")
