"""Scenario 5b: a shifted window.  Scenario 1 (hard variant, 60 s) with the middle window
40-60 % against 42-62 %; and the forecast 80-100 % against 78-100 %: the same diagnosis by
scen5's strict and lenient rules?   usage: python scen5b.py   (after scen1.py runs)
"""
import json
import os
import a44_sim as sim
import a44_scen5 as scen5


def terms_of(js):
    return scen5.terms(js)


for seed in (1, 2, 3):
    path = os.path.join(sim.OUT, "s1h_seed%d_dt60.csv" % seed)
    span = 162000.0
    for name, a_, b_ in (("middle", (0.40, 0.60), (0.42, 0.62)), ("forecast", (0.80, 1), (0.78, 1))):
        got = []
        for (a, b) in (a_, b_):
            hold = "%gs:%s" % (a * span, "%gs" % (b * span) if b < 1 else "")
            js = os.path.join(sim.OUT, "s5b_seed%d_%s_%g.json" % (seed, name, a))
            rc, so, err, data, cmd = sim.run_loop([path], js, None, ["--holdout-time", hold])
            got.append(terms_of(js))
        (f1, _, t1, e1), (f2, _, t2, e2) = got
        strict = f1 == f2 and all(scen5.matches(x, t1) for x in t2) and all(scen5.matches(x, t2) for x in t1)
        lenient = (f1 == f2 or f1 in e2 or f2 in e1) and all(scen5.matches_lenient(x, t1) for x in t2) \
            and all(scen5.matches_lenient(x, t2) for x in t1)
        print("seed %d %-8s fam %s/%s strict %s lenient %s" % (seed, name, f1, f2, strict, lenient))
        print("    ", [(x["basis"], x["tau_u"]) for x in t1])
        print("    ", [(x["basis"], x["tau_u"]) for x in t2])
