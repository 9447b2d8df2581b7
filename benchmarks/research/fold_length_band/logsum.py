"""The patch's log (FOLD_LENGTH_LOG) per channel-window: candidate 2 of ../nested_band's q
and this run's q on the same choice, their held-out coverage (before widenings), and the
diagnostics (rho, lambda, CV RMS, median sigma of both fold sets) where logged.
usage: python logsum.py LOG"""
import json
import os
import statistics
import sys

rows = [json.loads(l) for l in open(sys.argv[1])]
print("| window ch | family | K_L | q c2 | q long | cov c2 | cov long | rho 6 / long "
      "| lambda 6 / long | CV RMS 6 / long um | median sigma long CV / held-out |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
ratio, c2, lo, n = [], 0, 0, 0
for r in rows:
    w = os.path.basename(r["json"]).split("_")[1]
    d = lambda a, b, f="%.4g": ("%s / %s" % (f % r[a], f % r[b])) if a in r else "-"
    print("| %s %s | %s | %d | %.3f | %.3f | %.1f %% | %.1f %% | %s | %s | %s | %s |" % (
        w, r["label"], r["family"], r["K_long"], r["q_c2"], r["q_long"],
        100 * r["inside_c2"] / r["n_test"], 100 * r["inside_long"] / r["n_test"],
        d("rho_today", "rho_long"), d("lambda_today", "lambda_long"),
        d("cv_rms_today", "cv_rms_long", "%.3f"), d("median_sigma_long", "median_sigma_test", "%.3g")))
    ratio.append(r["q_long"] / r["q_c2"])
    c2 += r["inside_c2"]; lo += r["inside_long"]; n += r["n_test"]
print("\nq long / q c2: median %.2f, range %.2f-%.2f; pooled coverage c2 %.1f %%, long %.1f %% (%d readings)"
      % (statistics.median(ratio), min(ratio), max(ratio), 100 * c2 / n, 100 * lo / n, n))
