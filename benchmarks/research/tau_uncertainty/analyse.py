"""The figures of RULE.md from tau_profile.py's records (and the loop's JSON beside them).

usage: python analyse.py SIMDIR FLDIR      (prints the tables of RESULTS.md)
"""
import json
import math
import os
import statistics
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "acceptance", "issue44_independent"))
import a44_scen5 as scen5       # noqa: E402
import a44_sim as sim44          # noqa: E402

PLANTED = (1020.0, 9720.0)
ALL = ("J", "P", "Pprof", "Pnaive", "P+J", "Pblock", "Pblockprof")
VARIANTS = ALL


def rng(t, v):
    """[lo, hi] of term record t under variant v (None ends open: 0 / inf)."""
    if v == "P+J":
        a, b = rng(t, "P"), rng(t, "J")
        return [min(a[0], b[0]), max(a[1], b[1])]
    r = t[v]
    return [r["lo"] if r["lo"] is not None else 0.0,
            r["hi"] if r["hi"] is not None else math.inf]


def coverage(sim):
    print("## Coverage of the planted time constants (fit x planted tau, fits naming a heat term)")
    print("| variant of a44_scen1 | fits | fits naming a heat term | " + " | ".join(VARIANTS) + " |")
    print("|---|---|---|" + "---|" * len(VARIANTS))
    for var in ("hard", "easy", "speedonly"):
        fits = [f for f in sim if f["variant"] == var]
        use = []
        for f in fits:
            rec = f["records"][0]
            heat = [t for t in rec["terms"] if t["source"] == "heat"] if rec["named"] else []
            if heat:
                use.append(heat)
        cells = []
        for v in VARIANTS:
            k = sum(any(rng(t, v)[0] <= tau <= rng(t, v)[1] for t in heat)
                    for heat in use for tau in PLANTED)
            cells.append("%d of %d (%.0f %%)" % (k, 2 * len(use), 100.0 * k / max(2 * len(use), 1)))
        print("| %s | %d | %d | %s |" % (var, len(fits), len(use), " | ".join(cells)))
    for var in ("hard", "easy", "speedonly"):
        k = [sum(any(rng(t, "P")[0] <= tau <= rng(t, "P")[1] for t in f["records"][0]["terms"]
                     if t["source"] == "heat") for f in sim if f["variant"] == var
                 and f["records"][0]["named"]) for tau in PLANTED]
        print("P per planted tau, %s: 1020 s %d, 9720 s %d" % (var, k[0], k[1]))


def _clip(r, g):
    return max(min(r[1], g[1]), g[0]) - min(max(r[0], g[0]), g[1])


def fl_widths(fl):
    print("\n## FL_THERMAL named lags, 15 s (the six windows, five channels)")
    named = [t for f in fl if f["dt"] == 15 for rec in f["records"] if rec["named"]
             for t in rec["terms"]]
    print("named lags: %d" % len(named))
    no_u = [t["basis"] for t in named if t["J"]["u"] is None]
    no_span = [t for t in named if t["J"]["u"] is None and t["J"]["lo"] == t["J"]["hi"]]
    print("today: lag_s.std null %d (of which without a tau_equivalent span either: %d)"
          % (len(no_u), len(no_span)))
    for v in [v for v in VARIANTS if v not in ("J", "P+J")]:
        both = sum(1 for t in named if t[v]["lo"] is None and t[v]["hi"] is None)
        lo_open = sum(1 for t in named if t[v]["lo"] is None and t[v]["hi"] is not None)
        hi_open = sum(1 for t in named if t[v]["hi"] is None and t[v]["lo"] is not None)
        print("%s: without an interval 0; open at both ends (whole grid) %d, open below %d, "
              "open above %d" % (v, both, lo_open, hi_open))
    today = [_clip(rng(t, "J"), t["grid"]) for t in named if not (t in no_span)]
    print("median width today (s, clipped to the grid, %d ranges): %.0f"
          % (len(today), statistics.median(today)))
    for v in [v for v in VARIANTS if v != "J"]:
        w = [_clip(rng(t, v), t["grid"]) for t in named]
        print("median width %s (s, %d ranges): %.0f  (%.2f x today)"
              % (v, len(w), statistics.median(w), statistics.median(w) / statistics.median(today)))
    inside = sum(1 for t in named if rng(t, "P")[0] <= t["tau"] <= rng(t, "P")[1])
    print("P contains the reported tau: %d of %d" % (inside, len(named)))
    print("rho of the FL fits at 15 s: %s" % sorted({round(t["rho"], 3) for t in named}))


