"""FL_THERMAL at 15 s: per channel-window the family, held-out MAE, the median half-width
(um) and held-out coverage of each run's loop JSON, side by side (markdown).
usage: python fl_table.py LABEL=OUTDIR [LABEL=OUTDIR ...]   (OUTDIR: ACCEPT44_OUT of a run)"""
import json
import os
import sys

runs = [a.split("=", 1) for a in sys.argv[1:]]
print("| window ch | family | MAE um | " + " | ".join("%s hw um / cov" % l for l, _ in runs) + " |")
print("|---" * (3 + len(runs)) + "|")
for w in ("w0", "w1", "w2", "w3", "w4", "pub"):
    js = [json.load(open(os.path.join(d, "fl", "fl_%s_dt15.json" % w))) for _, d in runs]
    for ch in sorted(js[0]["channels"]):
        c0 = js[0]["channels"][ch]
        cells = ["%.2f / %.3f" % (j["channels"][ch]["interval"]["half_width_um"],
                                  j["channels"][ch]["interval"]["coverage_test"]) for j in js]
        print("| %s %s | %s | %.3f | %s |" % (w, ch, c0["family"], c0["mae_after_um"], " | ".join(cells)))
