"""Compare two trees' records of tau_range_probe.py: every pass's RSS, every decision.

    python benchmarks/speed_drift/tau_range_compare.py DIR_A DIR_B

Per file (A the reference):

* passes: the largest difference of an RSS relative to its array's largest; every
  coordinate-pass choice (the argmin of each row: ``_profile``'s) the same in both, and the
  least ratio of a choice's margin (second least RSS minus least, in A) to the largest
  difference between A and B in its row: above 1, no choice sits within the difference;
* intervals: the profile RSS and threshold's largest relative difference, the inside set
  (``rss <= threshold``) the same, and the least ratio of an RSS's distance from the
  threshold to the difference there;
* ends (``ranges``): the largest difference in s, the same as printed (``round(v, 1)`` in the
  JSON, ``{v:.0f}`` on the console), and the least ratio of an end's distance from a rounding
  boundary of either print to its difference.
"""
import math
import pickle
import sys
from pathlib import Path

import numpy as np

A, B = Path(sys.argv[1]), Path(sys.argv[2])


def passes(pa, pb) -> tuple:
    rel, same, ratio = 0.0, True, math.inf
    for a, b in zip(pa, pb, strict=True):
        a = a.reshape(b.shape)             # the no-other-term case: (X,) in A, (1, X) in B
        rel = max(rel, float(np.max(np.abs(b - a)) / max(np.max(np.abs(a)), 1e-300)))
        if b.ndim == 2 and b.shape[0] > 1 and b.shape[1] > 1:     # a pass that chooses
            same &= bool(np.array_equal(np.argmin(a, 1), np.argmin(b, 1)))
            s = np.sort(a, axis=1)
            diff = np.max(np.abs(b - a), axis=1)
            ratio = min(ratio, float(np.min((s[:, 1] - s[:, 0]) / np.maximum(diff, 1e-300))))
    return rel, same, ratio


def intervals(ia, ib) -> tuple:
    rel, same, ratio = 0.0, True, math.inf
    for (xa, ra, ta, _), (xb, rb, tb, _) in zip(ia, ib, strict=True):
        assert np.array_equal(xa, xb)
        rel = max(rel, float(np.max(np.abs(rb - ra)) / np.max(ra)), abs(tb - ta) / ta)
        same &= bool(np.array_equal(ra <= ta, rb <= tb))
        diff = np.abs(rb - ra) + abs(tb - ta)
        ratio = min(ratio, float(np.min(np.abs(ra - ta) / np.maximum(diff, 1e-300))))
    return rel, same, ratio


def ends(ga, gb) -> tuple:
    most, same, ratio = 0.0, True, math.inf
    for a, b in zip(ga, gb, strict=True):
        for ea, eb in zip(a, b, strict=True):
            if ea is None or eb is None:
                same &= (ea is None) == (eb is None)
                continue
            for lo, hi in zip(ea, eb, strict=True):
                if lo is None or hi is None:
                    same &= (lo is None) == (hi is None)
                    continue
                d = abs(hi - lo)
                most = max(most, d)
                same &= round(lo, 1) == round(hi, 1) and f"{lo:.0f}" == f"{hi:.0f}"
                for unit in (0.1, 1.0):          # the JSON's digit, the console's
                    f = lo / unit - math.floor(lo / unit)
                    ratio = min(ratio, abs(f - 0.5) * unit / max(d, 1e-300))
    return most, same, ratio


bad = 0
for fa in sorted(A.glob("*.pkl")):
    ra, rb = pickle.load(open(fa, "rb")), pickle.load(open(B / fa.name, "rb"))
    assert [k for k, _ in ra] == [k for k, _ in rb], fa.name

    def of(rec, kind):
        return [v for k, v in rec if k == kind]
    p = passes(of(ra, "pass"), of(rb, "pass"))
    i = intervals(of(ra, "interval"), of(rb, "interval"))
    e = ends(of(ra, "ranges"), of(rb, "ranges"))
    ok = p[1] and i[1] and e[1]
    bad += not ok
    print(f"{fa.name}: {len(of(ra, 'pass'))} passes, RSS rel diff {p[0]:.1e}, same choices "
          f"{p[1]}, least margin/diff {p[2]:.1e}; {len(of(ra, 'interval'))} intervals, rel "
          f"diff {i[0]:.1e}, same inside {i[1]}, least margin/diff {i[2]:.1e}; ends diff "
          f"{e[0]:.1e} s, printed same {e[1]}, least distance to rounding/diff {e[2]:.1e}")
print("ALL SAME AS PRINTED, EVERY CHOICE THE SAME" if not bad else f"{bad} FILES DIFFER")
