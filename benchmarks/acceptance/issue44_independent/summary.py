"""The acceptance table from the scenario scripts' printed results (out_*.txt).
usage: python summary.py > table.md"""
import glob
import json

print("| fit | family | held-out MAE / RMS um | floor MAE / RMS um | RMS / floor | static MAE | constant MAE | coverage (95 %) | <=1.5x floor | MAE <= 1.05 x min(static, constant) | coverage 90-98 % |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for f in sorted(glob.glob("out_s*.txt")):
    txt = open(f).read()
    try:
        data = json.loads(txt)
    except ValueError:
        continue
    rows = data if isinstance(data, list) else [data]
    for r in rows:
        if not isinstance(r, dict) or "tag" not in r or "floor_rms" not in r:
            continue
        if r.get("rc") != 0:
            print("| %s | exit %s | %s |" % (r["tag"], r.get("rc"), r.get("stderr", "")[:100]))
            continue
        cov = r.get("coverage_csv")
        print("| %s | %s | %.3f / %.3f | %.3f / %.3f | %.2f | %.3f | %.3f | %.3f | %s | %s | %s |" % (
            r["tag"], r["family"], r["mae"], r["rms"], r["floor_mae"], r["floor_rms"],
            r["rms"] / r["floor_rms"], r["static_mae"], r["const_mae"], cov,
            "yes" if r["rms"] <= 1.5 * r["floor_rms"] else "NO",
            "yes" if r["mae"] <= 1.05 * min(r["static_mae"], r["const_mae"]) else "NO",
            "yes" if 0.90 <= cov <= 0.98 else "NO"))
