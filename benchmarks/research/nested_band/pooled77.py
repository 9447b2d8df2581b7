"""The 77 fits' pooled coverage (RULE.md item 5: the mean of the fits' held-out coverages)
on the baseline and the candidate (run77.sh OUTDIRs), and from the candidate's log
(NESTED_BAND_LOG) the same mean under today's q, the pooled split-conformal q and the
expected-coverage q on the nested choice (unwidened), with each one's fits within 90-98 %.
usage: python pooled77.py BASE_OUT CAND_OUT CAND_LOG"""
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


def line(name, covs):
    covs = [c for c in covs if c is not None]
    print("%s: %d fits, mean coverage %.2f %%, within 90-98 %% %d, below 90 %% %d, above 98 %% %d" % (
        name, len(covs), 100 * sum(covs) / len(covs), sum(0.9 <= c <= 0.98 for c in covs),
        sum(c < 0.9 for c in covs), sum(c > 0.98 for c in covs)))


base, cand = fits(sys.argv[1]), fits(sys.argv[2])
tags = sorted(t for t in base if t in cand)
line("baseline (CSV)", [base[t].get("coverage_csv") for t in tags])
line("candidate (CSV)", [cand[t].get("coverage_csv") for t in tags])
recs = {}
for l in open(sys.argv[3]):
    r = json.loads(l)
    recs.setdefault(os.path.basename(r["json"])[:-5], []).append(r)
for rule in ("today", "pooled", "expected"):
    covs = []
    for t in tags:
        rs = [r for r in recs.get(t, []) if r["n_test"]]
        if rs:
            covs.append(sum(r["inside_" + rule] for r in rs) / sum(r["n_test"] for r in rs))
    line("log, nested choice, q %s (unwidened, the fit's channels pooled)" % rule, covs)
