"""fl.py's figures recomputed from the JSON and predictions files its runs left in DIR/out/fl
(the same rule: within bound = MAE <= 1.05 x min(static, constant) + 0.2 um; publication
window below the published best), and the sensors the screen kept out per channel-window.

usage: python fl_table.py DIR [DIR2]   (two dirs: side by side, MAE um)
"""
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "acceptance", "issue44_independent"))
import a44_sim as sim  # noqa: E402

PUBLISHED = {"ch1": 3.56, "ch2": 3.76, "ch3": 3.70, "ch4": 3.46, "ch5": 4.28}
TAGS = ["fl_%s_dt%d" % (w, dt) for dt in (15, 60) for w in ("w0", "w1", "w2", "w3", "w4", "pub")]


def rows(d):
    out = {}
    for tag in TAGS:
        js, pr = (os.path.join(d, "out", "fl", tag + x) for x in (".json", "_pred.csv"))
        if not os.path.exists(js):
            continue
        data, preds = json.load(open(js)), sim.read_predictions(pr)
        screen = data.get("sensor_screen", {})
        for ch in sorted(data["channels"]):
            s = sim.summarise(data, preds, ch)
            bound = 1.05 * min(s["static_mae"], s["const_mae"]) + 0.2
            out[(tag, ch)] = dict(fam=s["family"], mae=s["mae"], within=s["mae"] <= bound,
                                  pub=(s["mae"] < PUBLISHED[ch]) if "_pub_" in tag else None,
                                  out=len(screen.get(ch, {}).get("screened_out", [])))
    return out


def main(dirs):
    rs = [rows(d) for d in dirs]
    print("| channel-window | " + " | ".join("family, MAE um, within, sensors out (%s)" % os.path.basename(d.rstrip("/")) for d in dirs) + " |")
    print("|---|" + "---|" * len(dirs))
    for key in sorted(rs[0], key=lambda k: (TAGS.index(k[0]), k[1])):
        cells = []
        for r in rs:
            v = r.get(key)
            cells.append("-" if v is None else "%s %.3f %s %d%s" % (
                v["fam"], v["mae"], "ok" if v["within"] else "OVER", v["out"],
                "" if v["pub"] is None else (" pub-ok" if v["pub"] else " PUB-ABOVE")))
        print("| %s %s | %s |" % (key[0], key[1], " | ".join(cells)))
    for r, d in zip(rs, dirs):
        for dt in (15, 60):
            sub = [v for k, v in r.items() if k[0].endswith("dt%d" % dt)]
            pub = [v for k, v in r.items() if k[0] == "fl_pub_dt%d" % dt]
            print("%s dt %d: within bound %d of %d; publication below published %d of %d; "
                  "mean MAE %.3f um; channel-windows with a sensor screened out %d" % (
                      d, dt, sum(v["within"] for v in sub), len(sub), sum(v["pub"] for v in pub),
                      len(pub), sum(v["mae"] for v in sub) / max(len(sub), 1),
                      sum(v["out"] > 0 for v in sub)))


if __name__ == "__main__":
    main(sys.argv[1:])
