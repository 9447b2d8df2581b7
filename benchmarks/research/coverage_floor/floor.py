"""The per-window coverage a PERFECT model's 95 % band reaches on FL_THERMAL's 30 channel-windows
(issue 44 done-when 4: "the prediction intervals cover 90-98 % of held-out readings at 95 %").

A perfect model leaves only the noise; its band is the noise's exact marginal 95 % interval
(+-1.96 sigma, sigma known: no estimation error at all, which only widens real bands).  Per
channel-window, the noise is taken as a stationary Gaussian AR(1) process with the lag-1
autocorrelation of that channel-window's held-out residuals (the readings the band is judged
on; the CV residuals' rho the loop reports is given beside it) and the window's number of
held-out readings.  The fraction of the window's readings inside the band is then a random
variable: its mean is 0.95, its spread grows with rho (a 20 % window of a 46 h run at
15 s with rho 0.995 holds some ten correlation times).  Returned per channel-window: P(coverage
in [0.90, 0.98]) by simulation (M realisations, a fixed seed); summed over the 30: the expected
number of channel-windows a perfect model gets within 90-98 % (a Poisson-binomial; its 5-95 %
range by simulation of the sum).

Usage: python floor.py DIR  (DIR holds fl_<w>_dt15.json / fl_<w>_dt15_pred.csv as written by
band_per_family/run_fl15.py or nested_cv/run_fl15w.py).  Deterministic (seed 20261207).
"""
import csv
import json
import os
import sys

import numpy as np

WINDOWS = ("w0", "w1", "w2", "w3", "w4", "pub")
M = 2000
Z95 = 1.959963984540054


def held_out(path, ch):
    """(residual um = measured_um - after_um, the chosen model's prediction; half_width_um) of
    the held-out readings of one channel, in time order (the band is after_um +- half_width_um,
    docs/formats.md)."""
    rows = [r for r in csv.DictReader(open(path)) if r["channel"] == ch and r["split"] == "test"]
    rows.sort(key=lambda r: float(r["t_s"]))
    return (np.array([float(r["measured_um"]) - float(r["after_um"]) for r in rows]),
            np.array([float(r["half_width_um"]) for r in rows]))


def lag1(x):
    x = x - x.mean()
    return float(np.dot(x[1:], x[:-1]) / np.dot(x, x))


def coverage_draws(rho, n, rng):
    """(M,) fraction of n readings of a unit AR(1) (stationary) inside +-1.96."""
    e = np.empty((M, n))
    e[:, 0] = rng.standard_normal(M)
    w = rng.standard_normal((M, n)) * np.sqrt(1.0 - rho * rho)
    for i in range(1, n):
        e[:, i] = rho * e[:, i - 1] + w[:, i]
    return (np.abs(e) <= Z95).mean(axis=1)


def main(d):
    rng = np.random.default_rng(20261207)
    table, hits, low, high = [], [], [], []
    for w in WINDOWS:
        js = json.load(open(os.path.join(d, f"fl_{w}_dt15.json")))
        for ch, c in sorted(js["channels"].items()):
            r, hw = held_out(os.path.join(d, f"fl_{w}_dt15_pred.csv"), ch)
            rho = lag1(r)
            cov = coverage_draws(rho, len(r), rng)
            inside = (cov >= 0.90) & (cov <= 0.98)
            hits.append(inside)
            low.append(cov < 0.90)
            high.append(cov > 0.98)
            table.append((w, ch, c["family"], len(r), c["interval"]["rho"], rho,
                          float(np.mean(np.abs(r) <= hw)), float(inside.mean()),
                          float((cov < 0.90).mean()), float((cov > 0.98).mean())))
    print("| window | ch | family | n held out | rho CV | rho held out | coverage today | "
          "perfect model: P(90-98 %) | P(< 90 %) | P(> 98 %) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for t in table:
        print("| %s | %s | %s | %d | %.4f | %.4f | %.3f | %.2f | %.2f | %.2f |" % t)
    total = np.sum(hits, axis=0)          # per realisation: channel-windows within 90-98 %
    today = sum(1 for t in table if 0.90 <= t[6] <= 0.98)
    for name, arr, now in (("below 90 %", low, sum(t[6] < 0.90 for t in table)),
                           ("above 98 %", high, sum(t[6] > 0.98 for t in table))):
        k = np.sum(arr, axis=0)
        print(f"perfect model, channel-windows {name}: expected {k.mean():.1f}, 5-95 % range "
              f"{np.percentile(k, 5):.0f}-{np.percentile(k, 95):.0f}; today's loop: {now}")
    print(f"\nperfect model, channel-windows within 90-98 % of 30: expected "
          f"{total.mean():.1f}, 5-95 % range {np.percentile(total, 5):.0f}-"
          f"{np.percentile(total, 95):.0f}; P(>= 29 of 30) = {np.mean(total >= 29):.4f}; "
          f"P(30 of 30) = {np.mean(total == 30):.4f}")
    print(f"today's loop: {today} of 30")


if __name__ == "__main__":
    main(sys.argv[1])
