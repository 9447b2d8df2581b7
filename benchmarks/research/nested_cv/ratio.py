"""Held-out RMS / CV RMS (the CV's optimism) of the lag model and the regularised fit on the
FL 15 s channel-windows of a run (fl_<window>_dt15.json), over the windows where the family
is the one chosen and over all 30; medians and quartiles.
usage: python ratio.py OUT [OUT2]  (with OUT2: the lag model's ratio there beside OUT's)"""
import json
import os
import sys

import numpy as np

WINS = ("w0", "w1", "w2", "w3", "w4", "pub")


def load(d):
    out = {}
    for w in WINS:
        js = json.load(open(os.path.join(d, "fl", "fl_%s_dt15.json" % w)))
        for ch, c in js["channels"].items():
            out[(w, ch)] = c
    return out


def q(v):
    v = np.array(v)
    return "median %.2f (quartiles %.2f-%.2f, range %.2f-%.2f, n %d)" % (
        np.median(v), *np.percentile(v, [25, 75]), v.min(), v.max(), len(v))


for d in sys.argv[1:]:
    J = load(d)
    print(d)
    for fam, key in (("lag", "lag_model"), ("regularised", "regularised")):
        allr = [c[key]["rms_um"] / c[key]["cv_rms_um"] for c in J.values()]
        ch = [c[key]["rms_um"] / c[key]["cv_rms_um"] for c in J.values() if c["family"] == fam]
        print("  %s: chosen %s; all %s" % (fam, q(ch) if ch else "none", q(allr)))