def _with_ranges(terms, rec, v):
    """The tester's terms (scen5.terms) with each lagged term's range replaced by variant v
    (tau_u None, eq [lo, hi]); v 'J' leaves them as the JSON states them."""
    by = {t["basis"]: t for t in rec["terms"]}
    out = []
    for t in terms:
        t = dict(t)
        if v != "J" and t["tau"] is not None and t["basis"] in by:
            t["tau_u"], t["eq"] = None, rng(by[t["basis"]], v)
        out.append(t)
    return out


def _agree(a, b, ra, rb, v):
    """scen5's strict rule: same sources and every lagged term matched, both ways."""
    ta, tb = _with_ranges(a, ra, v), _with_ranges(b, rb, v)
    src = {t["src"] for t in ta} == {t["src"] for t in tb}
    lag = (all(_match(t, tb) for t in ta if t["tau"] is not None)
           and all(_match(t, ta) for t in tb if t["tau"] is not None))
    return src, lag


def _match(a, others):
    """scen5.matches with a range that need not contain the reported tau (the profile
    interval of RULE.md is not centred on it)."""
    if a["tau_u"] is None and a["eq"] is not None:
        for b in others:
            if b["src"] == a["src"] and a["eq"][0] <= (b["tau"] or 0.0) <= a["eq"][1]:
                return True
        a = dict(a, eq=None)
    return scen5.matches(a, others)


def decimation(sim, fl, simdir, fldir):
    print("\n## The tester's strict decimation rule with each variant's ranges (not a bar)")
    pairs = []
    for f in sim:
        if f["dt"] == 15:
            g = [x for x in sim if x["tag"] == f["tag"].replace("_dt15_", "_dt60_")][0]
            fa = scen5.terms(os.path.join(simdir, f["tag"] + ".json"))
            fb = scen5.terms(os.path.join(simdir, g["tag"] + ".json"))
            pairs.append((f["variant"], fa[0] == fb[0], fa[2], fb[2],
                          f["records"][0], g["records"][0]))
    for f in fl:
        if f["dt"] == 15:
            g = [x for x in fl if x["tag"] == f["tag"].replace("_dt15", "_dt60")][0]
            for ra in f["records"]:
                rb = [r for r in g["records"] if r["channel"] == ra["channel"]][0]
                a = fl_terms(os.path.join(fldir, f["tag"] + ".json"), ra["channel"])
                b = fl_terms(os.path.join(fldir, g["tag"] + ".json"), ra["channel"])
                fam = a[0] == b[0] or b[0] in a[2] or a[0] in b[2]
                pairs.append(("FL", fam, a[3], b[3], ra, rb))
    print("| set | pairs | " + " | ".join("%s: taus agree / same diagnosis" % v for v in VARIANTS) + " |")
    print("|---|---|" + "---|" * len(VARIANTS))
    for name in ("hard", "easy", "speedonly", "FL"):
        ps = [p for p in pairs if p[0] == name]
        cells = []
        for v in VARIANTS:
            ok = [_agree(p[2], p[3], p[4], p[5], v) for p in ps]
            cells.append("%d / %d" % (sum(l for s, l in ok),
                                      sum(p[1] and s and l for p, (s, l) in zip(ps, ok))))
        print("| %s | %d | %s |" % (name, len(ps), " | ".join(cells)))


def fl_terms(path, ch):
    """fl_decim.terms (that module runs on import): family, named, CV-equivalent families,
    the named terms as scen5.terms reads them."""
    d = json.load(open(path))
    c = d["channels"][ch]
    res = []
    for e in sim44.effects_of(d, ch):
        for t in e.get("terms", []):
            lag = t.get("lag_s") or {}
            res.append(dict(src=tuple(e.get("covariates") or []), basis=t.get("basis"),
                            value=t.get("value"), std=t.get("std"), tau=lag.get("value"),
                            tau_u=lag.get("std"), eq=t.get("tau_equivalent_s"),
                            alts=t.get("alternatives") or []))
    return (c.get("family"), c.get("lag_terms_named"),
            [x["family"] for x in c.get("families_equivalent", [])], res)


def main():
    simdir, fldir = sys.argv[1], sys.argv[2]
    global VARIANTS
    sim = json.load(open(os.path.join(simdir, "records_sim.json")))
    fl = json.load(open(os.path.join(fldir, "records_fl.json")))
    t0 = [t for f in sim for r in f["records"] for t in r["terms"]][0]
    VARIANTS = tuple(v for v in ALL if v == "P+J" or v in t0)
    coverage(sim)
    fl_widths(fl)
    decimation(sim, fl, simdir, fldir)


if __name__ == "__main__":
    main()
