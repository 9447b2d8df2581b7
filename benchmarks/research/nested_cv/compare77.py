"""The independent tester's 77 fits, baseline against candidate (run77.sh OUTDIRs): per fit
the family, held-out RMS / floor RMS and coverage; RULE.md item 4 (no fit at or below 1.5 x
its floor on the baseline above it on the candidate); which fits were nested (NESTED_LOG).
usage: python compare77.py BASE_OUT CAND_OUT [NESTED_LOG]"""
import glob
import json
import os
import sys


def fits(d):
    out = {}
    for f in sorted(glob.glob(os.path.join(d, "out_s*.txt"))):
        try:
            data = json.loads(open(f).read())
        except ValueError:
            continue
        for r in data if isinstance(data, list) else [data]:
            if isinstance(r, dict) and "tag" in r and "floor_rms" in r and r.get("rc") == 0:
                out[r["tag"]] = r
    return out


base, cand = fits(sys.argv[1]), fits(sys.argv[2])
nested = {}
if len(sys.argv) > 3 and os.path.exists(sys.argv[3]):
    for l in open(sys.argv[3]):
        r = json.loads(l)
        tag = os.path.basename(r["json"])[:-5] if r.get("json") else "?"
        nested.setdefault(tag, []).append(r)
tags = sorted(t for t in base if t in cand)
band = lambda v: v is not None and 0.90 <= v <= 0.98
print("| fit | nested channels | family base -> cand | RMS / floor base -> cand | coverage base -> cand |")
print("|---|---|---|---|---|")
worse, changed = [], 0
for t in tags:
    b, c = base[t], cand[t]
    rb, rc = b["rms"] / b["floor_rms"], c["rms"] / c["floor_rms"]
    nn = sum(r["nested"] for r in nested.get(t, []))
    if rb <= 1.5 < rc:
        worse.append(t)
    if (b["family"], round(b["mae"], 9), b.get("coverage_csv")) != (c["family"], round(c["mae"], 9), c.get("coverage_csv")):
        changed += 1
        print("| %s | %d | %s -> %s | %.2f -> %.2f | %.3f -> %.3f |" % (
            t, nn, b["family"], c["family"], rb, rc, b["coverage_csv"], c["coverage_csv"]))
print()
print("fits compared: %d (baseline %d, candidate %d); changed (family, MAE or coverage): %d"
      % (len(tags), len(base), len(cand), changed))
print("fits with a nested channel: %d" % sum(1 for t in tags if any(r["nested"] for r in nested.get(t, []))))
print("within 1.5 x floor: baseline %d, candidate %d" % (
    sum(base[t]["rms"] <= 1.5 * base[t]["floor_rms"] for t in tags),
    sum(cand[t]["rms"] <= 1.5 * cand[t]["floor_rms"] for t in tags)))
print("4. at or below 1.5 x floor on the baseline, above on the candidate: %s" % (", ".join(worse) or "none"))
print("coverage within 90-98 %%: baseline %d, candidate %d" % (
    sum(band(base[t].get("coverage_csv")) for t in tags), sum(band(cand[t].get("coverage_csv")) for t in tags)))
