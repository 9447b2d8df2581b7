"""The profile-likelihood interval of a named time constant, measured beside today's
blocked jackknife on the independent tester's fits and on FL_THERMAL (rule and bar:
RULE.md, written before any figure).

The loop is run in-process through its CLI (``volerr loop DMU50 drift:F --json J
--holdout-time W``) with ``volerr.loop.drift.fit._channel`` wrapped: after each channel the
wrapper records, for every term of the final lag-model fit with tau > 0, today's range (tau
+- 2 u united with ``tau_equivalent_s``) and the profile intervals (variants P and P-naive of
RULE.md).  Nothing of the loop's outputs is changed.

Profile interval (Bates & Watts 1988, Nonlinear Regression Analysis and Its Applications,
6.1; Venzon & Moolgavkar 1988, Appl. Statist. 37, 87-94): {tau : RSS(tau) <= RSS_min (1 +
F(0.95; 1, nu) / nu)}, RSS over the training readings with every coefficient refitted and
the other time constants fixed; nu = n_eff - p, n_eff = n (1 - rho) / (1 + rho) with rho the
lag-1 autocorrelation of the final fit's training residuals (Wilks 2011, Statistical
Methods in the Atmospheric Sciences, 3rd ed., 5.2.4).  Units: time constants s.

usage: python tau_profile.py sim|fl OUTDIR      (writes OUTDIR/records_{sim,fl}.json)
"""
import json
import math
import os
import sys

import numpy as np
from scipy import stats

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
ACC = os.path.join(ROOT, "benchmarks", "acceptance", "issue44_independent")
sys.path.insert(0, ACC)

from volerr.cli import main as cli_main          # noqa: E402
from volerr.loop.drift import basis              # noqa: E402
from volerr.loop.drift import fit as fitmod      # noqa: E402
from volerr.loop.drift import run as runmod      # noqa: E402
from volerr.loop.drift.family import SUB_BLOCKS  # noqa: E402

SUB = 4            # profile points per grid step
PROFILE_OTHERS = os.environ.get("TAU_PROF", "0") == "1"   # variant P-prof
RECORDS = []


def _rho(ch, fit):
    """Lag-1 autocorrelation of the final fit's training residuals (consecutive training
    readings of one run)."""
    tr = ch.s.train
    b = np.r_[fit["zeros"], fit["coef"]]
    e = np.where(tr, ch.y - fit["design"] @ b, 0.0)
    pair = tr[:-1] & tr[1:] & (ch.s.run[:-1] == ch.s.run[1:])
    den = float(e[tr] @ e[tr])
    return float((e[:-1][pair] @ e[1:][pair]) / den) if den > 0 else 0.0


def _interval(x, rss, thr):
    """Hull of {x : rss <= thr} with linearly interpolated ends (ln tau); None = open."""
    inside = np.flatnonzero(rss <= thr)
    a, b = int(inside[0]), int(inside[-1])

    def cross(i, j):          # i inside, j outside
        return x[i] + (thr - rss[i]) / (rss[j] - rss[i]) * (x[j] - x[i])
    lo = None if a == 0 else math.exp(cross(a, a - 1))
    hi = None if b == len(x) - 1 else math.exp(cross(b, b + 1))
    return lo, hi


def profile(ch, specs, fit, i):
    """Variants P and P-naive of RULE.md for term ``i``; and the profile itself."""
    s, y, tr = ch.s, ch.y, ch.s.train
    sp = specs[i]
    grid = basis.tau_grid(s)
    lg = np.log(grid)
    xs = np.linspace(lg[0], lg[-1], SUB * (len(grid) - 1) + 1)
    x = np.unique(np.r_[xs, math.log(sp["tau_s"])])
    x = x[(x >= lg[0] - 1e-12) & (x <= lg[-1] + 1e-12)]
    base = np.column_stack([ch.R] + [fitmod.column(s, o) for j, o in enumerate(specs) if j != i])
    T = np.column_stack([fitmod.column(s, sp, float(math.exp(v))) for v in x])
    rss = np.array(fitmod._trial_rss(base[tr], T[tr], y[tr]))
    D = fit["design"][tr]
    p = int(np.sum(np.any(D != 0, axis=0))) + sum(1 for o in specs if o["tau_s"] > 0)
    n = int(tr.sum())
    rho = _rho(ch, fit)
    out = {"grid": [float(grid[0]), float(grid[-1])], "rho": rho, "n": n, "p": p}
    prof = np.array(profiled(ch, specs, i, x, xs)) if PROFILE_OTHERS else None
    n_blocks = float(SUB_BLOCKS * (int(ch.fold.max()) + 1))
    out["curve"] = {"x": x.tolist(), "rss": rss.tolist(),
                    "prof": None if prof is None else prof.tolist(), "n_blocks": n_blocks}
    for name, r, curve in (("P", rho, rss), ("Pnaive", 0.0, rss), ("Pprof", rho, prof),
                           ("Pblock", None, rss), ("Pblockprof", None, prof)):
        if curve is None:
            continue
        if r is None:            # addendum 2: the paired test's blocks as independent units
            neff = n_blocks
        else:
            neff = n * (1 - r) / (1 + r) if r > 0 else float(n)
        nu = max(neff - p, 1.0)
        thr = curve.min() * (1 + stats.f.ppf(0.95, 1, nu) / nu)
        lo, hi = _interval(x, curve, thr)
        out[name] = {"lo": lo, "hi": hi, "nu": nu}
    return out


