"""Per FL 15 s channel-window of the candidate run: whether nested (NESTED_LOG records, in
the driver's window order and the file's channel order), the lag model's CV RMS un-nested
and nested, its held-out RMS and the ratio held-out / CV RMS each way, family before/after,
CPU of the channel and of its nested selections (s).
usage: python nested_table.py CAND_OUT NESTED_LOG"""
import json
import os
import sys

import numpy as np

WINS = ("w0", "w1", "w2", "w3", "w4", "pub")
recs = [json.loads(l) for l in open(sys.argv[2])]
i = 0
print("| window ch | nested | family before -> after | lag CV RMS un-nested / nested um | lag held-out RMS um | held-out / CV un-nested / nested | CPU channel / nested s |")
print("|---|---|---|---|---|---|---|")
rb, rn, cpu_c, cpu_n = [], [], [], []
for w in WINS:
    js = json.load(open(os.path.join(sys.argv[1], "fl", "fl_%s_dt15.json" % w)))
    for ch in js["channels"]:
        r = recs[i]
        i += 1
        assert r["label"] == ch, (w, ch, r["label"])
        ho = js["channels"][ch]["lag_model"]["rms_um"]
        a = r["cv_rms_before"]["lag"]
        cpu_c.append(r["cpu_channel_s"])
        if r["nested"]:
            b = r["cv_rms_after"]["lag"]
            rb.append(ho / a)
            rn.append(ho / b)
            cpu_n.append(r["cpu_nested_s"])
            print("| %s %s | yes | %s -> %s | %.3f / %.3f | %.3f | %.2f / %.2f | %.1f / %.1f |" % (
                w, ch, r["family_before"], r["family_after"], a, b, ho, ho / a, ho / b,
                r["cpu_channel_s"], r["cpu_nested_s"]))
        else:
            print("| %s %s | no (not named) | %s | %.3f / - | %.3f | %.2f / - | %.1f / - |" % (
                w, ch, r["family_before"], a, ho, ho / a, r["cpu_channel_s"]))
q = lambda v: "median %.2f (quartiles %.2f-%.2f, range %.2f-%.2f, n %d)" % (
    np.median(v), *np.percentile(v, [25, 75]), min(v), max(v), len(v))
print()
print("nested channel-windows: %d of %d" % (len(rn), i))
print("lag model held-out RMS / CV RMS over them: un-nested %s; nested %s" % (q(rb), q(rn)))
print("CPU: channels today %.1f s in all; nested selections %.1f s in all" % (sum(cpu_c), sum(cpu_n)))
