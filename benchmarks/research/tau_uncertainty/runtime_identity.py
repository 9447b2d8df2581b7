"""RULE.md addendum 4, bar 3: the 12 FL runs through ``volerr loop`` with the code before the
range (a tree on PYTHONPATH, BASE) and with it: JSON identical once ``range_k2`` is removed,
predictions CSV byte-identical.

usage: BASE=DIR OUT=DIR python runtime_identity.py   (DIR/volerr: the earlier runtime/)
"""
import json, os, subprocess, sys, filecmp
ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "benchmarks", "acceptance", "issue44_independent"))
import fl
OUT = os.environ["OUT"]; os.makedirs(OUT, exist_ok=True)
fl.D = OUT
fl.SRC = os.path.join(ROOT, "runtime", "data", "fl_thermal_spindle.csv")
files, span = fl.make_files()
def strip(o, seen):
    if isinstance(o, dict):
        if "range_k2" in o: seen.append(o.pop("range_k2"))
        for v in o.values(): strip(v, seen)
    elif isinstance(o, list):
        for v in o: strip(v, seen)
res = []
for dt in (15, 60):
    wins = [("w%d" % k, "%gs:%s" % (k * 0.2 * span, "%gs" % ((k + 1) * 0.2 * span) if k < 4 else ""), files[("full", dt)]) for k in range(5)]
    wins.append(("pub", "100035s:", files[("pub", dt)]))
    for name, hold, f in wins:
        tag = "fl_%s_dt%d" % (name, dt)
        for code in ("base", "new"):
            env = dict(os.environ)
            if code == "base": env["PYTHONPATH"] = os.environ["BASE"]
            js, pr = "%s/%s_%s.json" % (OUT, tag, code), "%s/%s_%s_pred.csv" % (OUT, tag, code)
            subprocess.run([os.path.join(os.path.dirname(sys.executable), "volerr"), "loop", "DMU50", "drift:" + f, "--json", js,
                            "--predictions-out", pr, "--holdout-time", hold], env=env, check=True, capture_output=True)
        a = json.load(open("%s/%s_base.json" % (OUT, tag))); b = json.load(open("%s/%s_new.json" % (OUT, tag)))
        seen = []; strip(b, seen)
        same_json = json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)
        same_pred = filecmp.cmp("%s/%s_base_pred.csv" % (OUT, tag), "%s/%s_new_pred.csv" % (OUT, tag), shallow=False)
        print(tag, "json identical but range_k2:", same_json, "(%d range_k2 keys)" % len(seen), "predictions CSV byte-identical:", same_pred, flush=True)
