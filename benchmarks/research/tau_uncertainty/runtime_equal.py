"""RULE.md addendum 4, bar 1: the runtime's ranges (``volerr.loop.drift.tau_range``,
``fit["tau_range"]``) against tau_profile.py's P-block-prof (``TAU_PROF=1``) on the same
fits: the 12 FL runs (6 windows x 15 / 60 s) or 8 simulated fits of a44_scen1 (hard seeds
4-5, speed-only 9-10, 15 s and 60 s, forecast window).  Units: s.

usage: python runtime_equal.py fl|fl15|fl60|sim OUTDIR   (prints the worst relative difference)
"""
import os, sys, json, math
os.environ["TAU_PROF"] = "1"
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tau_profile as tp
from volerr.loop.drift import fit as fitmod
from volerr.loop.drift import tau_range
CMP = []
inner = fitmod._channel
def outer(ch, cols, Z, cands, cache):
    r = inner(ch, cols, Z, cands, cache)
    rec = tp.RECORDS[-1]
    mine = [x for x, sp in zip(r["fit"]["tau_range"], r["terms"]) if sp["tau_s"] > 0]
    ref = [(t["Pblockprof"]["lo"], t["Pblockprof"]["hi"]) for t in rec["terms"]]
    n = int(ch.s.train.sum())
    for m, f in zip(mine, ref):
        CMP.append({"n_train": n, "thinned": n > tau_range.THIN_ABOVE, "mine": m, "script": list(f)})
    return r
fitmod._channel = outer
out = sys.argv[2]; os.makedirs(out, exist_ok=True)
if sys.argv[1] == "fl":
    tp.fl_fits(out)
elif sys.argv[1] in ("fl15", "fl60"):          # one sampling of fl_fits (run side by side)
    import fl
    fl.D = out
    fl.SRC = os.path.join(tp.ROOT, "runtime", "data", "fl_thermal_spindle.csv")
    files, span = fl.make_files()
    dt = int(sys.argv[1][2:])
    wins = [("w%d" % k, "%gs:%s" % (k * 0.2 * span, "%gs" % ((k + 1) * 0.2 * span)
                                    if k < 4 else ""), files[("full", dt)]) for k in range(5)]
    wins.append(("pub", "100035s:", files[("pub", dt)]))
    for name, hold, f in wins:
        tp.run(f, os.path.join(out, "fl_%s_dt%d.json" % (name, dt)), hold)
        print("fl_%s_dt%d" % (name, dt), flush=True)
else:
    import a44_scen1 as scen1
    for variant, seed in (("hard", 4), ("hard", 5), ("speedonly", 9), ("speedonly", 10)):
        scen1.VARIANT = variant
        m0 = scen1.make(seed)
        for dt in (15, 60):
            m = m0 if dt == 15 else scen1.decimate(m0, 4)
            path = os.path.join(out, "%s_%d_%d.csv" % (variant, seed, dt))
            scen1.write(m, path)
            span = m["t"][-1]
            tp.run(path, os.path.join(out, "x.json"), "%gs:" % (0.8 * span))
            print(variant, seed, dt, flush=True)
def rel(a, b):
    if a is None or b is None: return 0.0 if a is b else math.inf
    return abs(a - b) / abs(b)
worst = max((max(rel(c["mine"][0], c["script"][0]), rel(c["mine"][1], c["script"][1])) for c in CMP), default=0)
json.dump(CMP, open(os.path.join(out, "compare.json"), "w"), indent=1)
print("terms compared:", len(CMP), "thinned:", sum(c["thinned"] for c in CMP), "worst relative difference:", worst)
