"""RULE.md addendum 4, bar 2, under a shared machine's load: ``bench_loop.py --drift`` run
in one process six times, the range disabled and enabled alternately (off, on, off, ...),
so that both see the same load; each run's CPU (s) and the range's own CPU.

usage: python benchmarks/research/tau_uncertainty/range_cost_ab.py   (from the root)
"""
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
import bench_loop                                   # noqa: E402
from volerr.loop.drift import tau_range             # noqa: E402

ORIG = tau_range.ranges
SPENT = [0.0]


def timed(ch, specs, fit):
    c0 = time.process_time()
    r = ORIG(ch, specs, fit)
    SPENT[0] += time.process_time() - c0
    return r


for k in range(6):
    on = k % 2 == 1
    tau_range.ranges = timed if on else (lambda ch, specs, fit: None)
    SPENT[0] = 0.0
    print("range", "on " if on else "off", end=": ", flush=True)
    bench_loop.drift(100000)
    if on:
        print("  the range's own CPU %.3f s" % SPENT[0], flush=True)
