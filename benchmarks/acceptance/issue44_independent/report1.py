"""Print a compact table of scen1-style result JSON lists given on the command line."""
import json, sys
for f in sys.argv[1:]:
    txt = open(f).read()
    txt = txt[txt.index('['):]
    for r in json.loads(txt):
        if r.get("rc") != 0:
            print(r["tag"], "rc", r["rc"], r["stderr"][-300:]); continue
        eff = "; ".join("%s lag %s+-%s" % (e.get("covariates"), e.get("lag_s"), e.get("lag_std_s")) for e in r["effects"])
        print("%-28s %-11s mae %.3f rms %.3f floor %.3f/%.3f ratio_rms %.2f ratio_mae %.2f static %.3f const %.3f cov %.3f named %s | %s" % (
            r["tag"], r["family"], r["mae"], r["rms"], r["floor_mae"], r["floor_rms"], r["ratio_rms"], r["ratio_mae"],
            r["static_mae"], r["const_mae"], r["coverage_csv"] or -1, r["lag_terms_named"], eff))
