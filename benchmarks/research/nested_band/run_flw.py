"""FL_THERMAL windows at one sampling (``../nested_cv/run_fl15w.py`` with the sampling as an
argument and the CLI's CPU time per window): each window's rows written to
fl_rows_<window>_dt<DT>.json in ACCEPT44_OUT as soon as it ends.
usage: ACCEPT44_OUT=DIR [NESTED_BAND=1 NESTED_BAND_LOG=F PYTHONPATH=this folder]
       python run_flw.py DT [w0 w1 w2 w3 w4 pub]      (DT 15 or 60)"""
import json, os, resource, sys, time
REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
D = os.path.join(REPO, "benchmarks", "acceptance", "issue44_independent")
sys.path.insert(0, D); os.chdir(D)
import a44_sim as sim
sim.ROOT = REPO
import fl
fl.SRC = os.path.join(sim.ROOT, "runtime", "data", "fl_thermal_spindle.csv")
dt = int(sys.argv[1])
files, span = fl.make_files()
wins = [("w%d" % k, "%gs:%s" % (k * 0.2 * span, "%gs" % ((k + 1) * 0.2 * span) if k < 4 else ""),
         files[("full", dt)]) for k in range(5)] + [("pub", "100035s:", files[("pub", dt)])]
want = sys.argv[2:] or [w[0] for w in wins]


def child_cpu():
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


for name, hold, f in wins:
    if name not in want:
        continue
    tag = "fl_%s_dt%d" % (name, dt)
    js, pr = os.path.join(fl.D, tag + ".json"), os.path.join(fl.D, tag + "_pred.csv")
    t0, c0 = time.time(), child_cpu()
    rc, so, err, data, cmd = sim.run_loop([f], js, pr, ["--holdout-time", hold], timeout=7200)
    wall, cpu = time.time() - t0, child_cpu() - c0
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
                             cov=s["coverage_csv"], n=n, q=(s["interval"] or {}).get("q"),
                             wall_s=round(wall, 1), cpu_s=round(cpu, 1)))
    json.dump(rows, open(os.path.join(fl.D, "fl_rows_%s_dt%d.json" % (name, dt)), "w"), indent=1)
    print(name, dt, "done wall", round(wall, 1), "cpu", round(cpu, 1), flush=True)
