"""FL_THERMAL figures of RULE.md, baseline against candidate (run_flw.py's rows).
usage: python compare_fl.py BASE_FL_DIR CAND_FL_DIR DT [CAND_LOG]
Per channel-window: family, MAE, bound, within, coverage; the bar's counts; with the log
(NESTED_BAND_LOG of the candidate) the coverage of the nested choice under today's q."""
import glob
import json
import os
import sys

PUBLISHED = {"ch1": 3.561, "ch2": 3.755, "ch3": 3.704, "ch4": 3.461, "ch5": 4.284}
ORDER = ["w0", "w1", "w2", "w3", "w4", "pub"]


def rows(d, dt):
    out = {}
    for w in ORDER:
        p = os.path.join(d, "fl_rows_%s_dt%d.json" % (w, dt))
        if os.path.exists(p):
            for r in json.load(open(p)):
                out[(w, r.get("ch"))] = r
    return out


def counts(rs):
    cov = [r["cov"] for r in rs]
    n = sum(r["n"] for r in rs)
    pooled = sum(r["cov"] * r["n"] for r in rs) / n if n else float("nan")
    return (sum(0.90 <= c <= 0.98 for c in cov), sum(c < 0.90 for c in cov),
            sum(c > 0.98 for c in cov), pooled)


def cpu(d, dt):
    per = {}
    for (w, ch), r in rows(d, dt).items():
        per[w] = r.get("cpu_s")
    return per


def main():
    base, cand, dt = rows(sys.argv[1], int(sys.argv[3])), rows(sys.argv[2], int(sys.argv[3])), int(sys.argv[3])
    keys = [k for k in sorted(base, key=lambda k: (ORDER.index(k[0]), k[1])) if k in cand]
    print("| window ch | family base -> cand | MAE base / cand um | bound um | within base / cand | coverage base / cand | q base / cand |")
    print("|---|---|---|---|---|---|---|")
    for k in keys:
        b, c = base[k], cand[k]
        print("| %s %s | %s -> %s | %.3f / %.3f | %.3f | %s / %s | %.3f / %.3f | %.3g / %.3g |" % (
            k[0], k[1], b["family"], c["family"], b["mae"], c["mae"], b["bound"],
            "yes" if b["within"] else "NO", "yes" if c["within"] else "NO", b["cov"], c["cov"],
            b.get("q") or float("nan"), c.get("q") or float("nan")))
    print()
    for name, d in (("baseline", base), ("candidate", cand)):
        rs = [d[k] for k in keys]
        w, lo, hi, pooled = counts(rs)
        pub = " / ".join("%.2f" % d[("pub", ch)]["mae"] for ch in sorted(PUBLISHED) if ("pub", ch) in d)
        pub_ok = all(d[("pub", ch)]["mae"] < PUBLISHED[ch] for ch in PUBLISHED if ("pub", ch) in d)
        print("%s (dt %d s, %d channel-windows): within the bound %d; coverage within 90-98 %% %d, below 90 %% %d, above 98 %% %d; pooled %.2f %%; publication MAE %s um (all below the published: %s); CPU s per window %s"
              % (name, dt, len(rs), sum(r["within"] for r in rs), w, lo, hi, 100 * pooled, pub,
                 pub_ok, cpu(sys.argv[1] if name == "baseline" else sys.argv[2], dt)))
    print("families changed:", ", ".join("%s %s %s->%s" % (k[0], k[1], base[k]["family"], cand[k]["family"])
                                       for k in keys if base[k]["family"] != cand[k]["family"]) or "none")
    if len(sys.argv) > 4:
        log(sys.argv[4], dt)


def log(path, dt):
    """The candidate's log: per channel-window the coverage under today's q (the nested
    choice alone) and under the pooled q (before widenings)."""
    recs = {}
    for l in open(path):
        r = json.loads(l)
        tag = os.path.basename(r["json"]).replace(".json", "")
        if tag.endswith("_dt%d" % dt):
            recs[(tag.split("_")[1], r["label"])] = r
    for rule in ("today", "pooled"):
        cov = [(r["inside_%s" % rule] / r["n_test"], r["n_test"]) for r in recs.values() if r["n_test"]]
        n = sum(m for _, m in cov)
        print("log, nested choice with q %s (unwidened, %d channel-windows): within 90-98 %% %d, below %d, above %d, pooled %.2f %%" % (
            rule, len(cov), sum(0.9 <= c <= 0.98 for c, _ in cov), sum(c < 0.9 for c, _ in cov),
            sum(c > 0.98 for c, _ in cov), 100 * sum(c * m for c, m in cov) / n))
    nested = [(k, r) for k, r in sorted(recs.items()) if r.get("nested")]
    print("nested channel-windows: %d; CPU of the nested selections %.1f s; %s" % (
        len(nested), sum(r["cpu_nested_s"] for _, r in nested),
        "; ".join("%s %s %s CV RMS %.2f -> %.2f um" % (k[0], k[1], r["family"], r["cv_rms_before"], r["cv_rms_nested"]) for k, r in nested)))
    fams = {}
    for r in recs.values():
        fams.setdefault(r["family"], []).append(r["q_pooled"] / r["q_today"])
    print("q pooled / q today by family (median, range): " + "; ".join(
        "%s %d: %.2f (%.2f-%.2f)" % (f, len(v), sorted(v)[len(v) // 2], min(v), max(v)) for f, v in sorted(fams.items())))


main()
