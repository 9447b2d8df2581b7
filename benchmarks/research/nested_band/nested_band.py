"""Research version of RULE.md's rule (not the package), patched into the CLI's process by
``sitecustomize.py``:

``NESTED_BAND=1`` (the candidate): where today's family is the lag model, its CV residuals
nested (``../nested_cv/nested.py``'s ``nested_residuals``, reused) and ``family.choose``
run again with them; the band's ``q`` the split-conformal ``ceil(0.95 (n + 1))``-th
smallest of the ``n`` pooled training scores ``abs(r) / sigma`` (``sigma`` today's).

``NESTED_BAND=2`` (RULE.md addendum 1): the same nested choice; ``q`` the scale at which
one more fold's expected coverage is 95 % under today's log-normal predictive model of the
folds' scale (:func:`expected_q`).

``NESTED_BAND=log`` (an observer for the baseline): nothing changes; the log says what the
candidate's ``q`` would give on today's choice.

``NESTED_BAND_LOG=FILE``: one JSON line per channel and call: {"json", "label", "family",
"nested", "family_before", "cpu_nested_s", "q_today", "q_pooled", "q_expected", "n_test",
"inside_today", "inside_pooled", "inside_expected"} (inside: held-out readings with abs(y - pred) <= q sigma,
before the room / kept-out widenings, which neither rule changes)."""
import json
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "nested_cv"))
import nested  # noqa: E402  (the nested selection of ../nested_cv, reused as it is)

from volerr.loop.drift import family, fit, run  # noqa: E402
from volerr.loop.drift import interval as band  # noqa: E402

MODE = os.environ.get("NESTED_BAND", "")
_state = {"label": "?", "family": "?", "nested": {}}


def _log(rec):
    path = os.environ.get("NESTED_BAND_LOG")
    if path:
        argv = sys.argv
        rec = {"json": argv[argv.index("--json") + 1] if "--json" in argv else "", **rec}
        with open(path, "a") as f:
            f.write(json.dumps(rec) + "\n")


def pooled_q(cv_resid, sigma, fold) -> float:
    """The split-conformal ``ceil((1 - alpha)(n + 1))``-th smallest of the ``n`` finite
    training scores ``abs(r) / sigma`` (alpha = 1 - LEVEL), the largest where that rank
    exceeds n (RULE.md step 2; Lei et al. 2018, JASA 113, 2.2)."""
    z = np.abs(cv_resid[fold >= 0]) / sigma[fold >= 0]
    z = np.sort(z[np.isfinite(z)])
    if not len(z):
        return float("nan")
    k = math.ceil(band.LEVEL * (len(z) + 1))
    return float(z[min(k, len(z)) - 1])


#: the quantiles of T at which the expected coverage is integrated (RULE.md addendum 1)
T_POINTS = 2000


def expected_q(cv_resid, sigma, fold) -> float:
    """The ``q`` at which one more fold's expected coverage is ``LEVEL`` (RULE.md addendum
    1): the folds' 95 % quantiles ``q_k`` of the scores ``abs(r) / sigma``, the scores over
    their fold's ``q_k`` pooled (``F_u``), one more fold's scale log-normal with today's
    Student predictive spread; ``q`` solves ``E_T[F_u(q / s)] = LEVEL`` (bisection on ln q)."""
    from scipy.stats import t as student
    qs, us = [], []
    for k in range(int(fold.max()) + 1):
        z = np.abs(cv_resid[fold == k]) / sigma[fold == k]
        z = z[np.isfinite(z)]
        if len(z):
            qk = float(np.quantile(z, band.LEVEL))
            qs.append(qk)
            if qk > 0:
                us.append(z / qk)
    pos = np.array([q for q in qs if q > 0])
    if len(pos) < 2:
        return float(max(qs)) if qs else float("nan")
    K, ln = len(pos), np.log(pos)
    T = student.ppf((np.arange(T_POINTS) + 0.5) / T_POINTS, K - 1)
    s = np.exp(ln.mean() + ln.std(ddof=1) * np.sqrt(1.0 + 1.0 / K) * T)
    u = np.sort(np.concatenate(us))
    u = u[u > 0] if np.any(u > 0) else u

    def coverage(lnq):
        return np.searchsorted(u, np.exp(lnq) / s, side="right").mean() / len(u)

    lo, hi = np.log(u[0] * s.min()) - 1.0, np.log(u[-1] * s.max()) + 1.0
    while hi - lo > 1e-9:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if coverage(mid) < band.LEVEL else (lo, mid)
    return float(np.exp(hi))


