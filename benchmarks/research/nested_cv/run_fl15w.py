"""band_per_family/run_fl15.py with the windows named on the command line, each window's
rows written to fl_rows_<window>.json as soon as it ends (a long run can be read as it goes),
the CLI's wall time per window recorded, and no 900 s timeout.
usage: ACCEPT44_OUT=DIR [NESTED_CV=1 NESTED_LOG=F PYTHONPATH=this folder] python run_fl15w.py [w0 w1 w2 w3 w4 pub]"""
import json, os, sys, time
REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
D = os.path.join(REPO, "benchmarks", "acceptance", "issue44_independent")
sys.path.insert(0, D); os.chdir(D)
import a44_sim as sim
sim.ROOT = REPO
import fl
fl.SRC = os.path.join(sim.ROOT, "runtime", "data", "fl_thermal_spindle.csv")
files, span = fl.make_files()
wins = [("w%d" % k, "%gs:%s" % (k * 0.2 * span, "%gs" % ((k + 1) * 0.2 * span) if k < 4 else ""),
         files[("full", 15)]) for k in range(5)] + [("pub", "100035s:", files[("pub", 15)])]
want = sys.argv[1:] or [w[0] for w in wins]
for name, hold, f in wins:
    if name not in want:
        continue
    tag = "fl_%s_dt15" % name
    js, pr = os.path.join(fl.D, tag + ".json"), os.path.join(fl.D, tag + "_pred.csv")
    t0 = time.time()
    rc, so, err, data, cmd = sim.run_loop([f], js, pr, ["--holdout-time", hold], timeout=7200)
    wall = time.time() - t0
    rows = []
    if data is None:
        rows.append(dict(tag=tag, rc=rc, err=err[-800:]))
    else:
        preds = sim.read_predictions(pr)
        for ch in sorted(data["channels"]):
            s = sim.summarise(data, preds, ch)
            n = sum(1 for r in preds if r["split"] == "test" and r["channel"] == ch)
            bound = 1.05 * min(s["static_mae"], s["const_mae"]) + 0.2
            rows.append(dict(tag=tag, ch=ch, family=s["family"], mae=s["mae"], static=s["static_mae"],
                             const=s["const_mae"], bound=bound, within=s["mae"] <= bound,
                             cov=s["coverage_csv"], n=n, wall_s=round(wall, 1)))
    json.dump(rows, open(os.path.join(fl.D, "fl_rows_%s.json" % name), "w"), indent=1)
    print(name, "done", round(wall, 1), flush=True)
