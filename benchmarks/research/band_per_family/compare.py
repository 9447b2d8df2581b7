"""Baseline vs a variant on the three benchmarks of RULE.md (figures printed; nothing tuned).

usage: python compare.py fl BASE_fl_results.json VAR_fl_results.json
       python compare.py a44 BASE_DIR VAR_DIR          (out_*.txt of run77.sh)
       python compare.py tc BASE.json VAR.json         (accept.py --json-out)
Coverage: the share of held-out readings inside the 95 % interval; MAE um."""
import glob
import json
import os
import sys


def fl(a, b):
    A = {(r["tag"], r["ch"]): r for r in json.load(open(a)) if "ch" in r}
    B = {(r["tag"], r["ch"]): r for r in json.load(open(b)) if "ch" in r}
    for dt in (15, 60):
        keys = sorted(k for k in A if k[0].endswith("dt%d" % dt))
        rows = [(k, A[k]["family"], A[k]["mae"], B[k]["mae"], A[k]["cov"], B[k]["cov"],
                 A[k]["n"]) for k in keys if k in B]
        _report("FL dt %d" % dt, rows)


def a44(a, b):
    def load(d):
        out = {}
        for f in glob.glob(os.path.join(d, "out_s*.txt")):
            try:
                data = json.loads(open(f).read())
            except ValueError:
                continue
            for r in (data if isinstance(data, list) else [data]):
                if isinstance(r, dict) and "tag" in r and r.get("rc") == 0:
                    out[r["tag"]] = r
        return out
    A, B = load(a), load(b)
    rows = [(k, A[k]["family"], A[k]["mae"], B[k]["mae"], A[k]["coverage_csv"],
             B[k]["coverage_csv"], None) for k in sorted(A) if k in B]
    _report("77 fits (%d paired)" % len(rows), rows)


def tc(a, b):
    A, B = json.load(open(a)), json.load(open(b))
    rows = []
    for ra, rb in zip(A, B):
        assert (ra["seed"], ra["split"]) == (rb["seed"], rb["split"])
        for ax in ra["loop"]:
            if ax in ra["mae_um"]["loop"]:
                rows.append(("seed%d %s %s" % (ra["seed"], ra["split"], ax),
                             ra["loop"][ax]["family"], ra["mae_um"]["loop"][ax],
                             rb["mae_um"]["loop"][ax], ra["loop"][ax]["coverage_95"],
                             rb["loop"][ax]["coverage_95"], None))
    _report("turning centre", rows)


def _report(name, rows):
    if not rows:
        return
    print("== %s" % name)
    for k, fam, m0, m1, c0, c1, n in rows:
        flag = "" if m0 == m1 else "  MAE CHANGED"
        flag += "  FELL<85" if c0 >= 0.90 and c1 < 0.85 else ""
        print("%-34s %-11s mae %7.3f -> %7.3f  cov %.3f -> %.3f%s" % (str(k), fam, m0, m1, c0, c1, flag))
    inb = lambda c: 0.90 <= c <= 0.98
    for lab, i in (("baseline", 4), ("variant", 5)):
        cs = [r[i] for r in rows]
        msg = "%s: within 90-98 %% %d of %d (above %d, below %d)" % (
            lab, sum(map(inb, cs)), len(cs), sum(c > 0.98 for c in cs), sum(c < 0.90 for c in cs))
        if all(r[6] for r in rows):
            msg += "; pooled %.4f" % (sum(r[i] * r[6] for r in rows) / sum(r[6] for r in rows))
        print(msg)
    fams = sorted({r[1] for r in rows})
    for f in fams:
        rs = [r for r in rows if r[1] == f]
        print("  %-11s n %2d: in 90-98 %% %d -> %d; above %d -> %d; below %d -> %d" % (
            f, len(rs), sum(inb(r[4]) for r in rs), sum(inb(r[5]) for r in rs),
            sum(r[4] > 0.98 for r in rs), sum(r[5] > 0.98 for r in rs),
            sum(r[4] < 0.90 for r in rs), sum(r[5] < 0.90 for r in rs)))
    print("MAE identical: %s; >=90 %% falling below 85 %%: %d" % (
        all(r[2] == r[3] for r in rows), sum(r[4] >= 0.90 and r[5] < 0.85 for r in rows)))


if __name__ == "__main__":
    {"fl": fl, "a44": a44, "tc": tc}[sys.argv[1]](sys.argv[2], sys.argv[3])
