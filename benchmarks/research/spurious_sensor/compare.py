"""The bar of RULE.md from two runs of the issue-44 tester's drivers (before / after).

usage: python compare.py BEFORE_DIR AFTER_DIR
Each DIR holds the out_*.txt of `benchmarks/acceptance/issue44_independent/` (a44_scen1.py
speedonly seeds 1-8 at 15 s and 60 s, easy and hard seeds 1-3, a44_scen2.py base, constonly,
env3 seeds 1-3, a44_scen34.py 3 and 4 seeds 1-3; `ACCEPT44_OUT=DIR/out`) and, optionally,
out/fl/fl_results.json of fl.py.  Prints per fit the RMS / floor before and after and the
irrelevant sensors (`T_x*`, a room swing plus a random walk) named as effects; then the
counts the bar asks for.  Units um.
"""
import glob
import json
import os
import sys


def fits(d):
    out = {}
    for f in sorted(glob.glob(os.path.join(d, "out_s*.txt"))):
        try:
            rows = json.load(open(f))
        except ValueError:
            continue
        for r in rows if isinstance(rows, list) else [rows]:
            if isinstance(r, dict) and "tag" in r and "floor_rms" in r and r.get("rc") == 0:
                out[r["tag"]] = r
    return out


def irrelevant(d, tag):
    """The irrelevant sensors (T_x*) among the named effects' covariates of the fit's JSON
    (DIR/out/TAG.json, the loop's own output)."""
    path = os.path.join(d, "out", tag + ".json")
    if not os.path.exists(path):
        return ["(no json)"]
    data = json.load(open(path))
    return sorted({c for e in data.get("effects", []) for c in (e.get("covariates") or [])
                   if c.startswith("T_x")})


def main(before, after):
    b, a = fits(before), fits(after)
    worse = named_b = named_a = 0
    print("| fit | RMS / floor before | after | T_x named before | after |")
    print("|---|---|---|---|---|")
    for tag in sorted(set(b) | set(a)):
        rb, ra = b.get(tag), a.get(tag)
        qb = rb["rms"] / rb["floor_rms"] if rb else float("nan")
        qa = ra["rms"] / ra["floor_rms"] if ra else float("nan")
        nb, na = irrelevant(before, tag), irrelevant(after, tag)
        named_b += bool(nb)
        named_a += bool(na)
        if qb <= 1.5 < qa:
            worse += 1
        print("| %s | %.2f | %.2f | %s | %s |" % (tag, qb, qa, " ".join(nb) or "-",
                                               " ".join(na) or "-"))
    within_b = sum(r["rms"] <= 1.5 * r["floor_rms"] for r in b.values())
    within_a = sum(r["rms"] <= 1.5 * r["floor_rms"] for r in a.values())
    print("\nfits: before %d, after %d; within 1.5x floor: before %d, after %d; "
          "within before and above after: %d" % (len(b), len(a), within_b, within_a, worse))
    print("fits naming an irrelevant sensor (T_x*): before %d, after %d" % (named_b, named_a))
    key = "s1s_seed3_dt15_forecast"
    if key in b and key in a:
        print("%s: %.2fx -> %.2fx floor" % (key, b[key]["rms"] / b[key]["floor_rms"],
                                            a[key]["rms"] / a[key]["floor_rms"]))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
