"""Diagnostic (judges nothing): per channel-window the q that would have covered exactly 95 %
of its held-out readings (q* = the ceil(0.95 n)-th smallest held-out abs(y - pred) / sigma,
sigma = half-width / q from the predictions CSV and the rows' q), against today's, the
pooled and the expected-coverage q of the candidate's log.
usage: python qstar.py FL_DIR DT LOG   (FL_DIR: run_flw.py's, with the predictions CSVs)"""
import csv
import json
import math
import os
import statistics
import sys

d, dt, logf = sys.argv[1], int(sys.argv[2]), sys.argv[3]
log = {}
for l in open(logf):
    r = json.loads(l)
    log[(os.path.basename(r["json"]).split("_")[1], r["label"])] = r
ratios = {"today": [], "pooled": [], "expected": []}
print("| window ch | q* / q today | q* / q pooled | q* / q expected |")
print("|---|---|---|---|")
for w in ["w0", "w1", "w2", "w3", "w4", "pub"]:
    q = {r["ch"]: r["q"] for r in json.load(open(os.path.join(d, "fl_rows_%s_dt%d.json" % (w, dt))))}
    sc = {}
    for r in csv.DictReader(open(os.path.join(d, "fl_%s_dt%d_pred.csv" % (w, dt)))):
        if r["split"] == "test":
            sc.setdefault(r["channel"], []).append(
                abs(float(r["measured_um"]) - float(r["after_um"])) * q[r["channel"]] / float(r["half_width_um"]))
    for ch, v in sorted(sc.items()):
        v.sort()
        qs = v[math.ceil(0.95 * len(v)) - 1]
        rec = log[(w, ch)]
        rs = [qs / rec["q_" + k] for k in ("today", "pooled", "expected")]
        for k, x in zip(("today", "pooled", "expected"), rs):
            ratios[k].append(x)
        print("| %s %s | %.2f | %.2f | %.2f |" % (w, ch, *rs))
print()
for k, v in ratios.items():
    v = sorted(v)
    print("q* / q %s: median %.2f, quartiles %.2f-%.2f, range %.2f-%.2f" % (
        k, statistics.median(v), v[len(v) // 4], v[(3 * len(v)) // 4], v[0], v[-1]))