def profiled(ch, specs, i, x, xs):
    """Variant P-prof: RSS(tau) with the other lagged terms' time constants re-optimised at
    each tau of term i (one coordinate pass in the terms' order over the grid ``xs``)."""
    s, y, tr = ch.s, ch.y, ch.s.train
    lagged = [j for j, o in enumerate(specs) if j != i and o["tau_s"] > 0]
    Tj = {j: np.column_stack([fitmod.column(s, specs[j], float(math.exp(v))) for v in xs])[tr]
          for j in lagged}
    out = []
    for v in x:
        cur = {j: fitmod.column(s, specs[j])[tr] for j in range(len(specs)) if j != i}
        cur[i] = fitmod.column(s, specs[i], float(math.exp(v)))[tr]
        best = None
        for j in lagged:
            B = np.column_stack([ch.R[tr]] + [cur[k] for k in sorted(cur) if k != j])
            r = np.array(fitmod._trial_rss(B, Tj[j], y[tr]))
            cur[j] = Tj[j][:, int(np.argmin(r))]
            best = float(r.min())
        if best is None:
            B = np.column_stack([ch.R[tr]] + [cur[k] for k in sorted(cur)])
            best = fitmod._trial_rss(B[:, :-1], B[:, -1:], y[tr])[0]
        out.append(best)
    return out


def today(sp, u):
    """Today's stated range: tau +- 2 u (u None: the point) united with tau_equivalent_s."""
    tau = sp["tau_s"]
    lo, hi = (tau - 2 * u, tau + 2 * u) if u is not None else (tau, tau)
    span = runmod._tau_span(sp)
    if span is not None:
        lo, hi = min(lo, span[0]), max(hi, span[1])
    return {"lo": lo, "hi": hi, "u": u}


_orig = fitmod._channel


def _wrapped(ch, cols, Z, cands, cache):
    r = _orig(ch, cols, Z, cands, cache)
    label = [k for k, v in ch.s.channels.items() if v is ch.y]
    terms = []
    for i, sp in enumerate(r["terms"]):
        if not sp["tau_s"] > 0:
            continue
        rec = {"basis": runmod._basis(sp), "source": sp["source"], "tau": sp["tau_s"],
               "J": today(sp, r["fit"]["tau_std"][i])}
        rec.update(profile(ch, r["terms"], r["fit"], i))
        terms.append(rec)
    RECORDS.append({"channel": label[0] if label else None,
                    "named": bool(r["choice"]["named"]), "family": r["choice"]["family"],
                    "terms": terms})
    return r


fitmod._channel = _wrapped


def run(path, js, hold):
    """One loop run; its records (one per channel)."""
    del RECORDS[:]
    try:
        rc = cli_main(["loop", "DMU50", "drift:" + path, "--json", js, "--holdout-time", hold])
    except SystemExit as e:          # the CLI's exit
        rc = e.code
    assert rc in (0, None), rc
    return list(RECORDS)


def sim_fits(out):
    import a44_scen1 as scen1
    res = []
    plan = (("hard", (1, 2, 3)), ("easy", (1, 2, 3)), ("speedonly", range(1, 9)))
    if os.environ.get("TAU_FRESH") == "1":       # RULE.md addendum 3: seeds never measured
        plan = (("hard", range(4, 10)), ("speedonly", range(9, 15)))
    only = os.environ.get("TAU_VARIANTS")
    for variant, seeds in [v for v in plan if not only or v[0] in only.split(",")]:
        scen1.VARIANT = variant
        pre = {"easy": "s1", "hard": "s1h", "speedonly": "s1s"}[variant]
        for seed in seeds:
            m0 = scen1.make(seed)
            for dt in (15, 60):
                m = m0 if dt == 15 else scen1.decimate(m0, 4)
                path = os.path.join(out, "%s_seed%d_dt%d.csv" % (pre, seed, dt))
                scen1.write(m, path)
                span = m["t"][-1]
                for wname, (a, b) in (("forecast", (0.8, 1.0)), ("middle", (0.4, 0.6))):
                    hold = "%gs:%s" % (a * span, ("%gs" % (b * span)) if b < 1 else "")
                    tag = "%s_seed%d_dt%d_%s" % (pre, seed, dt, wname)
                    recs = run(path, os.path.join(out, tag + ".json"), hold)
                    res.append({"tag": tag, "variant": variant, "seed": seed, "dt": dt,
                                "window": wname, "records": recs})
                    print(tag, flush=True)
                    _dump(out, "sim", res)
    return res


def fl_fits(out):
    import fl
    fl.D = out
    fl.SRC = os.path.join(ROOT, "runtime", "data", "fl_thermal_spindle.csv")
    files, span = fl.make_files()
    res = []
    for dt in (15, 60):
        wins = [("w%d" % k, "%gs:%s" % (k * 0.2 * span, "%gs" % ((k + 1) * 0.2 * span)
                                        if k < 4 else ""), files[("full", dt)])
                for k in range(5)]
        wins.append(("pub", "100035s:", files[("pub", dt)]))
        for name, hold, f in wins:
            tag = "fl_%s_dt%d" % (name, dt)
            recs = run(f, os.path.join(out, tag + ".json"), hold)
            res.append({"tag": tag, "dt": dt, "window": name, "records": recs})
            print(tag, flush=True)
            _dump(out, "fl", res)
    return res


def _dump(out, what, res):
    """The records so far (written after every fit)."""
    with open(os.path.join(out, "records_%s.json" % what), "w") as f:
        json.dump(res, f, indent=1)


def main():
    what, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    _dump(out, what, sim_fits(out) if what == "sim" else fl_fits(out))


if __name__ == "__main__":
    main()
