"""Research version of RULE.md's rule: the lag model's CV residuals with its whole selection
redone without each fold (nested CV / CV+), where today's CV names the lag model.

Installed into the CLI's process by ``sitecustomize.py`` (``NESTED_CV=1``): replaces
``volerr.loop.drift.fit._channel`` by a wrapper that runs today's channel, then (where
``choice["named"]``) the nested residuals and ``family.choose`` again with them.
``NESTED_LOG=FILE``: one JSON line per channel (family before/after, CV RMS, seconds)."""
import dataclasses
import json
import math
import os
import time

import numpy as np

from volerr.loop.drift import basis, family, fit, select as sel
from volerr.loop.drift.engine import Engine


def _fold_view(ch, cache, k):
    """(s_k, fold_k, cache_k): the series with fold k held out too (its own memo copy, the
    outer tau grid), the folds renumbered without k, the engine cache with the outer
    folds' cross-products under their new numbers (shared by the channels)."""
    key = ("nested", k)
    if key not in cache:
        s = ch.s
        fk = ch.fold.copy()
        fk[ch.fold == k] = -1
        fk[ch.fold > k] -= 1
        s_k = dataclasses.replace(s, test=s.test | (ch.fold == k), memo=dict(s.memo))
        s_k.memo[("_tau_grid", s_k.test.tobytes())] = basis.tau_grid(s)
        ck = {}
        for j in range(int(ch.fold.max()) + 1):
            if j == k:
                continue
            j2 = j if j < k else j - 1
            for part in ("fit", "test"):
                if (part, j) in cache:
                    ck[(part, j2)] = cache[(part, j)]
        cache[key] = (s_k, fk, ck)
    return cache[key]


def select_lag(ch, cols, Z, cands, cache):
    """fit._channel's lag selection (forward heat + sensors, backward, refine, significance)
    on the channel ``ch``: (specs, fit dict)."""
    eng = Engine(Z, ch.y, ch.fold, basis.whole_runs(ch.rule), ch.s.run, ch.n_runs, cache,
                 ch.s.zero(ch.y))
    heat_c, sensor_c = cands
    terms = []
    if len(heat_c):
        terms = sel.select_terms(eng, cols, ch.n_runs, cands=heat_c, max_terms=fit.HEAT_TERMS)
    if len(sensor_c):
        terms = terms + sel.select_terms(eng, cols, ch.n_runs, cands=sensor_c, start=terms)
    specs = fit._backward(ch, [fit._spec(cols, t) for t in terms])
    specs = fit._refine_all(ch, specs)
    return fit._significant(ch, specs)


def nested_residuals(ch, cols, Z, cands, cache):
    """(N,) um: fold k predicted by the lag model selected and fitted without fold k."""
    r = np.full(len(ch.y), np.nan)
    first = ch.s.run_zeros(ch.y)
    for k in range(int(ch.fold.max()) + 1):
        s_k, fk, ck = _fold_view(ch, cache, k)
        ch_k = fit.Channel(s_k, ch.y, ch.R, fk, ch.rule)
        specs, _ = select_lag(ch_k, cols, Z, cands, ck)
        D = ch_k.design(specs)
        b = fit._fit(D, ch.y, s_k.train)
        m = ch.fold == k
        if basis.whole_runs(ch.rule):
            pred = first[ch.s.run[m]] + D[m, ch.n_runs:] @ b[ch.n_runs:]
        else:
            pred = D[m] @ b
        r[m] = ch.y[m] - pred
    return r


_orig_channel = fit._channel


def _channel(ch, cols, Z, cands, cache):
    t0 = time.process_time()
    out = _orig_channel(ch, cols, Z, cands, cache)
    t1 = time.process_time()
    before = out["choice"]
    argv = __import__("sys").argv
    rec = {"json": argv[argv.index("--json") + 1] if "--json" in argv else "",
           "label": next((l for l, v in ch.s.channels.items() if v is ch.y), "?"),
           "family_before": before["family"], "named_before": bool(before["named"]),
           "cv_rms_before": {f: round(v, 4) for f, v in before["cv_rms_um"].items()},
           "cpu_channel_s": round(t1 - t0, 2), "nested": False}
    if before["named"]:
        rn = nested_residuals(ch, cols, Z, cands, cache)
        designs = {"constant": ch.R, "static": fit._static_design(ch),
                   "lag": out["fit"]["design"]}
        orig = family.cv_residuals

        def cvr(c, D):
            return rn if D is designs["lag"] else orig(c, D)

        family.cv_residuals = cvr
        try:
            out["choice"] = family.choose(ch, designs, bool(out["terms"]),
                                          fit._nested_in_static(out["terms"]),
                                          regularised=out["shrink"]["cv_resid"])
        finally:
            family.cv_residuals = orig
        out["leverage"] = fit._leverage(ch, out["choice"]["family"], designs, out["shrink"],
                                        Z, cache)
        after = out["choice"]
        rec.update(nested=True, family_after=after["family"], named_after=bool(after["named"]),
                   cv_rms_after={f: round(v, 4) for f, v in after["cv_rms_um"].items()},
                   t_after={f: round(v, 3) for f, v in after["t"].items()},
                   cpu_nested_s=round(time.process_time() - t1, 2))
    log = os.environ.get("NESTED_LOG")
    if log:
        with open(log, "a") as f:
            f.write(json.dumps(rec) + "\n")
    return out


def install():
    fit._channel = _channel
