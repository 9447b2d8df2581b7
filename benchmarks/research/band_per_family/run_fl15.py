"""fl.py's FL_THERMAL windows at 15 s only (the bar's sampling), same rows and fl_results.json.
usage: ACCEPT44_OUT=DIR [BAND_RULE=A PYTHONPATH=this folder] python run_fl15.py"""
import json, os, sys
REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
D = os.path.join(REPO, "benchmarks", "acceptance", "issue44_independent")
sys.path.insert(0, D); os.chdir(D)
import a44_sim as sim
sim.ROOT = REPO
import fl
fl.SRC = os.path.join(sim.ROOT, "runtime", "data", "fl_thermal_spindle.csv")
files, span = fl.make_files()
rows = []
wins = [("w%d" % k, "%gs:%s" % (k * 0.2 * span, "%gs" % ((k + 1) * 0.2 * span) if k < 4 else ""),
         files[("full", 15)]) for k in range(5)] + [("pub", "100035s:", files[("pub", 15)])]
for name, hold, f in wins:
    tag = "fl_%s_dt15" % name
    js, pr = os.path.join(fl.D, tag + ".json"), os.path.join(fl.D, tag + "_pred.csv")
    rc, so, err, data, cmd = sim.run_loop([f], js, pr, ["--holdout-time", hold])
    preds = sim.read_predictions(pr)
    for ch in sorted(data["channels"]):
        s = sim.summarise(data, preds, ch)
        n = sum(1 for r in preds if r["split"] == "test" and r["channel"] == ch)
        bound = 1.05 * min(s["static_mae"], s["const_mae"]) + 0.2
        rows.append(dict(tag=tag, ch=ch, family=s["family"], mae=s["mae"], static=s["static_mae"],
                         const=s["const_mae"], bound=bound, within=s["mae"] <= bound,
                         cov=s["coverage_csv"], n=n))
json.dump(rows, open(os.path.join(fl.D, "fl_results.json"), "w"), indent=1)
print("done", len(rows))
