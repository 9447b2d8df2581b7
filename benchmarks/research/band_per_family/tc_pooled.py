"""The turning centre's held-out coverage per axis-split and pooled, from the loop's
predictions CSVs (accept.py's --work DIR: s<seed>_d2/<split>_pred.csv); abs(measured -
after) <= half_width counts as inside.  usage: python tc_pooled.py WORKDIR"""
import csv
import glob
import os
import sys

tot = ins = 0
for p in sorted(glob.glob(os.path.join(sys.argv[1], "s*_d*", "*_pred.csv"))):
    by = {}
    for r in csv.DictReader(open(p)):
        if r["split"] != "test":
            continue
        n, k = by.get(r["channel"], (0, 0))
        ok = abs(float(r["measured_um"]) - float(r["after_um"])) <= float(r["half_width_um"])
        by[r["channel"]] = (n + 1, k + ok)
    for ch, (n, k) in sorted(by.items()):
        print("%s %s %s: %d of %d, %.4f" % (p.split("/")[-2], os.path.basename(p)[:-9], ch, k, n, k / n))
        tot, ins = tot + n, ins + k
print("pooled %d of %d: %.4f" % (ins, tot, ins / tot))
