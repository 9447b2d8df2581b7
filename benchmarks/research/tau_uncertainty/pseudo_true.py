"""Where the planted time constants go when the exponent is not the planted one: the
tester's speed-only machine (a44_scen1.py, S1_VARIANT=speedonly, seeds 1-3, 15 s, the first
80 % as training), drift = 6 lag(q, 1020 s) + 14 lag(q, 9720 s) + noise with q =
(S/S_max)^1.3, fitted by least squares on a constant and two lags of (S/S_max)^p for p in
the loop's exponent grid near 1.3 (1.0, 1.5; basis.P_GRID) and at the planted 1.3: the
pair of time constants of least RSS over a geometric grid (60 s to 64800 s, 40 points),
with the tester's own lag (a44_sim.lag).  Diagnostic only (not a rule): the "truth" a
named term's interval is judged against is the planted tau only where the loop's model
family contains the planted model.  Units: s, um.

usage: python pseudo_true.py
"""
import os
import sys

import numpy as np
from scipy.signal import lfilter

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "acceptance", "issue44_independent"))
import a44_scen1 as scen1      # noqa: E402


def lag(x, tau, dt):
    """a44_sim.lag (y0 = x0, y_k = a y_(k-1) + (1 - a) x_k), by a linear filter."""
    a = np.exp(-dt / tau)
    y, _ = lfilter([1 - a], [1, -a], x[1:], zi=[a * x[0]])
    return np.r_[x[0], y]


def main():
    scen1.VARIANT = "speedonly"
    taus = np.geomspace(60, 64800, 40)
    for seed in (1, 2, 3):
        m = scen1.make(seed)
        n = len(m["t"])
        tr = np.arange(n) < int(0.8 * n)
        y = m["d"][tr]
        for p in (1.0, 1.3, 1.5):
            u = (m["S"] / m["S"].max()) ** p
            L = np.array([lag(u, t, 15.0)[tr] for t in taus])
            best = None
            for i in range(len(taus)):
                for j in range(i + 1, len(taus)):
                    A = np.column_stack([np.ones(tr.sum()), L[i], L[j]])
                    r = np.linalg.lstsq(A, y, rcond=None)[1]
                    rss = float(r[0]) if len(r) else np.inf
                    if best is None or rss < best[0]:
                        best = (rss, taus[i], taus[j])
            print("seed %d p %.1f: least RSS %.1f um^2 at tau %.0f s and %.0f s"
                  % (seed, p, best[0], best[1], best[2]))


if __name__ == "__main__":
    main()
