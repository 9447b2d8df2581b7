"""FL_THERMAL done-when items 1, 2 and 4, run as a user would (independent driver).

Windows: the five 20 % windows of the file's span (training on both sides; the last one is
the forecast, trained before it only), and the publication split (t < 133380 s,
`--holdout-time 100035s:`).  At 15 s (the file) and at 60 s (every 4th reading).
Item 1: every channel's held-out MAE <= 1.05 x min(static, constant) + 0.2 um (the JSON's
baselines); publication MAE below the published best (3.56 3.76 3.70 3.46 4.28 um).
Item 4: the share of held-out readings inside the 95 % interval (predictions CSV), per
channel-window and pooled.  Item 2 compared by scen5.terms / scen5.matches.

usage: python fl.py
"""
import json
import os
import a44_sim as sim
import a44_scen5 as scen5

SRC = os.path.join(sim.ROOT, "runtime", "data", "fl_thermal_spindle.csv")
D = os.path.join(sim.OUT, "fl")
PUBLISHED = {"ch1": 3.56, "ch2": 3.76, "ch3": 3.70, "ch4": 3.46, "ch5": 4.28}


def make_files():
    os.makedirs(D, exist_ok=True)
    lines = open(SRC).read().splitlines()
    head = [l for l in lines if l.startswith("#")]
    body = [l for l in lines if not l.startswith("#")]
    cols, data = body[0], body[1:]
    out = {}
    for dt, step in ((15, 1), (60, 4)):
        full = data[::step]
        pub = [r for r in full if float(r.split(",")[0]) < 133380]
        for name, rows in (("full", full), ("pub", pub)):
            p = os.path.join(D, "fl_%s_dt%d.csv" % (name, dt))
            open(p, "w").write("\n".join(head + [cols] + rows) + "\n")
            out[(name, dt)] = p
    span = float(data[-1].split(",")[0])
    return out, span


def main():
    files, span = make_files()
    rows = []
    for dt in (15, 60):
        wins = [("w%d" % k, "%gs:%s" % (k * 0.2 * span, "%gs" % ((k + 1) * 0.2 * span)
                                        if k < 4 else ""), files[("full", dt)])
                for k in range(5)]
        wins.append(("pub", "100035s:", files[("pub", dt)]))
        for name, hold, f in wins:
            tag = "fl_%s_dt%d" % (name, dt)
            js, pr = os.path.join(D, tag + ".json"), os.path.join(D, tag + "_pred.csv")
            rc, so, err, data, cmd = sim.run_loop([f], js, pr, ["--holdout-time", hold])
            if data is None:
                rows.append(dict(tag=tag, rc=rc, err=err[-500:]))
                continue
            preds = sim.read_predictions(pr)
            for ch in sorted(data["channels"]):
                s = sim.summarise(data, preds, ch)
                bound = 1.05 * min(s["static_mae"], s["const_mae"]) + 0.2
                n = sum(1 for r in preds if r["split"] == "test" and r["channel"] == ch)
                rows.append(dict(tag=tag, ch=ch, family=s["family"], mae=s["mae"],
                                 static=s["static_mae"], const=s["const_mae"], bound=bound,
                                 within=s["mae"] <= bound, cov=s["coverage_csv"], n=n,
                                 pub_ok=(s["mae"] < PUBLISHED[ch]) if name == "pub" else None))
    json.dump(rows, open(os.path.join(D, "fl_results.json"), "w"), indent=1)
    for r in rows:
        if "ch" not in r:
            print(r)
            continue
        print("%-14s %s %-11s mae %6.3f static %6.3f const %6.3f bound %6.3f %s cov %.3f%s" % (
            r["tag"], r["ch"], r["family"], r["mae"], r["static"], r["const"], r["bound"],
            "ok  " if r["within"] else "OVER", r["cov"],
            "" if r["pub_ok"] is None else (" pub<%.2f %s" % (PUBLISHED[r["ch"]], r["pub_ok"]))))
    for dt in (15, 60):
        rs = [r for r in rows if "ch" in r and r["tag"].endswith("dt%d" % dt)]
        inside = sum(r["cov"] * r["n"] for r in rs)
        tot = sum(r["n"] for r in rs)
        print("dt %d: within bound %d of %d; coverage pooled %.3f; per channel-window in 90-98 %%: "
              "%d of %d" % (dt, sum(r["within"] for r in rs), len(rs), inside / tot,
                            sum(0.90 <= r["cov"] <= 0.98 for r in rs), len(rs)))


if __name__ == "__main__":
    main()