_orig_interval = band.interval


def interval(cv_resid, y, pred, fold, test, lev=None) -> dict:
    """Today's interval, with ``q`` the pooled split-conformal quantile under the candidate
    (the same ``sigma``); both rules' held-out coverage logged."""
    iv = _orig_interval(cv_resid, y, pred, fold, test, lev)
    lev = np.zeros(len(y)) if lev is None else np.asarray(lev, float)
    rho = band.autocorrelation(cv_resid, fold)
    sigma = np.sqrt(1.0 + (1.0 + rho) / (1.0 - rho) * np.nan_to_num(lev, nan=0.0))
    q_today, q_pool, q_exp = iv["q"], pooled_q(cv_resid, sigma, fold), expected_q(cv_resid, sigma, fold)
    q_new = {"1": q_pool, "2": q_exp}.get(MODE)
    e = np.abs((y - pred)[test])
    _log({"label": _state["label"], "family": _state["family"],
          **_state["nested"].get(_state["label"], {"nested": False}),
          "q_today": q_today, "q_pooled": q_pool, "q_expected": q_exp, "n_test": int(len(e)),
          "inside_today": int(np.sum(e <= q_today * sigma[test])),
          "inside_pooled": int(np.sum(e <= q_pool * sigma[test])),
          "inside_expected": int(np.sum(e <= q_exp * sigma[test]))})
    if q_new is not None:
        hw = q_new * sigma
        at = hw[test] if np.any(test) else hw
        iv.update({"half_width_um": float(np.median(at)),
                   "half_width_um_range": [float(np.min(at)), float(np.max(at))], "q": q_new,
                   "coverage_test": float(np.mean(e <= hw[test])) if len(e) else None,
                   "method": iv["method"].replace(
                       "q the one-sided 95 % log-normal prediction bound of one more fold's 95 % "
                       "quantile of |CV residual| / sigma from the K folds'",
                       {"1": "q the ceil(0.95 (n + 1))-th smallest of the n pooled |CV "
                             "residual| / sigma (split conformal)",
                        "2": "q at which one more fold's expected coverage of |CV residual| / "
                             "sigma is 95 % (the folds' scale log-normal, Student predictive)"}[MODE]),
                   "per_reading": hw})
    return iv


_orig_family = run._family


def _family(s, label, p, r, room=None, kept=()):
    _state["label"], _state["family"] = label, p.get("family", "?") if isinstance(p, dict) else "?"
    if r is not None:
        _state["family"] = r["choice"]["family"]
    return _orig_family(s, label, p, r, room, kept)


_orig_channel = fit._channel


def _channel(ch, cols, Z, cands, cache):
    """Today's channel; where its family is the lag model, the choice again with the lag
    model's nested CV residuals (RULE.md step 1; the code of ``nested._channel`` with the
    cheaper skip)."""
    out = _orig_channel(ch, cols, Z, cands, cache)
    before = out["choice"]
    if before["family"] != "lag":
        return out
    label = next((l for l, v in ch.s.channels.items() if v is ch.y), "?")
    t0 = time.process_time()
    rn = nested.nested_residuals(ch, cols, Z, cands, cache)
    designs = {"constant": ch.R, "static": fit._static_design(ch), "lag": out["fit"]["design"]}
    orig = family.cv_residuals
    family.cv_residuals = lambda c, D: rn if D is designs["lag"] else orig(c, D)
    try:
        out["choice"] = family.choose(ch, designs, bool(out["terms"]),
                                      fit._nested_in_static(out["terms"]),
                                      regularised=out["shrink"]["cv_resid"])
    finally:
        family.cv_residuals = orig
    out["leverage"] = fit._leverage(ch, out["choice"]["family"], designs, out["shrink"], Z, cache)
    _state["nested"][label] = {"nested": True, "family_before": "lag",
                               "cpu_nested_s": round(time.process_time() - t0, 2),
                               "cv_rms_nested": round(float(np.sqrt(np.nanmean(rn[ch.fold >= 0] ** 2))), 4),
                               "cv_rms_before": round(before["cv_rms_um"]["lag"], 4)}
    return out


def install():
    band.interval = interval
    run._family = _family
    if MODE in ("1", "2"):
        fit._channel = _channel
