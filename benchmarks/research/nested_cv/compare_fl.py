"""FL 15 s baseline against candidate, from run_fl15w.py's fl_rows_<window>.json: per
channel-window family, held-out MAE, bound, coverage; the bar's counts (RULE.md items 1-3).
usage: python compare_fl.py BASE_OUT CAND_OUT [NESTED_LOG]"""
import json
import os
import sys

PUBLISHED = {"ch1": 3.56, "ch2": 3.76, "ch3": 3.70, "ch4": 3.46, "ch5": 4.28}
WINS = ("w0", "w1", "w2", "w3", "w4", "pub")


def rows(d):
    out = {}
    for w in WINS:
        p = os.path.join(d, "fl", "fl_rows_%s.json" % w)
        if os.path.exists(p):
            for r in json.load(open(p)):
                if "ch" in r:
                    out[(w, r["ch"])] = r
    return out


base, cand = rows(sys.argv[1]), rows(sys.argv[2])
log = {}
if len(sys.argv) > 3 and os.path.exists(sys.argv[3]):
    recs = [json.loads(l) for l in open(sys.argv[3])]
    # one record per channel in window order (the driver's order is given by argv order)
    log = recs
keys = [k for k in base if k in cand]
keys.sort(key=lambda k: (WINS.index(k[0]), k[1]))
print("| window ch | family base -> cand | MAE base / cand um | bound um | within base / cand | coverage base / cand |")
print("|---|---|---|---|---|---|")
for k in keys:
    b, c = base[k], cand[k]
    print("| %s %s | %s -> %s | %.3f / %.3f | %.3f | %s / %s | %.3f / %.3f |" % (
        k[0], k[1], b["family"], c["family"], b["mae"], c["mae"], c["bound"],
        "yes" if b["within"] else "NO", "yes" if c["within"] else "NO", b["cov"], c["cov"]))


def band(v):
    return 0.90 <= v <= 0.98


n = len(keys)
wb = sum(base[k]["within"] for k in keys)
wc = sum(cand[k]["within"] for k in keys)
cb = sum(band(base[k]["cov"]) for k in keys)
cc = sum(band(cand[k]["cov"]) for k in keys)
fell = [k for k in keys if base[k]["cov"] >= 0.90 and cand[k]["cov"] < 0.85]
pub = {k[1]: cand[k]["mae"] for k in keys if k[0] == "pub"}
pooled = lambda R: sum(R[k]["cov"] * R[k]["n"] for k in keys) / sum(R[k]["n"] for k in keys)
print()
print("channel-windows compared: %d" % n)
print("1. within the bound: baseline %d, candidate %d" % (wb, wc))
print("2. publication window (candidate): " + ", ".join(
    "%s %.2f (%s %.2f)" % (ch, pub[ch], "<" if pub[ch] < PUBLISHED[ch] else ">=", PUBLISHED[ch])
    for ch in sorted(pub)))
print("3. coverage within 90-98 %%: baseline %d, candidate %d; >= 90 %% on baseline falling "
      "below 85 %%: %s" % (cb, cc, ", ".join("%s %s %.3f -> %.3f" % (k[0], k[1], base[k]["cov"],
                                                                   cand[k]["cov"]) for k in fell) or "none"))
print("pooled coverage: baseline %.3f, candidate %.3f" % (pooled(base), pooled(cand)))
print("families changed: %d" % sum(base[k]["family"] != cand[k]["family"] for k in keys))
